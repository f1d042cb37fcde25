#pragma once
// rectification/simulation/sweep.hpp -- a grid of shaker runs, run in parallel.
//
// Takes: a plant, the shake settings, and a grid: frequencies (Hz) x amplitudes (g peak)
//        x directions (unit vectors in sensor axes; the vibration is amplitude * direction,
//        in phase) x static orientations (gravity in sensor axes, g).
// Gives: one SweepRow per condition (measured error, sigma, eq. (3) prediction), computed
//        on `threads` threads (0: all cores) or on the ranks of mpirun (core::dispatch; the
//        rows then reach on_row on rank 0 only); conditions listed in `skip` (already on disk) are not run.
//        A solver failure in one condition is recorded in its row (ok = false, message
//        naming the call and the simulated time); the others go on. With a readout, the
//        noise of condition i is drawn from seed readout.seed + i (independent runs).
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "plant/accelerometer.hpp"
#include "rectification/simulation/shake.hpp"

namespace vrelab::rectification {

struct SweepGrid {
  std::vector<double> frequencies_Hz;
  std::vector<double> amplitudes_g;
  std::vector<Vec3> directions;
  std::vector<Vec3> orientations_g;
  std::size_t size() const {
    return frequencies_Hz.size() * amplitudes_g.size() * directions.size() * orientations_g.size();
  }
  // False (with the reason, naming the list, in *why) for an empty grid, a frequency or an
  // amplitude that is not positive, or a zero direction.
  bool IsValid(std::string* why) const;
};

struct SweepCondition {
  std::size_t index = 0;
  double frequency_Hz = 0, amplitude_g = 0;
  Vec3 direction = Vec3::Zero(), orientation_g = Vec3::Zero();
  vibration::SineVibration vibration() const;  // amplitude |d_i| A, phase 0 or 180 deg
};

// Condition `index` of the grid; the frequency varies fastest, then amplitude, direction,
// orientation.
SweepCondition sweep_condition(const SweepGrid& g, std::size_t index);
// n points from f1 to f2, logarithmically or linearly spaced.
std::vector<double> spaced(double f1, double f2, int n, bool logarithmic);

struct SweepRow {
  SweepCondition condition;
  bool ok = false;
  std::string error;
  double measured_g = 0, sigma_g = 0, predicted_eq3_g = 0;
  double settle_s = 0, wall_s = 0;
  long steps = 0;
};

// Runs every condition not in `skip` (sorted indices). `on_row` is called under a lock, from
// the worker threads (rank 0's under MPI), as rows complete.
// `truth`: the coefficients eq. (3) is evaluated with (for a physical plant, the implied ones).
void run_sweep(const plant::PlantConfig& plant, const plant::Coefficients& truth, const ShakeSettings& settings,
               const SweepGrid& grid,
               const std::vector<std::size_t>& skip, int threads,
               const std::function<void(const SweepRow&)>& on_row);

}  // namespace vrelab::rectification
