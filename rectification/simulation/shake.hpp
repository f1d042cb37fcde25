#pragma once
// rectification/simulation/shake.hpp -- the vibration error measured on the virtual shaker.
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
//  - shake_sine by default reaches the periodic steady state directly and measures one
//    period that stands for the `periods` of the layout (docs/performance.md: the deviation
//    from the linear periodic solution, settled or found by shooting); ShakeResult::path
//    says which path ran, "transient" being the rule above;
//  - the paper's integral: Q(t) = integral of (U/K1 - baseline) is a state of the ODE, so
//    the mean over whole periods is (Q(t2) - Q(t1)) / (t2 - t1) to the solver's tolerance;
//  - uncertainty: the measuring interval is cut into `blocks` equal runs of whole periods;
//    sigma = standard deviation of the block means / sqrt(blocks), floored at the solver's
//    tolerance times the output amplitude divided by the number of periods;
//  - with a Readout: the output is sampled synchronously (the rate raised to the next whole
//    number of samples per period), noise and quantisation added, and the error is the mean
//    of the samples over whole periods minus the mean of a record of equal length at rest
//    (recorded first, at t < 0; the vibration starts at t = 0); sigma combines the
//    batch-mean sigmas of both records.
#include <cstdint>
#include <functional>
#include <string>

#include "plant/accelerometer.hpp"
#include "vibration/excitation.hpp"
#include "vibration/profile.hpp"

namespace vrelab::rectification {

// The data acquisition: sampling, noise, quantisation (input-equivalent, g). Off when
// sample_rate_Hz = 0: the measurement then uses the continuous integral Q.
struct Readout {
  double sample_rate_Hz = 0.0;
  double noise_sigma_g = 0.0;       // white, per sample
  double quantisation_lsb_g = 0.0;  // ADC step; 0 = off
  std::uint64_t seed = 1;
  bool active() const { return sample_rate_Hz > 0; }
};

struct ShakeSettings {
  Readout readout;
  double relative_tolerance = 1e-10;
  double settle_decay = 1e-7;  // fraction to which transients decay before measuring
  int blocks = 4;              // batch means for the uncertainty
  double min_measure_s = 0.0;  // measure at least this long (whole periods)
  // shake_sine: reach the periodic steady state directly (docs/performance.md) instead of
  // integrating the settling; false forces the transient path (settle, then measure).
  bool periodic_steady_state = true;
  // shake_excitation with a RandomExcitation: step once per sample with the exact
  // discretisation of the linear loop and an exponential-integrator correction for the
  // nonlinear terms (rectification/simulation/discretised.hpp); false forces CVODE.
  bool exponential_integrator = true;
  // CVODE (the transient path, the random fallback) with the plant's analytic Jacobian where
  // it has one (plant/accelerometer.hpp); false (the default): CVODE's difference
  // quotients. Opt-in: the Jacobian steers only Newton's iteration, but CVODE's
  // steps then differ, and at a case's loose tolerance (rtol 1e-4) the answer moves by the
  // solver's own error (docs/performance.md: 4e-9 g of shake-sine-on-random, 1e-4 sigma).
  bool analytic_jacobian = false;
  bool IsValid(std::string* error) const;
};

struct ShakeResult {
  double measured_g = 0;
  double sigma_g = 0;
  // The paper's method: least-squares slope of the running integral of (U/K1 - baseline).
  // Over L seconds it carries a bias up to 12 w_IA / (omega^2 L^2) from the oscillation, so
  // measured_g (the whole-period mean) is the estimate; the slope is kept for comparison.
  double integral_slope_g = 0;
  std::string method;              // "continuous integral" or "sampled record"
  double sample_rate_Hz = 0;       // sampled record: synchronous with the vibration
  long samples = 0;
  double baseline_g = 0;           // U/K1 at rest
  double settle_s = 0;             // skipped before measuring
  double slowest_time_constant_s = 0;
  int periods = 0;                 // measured
  long steps = 0, rhs_evaluations = 0;
  // How the run reached the state it measured (docs/performance.md): "transient" (settled
  // for settle_s, measured `periods` periods), "settle + one period" or "shooting" (the
  // periodic steady state; one period stands for all, the record is replayed); aperiodic
  // runs: "exponential integrator" (one step per sample) or "CVODE" followed by the reason
  // the exponential integrator did not apply.
  std::string path = "transient";
  int shooting_iterations = 0;  // one-period maps evaluated by the shooting
  double simulated_s = 0;       // time the ODE actually integrated
};

// Called for every sample of the record (time s, dynamic input g, output in output units):
// first the record at rest (t < 0), then the vibration (t >= 0).
using SampleSink = std::function<void(double t_s, const Vec3& input_g, double output)>;

// `input`, when given, replaces the pure sine as the table's motion (shaker imperfections
// on the commanded sine v: it must repeat with v's period); v still sets the periods, the
// phasor start and the prediction.
ShakeResult shake_sine(const plant::PlantConfig& plant, const Vec3& a_static_g, const vibration::SineVibration& v,
                       const ShakeSettings& s = {}, const SampleSink& sink = {},
                       const vibration::Excitation* input = nullptr);

// Any excitation (random, sine-on-random, swept sine): the plant starts at rest in its
// equilibrium, settles for ln(1/settle_decay) slowest time constants with the vibration on,
// then the error is measured over `measure_s` seconds cut into `blocks` equal blocks. The
// plant's own linearisation runs beside it on the same input, and the error is the mean of
// the output minus that linear output: a finite record of random motion has a non-zero
// mean and the loop delays it across the window edges, and neither is rectification (a
// lab does the same, less exactly, with its reference accelerometer and long records).
ShakeResult shake_excitation(const plant::PlantConfig& plant, const Vec3& a_static_g,
                             const vibration::Excitation& input, double measure_s, const ShakeSettings& s = {},
                             const SampleSink& sink = {});

}  // namespace vrelab::rectification
