#pragma once
// The tests' small campaign: 4 frequencies x 3 amplitudes x 3 directions x 2 orientations = 72
// runs and the default static test, the default design's kinds of run, fewer of them (seconds
// to simulate and diagnose).
#include "validation/diagnosis/campaign.hpp"

namespace vrelab::test {

inline validation::CampaignDesign small_design() {
  validation::CampaignDesign d = validation::default_design();
  d.frequencies_Hz = {10, 100, 400, 1000};
  d.amplitudes_g = {1, 2, 4};
  d.directions = {Vec3(1, 0, 0), Vec3(0, 1, 0), Vec3(1, 1, 0).normalized()};
  return d;
}

}  // namespace vrelab::test
