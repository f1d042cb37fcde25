#pragma once
// validation/diagnosis/diagnose.hpp -- the sim-to-real gap: where it lies, which effect causes it, how
// far it shrinks (docs/diagnose.md).
//
// Takes: a campaign (a lab's static readings and shaker-run summaries, in memory; the lab
//        data format of docs/data-format.md is read by the app) and the nominal dynamics.
// Gives: the identified coefficients; per run the prediction of the nominal simulation (the
//        frequency-dependent eq. (3) of the plant built from the identified coefficients and
//        the nominal dynamics), the gap and its significance; each candidate effect of the
//        library fitted and scored on held-out runs (leave one frequency out); the verdict
//        (no significant gap / explained by <effect> / not explained by any known effect);
//        the held-out gap rms before and after the chosen effect.
//
// The statistics: the predictions share the static test's coefficient errors, so the gap
// vector r has covariance V = diag(sigma_run^2 + (f_model pred)^2) + G Sigma G^T (G: the
// prediction's gradient in the coefficients, Sigma their covariance from the static test,
// f_model the simulation's own relative accuracy). Fits and chi^2 use V.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "plant/accelerometer.hpp"
#include "rectification/measurement/reference.hpp"
#include "validation/diagnosis/effect.hpp"
#include "validation/diagnosis/settings.hpp"
#include "validation/identification/dividing_head.hpp"
#include "validation/identification/identification.hpp"
#include "validation/identification/uncertainty.hpp"
#include "vibration/decorators.hpp"
#include "vibration/profile.hpp"
#include "vibration/random.hpp"

namespace vrelab::validation {

// One static reading: the orientation (gravity in sensor axes, g), the mean output (output
// units) and its standard uncertainty.
struct StaticRecord {
  Vec3 orientation_g = Vec3::Zero();
  double output = 0, sigma_output = 0;
  std::string where;  // file:line, for messages
};

// One shaker run, summarised: a sine of amplitude_g peak along `direction` (unit, sensor
// axes, in phase) at frequency_Hz, the sensor statically at orientation_g; the measured
// vibration error (g) and its standard uncertainty.
struct RunRecord {
  std::string id;
  double frequency_Hz = 0, amplitude_g = 0;
  Vec3 direction = Vec3::UnitX(), orientation_g = Vec3::UnitX();
  double measured_g = 0, sigma_g = 0;
  std::string where;
  // The run's time in the campaign (h from its start; NaN: not given) and the output at rest
  // just before it, over K1, against the reference the measured error is taken from (g; NaN:
  // not given): a bias that drifts shows in both alike (docs/data-format.md, time_h, rest_ug).
  double time_h = NAN, rest_g = NAN;
  // Random and sine-on-random runs (docs/data-format.md): the random part, one PSD table per
  // sensor axis. For a random run (sine_part false) frequency_Hz, amplitude_g and direction
  // only describe it (the PSD's mean frequency, sqrt(2) x its rms, each axis's rms share).
  std::optional<vibration::RandomProfile> random;
  bool sine_part = true;
  // The table's motion as a reference accelerometer measured it (raw records with reference
  // channels, docs/data-format.md): for a sine run its tones, for a random run its Welch PSD;
  // the prediction takes it instead of the commanded motion, and the table-motion effects
  // are not applied to the run (they are measured). Empty: the commanded motion.
  std::optional<rectification::MeasuredMotion> motion;
  vibration::SineVibration vibration() const;
};

// A run's raw record (the virtual lab's, when asked for): time (s) and output (output units),
// the rest at t < 0 then the vibration, with the windows a lab would measure over.
struct RawRecord {
  std::vector<double> t_s, output;
  double rest_from_s = 0, rest_to_s = 0, on_from_s = 0, on_to_s = 0;
};

struct Campaign {
  std::string name;
  std::vector<RawRecord> raw;  // one per run when the runs were recorded raw; else empty
  plant::Dynamics dynamics;  // nominal
  FixedSet fixed{};          // coefficients the identification holds
  std::vector<StaticRecord> statics;
  std::vector<RunRecord> runs;
  std::vector<std::string> skipped;  // runs the reader could not use, each with why
};

// A random run (no sine part) described by its PSD for the grouping of the gap: frequency_Hz
// its mean frequency (integral f G df / integral G df), amplitude_g sqrt(2) x the rms of the
// motion's magnitude, direction each axis's rms share. std::invalid_argument without a random part.
void describe_random_motion(RunRecord& r);

// The table's motion of a run as the prediction takes it: the commanded sine, no imperfection.
TableMotion table_motion(const RunRecord& r);

// What a static test at `positions` (weights, held coefficients) takes up into the identified
// coefficients of an effect that acts at rest, per unit of its parameter (linear effects).
plant::Coefficients taken_up_by_static_test(const Effect& e, const plant::PlantConfig& plant,
                                     const std::vector<Position>& positions, const std::vector<double>& weights,
                                     const FixedSet& fixed);

// The simulation's prediction of one run: eq. (3) through the plant's dynamics, with an
// effect (name, parameter) applied when given. g.
// (e must be in the library; p is its first parameter, the others nominal.)
double predict_run_g(const plant::PlantConfig& nominal, const RunRecord& r, const Effect* e = nullptr, double p = 0);
// The same at every parameter's value (the natural form).
double predict_run_g(const plant::PlantConfig& nominal, const RunRecord& r, const Effect& e, ParameterValues values);

// How a fitted effect's parameter got its value: fitted (with a sigma), chosen (a discrete
// parameter: one of its values), or held at its nominal.
enum class ParameterStatus { fitted, chosen, held };

// One parameter of a fitted effect: its value and sigma (fitted on all runs), or held at its
// nominal (the data do not pin it: its sigma from the data alone would not be smaller than its
// prior width, or its slope is in the span of the others'), with its prior range.
struct FittedParameter {
  std::string name, unit;
  double value = 0, sigma = NAN;
  ParameterStatus status = ParameterStatus::fitted;
  double lower = -INFINITY, upper = INFINITY;  // the prior range
  bool at_bound = false;  // fitted, but ended on the edge of its range (its sigma ignores the edge)
  bool sign_identifiable = true;  // false: the value is a magnitude (EffectParameter::sign_identifiable)
};

struct EffectFit {
  std::string name, parameter, unit;
  double value = 0, sigma = 0;   // fitted on all runs (the first parameter)
  std::vector<FittedParameter> parameters;  // every parameter, the first too
  std::vector<double> values() const;       // every parameter's value
  double evidence = 0;           // held-out chi^2 reduction, summed over folds
  double heldout_chi2 = 0;       // held-out chi^2 with the effect (given the training runs), summed over folds
  // chi^2 of every run with the effect fitted on every run, and its degrees of freedom (the
  // runs less the parameters fitted): the fit's own adequacy, which no parameter's looseness
  // on a fold's training runs can soften (docs/diagnose.md, "The verdict").
  double insample_chi2 = NAN;
  int insample_dof = 0;
  bool at_bound = false;         // the fit ended on the edge of its range (no curvature: no sigma)
  std::string not_ranked;        // why the effect is no candidate (listed after the ranked ones); empty: ranked
};

// Two effects fitted together (additive to first order), when one leaves a gap or a second is still needed.
struct PairFit {
  std::string a, b;
  double pa = 0, pb = 0;         // their parameters, fitted on all runs
  double evidence = 0, heldout_chi2 = 0;
  double insample_chi2 = NAN;    // every run, the pair fitted on every run (n - 2 degrees of freedom)
};

// A lab nuisance (not physics): estimated, removed or allowed for, and reported apart from
// the effects. bias_drift: the rate of the rest readings' line over the campaign's time (ug/h),
// removed from every run with a time; sigma_scale: the factor the stated sigma falls short by,
// from repeated runs or from the gaps no effect explains.
struct Nuisance {
  std::string name, unit;
  double value = 0, sigma = NAN;
  bool estimated = false;  // the data allowed an estimate
  bool applied = false;    // removed from the data (drift) or used to judge the gap (sigma)
  // The data show it beyond chance (reported in the verdict whatever the gap's): the drift's
  // rate beyond 3 sigma of its own estimate (Student's t of the line fit); the stated sigma's
  // overdispersion beyond the chi^2 quantile at the same one-sided level (from repeats; or
  // from the gaps when no effect explains them). docs/diagnose.md, "Lab nuisances".
  bool significant = false;
  std::string note;
};

// A run to add (docs/diagnose.md, "11. Next runs"). purpose "separates": where the tied
// effects are furthest apart; `between` ("A vs B") the pair it separates least; what it
// promises is the rise of the rival's -2 ln L over the truth's when appended, as a normal
// deviate (internal/next_runs.hpp): if_first_sigma with A the truth, if_second_sigma with B,
// separation_sigma the smaller. purpose "locates" (an unexplained gap): `between` says what
// it locates (which axis, frequency band, amplitude law); separation_sigma the gap (|z|) the
// campaign's scaling laws expect there (NaN: none expected).
struct NextRun {
  double frequency_Hz = 0, amplitude_g = 0;
  Vec3 direction = Vec3::UnitX(), orientation_g = Vec3::UnitX();
  double separation_sigma = 0;
  std::string between;  // "A vs B", or what the run locates
  std::string purpose;  // separates, locates
  double if_first_sigma = NAN, if_second_sigma = NAN;  // separates: the rival's rise with A, with B the truth
};

// The effects a diagnosis chose: the best one, or two fitted together when a pair explains the
// gap; none when no effect is ranked.
struct ChosenEffects {
  std::vector<std::string> names;  // at most two
  bool empty() const { return names.empty(); }
  bool operator==(const ChosenEffects&) const = default;
};

// What the diagnosis concludes. explained: by the chosen effect(s); ambiguous: more than one
// effect explains the gap equally well (Diagnosis::ambiguous_with); none: not diagnosed (a
// Diagnosis as constructed).
enum class Verdict { none, no_significant_gap, explained, not_explained, ambiguous };

struct RunDiagnosis {
  double predicted_g = 0, sigma_predicted_g = 0;  // nominal simulation
  double gap_g = 0, sigma_g = 0;                  // measured - predicted; sigma from V's diagonal
  double adjusted_gap_g = 0;  // the gap the static test's coefficient errors cannot take up (all runs)
  double z = 0;               // adjusted_gap_g over the run's own sigma (measurement, simulation accuracy)
  double sigma_simulation_g = 0;  // the simulation's accuracy: model_accuracy x the run's best estimate (docs/diagnose.md, "Covariance")
  double sigma_adjusted_g = 0;    // adjusted_gap_g's own sd with no gap (less than sigma: the coefficients take up a share)
  double heldout_before_g = 0;                    // the gap the coefficient errors cannot take up (nominal), held out
  double heldout_after_g = 0;                     // the same with the chosen effect, fitted without this run's fold
  double heldout_floor_g = 0;  // the rms heldout_before_g has with no gap: noise, simulation accuracy, coefficients' extrapolation
};

struct Diagnosis {
  plant::Coefficients identified;
  Propagation identified_uncertainty;
  std::vector<RunDiagnosis> runs;
  double chi2_nominal = 0;
  int significant_runs = 0;
  bool gap_significant = false;
  double max_abs_z = 0;
  // Where: the significant runs' span, and the gap's scaling with amplitude (power p of
  // |gap| ~ A^p, least squares on the significant runs; 0 when fewer than 3).
  // Also: the run with the largest |z| (peak), the power q of |gap| ~ f^q pooled within
  // (direction, amplitude, orientation) groups, the rms z per direction, and the share of the
  // gap odd in the static a_IA (runs alike but for its sign, where either is significant;
  // NaN without such pairs).
  std::string where, peak;
  double amplitude_power = 0, frequency_power = 0;
  std::vector<std::pair<std::string, double>> rms_z_by_direction;
  double odd_in_a_IA_fraction = NAN;
  std::vector<EffectFit> effects;  // best first (evidence)
  std::vector<PairFit> pairs;      // tried when a significant gap needs a second effect (docs/diagnose.md); best first
  double pair_evidence_margin = 0;  // a pair is chosen only when its evidence beats the best single effect's by this
  ChosenEffects chosen;            // the best effect, or the pair that explains the gap
  std::string folds;               // the cross-validation used
  Verdict verdict = Verdict::none;  // in words (with the nuisances applied): verdict_text
  // An effect (or pair) explains the gap, alone or tied with others.
  bool explained() const { return verdict == Verdict::explained || verdict == Verdict::ambiguous; }
  std::vector<Nuisance> nuisances;        // bias_drift, sigma_scale
  std::vector<std::string> ambiguous_with;  // the effects that explain the gap equally well (empty: not ambiguous)
  std::vector<NextRun> next_runs;         // best first; for an ambiguous or unexplained gap
  const Nuisance* nuisance(const std::string& name) const;
  double rms_before_g = 0, rms_after_g = 0;          // held-out, over all runs
  double rms_before_sigma = 0, rms_after_sigma = 0;  // the same in units of each run's sigma
  // The floor no effect removes: the held-out rms with no gap (RunDiagnosis::heldout_floor_g).
  double rms_floor_g = 0, rms_floor_sigma = 0;
  // 1 - (after above the floor) / (before above the floor), in quadrature; NaN when the gap
  // before is within its floor (nothing to shrink).
  double shrinkage_above_floor() const;
  // The confirmation on the ODE plant (the runs with the largest gaps; coefficients corrected
  // by all runs under the chosen effect): rms of measured - ODE without and with the effect.
  // Only when the gap is explained; runs whose simulation failed are listed (id: why) and left out.
  int resimulated_runs = 0;
  double resimulated_rms_before_g = 0, resimulated_rms_after_g = 0;
  std::vector<std::string> resimulation_failures;
  // Reference channels: the table-motion effects (shaker transverse motion, harmonic
  // distortion, third harmonic, fixture rocking) left out of the candidates because every
  // sine run's motion is measured (they are measured, not fitted), and how many runs have
  // measured motion. In a campaign where only some sine runs have it the effects stay
  // candidates, their hypotheses applied to the other runs only.
  std::vector<std::string> measured_effects;
  int runs_with_measured_motion = 0;
  // The verdict and the held-out shrinkage (brief), or everything found: where, the folds, each
  // effect and pair, the shrinkage, the ODE confirmation (full; wall_s >= 0 is printed).
  // validation/diagnosis/diagnosis_report.cpp.
  std::string BriefReport() const;
  std::string FullReport(double wall_s = -1) const;
};

// The bias drift (diagnose's first step): the rest readings' line over the runs' time (rate in
// ug/h, its sigma, significant beyond Student's t at the nuisances' 3-sigma level, two-sided),
// removed from every run with a time. Fewer than 3 rest readings: not estimated, c unchanged.
Nuisance remove_drift(Campaign& c);

// Told after each effect's fits and folds (done of total; under a lock, one call at a time): a
// progress display. A diagnosis whose stated sigma is scaled fits the effects twice.
using EffectsProgress = std::function<void(std::size_t done, std::size_t total)>;

// threads: the effects' fits and folds on this many threads (0: all cores); the diagnosis is
// the same numbers whatever the count. A caller that diagnoses campaigns in parallel keeps 1.
Diagnosis diagnose(const Campaign& c, const DiagnoseSettings& s = {}, int threads = 1, const EffectsProgress& progress = {});

// The gap a hidden effect makes, as the diagnosis' nominal model sees it (blind's family size;
// docs/blind.md, "Blind's measures"). `with` and `without` are one virtual-lab campaign
// simulated with and without the effect from the same seed (the same noise draws, in the
// static readings and in the runs). Each is seen as diagnose sees a campaign before any
// effect hypothesis: its drift line removed, the coefficients identified from its own static
// readings, the nominal simulation's gap r = measured - predicted. The effect's gap is
// g = r_with - r_without (the noise cancels; what the static test took up of an effect that
// acts at rest is out of it, as it is out of the gap the diagnosis sees), and its
// significance sqrt(g^T V^-1 g), V the covariance diagnose judges `with`'s runs by
// (each run's sigma^2 and (the simulation's relative accuracy x prediction)^2, plus G Sigma G^T: the static
// test's coefficient uncertainty through the nominal prediction). No effect hypothesis is
// used. Throws std::invalid_argument when the campaigns' runs differ or the static readings
// do not determine the coefficients.
double nominal_gap_significance(const Campaign& with, const Campaign& without, const DiagnoseSettings& s = {});

// Each run's held-out nominal residual as diagnose computes it (RunDiagnosis::heldout_before_g:
// measured - predicted less the coefficients' correction from the other folds' runs; its
// folds), for the campaign as given: its drift line removed as diagnose removes it, then each
// run's sigma times sigma_scale (diagnose's sigma_scale when it applied one). The residual is
// affine in the measured values: blind takes it of the campaign with the lab's noise taken out
// (the gap's own held-out residual) and the difference from the diagnosis' is the noise's
// held-out image, its own and through the coefficients' correction (docs/diagnose.md).
std::vector<double> heldout_nominal_gap_g(const Campaign& c, const DiagnoseSettings& s = {}, double sigma_scale = 1);

// What diagnose subtracts from each run's measured_g as the bias drift (the rest readings'
// line at the run's time; 0 for a run without a time or when the line is not estimable), g.
std::vector<double> drift_line_removed_g(const Campaign& c);

}  // namespace vrelab::validation
