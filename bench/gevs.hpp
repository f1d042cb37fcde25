// The benchmarks' random profile: GEVS 20 Hz - 2 kHz along IA (14.1 g rms), PSD in g^2/Hz.
#pragma once

#include "vibration/sampled.hpp"

namespace vrelab::bench {

inline vibration::RandomProfile gevs_along_ia() {
  vibration::RandomProfile p;
  vibration::PsdTable t;
  t.rows = {vibration::PsdRow::level(20, 0.026), vibration::PsdRow::level(50, 0.16),
            vibration::PsdRow::level(800, 0.16), vibration::PsdRow::level(2000, 0.026)};
  p.psd[IA] = t;
  return p;
}

}  // namespace vrelab::bench
