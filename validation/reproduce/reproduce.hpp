#pragma once
// validation/reproduce/reproduce.hpp -- the paper's experiment, end to end, on the virtual instrument.
//
// Takes: the ODE plant (the "true" instrument), the static test (positions, error sources,
//        fixed coefficients), the shaker runs (one frequency; amplitudes x directions x
//        static orientations), the confirmation run, the frequency departure grid, the
//        invisible shift c, and the measurement settings (with the lab's readout).
// Gives:
//  1. the static test: readings from the plant settled in each position, the identified
//     coefficients per method, with first-order uncertainty and covariance;
//  2. the confirmation run: the sampled record (rest, then vibration), the measured error,
//     the running integral's slope and eq. (3) from the identified coefficients;
//  3. the amplitude study: per run, the measured error and eq. (3) (corrected, and as
//     printed) from the least-squares coefficients, each with its standard uncertainty; the
//     prediction's uncertainty is g^T Sigma g, g the gradient of eq. (3) in the coefficients
//     (eq. (3) is linear in them) and Sigma their covariance from the static test;
//  4. the departure in frequency: the confirmation condition measured over frequency
//     (sorted), with the quasi-static and the frequency-dependent eq. (3) (plant built from
//     the identified coefficients and the nominal dynamics);
//  5. what no static test can see: a second instrument whose (k0, k2, k_PP, k_OO) differ by
//     c (1, -1, -1, -1) reads the same in every static position; it is shaken along IA, PA
//     and OA, and c is fitted back from the residuals, which should be -c |w|^2 / 2.
// All errors in g; amplitudes in g peak; frequencies in Hz; times in s. With a readout, run i
// of section k (1 amplitude, 2 frequency, 3 invisible) draws its noise from seed
// readout.seed + k * 1000003 + i; the confirmation run from readout.seed.
#include <cstdint>
#include <functional>
#include <ostream>
#include <string>
#include <vector>

#include "plant/accelerometer.hpp"
#include "rectification/simulation/shake.hpp"
#include "validation/identification/static_test.hpp"

namespace vrelab::validation {

struct NamedVector {
  std::string name;  // e.g. "IA", "oblique", "IA up"
  Vec3 v = Vec3::Zero();
};

// A static orientation is gravity in sensor axes, in units of the local g: |a| = 1 g, within
// this. A vector typed with four digits (0.7071) is off by ~1e-4, while a norm of 0 g (no
// gravity) or 10 g (a centrifuge, or m/s^2 typed for g) is not a static test on the earth.
inline constexpr double kGravityNormTolerance_g = 1e-3;

// The confirmation run: the record (rest, then vibration) of one condition. Described as the
// nested table [reproduce.confirmation]; a case names the orientation and the direction by
// their index in [reproduce]'s lists (ConfirmationIndices, through ReproduceLists::apply).
struct ConfirmationSettings {
  NamedVector orientation, direction;
  double amplitude_g = 3.0;
  double record_s = 2.0;  // at rest, and measured under vibration

  template <class V>
  static void Describe(V& v) {
    using S = ConfirmationSettings;
    using core::field;
    v(field("orientation", &S::orientation, "g", core::any_value(), "Gravity in sensor axes during the run, named")
          .set_by("orientation, an index into [reproduce] orientations_g (ReproduceLists)"));
    v(field("direction", &S::direction, "", core::any_value(), "Vibration direction in sensor axes (in phase), named")
          .set_by("direction, an index into [reproduce] directions (ReproduceLists)"));
    v(field("amplitude_g", &S::amplitude_g, "g", core::open_closed(0, 1000), "Peak amplitude along direction"));
    v(field("record_s", &S::record_s, "s", core::open_closed(0, 1e6),
            "Length of the record at rest and of the measured interval (as [shake] min_measure_s)"));
  }
  // The ranges, a direction set (not zero) and an orientation of |a| = 1 g.
  bool IsValid(std::string* why) const;
};

// The experiment's settings. Describe lists each field once (core/settings_description.hpp):
// the case's [reproduce] table (its lists through ReproduceLists below), the JSON record of the
// settings used, and IsValid. The static test, the seed and the measurement come from other
// tables, as their set_by says.
struct ReproduceSettings {
  // Static test (readings: the plant settled in each position).
  std::vector<Position> positions;
  StaticTestErrors errors;
  FixedSet fixed{};
  std::uint64_t seed = 1;
  // Shaker runs: measurement (its readout seed is offset per run) and the grid.
  rectification::ShakeSettings shake;
  double frequency_Hz = 20.0;
  std::vector<double> amplitudes_g;
  std::vector<NamedVector> directions;    // unit vectors, sensor axes (in phase)
  std::vector<NamedVector> orientations;  // gravity in sensor axes, g
  ConfirmationSettings confirmation;
  // The departure in frequency (the confirmation condition); empty: skipped.
  std::vector<double> departure_frequencies_Hz;
  // The invisible shift c (1/g); 0: skipped.
  double invisible_shift_per_g = 0.0;
  int threads = 0;  // 0: all cores

  template <class V>
  static void Describe(V& v) {
    using S = ReproduceSettings;
    using core::field;
    v(field("positions", &S::positions, "", core::any_value(), "The static test's positions on the dividing head")
          .set_by("[dividing_head] positions_per_series (and series), positions or orientations_g"));
    v(field("errors", &S::errors, "", core::any_value(), "The static test's error sources")
          .set_by("[dividing_head] initial_error_arcsec, angle_sigma_arcsec, noise_sigma_ug, repeats"));
    v(field("fixed", &S::fixed, "", core::any_value(), "Coefficients held at a given value, not identified")
          .set_by("[identification] fixed"));
    v(field("seed", &S::seed, "", core::any_value(), "Seed of the static test's draws")
          .set_by("[run] seed"));
    v(field("shake", &S::shake, "", core::any_value(), "Every shaker run's measurement (the readout's seed offset per run)")
          .set_by("the [shake] and [readout] tables"));
    v(field("frequency_Hz", &S::frequency_Hz, "Hz", core::above(0),
            "Frequency of the amplitude study and the confirmation run"));
    // At most 1000 g, as every amplitude of a case (shakers reach ~100 g).
    v(field("amplitudes_g", &S::amplitudes_g, "g", core::open_closed(0, 1000), "Peak amplitudes of the amplitude study"));
    v(field("directions", &S::directions, "", core::any_value(), "Vibration directions in sensor axes, named")
          .set_by("directions and direction_names (ReproduceLists)"));
    v(field("orientations", &S::orientations, "g", core::any_value(), "Static orientations, gravity in sensor axes, named")
          .set_by("orientations_g and orientation_names (ReproduceLists)"));
    v(field("confirmation", &S::confirmation, "", core::any_value(), "The confirmation run"));
    v(field("departure_frequencies_Hz", &S::departure_frequencies_Hz, "Hz", core::above(0),
            "The confirmation condition measured over these frequencies; none: skipped"));
    v(field("invisible_shift_per_g", &S::invisible_shift_per_g, "1/g", core::finite(),
            "c of the second instrument, (k0, k2, k_PP, k_OO) += c (1, -1, -1, -1); 0: skipped"));
    v(field("threads", &S::threads, "threads", core::closed(0, 1024), "Threads of the shaker runs; 0: all cores"));
  }

  // True when the settings describe a run: the described ranges; the amplitude study has
  // amplitudes, directions (none zero) and orientations (each |a| = 1 g); the confirmation run
  // is set; the position set identifies the coefficients not held fixed (full rank). Else
  // false, with the reason (naming the setting) in *why when given.
  bool IsValid(std::string* why) const;
};

// [reproduce.confirmation]'s orientation and direction as a case writes them: 1-based indices
// into [reproduce] orientations_g and directions.
struct ConfirmationIndices {
  int orientation = 1, direction = 1;

  template <class V>
  static void Describe(V& v) {
    using S = ConfirmationIndices;
    using core::field;
    v(field("orientation", &S::orientation, "", core::at_least(1), "The run's orientation: its index in orientations_g, from 1"));
    v(field("direction", &S::direction, "", core::at_least(1), "The run's direction: its index in directions, from 1"));
  }
  bool IsValid(std::string* why) const { return core::validate(*this, why); }
};

// [reproduce]'s lists as a case writes them: the vectors, with their names in a list beside
// them (none: each named by its vector written out), and the confirmation run's condition as
// indices into them. ReproduceSettings holds each vector with its name, so the keys are
// described here, as written, and apply() is the one conversion.
struct ReproduceLists {
  std::vector<Vec3> directions;
  std::vector<std::string> direction_names;
  std::vector<Vec3> orientations_g;
  std::vector<std::string> orientation_names;
  ConfirmationIndices confirmation;

  template <class V>
  static void Describe(V& v) {
    using S = ReproduceLists;
    using core::field;
    v(field("directions", &S::directions, "", core::any_value(),
            "Vibration directions in sensor axes [IA, PA, OA] (normalised; in phase)"));
    v(field("direction_names", &S::direction_names, "", core::any_value(),
            "One name per direction; none: the vector written out"));
    v(field("orientations_g", &S::orientations_g, "g", core::any_value(),
            "Static orientations: gravity in sensor axes [IA, PA, OA], |a| = 1 g"));
    v(field("orientation_names", &S::orientation_names, "", core::any_value(), "One name per orientation"));
    v(field("confirmation", &S::confirmation, "", core::any_value(), "The confirmation run's condition"));
  }
  // The ranges; each list given; a name per vector, none empty; no zero direction; each
  // orientation |a| = 1 g; the indices within their lists. Else false, the reason naming the
  // key ("orientations_g[1] = [0, 0.6, 0.9]: ...", "confirmation.orientation = 3: ...").
  bool IsValid(std::string* why) const;
  // s's directions (normalised), orientations and confirmation orientation and direction
  // from these lists; for lists IsValid accepts.
  void apply(ReproduceSettings& s) const;
};

struct Prediction {
  double value_g = 0, sigma_g = 0;
};

struct RunResult {
  std::string orientation, direction;
  Vec3 orientation_g = Vec3::Zero(), direction_unit = Vec3::Zero();
  double frequency_Hz = 0, amplitude_g = 0;
  double measured_g = 0, sigma_measured_g = 0;
  Prediction predicted;   // corrected eq. (3), least-squares coefficients
  double printed_g = 0;   // eq. (3) as printed, same coefficients
  Prediction at_frequency;  // frequency-dependent eq. (3), same coefficients, nominal dynamics
  double true_eq3_g = 0;  // corrected eq. (3) with the true coefficients (for the record)
  double true_at_frequency_g = 0;  // frequency-dependent, the true plant (its effects included)
  double residual_g() const { return measured_g - predicted.value_g; }
  double combined_sigma_g() const;
  double z() const { return residual_g() / combined_sigma_g(); }
};

// The confirmation run's record and the paper's integral. The running integral of
// (output/K1 - mean at rest) swings by w_IA/omega at the vibration frequency; a straight
// line fitted to it is biased by that swing (shake.integral_slope_g). The slope here is
// fitted with the swing: a line plus the first three harmonics of the vibration frequency
// over the measured interval; `integral_without_oscillation_g_s` is the integral with those
// fitted harmonics taken off from t = 0 on (as p(t) - p(0), p the fitted periodic part).
struct ConfirmationRecord {
  std::vector<double> t_s, output;  // output in output units; rest at t < 0
  std::vector<double> integral_g_s, integral_without_oscillation_g_s;  // g*s
  double K1 = 1, rest_mean_g = 0;
  double t_measure_start_s = 0, t_end_s = 0;
  double integral_slope_g = 0;  // line + harmonics fit over the measured interval, g
  double oscillation_amplitude_g_s = 0;  // of the fitted fundamental in the integral
  rectification::ShakeResult shake;
  Prediction predicted;
};

struct InvisibleResult {
  double c_per_g = 0;
  double max_static_difference_g = 0;  // between the two instruments' settled static outputs
  std::vector<RunResult> runs;         // residual expected: -c |w|^2 / 2
  double c_fit_per_g = 0, c_fit_sigma_per_g = 0;
};

// Agreement statistics of a set of runs against the corrected eq. (3).
struct Agreement {
  std::size_t n = 0, within_2 = 0, within_3 = 0;
  double max_abs_z = 0, rms_residual_g = 0, max_abs_residual_g = 0;
  double median_relative = 0;  // |residual| / |predicted| over runs with |predicted| > 3 sigma_pred
  std::string worst;           // the run with max |z|
};
Agreement agreement(const std::vector<RunResult>& runs);
// "3 g along IA at IA up (20 Hz)": a run in words.
std::string run_label(const RunResult& r);

// What the amplitude study shows, computed from its runs.
struct AmplitudeAnalysis {
  double max_amplitude_g = 0;
  Agreement all, nonzero;                 // nonzero: runs whose prediction is not zero by symmetry
  std::size_t prediction_dominates = 0;   // runs where the prediction's sigma exceeds the measurement's
  // Where the printed eq. (3) departs from the measurement by more than 3 combined sigma.
  std::size_t printed_off_runs = 0;
  double printed_worst_g = 0;             // measured - printed, the largest such
  std::vector<std::string> printed_off_where;  // "<orientation> along <direction>", once each
  // How far the printed form is from the corrected one (largest over the runs), and where.
  double printed_gap_g = 0, printed_gap_sigma_g = 0;
  std::string printed_gap_where;
  // Largest |frequency-dependent - quasi-static| over the runs with a non-zero prediction.
  double frequency_departure_g = 0;
  // Runs at the largest amplitude along the first direction with a non-zero prediction.
  std::vector<std::size_t> growth_runs;   // indices into amplitude_runs
};

// A point of the predicted curves over amplitude (per orientation and direction).
struct CurvePoint {
  std::string orientation, direction;
  double amplitude_g = 0;
  Prediction predicted;
  double printed_g = 0;
};

// The change of a frequency run from the reference run: measured (sigma of the two runs),
// predicted by the frequency-dependent eq. (3) (its own sigma), with the true coefficients.
struct FrequencyChange {
  double measured_g = 0, sigma_measured_g = 0;
  Prediction predicted;
  double true_g = 0;
  double z = 0;  // (measured - predicted) / combined sigma
};

// The departure test over frequency (empty when no frequency runs).
struct DepartureAnalysis {
  std::size_t reference = 0;  // index in frequency_runs: the study's frequency, or the lowest
  double reference_Hz = 0;
  std::vector<FrequencyChange> changes;  // one per frequency run (the reference's is zero)
  std::vector<double> departs_Hz;        // where the measured change exceeds 3 sigma
  double worst_z_change = 0, worst_z_change_Hz = 0, worst_z_true = 0;
  std::vector<RunResult> curve;          // predictions over a log grid around the frequencies
};

struct ReproduceResult {
  plant::Coefficients truth;       // the plant's coefficients
  StaticTestReport static_test;
  plant::Coefficients identified;  // least squares
  plant::PlantConfig nominal;      // identified coefficients, nominal dynamics, no effects
  Propagation identified_uncertainty;
  ConfirmationRecord confirmation;
  std::vector<RunResult> amplitude_runs;
  std::vector<RunResult> frequency_runs;
  InvisibleResult invisible;
  AmplitudeAnalysis amplitude;
  std::vector<CurvePoint> amplitude_curves;
  DepartureAnalysis departure;
};

// Progress messages (one line each) go to `log` when given; with `progress` set, each stage of
// shaker runs draws a core::Progress there (ETA). Throws std::invalid_argument when
// !s.IsValid(). The analysis (agreement, the printed-vs-corrected gap, the departure test,
// the predicted curves) is in the result.
ReproduceResult reproduce(const plant::PlantConfig& truth_plant, const ReproduceSettings& s,
                          const std::function<void(const std::string&)>& log = {},
                          std::ostream* progress = nullptr);

// Fills the predictions of a run (orientation, direction, amplitude, frequency given) from
// the coefficients of `nominal` and their covariance.
void predict_run(RunResult& r, const plant::PlantConfig& nominal,
                 const std::array<CoefArray, plant::kNumCoefficients>& covariance);

// The change of the frequency-dependent eq. (3) from run `ref` to run `r` (same condition,
// another frequency), with its standard uncertainty: the coefficient errors do not cancel in
// it (terms scale differently with frequency), so it has its own sigma.
Prediction predicted_change(const RunResult& r, const RunResult& ref, const plant::PlantConfig& nominal,
                            const std::array<CoefArray, plant::kNumCoefficients>& covariance);

// f(c) with the standard uncertainty sqrt(g^T Sigma g), g its gradient in the coefficients
// (rectification/prediction/gradient.hpp).
Prediction predict_with_uncertainty(const std::function<double(const plant::Coefficients&)>& f,
                                    const plant::Coefficients& c,
                                    const std::array<CoefArray, plant::kNumCoefficients>& covariance);

}  // namespace vrelab::validation
