#pragma once
// validation/diagnosis/campaign.hpp -- the virtual lab: a whole test campaign simulated from a "truth"
// instrument that may carry hidden effects.
//
// Takes: the truth plant (coefficients, dynamics), the hidden effects (names in the effect
//        registry, validation/diagnosis/effect.hpp, with their parameter: the library's and
//        the out-of-library "readout_clipping" and "shaker_third_harmonic"), the campaign design (the
//        static positions and errors; the shaker runs: frequencies x amplitudes x directions
//        x static orientations; each run's measurement sigma), a seed.
// Gives: a Campaign as a lab would hand it over: static readings (the ODE plant settled in
//        each position, with set-angle errors and noise, each with its first-order sigma)
//        and per run the measured vibration error (the ODE on the virtual shaker with the
//        hidden effects, plus Gaussian noise of the run's sigma). The nominal dynamics are
//        the truth's without its hidden effects. Nothing of the truth is in the Campaign.
// The truth is built by each effect's truth hook (plant modules and shaker decorators), not
// by the hypothesis the diagnosis fits (docs/effects.md, "Truth and hypothesis").
#include <cstddef>
#include <cstdint>
#include <functional>
#include <random>
#include <string>
#include <utility>
#include <vector>

#include "plant/accelerometer.hpp"
#include "validation/diagnosis/diagnose.hpp"
#include "validation/identification/dividing_head.hpp"
#include "vibration/random.hpp"

namespace vrelab::validation {

struct HiddenEffect {
  HiddenEffect() = default;
  HiddenEffect(std::string name_, double parameter_, std::vector<double> form_ = {})
      : name(std::move(name_)), parameter(parameter_), form(std::move(form_)) {}
  std::string name;
  double parameter = 0;  // the effect's first parameter
  // Its further parameters (the natural form: Effect::parameters[1..]); empty: their nominals
  // (the library's default form).
  std::vector<double> form;
  std::vector<double> values(const Effect& e) const;  // every parameter's value
};

// A blind campaign's draw of the effect's parameter (Effect::draw: the ranges where its gap is
// several sigma in the default design). Fixed rng calls per effect, so a blind seed draws the
// same truths.
HiddenEffect draw_hidden(const Effect& e, std::mt19937_64& rng);
// The same, then the further parameters away from their defaults (Effect::draw_form; the
// default form when the effect has none).
HiddenEffect draw_hidden_natural(const Effect& e, std::mt19937_64& rng);

// A random or sine-on-random run of the design (docs/data-format.md, "Random and
// sine-on-random runs"): the random part's PSD tables (g^2/Hz per sensor axis) and coupling,
// the static orientation (g) and, for sine on random, the sine (Hz, g peak, direction in
// sensor axes; the two parts independent).
struct RandomRunDesign {
  vibration::RandomProfile profile;
  Vec3 orientation_g = Vec3::UnitZ();
  bool sine_part = false;
  double frequency_Hz = 0, amplitude_g = 0;
  Vec3 direction = Vec3::UnitX();
};

struct CampaignDesign {
  int positions_per_series = 12;  // 30 deg steps: rank 12 of 13, only k_PP must be held
  StaticTestErrors errors;
  std::vector<double> frequencies_Hz, amplitudes_g;
  std::vector<Vec3> directions, orientations_g;
  double run_sigma_g = 0.3e-6;
  // Raw records instead of summaries (raw_sample_rate_Hz > 0): each run read by a readout at
  // that rate (raised to at least 20 samples per period) with this noise per sample, a record
  // at rest then at least raw_record_s under vibration; Campaign::raw holds them and each
  // run's measured_g / sigma_g is the batch-means measurement of its own record.
  double raw_sample_rate_Hz = 0, raw_noise_sigma_g = 20e-6, raw_record_s = 1.0;
  // Random and sine-on-random runs after the sine runs, each measured by the ODE over
  // random_record_s of motion (after settling) in 8 blocks: its measured error is the ODE's
  // plus Gaussian noise of run_sigma_g, its sigma the blocks' and run_sigma_g in quadrature.
  // Plant and acquisition effects act on them as on sine runs; of the table-motion effects,
  // the sine of a sine-on-random run takes them, the random part only the fixture's turn
  // (VirtualLab::random_turn: mounting_misalignment), as the diagnosis' hypotheses do
  // (docs/data-format.md). Summaries only: raw records of random runs are refused.
  std::vector<RandomRunDesign> random_runs;
  double random_record_s = 16.0;
  // The sine runs the grid makes (frequencies x amplitudes x directions x orientations).
  std::size_t sine_runs() const {
    return frequencies_Hz.size() * amplitudes_g.size() * directions.size() * orientations_g.size();
  }
};

// The default design (docs/data-format.md): 7 frequencies 10 Hz - 1.5 kHz x 1, 2, 4 g x
// IA, PA, OA, IA+PA x two static orientations with opposite a_IA (+-0.71 g, OA up: the
// terms odd in a_IA change sign, the even ones do not); 3 x 12 static positions, twice each.
CampaignDesign default_design();

// A lab's back-off: each random or sine-on-random run whose rebalance current would pass
// range_g (g peak) at its random part's 3 sigma plus the sine's amplitude, on the truth with
// its hidden effects (the loop's linear response: rectification::random_response and
// loop_response on the run's plant, the fixture's turn included), run instead with its random
// levels scaled to reach range_g there, as a lab lowers a test whose output clips (a lightly
// damped mode can lift 11 g rms of table motion to 32 g rms of current). The runs within range
// and the sine runs as they are, and a sine-on-random run whose sine alone passes the range
// (not backed off: the sine is the test's point). The truth's linear response sizes the level
// only; what the run measures is the ODE's.
CampaignDesign within_output_range(CampaignDesign design, const plant::PlantConfig& truth, const std::vector<HiddenEffect>& hidden,
                                   double range_g);

// Out-of-library effects the virtual lab can hide (diagnose must call them unexplained).
bool is_out_of_library(const std::string& name);
// The registry's validity check of a hidden effect (known name, values its check accepts);
// std::invalid_argument "campaign: ..." otherwise.
void validate(const HiddenEffect& h);

// threads: 0 all cores. run_done, when given, is called (under a lock) after each shaker run.
// run_noise_g, when given, receives each run's added noise (g, run_sigma_g x its normal draw:
// measured_g is the ODE's plus it), the virtual lab's own knowledge (blind's noise-free
// shrinkage); NaN for runs recorded raw (their noise is the readout's, per sample). A random
// run's own scatter (its finite record) is in the ODE's value, not in this.
Campaign simulate_campaign(const plant::PlantConfig& truth, const std::vector<HiddenEffect>& hidden,
                           const CampaignDesign& design, std::uint64_t seed, int threads = 1,
                           const std::function<void()>& run_done = {}, std::vector<double>* run_noise_g = nullptr);

}  // namespace vrelab::validation
