#pragma once
// rectification/shake.hpp -- the vibration error measured on the virtual shaker.
//
// Takes: a plant (plant/accelerometer.hpp), the static orientation (gravity in sensor
//        axes, g), a sine vibration (g peak, per-axis phase, frequency in Hz), and the
//        measurement settings.
// Gives: the measured vibration error e = <U/K1 under vibration> - U/K1 at rest (g), its
//        standard uncertainty, and what the measurement did (settling, periods, steps).
//
// The measurement (docs/measurement.md):
//  - baseline: the same plant at rest in the same orientation (its exact equilibrium);
//  - start: the linear periodic steady state (phasor of the linearised plant), so only the
//    transient that the nonlinear terms cause remains;
//  - settling rule: skip ln(1/settle_decay) slowest closed-loop time constants, rounded up
//    to whole periods;
//  - the paper's integral: Q(t) = integral of (U/K1 - baseline) is a state of the ODE, so
//    the mean over whole periods is (Q(t2) - Q(t1)) / (t2 - t1) to the solver's tolerance;
//  - uncertainty: the measuring interval is cut into `blocks` equal runs of whole periods;
//    sigma = standard deviation of the block means / sqrt(blocks), floored at the solver's
//    tolerance times the output amplitude divided by the number of periods.
#include "plant/accelerometer.hpp"
#include "vibration/profile.hpp"

namespace vrelab::rectification {

struct ShakeSettings {
  double relative_tolerance = 1e-10;
  double settle_decay = 1e-7;  // fraction to which transients decay before measuring
  int blocks = 4;              // batch means for the uncertainty
  double min_measure_s = 0.0;  // measure at least this long (whole periods)
  bool IsValid(std::string* error) const;
};

struct SineShakeResult {
  double measured_g = 0;
  double sigma_g = 0;
  double baseline_g = 0;           // U/K1 at rest
  double settle_s = 0;             // skipped before measuring
  double slowest_time_constant_s = 0;
  int periods = 0;                 // measured
  long steps = 0, rhs_evaluations = 0;
};

SineShakeResult shake_sine(const plant::PlantConfig& plant, const Vec3& a_static_g,
                           const vibration::SineVibration& v, const ShakeSettings& s = {});

}  // namespace vrelab::rectification
