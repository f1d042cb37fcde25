#pragma once
// rectification/simulation/work_estimate.hpp -- what a run will cost, before it starts.
//
// Takes: the plant (its fastest pole and slowest time constant, from the linearisation at
//        rest), the highest frequency of the commanded motion, the simulated time, the
//        readout's sample rate and the number of runs, each with the case key that sets it.
// Gives: the estimated ODE steps, samples and memory, and which key drives the largest; and
//        a check against documented limits (docs/case-files.md "Limits"): a Hz/kHz slip
//        (frequency_Hz = 1e9) or a duration of years would otherwise look like a hang.
//
// The estimate is deliberately coarse (within a factor of a few): steps ~ simulated time x
// kStepsPerPeriod x the highest frequency in the problem (drive, plant pole, sample rate: the
// solver resolves each); samples ~ time x sample rate; memory ~ kBytesPerSample per sample
// kept by one run. The limits lie far above every shipped case: the largest, `reproduce
// cases/paper.toml`, is estimated at 1.3e8 steps in all and 0.2 MiB per run (75x and 2e4x
// below); a single shake run at 1e4-4e5 steps (2500x below the per-run limit).
#include <string>

#include "plant/accelerometer.hpp"

namespace vrelab::rectification {

inline constexpr double kStepsPerPeriod = 20;     // an adaptive solver at rtol 1e-10: ~10-40
inline constexpr double kBytesPerSample = 16;     // time and output, double each
inline constexpr double kMaxStepsPerRun = 1e9;   // ~15 min of CPU at ~1e6 steps/s
inline constexpr double kMaxSteps = 1e10;         // all runs: ~3 h of CPU
inline constexpr double kMaxBytes = 4.0 * (1ull << 30);  // 4 GiB

// One kind of run, repeated `runs` times.
struct WorkRequest {
  double simulated_s = 0;        // settling + measuring, per run
  std::string time_key;          // the key that sets the simulated time (e.g. "[vibration] duration_s")
  double drive_Hz = 0;           // highest frequency of the motion
  std::string drive_key;         // e.g. "[vibration] frequency_Hz"
  double sample_rate_Hz = 0;     // 0: continuous integral (no samples kept)
  double runs = 1;
  std::string runs_key;          // e.g. "[sweep] grid" (empty for one run)
  double samples_extra = 0;      // samples that cost no ODE step (e.g. Monte Carlo readings)
  std::string samples_extra_key;
};

struct WorkEstimate {
  double steps = 0, steps_per_run = 0, samples = 0, bytes = 0;  // bytes: one run's record
  double fastest_Hz = 0;  // the highest frequency the solver must resolve
  std::string fastest_key;
  std::string Describe() const;  // "~3.2e+12 ODE steps (... set by ...), ..."
};

// The plant's fastest pole (Hz) and slowest time constant (s) at rest in orientation a_g.
struct PlantTimescales {
  double fastest_pole_Hz = 0;
  double slowest_time_constant_s = 0;
};
PlantTimescales plant_timescales(const plant::PlantConfig& plant, const Vec3& a_static_g);

WorkEstimate estimate_work(const WorkRequest& r, const PlantTimescales& plant);

// Throws std::invalid_argument naming the estimate, the key that drives it and the flag to go
// on anyway, when the estimate exceeds kMaxSteps or kMaxBytes.
void check_work(const WorkEstimate& e, const std::string& flag = "--no-work-limit");

}  // namespace vrelab::rectification
