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

#include "core/settings_description.hpp"
#include "plant/accelerometer.hpp"
#include "vibration/excitation.hpp"
#include "vibration/profile.hpp"

namespace vrelab::rectification {

// The data acquisition: sampling, noise, quantisation (input-equivalent, g). Off when
// sample_rate_Hz = 0: the measurement then uses the continuous integral Q. Describe lists each
// field once (core/settings_description.hpp): the case's [readout] table (noise and LSB written
// in ug, held in g) and the JSON record of the settings used.
struct Readout {
  double sample_rate_Hz = 0.0;
  double noise_sigma_g = 0.0;       // white, per sample
  double quantisation_lsb_g = 0.0;  // ADC step; 0 = off
  std::uint64_t seed = 1;
  bool active() const { return sample_rate_Hz > 0; }

  template <class V>
  static void Describe(V& v) {
    using S = Readout;
    using core::field;
    // 0 (off) is the struct's default; a [readout] table must give a positive rate (the reader).
    v(field("sample_rate_Hz", &S::sample_rate_Hz, "Hz", core::at_least(0),
            "Sampling of the output (synchronous with a sine: raised to whole samples per period); 0: off"));
    v(field("noise_sigma_ug", &S::noise_sigma_g, "ug", core::at_least(0), "White noise per sample, input-equivalent")
          .scaled(1e-6));
    v(field("quantisation_lsb_ug", &S::quantisation_lsb_g, "ug", core::at_least(0),
            "ADC step, input-equivalent; 0: off")
          .scaled(1e-6));
    v(field("seed", &S::seed, "", core::any_value(), "Seed of the noise draws").set_by("[run] seed"));
  }
  bool IsValid(std::string* why) const { return core::validate(*this, why); }
};

// The measurement's settings. Describe lists each field once: the case's [shake] table, the
// JSON record of the settings used; IsValid checks the described ranges.
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

  template <class V>
  static void Describe(V& v) {
    using S = ShakeSettings;
    using core::field;
    v(field("readout", &S::readout, "", core::any_value(), "The data acquisition").set_by("the [readout] table"));
    v(field("relative_tolerance", &S::relative_tolerance, "", core::open(0, 1e-3),
            "CVODE's relative tolerance (1e-4 suits random records)"));
    v(field("settle_decay", &S::settle_decay, "", core::open(0, 1),
            "Transients decay to this fraction before measuring"));
    v(field("blocks", &S::blocks, "blocks", core::closed(2, 1000), "Batch means for the uncertainty"));
    // 1e6 s (11.6 days of simulated vibration) is far beyond any run (the shipped cases ask 2 s).
    v(field("min_measure_s", &S::min_measure_s, "s", core::closed(0, 1e6),
            "Measure at least this long (sine: whole periods)"));
    v(field("periodic_steady_state", &S::periodic_steady_state, "", core::any_value(),
            "Sine: reach the periodic steady state directly; false: settle, then measure"));
    v(field("exponential_integrator", &S::exponential_integrator, "", core::any_value(),
            "Random: one exponential-integrator step per sample; false: CVODE"));
    v(field("analytic_jacobian", &S::analytic_jacobian, "", core::any_value(),
            "CVODE with the plant's analytic Jacobian; false: difference quotients"));
  }
  bool IsValid(std::string* why) const { return core::validate(*this, why); }
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
// lab does the same, less exactly, with its reference accelerometer and long records). The
// motion's deterministic mean (Excitation::mean_g: a rocking fixture's) is real, not the
// record's: its linear output (the linearisation's DC gain) is given back.
ShakeResult shake_excitation(const plant::PlantConfig& plant, const Vec3& a_static_g,
                             const vibration::Excitation& input, double measure_s, const ShakeSettings& s = {},
                             const SampleSink& sink = {});

}  // namespace vrelab::rectification
