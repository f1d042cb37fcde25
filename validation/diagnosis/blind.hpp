#pragma once
// validation/diagnosis/blind.hpp -- the blind test of the diagnosis (docs/blind.md):
// campaigns simulated with random hidden effects, diagnosed without their keys, then scored.
//
// Takes: BlindSettings (how many campaigns, the seed of the draw, threads, the diagnosis' settings).
// Gives: BlindResult: per campaign its key (category, hidden effects), what diagnose called it
//        and the diagnosis; the scores against the keys (top-1 attribution of single
//        in-library effects, false alarms on clean campaigns, out-of-library effects called
//        unexplained, two-effect campaigns, the median held-out shrinkage), the confusion
//        matrix, and the campaigns scored wrong with why. The draw depends on the seed only:
//        campaign i is seeded seed * 1000003 + i whatever the threads.
//
// The mix, per 12 campaigns (the families, scored apart): 2 clean, 1 out of library
// (shaker_third_harmonic, or readout_clipping every other twelve), 1 with two library effects
// ("pair"), 1 whose stated sigma is understated (the scatter 1.8-3 times it, no effect),
// 1 with a bias drift (0.2-2 ug/h either sign over the campaign, no effect), 6 with one
// library effect in its default form ("single"). Every campaign's runs carry their time
// (3 min a run, in the design's order) and a rest reading before each (sigma 0.3 ug), as a
// lab's log would. The nuisances are the lab's data acquisition's: applied to the runs'
// summaries, not to the physics (which stays the ODE's).
// A single effect (or a natural form) whose gap, as the diagnosis' nominal model sees it, is
// below 5 sigma (effect_gap_sigma) is reported, not scored; the largest run's size (the
// largest run's gap in its own sigma, effect_max_sigma) is scored beside it
// (BlindScores::by_max_run_sigma).
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <map>
#include <random>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "validation/diagnosis/campaign.hpp"
#include "validation/diagnosis/diagnose.hpp"

namespace vrelab::validation {

struct BlindSettings {
  int n = 40;
  std::uint64_t seed = 7;
  int threads = 0;
  bool mixed = false;  // every campaign on a mixed sine, random and sine-on-random design (blind_design)
  DiagnoseSettings diagnose;

  // Each field once (core/settings_description.hpp).
  template <class V>
  static void Describe(V& v) {
    using S = BlindSettings;
    using core::field;
    v(field("n", &S::n, "campaigns", core::at_least(1), "Number of campaigns"));
    v(field("seed", &S::seed, "", core::any_value(), "Seed of the draw"));
    v(field("threads", &S::threads, "threads", core::at_least(0), "Threads (0: all cores; under mpirun per rank, 0 = 1)"));
    v(field("mixed", &S::mixed, "", core::any_value(),
            "Every campaign on a design of its own that mixes sine, random and sine-on-random runs (docs/blind.md)"));
    v(field("diagnose", &S::diagnose, "", core::any_value(), "Each campaign's diagnosis"));
  }
  // False with `why` naming the field ("diagnose.x" for a diagnosis setting), its value and rule.
  bool IsValid(std::string* why) const;
};

// One blind campaign: its key, and what the diagnosis made of it without the key.
struct BlindCampaign {
  int index = 0;
  std::uint64_t seed = 0;
  std::string category;  // clean, single, two, out_of_library
  bool mixed = false;    // its design: the default sine design, or a mixed one (blind_design)
  std::vector<HiddenEffect> hidden;
  double noise_scale = 1;     // the runs' scatter over their stated sigma (sigma_understated)
  double drift_g_per_h = 0;   // the bias drift (drift)
  // dynamics_off: the manifest's nominal dynamics against the truth's (a lab's estimate): its
  // crossover and pendulum frequency as ratios to the truth's, its phase margin's offset (deg).
  double manifest_crossover_ratio = 1, manifest_pendulum_ratio = 1, manifest_margin_offset_deg = 0;
  Diagnosis diagnosis;
  std::string error;     // the simulation or diagnosis failed: why ("" otherwise)
  std::string called;    // clean, <effect>, "<A> + <B>", unexplained, or error
  std::string top;       // the effect ranked first ("" on error)
  double simulate_s = 0, wall_s = 0;  // the campaign's simulation (with its effect-free twin and the gap size); with its diagnosis
  // A single effect's (or natural form's) size, through the ODE (the virtual lab with the
  // effect and without it, the same noise draws), never through the diagnosis' hypotheses.
  // effect_gap_sigma (the scored size): sqrt(g^T V^-1 g), the gap g as the diagnosis' nominal
  // model sees it (less what the static test takes up) against the covariance V it judges the
  // runs by (nominal_gap_significance): the separation of the best test of a known-shape gap.
  // Scored (single, natural) when >= 5. NaN: not computed (other families; an error).
  // effect_max_sigma (the largest run's size, reported beside it): the largest
  // |with - without| over the runs in that run's sigma; it ignores what the coefficients'
  // uncertainty can absorb.
  double effect_max_sigma = 0;
  double effect_gap_sigma = NAN;
  // The held-out gap rms without the lab's noise (the noise-free shrinkage's two terms, g):
  // the diagnosis' held-out residuals before (nominal) and after (the chosen effect) less
  // what the virtual lab added to each run beyond the ODE (its noise draw; the drift and the
  // extra scatter of the lab log) plus the drift line the diagnosis removed. NaN: not known
  // (an error; a result line without them).
  double gap_rms_before_g = NAN, gap_rms_after_g = NAN;
};

// One family's outcomes (a campaign counts in exactly one of right .. wrong, error apart):
//  right: the right effect (single; pair: both; a nuisance family: the nuisance reported and
//         no effect called; clean: no gap; out of library: unexplained);
//  family: an effect of the right physics (what it acts on: instrument, table motion, data
//          acquisition) but not the right one, or one of a pair;
//  unexplained, no_gap: those verdicts where they are not right;
//  wrong: explained by an effect of another physics (confidently wrong);
//  ambiguous: "ambiguous between" verdicts, counted apart (right_among: the truth among them).
//  parameters_off (natural forms, dynamics_off): the right effect, but a fitted parameter beyond
//         3 sigma of the truth (or a discrete one, the mode's axis, not the truth's); for
//         dynamics_off the truth is the loop's departure from the manifest (servo_dynamics'
//         crossover ratio, margin change and pendulum frequency ratio).
struct FamilyScore {
  int n = 0, right = 0, family = 0, unexplained = 0, no_gap = 0, wrong = 0, ambiguous = 0, right_among = 0, error = 0;
  int parameters_off = 0;
};

// The families sized by the largest run (a single or natural campaign below 5 sigma in every run,
// effect_max_sigma, is "_below_5_sigma"), kept beside the scored ones (effect_gap_sigma).
struct LargestRunSizeScores {
  int single = 0, single_right = 0, small = 0, small_right = 0;
  double median_shrinkage = 0, median_shrinkage_in_sigma = 0;  // with the runs' noise, its single family
  std::map<std::string, FamilyScore> families;
};

struct BlindScores {
  int single = 0, single_right = 0;  // scored single in-library effects (gap >= 5 sigma); called right ("explained by" it)
  int single_top_right = 0;          // ... ranked first whatever the verdict
  int small = 0, small_right = 0;    // single effects with a gap below 5 sigma (not scored); called right anyway
  int clean = 0, false_alarms = 0;
  int out_of_library = 0, out_of_library_unexplained = 0;  // scored: the gap >= 5 sigma in the campaign's design
  int out_of_library_small = 0;                              // its gap below 5 sigma (not scored)
  int two = 0, two_by_one = 0, two_by_both = 0;
  // Detection at the limit: single and natural campaigns whose gap's expected chi^2 deviate,
  // effect_gap_sigma^2 / sqrt(2 n) over the campaign's n runs (the mean rise of chi^2 over its
  // n, in chi^2's own sigma), is >= 5; the gap found significant.
  int at_limit = 0, at_limit_found = 0;
  // The held-out shrinkage 1 - rms_after / rms_before, median over the scored single family:
  // of the gap itself (the lab's noise removed: gap_rms_*_g), the measure, and of the
  // residuals as the diagnosis sees them (with each run's noise; in g and in each run's sigma).
  double median_gap_shrinkage = 0;
  int gap_shrinkage_campaigns = 0;  // single campaigns it is the median of
  double median_shrinkage = 0, median_shrinkage_in_sigma = 0;
  // ... and of the residuals above their floor (Diagnosis::shrinkage_above_floor), over the
  // single campaigns whose gap before exceeds it.
  double median_shrinkage_above_floor = 0;
  int above_floor_campaigns = 0;
  LargestRunSizeScores by_max_run_sigma;  // the families by the largest run's size, beside
  std::map<std::string, FamilyScore> families;  // per family (category)
  static double rate(int k, int of) { return of ? static_cast<double>(k) / of : 0.0; }
};

// The exact (Clopper-Pearson) two-sided interval of a rate k/n at `confidence`: the p at which
// seeing k or more (lo), or k or fewer (hi), has probability (1 - confidence)/2. [0, 1] when
// n = 0. A family of ~24 campaigns pins its rate only to about +-10 %.
struct RateInterval {
  double lo = 0, hi = 1;
};
RateInterval clopper_pearson(int k, int n, double confidence = 0.95);

// One of issue 15's must-show criteria read off a blind run: `k` of `n` campaigns, the target
// rate and whether it is a floor (at_least) or a ceiling; `met` compares the rate itself, and
// the interval says what the run's size allows.
struct BlindCriterion {
  std::string name;
  int k = 0, n = 0;
  double target = 0;
  bool at_least = true;
  RateInterval ci95;
  double rate() const { return n ? static_cast<double>(k) / n : 0.0; }
  bool met() const { return n > 0 && (at_least ? rate() >= target : rate() <= target); }
};

struct BlindResult {
  BlindSettings settings;
  int threads = 1;    // used (per rank)
  int ranks = 1;      // MPI ranks (1 without mpirun)
  double wall_s = 0;
  int resumed = 0;    // campaigns read back from an earlier run's results (not an outdated line)
  std::vector<std::string> library;  // the effect library's names (the confusion matrix's order)
  std::vector<BlindCampaign> campaigns;
  BlindScores scores;
  std::map<std::string, std::map<std::string, int>> confusion;  // truth -> called -> count
  std::vector<std::string> wrong;  // campaigns scored wrong (and single effects not scored), with why

  // "blind --n N --seed S: W s wall on T threads" and the scores (no program name: the CLI
  // puts it first); FullReport adds the campaigns scored wrong.
  std::string BriefReport() const;
  std::string FullReport() const;
  std::string FamilyTable() const;  // the per-family outcomes, one line each
  // Issue 15's rate criteria (single, natural, out of library, sigma understated, drift, clean,
  // confidently wrong over all families), each with its 95 % interval.
  std::vector<BlindCriterion> Criteria() const;
};

// Called after each campaign (under the pool's lock): campaigns done, of total.
// The truth of a blind campaign: paper-like coefficients, each perturbed, drawn from rng.
plant::PlantConfig blind_truth(std::mt19937_64& rng);

using BlindProgress = std::function<void(std::size_t done, std::size_t total)>;

// Campaign `index`'s key in a blind draw of `seed` (category, hidden effects with their natural
// form, the nuisances' sizes): what run_blind simulates, without running it.
BlindCampaign blind_key(int index, std::uint64_t seed, bool mixed = false);

// The design campaign k is simulated on: default_design(), or for a mixed campaign one drawn
// from its seed (a stream of its own: the key is the sine draw's): 36 sine runs (3 of the
// default's frequencies x 1, 2, 4 g x IA and PA x a_IA = +-0.71 g), 5-8 random runs (GEVS,
// NAVMAT or flat 20 Hz - 2 kHz shapes at 2-12 g rms log-uniform; along IA, PA or OA, or IA
// with PA or OA, common or independent; either orientation) and 1-2 sine-on-random runs (a
// 1-3 g sine at 40-400 Hz along IA or PA on 2-6 g rms), each random record 8 s; a random run
// whose output would pass kBlindOutputRange_g at 3 sigma on the campaign's truth backed off to
// it (within_output_range: a hidden mode can amplify the table's motion threefold).
inline constexpr double kBlindOutputRange_g = 50;
CampaignDesign blind_design(const BlindCampaign& k);

// Campaign k as the virtual lab hands it to diagnose (what run_blind diagnoses): simulated on
// the ODE plant from its truth and hidden effects on blind_design(k), the lab's log applied
// (each run's time and rest reading, the drift and extra scatter of a nuisance campaign), the
// manifest's dynamics the lab's estimate. A scored campaign's full diagnosis, which blind's
// result text does not carry: diagnose(blind_lab_campaign(k), BlindSettings{}.diagnose).
Campaign blind_lab_campaign(const BlindCampaign& k);

// The lab's log of one run of campaign k at `position` in the campaign's order: its time
// (3 min a run), a rest reading before it (sigma 0.3 ug), the drift in both and the scatter
// beyond the stated sigma, drawn from rng through n01 (blind's own log draws every run of a
// campaign from one stream). Returns what it added to measured_g (g).
double log_run(RunRecord& r, const BlindCampaign& k, std::size_t position, std::mt19937_64& rng,
               std::normal_distribution<double>& n01);

// A natural form's scoring: the diagnosis' top effect is the hidden one and each of its
// parameters the data pinned is within 3 sigma of the truth (a phase's difference wrapped to
// [-pi, pi); a discrete one, the mode's axis, equal, chosen or held); a held continuous
// parameter (reported at its nominal, the data do not pin it) is not judged. `why` names the parameter that failed, or
// lists the held ones.
bool parameters_match(const HiddenEffect& truth, const Diagnosis& d, std::string* why);

// The held-out gap's rms before (nominal) and after (the chosen effect), g, without the lab's
// noise. gap_before_g: each run's held-out nominal residual of the campaign with what the
// virtual lab added beyond the ODE taken out (heldout_nominal_gap_g of it: its noise draw,
// simulate_campaign's run_noise_g; the lab log's drift and extra scatter). That residual is
// affine in the measured values, so d.runs[k].heldout_before_g - gap_before_g[k] is the noise's
// held-out image (the run's own noise and what the other runs' noise moved the coefficients'
// correction by); it is taken out of the residual after the effect too. What the noise moved
// the effect's fitted parameters by stays in (the diagnosis' own error, part of the gap it
// leaves). Throws std::invalid_argument when the sizes differ or there are no runs.
std::pair<double, double> gap_rms_without_lab_noise(const Diagnosis& d, const std::vector<double>& gap_before_g);

// The campaign's outcome in its blind family (FamilyScore's fields: right, family,
// unexplained, no_gap, wrong, ambiguous, parameters_off, error) from k.diagnosis and k.error.
std::string blind_outcome(const BlindCampaign& k);
// What blind calls a diagnosis: clean, <effect>, "<A> + <B>", ambiguous, unexplained.
std::string blind_called(const Diagnosis& d);

// Invalid settings throw std::invalid_argument naming the key. A campaign whose simulation or
// diagnosis fails is kept with its error (called "error").
BlindResult run_blind(const BlindSettings& settings, const BlindProgress& progress = {});

// The same, resumable and across the ranks of mpirun (core/dispatch.hpp): campaigns in `done`
// (index -> campaign_result_text, from an earlier run with the same seed and diagnose
// settings) are read back, not run; each campaign run is passed to on_campaign (rank 0, under
// the lock) as it finishes. Under mpirun only rank 0's result is complete (the others return
// theirs unscored).
using BlindCampaignDone = std::function<void(int index, const std::string& text)>;
BlindResult run_blind(const BlindSettings& settings, const BlindProgress& progress,
                      const std::map<int, std::string>& done, const BlindCampaignDone& on_campaign);

// What the diagnosis found for campaign k (not its key, which the draw gives), as one line of
// text (no newline; numbers to 17 digits: read back exactly), and back into a drawn campaign.
// read_campaign_result throws std::invalid_argument for a line it cannot read.
// A line without the gap's size and noise-free rms (effect_gap_sigma, gap_rms_*_g) throws
// OutdatedCampaignResult: run_blind diagnoses that campaign again rather than score it
// without them.
struct OutdatedCampaignResult : std::invalid_argument {
  using std::invalid_argument::invalid_argument;
};
std::string campaign_result_text(const BlindCampaign& k);
void read_campaign_result(const std::string& text, BlindCampaign& k);

}  // namespace vrelab::validation
