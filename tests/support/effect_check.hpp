#pragma once
// Test support for the checks of each effect's prediction against the ODE: the run where every
// effect acts, and the coefficients the static test identifies from an instrument.
#include <vector>

#include "plant/accelerometer.hpp"
#include "validation/diagnosis/campaign.hpp"
#include "validation/identification/dividing_head.hpp"
#include "validation/identification/identification.hpp"

namespace vrelab::test {

// The run where every effect acts: 4 g along IA+PA, the static a_IA +0.71 g.
inline validation::RunRecord strong_run(double frequency_Hz) {
  validation::RunRecord r;
  r.frequency_Hz = frequency_Hz, r.amplitude_g = 4, r.direction = Vec3(1, 1, 0).normalized();
  r.orientation_g = Vec3(1, 0, 1).normalized();
  return r;
}

// What the static test of `instrument` identifies (12 equally spaced positions per series,
// noise-free, k_PP held at 0), as the diagnosis does it.
inline plant::Coefficients identified_by_static_test(const plant::PlantConfig& instrument) {
  const std::vector<validation::Position> positions = validation::equally_spaced_positions(12);
  const std::vector<double> weights(positions.size(), 1.0);
  validation::FixedSet fixed{};
  fixed[plant::k_PP] = 0.0;
  std::vector<validation::Reading> readings;
  const double K1 = instrument.coefficients[plant::K1];
  for (std::size_t i = 0; i < positions.size(); ++i)
    readings.push_back({static_cast<int>(i), K1 * plant::settled_output_g(instrument, positions[i].nominal_g)});
  return validation::least_squares(positions, readings, weights, fixed).estimate.value;
}

}  // namespace vrelab::test
