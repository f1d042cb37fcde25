// The natural-form misses of blind's seeds 8601, 8701, 8801, 8901, 9301 and 9601 (and a
// default-form miss of 11001, a mixed campaign of 11301), each campaign
// replayed exactly as `blind` makes it (run_blind with every other campaign of the draw read
// back from a result line, so only this one is simulated on the ODE plant through the effects'
// truth hooks and diagnosed): the truth is the key's, never the diagnosis' hypothesis.
// Each diagnoses a 168-run campaign (20-40 s in Release): label "campaign".
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <map>
#include <numbers>
#include <string>

#include "support/blind_replay.hpp"
#include "support/diagnosis_lookup.hpp"
#include "validation/diagnosis/blind.hpp"
#include "validation/diagnosis/diagnosis_text.hpp"

namespace test_natural_misses {

using namespace vrelab;
using namespace vrelab::validation;
using vrelab::test::parameter_named;

namespace {

BlindResult replay(std::uint64_t seed, int index) { return test::replay_blind_campaign(seed, index); }

// A harmonic's campaign replayed: the verdict's top effect is the hidden harmonic, its phase
// fitted and a claim (3 sigma below pi), ratio and phase within 3 sigma of the key's, and the
// campaign scored right. Returns the ratio for further checks.
FittedParameter expect_harmonic_within_3_sigma(std::uint64_t seed, int index, const std::string& effect,
                                               const std::string& ratio_name, const std::string& phase_name,
                                               bool scored_right = true) {
  const BlindResult r = replay(seed, index);
  const BlindCampaign& k = r.campaigns.at(static_cast<std::size_t>(index));
  EXPECT_EQ(k.category, "natural");
  EXPECT_EQ(k.hidden.at(0).name, effect);
  const Diagnosis& d = k.diagnosis;
  std::printf("  %s\n", verdict_text(d).c_str());
  EXPECT_EQ(d.effects.front().name, effect);
  if (d.effects.front().name != effect) return {};
  const FittedParameter& ratio = parameter_named(d.effects.front(), ratio_name);
  const FittedParameter& phase = parameter_named(d.effects.front(), phase_name);
  const double ratio_truth = k.hidden[0].parameter, phase_truth = k.hidden[0].form.at(0);
  std::printf("  ratio %.4f +- %.4f (truth %.4f), phase %.4f +- %.4f rad (truth %.4f)\n", ratio.value, ratio.sigma,
              ratio_truth, phase.value, phase.sigma, phase_truth);
  EXPECT_EQ(phase.status, ParameterStatus::fitted);
  EXPECT_LT(3 * phase.sigma, std::numbers::pi);  // a claim, judged
  EXPECT_LE(std::abs(std::remainder(phase.value - phase_truth, 2 * std::numbers::pi)), 3 * phase.sigma);
  EXPECT_LE(std::abs(ratio.value - ratio_truth), 3 * ratio.sigma);
  if (scored_right) {
    EXPECT_EQ(r.scores.families.at("natural").right, 1);
  }
  return ratio;
}

}  // namespace

// Seed 8601, campaign 19: a 3rd harmonic, ratio 0.1855 at 0.143 rad. A sigma from second
// differences over a 1e-3 rad step, below the simulation's rounding in -2 ln L, would report
// its phase 0.219 +- 0.0094 rad (7.6 sigma off) although -2 ln L at the truth is 0.29 above
// the minimum. With the objective's Hessian over steps the likelihood
// resolves, the phase's sigma is what -2 ln L says (~0.3 rad) and the truth lies within 3 sigma.
TEST(NaturalMissesCampaign, AThirdHarmonicsPhaseSigmaIsWhatTheLikelihoodSays) {
  const BlindResult r = replay(8601, 19);
  const BlindCampaign& k = r.campaigns.at(19);
  ASSERT_EQ(k.category, "natural");
  ASSERT_EQ(k.hidden.at(0).name, "shaker_third_harmonic");
  const Diagnosis& d = k.diagnosis;
  std::printf("  %s\n", verdict_text(d).c_str());
  ASSERT_EQ(d.effects.front().name, "shaker_third_harmonic");
  const FittedParameter& phase = parameter_named(d.effects.front(), "third_harmonic_phase_rad");
  const double truth = k.hidden[0].form.at(0);
  std::printf("  phase %.4f +- %.4f rad (truth %.4f)\n", phase.value, phase.sigma, truth);
  EXPECT_EQ(phase.status, ParameterStatus::fitted);
  EXPECT_LE(std::abs(std::remainder(phase.value - truth, 2 * std::numbers::pi)), 3 * phase.sigma);
  // -2 ln L rises by 0.13 over +-0.1 rad about the minimum (the profile, printed while
  // developing this): a sigma below 0.05 rad would contradict it.
  EXPECT_GT(phase.sigma, 0.05);
  EXPECT_EQ(r.scores.families.at("natural").right, 1);
}

// Seed 8701, campaign 43: a 3rd harmonic, ratio 0.2317 at 2.255 rad. On the fold that leaves
// 2 g out, Levenberg-Marquardt from the best start (0 rad) ends in the phase's other valley
// (0.30 rad, 36 above the one at 2.3 rad that the start at pi/2 leads to), and the held-out
// 2 g runs fail it: descended from that start alone, the gap would be "not explained". So
// every start within 25 of the best descends; the lowest wins. Checked: the gap explained by
// the 3rd harmonic (held-out runs included), its phase in the truth's valley (within 3 sigma
// of 2.255 rad, not the other valley's 0.30 rad) and blind's score.
TEST(NaturalMissesCampaign, AThirdHarmonicsPhaseIsFoundInItsValleyAndExplainsTheGap) {
  const BlindResult r = replay(8701, 43);
  const BlindCampaign& k = r.campaigns.at(43);
  ASSERT_EQ(k.category, "natural");
  ASSERT_EQ(k.hidden.at(0).name, "shaker_third_harmonic");
  const Diagnosis& d = k.diagnosis;
  std::printf("  %s; held-out chi2 %.1f\n", verdict_text(d).c_str(), d.effects.front().heldout_chi2);
  EXPECT_TRUE(d.explained());
  EXPECT_EQ(to_string(d.chosen), "shaker_third_harmonic");
  ASSERT_EQ(d.effects.front().name, "shaker_third_harmonic");
  const FittedParameter& phase = parameter_named(d.effects.front(), "third_harmonic_phase_rad");
  const double truth = k.hidden[0].form.at(0);
  std::printf("  phase %.4f +- %.4f rad (truth %.4f)\n", phase.value, phase.sigma, truth);
  EXPECT_NEAR(truth, 2.255, 0.001);  // the campaign this test is about
  EXPECT_EQ(phase.status, ParameterStatus::fitted);
  const double off = std::abs(std::remainder(phase.value - truth, 2 * std::numbers::pi));
  EXPECT_LE(off, 3 * phase.sigma);
  EXPECT_LT(off, std::abs(2.255 - 0.30) / 2) << "the phase is in the other valley";
  EXPECT_EQ(r.scores.families.at("natural").right, 1);
}

// Seed 8801, campaign 7: a 3rd harmonic, ratio 0.1322 at 2.327 rad, fitted 0.1445 at 1.940 rad
// (the Hessian's sigma 0.0064 and 0.27 rad). With the first-order shift C J^T V^-1 f Delta
// as the hypothesis' accuracy term, whose Gauss-Newton slopes J overstate the phase's
// curvature hundredfold against the Hessian's C, it would be reported +- 0.033 and
// +- 11.7 rad. Two refits of
// the data shifted by +-f Delta move the phase by ~0.01 rad and the ratio by ~0.006 (the
// effect's change is not linear in the ratio at this phase): the sigma claims something (3
// sigma of the phase below pi, the ratio's sigma below its prior width) and the truth lies
// within 3 sigma (1.4 sigma each, printed while developing this).
TEST(NaturalMissesCampaign, AThirdHarmonicsSigmaWithTheHypothesisAccuracyClaimsSomething) {
  const FittedParameter ratio =
      expect_harmonic_within_3_sigma(8801, 7, "shaker_third_harmonic", "third_harmonic_ratio", "third_harmonic_phase_rad");
  // The ratio (the first parameter) has no prior: a quarter of its grid (0 to 0.5) is what a
  // further parameter's width would be, 0.125; the bar is tighter (the Hessian's sigma 0.0064).
  EXPECT_LT(ratio.sigma, 0.05);
  // The hypothesis' 1 % is in the ratio's sigma: at least f times the ratio.
  EXPECT_GE(ratio.sigma, 0.01 * ratio.value);
}

// Seed 9301, campaign 54: a 2nd harmonic, ratio 0.2166 at 2.530 rad. The first-order
// prediction is right there (its change against the ODE's, the truth's coefficients, over
// 168 runs x 18 phases round the circle: within 0.11 of a run's sigma in every run, sum of
// squares <= 0.05, printed while developing this); the descent must take the phase's
// differences round the circle. Clamped at the range's ends (one-sided, no curvature
// rescaling), Levenberg-Marquardt from the best start, -pi, would creep 0.016 rad in 15 steps,
// to 3.126 rad, where -2 ln L profiled over the phase is 63 above its valley at 2.55 rad
// (fitted 0.186 +- 0.010 at 3.126 +- 0.08 rad, the phase 7 sigma off). Taken round the circle,
// the descent reaches the valley.
// The verdict is not judged here: "not explained". The 4 g fold, fitted on the 1-2 g runs
// alone, lands at 0.1875 +- 0.0099 and 1.15 +- 0.16 rad, 9 sigma from the phase the whole
// campaign pins, and the held-out 4 g runs are then 8 ug off over a floor of 1.7 ug (held-out
// chi^2 406 for 168 runs). It was called explained while the simulation's accuracy sat at the
// static test's prediction (-514 ug at 4 g along IA where +219 ug is measured), which diluted
// that chi^2 to 231 (docs/diagnose.md, "Covariance").
TEST(NaturalMissesCampaign, ASecondHarmonicsPhaseDescendsAcrossPi) {
  expect_harmonic_within_3_sigma(9301, 54, "shaker_harmonic_distortion", "second_harmonic_ratio", "second_harmonic_phase_rad",
                                 false);
}

// Seed 8901, campaign 90: a 2nd harmonic, ratio 0.1418 at 0.969 rad. -2 ln L profiled over
// the phase has its valley at 0.8-1.0 rad, 37 below the phase held at 0: the data pin it.
// From the best start (pi/2) the descent meets the valley's flank at 1.52 rad, where -2 ln L
// is concave along the phase: without a curvature to step by, Gauss-Newton's (hundredfold a
// phase's) would make the steps crawl and stop there, and the Hessian there, not positive
// definite, would have the phase held at 0 and the ratio fitted 0.072 +- 0.015 (4.7 sigma
// off). With a trust step where the objective is not convex, the descent reaches the valley.
TEST(NaturalMissesCampaign, ASecondHarmonicsPhaseIsFoundFromTheFlankOfItsValley) {
  expect_harmonic_within_3_sigma(8901, 90, "shaker_harmonic_distortion", "second_harmonic_ratio", "second_harmonic_phase_rad");
}

// Seed 9601, campaign 30: a mechanical mode at 719.5 Hz, damping 0.076, along IA (a 7405 sigma
// gap); the prediction is right (0.08 % of the ODE's change at most). The frequency and
// damping lie in a narrow curved valley (correlation -0.998): differences over the slopes'
// steps (0.72 Hz, 5e-4) span ~50 and ~10 conditional sigma across it and give the slope along
// the frequency the wrong sign, so a descent by them stops on the valley's flank (720.4 +-
// 0.26 Hz, 3.5 sigma off, although -2 ln L at the truth is 23.6 below there). With the
// differences over a fraction of the conditional sigma, the objective's own Hessian and a
// line search along its Newton step, the descent reaches the valley's floor.
TEST(NaturalMissesCampaign, AResonancesFrequencyAndDampingAreFoundInTheirNarrowValley) {
  const BlindResult r = replay(9601, 30);
  const BlindCampaign& k = r.campaigns.at(30);
  ASSERT_EQ(k.category, "natural");
  ASSERT_EQ(k.hidden.at(0).name, "mechanical_mode");
  const Diagnosis& d = k.diagnosis;
  std::printf("  %s\n", verdict_text(d).c_str());
  EXPECT_TRUE(d.explained());
  ASSERT_EQ(d.effects.front().name, "mechanical_mode");
  const FittedParameter& f = parameter_named(d.effects.front(), "frequency_Hz");
  const FittedParameter& z = parameter_named(d.effects.front(), "damping_ratio");
  const double f_truth = k.hidden[0].parameter, z_truth = k.hidden[0].form.at(0);
  std::printf("  frequency %.3f +- %.3f Hz (truth %.3f), damping %.5f +- %.5f (truth %.5f)\n", f.value, f.sigma, f_truth,
              z.value, z.sigma, z_truth);
  EXPECT_EQ(z.status, ParameterStatus::fitted);
  EXPECT_LE(std::abs(f.value - f_truth), 3 * f.sigma);
  EXPECT_LE(std::abs(z.value - z_truth), 3 * z.sigma);
  EXPECT_EQ(r.scores.families.at("natural").right, 1);
}

// Seed 11001, campaign 69: a third harmonic in its default form (ratio 0.232, phase 0; 48 sigma)
// was called "shaker_third_harmonic + servo_dynamics" (a confident wrong pair): the natural
// form's fits on each fold (ratio and phase on the training runs) left a held-out chi^2 of 303
// for 168 runs, the truth's own form predicted the held-out runs to 0.53 ug, and a pair holding
// the harmonic's phase at its nominal gained that (servo_dynamics at a crossover ratio of
// 1.0027, 2.7 sigma of none, or fixture_rocking at 0: the same +120 of evidence). The
// hypothesis at the truth follows the ODE to 0.03 ug in every run. The default form alone is
// the natural form's rival before any pair: it explains the gap, the pair is not tried.
TEST(NaturalMissesCampaign, ADefaultFormHarmonicIsNotCalledAPairWhenItsOwnFormExplainsTheGap) {
  const BlindResult r = replay(11001, 69);
  const BlindCampaign& k = r.campaigns.at(69);
  ASSERT_EQ(k.category, "single");
  ASSERT_EQ(k.hidden.at(0).name, "shaker_third_harmonic");
  std::printf("  %s\n", verdict_text(k.diagnosis).c_str());
  EXPECT_EQ(k.called, "shaker_third_harmonic");
  EXPECT_EQ(k.diagnosis.chosen.names.size(), 1u);
}

// Seed 11301 (mixed), campaign 139: a transverse motion on the other axis cycle (in phase
// -0.0923, quadrature -0.0127, power 1.13), 46 sine, random and sine-on-random runs. The fit on
// all runs found it, but the fold leaving 4 g out chose the next cycle on the 1 and 2 g runs and
// its 4 g runs then missed: held-out chi^2 186, "not explained". Scored over the forms the
// training runs leave open (docs/diagnose.md, section 7), the fold no longer fails the effect
// for that choice.
TEST(NaturalMissesCampaign, ATransverseMotionsAxisCycleThatAFoldCannotChooseIsScoredOverBoth) {
  const BlindResult r = test::replay_blind_campaign(11301, 139, true);
  const BlindCampaign& k = r.campaigns.at(139);
  ASSERT_EQ(k.category, "natural");
  ASSERT_EQ(k.hidden.at(0).name, "shaker_transverse_motion");
  ASSERT_EQ(k.hidden.at(0).form.at(2), 1.0);  // the other cycle
  const Diagnosis& d = k.diagnosis;
  std::printf("  %s\n", verdict_text(d).c_str());
  EXPECT_EQ(d.verdict, Verdict::explained);
  ASSERT_EQ(d.effects.front().name, "shaker_transverse_motion");
  const FittedParameter& ratio = parameter_named(d.effects.front(), "ratio_at_1kHz");
  std::printf("  ratio %.4f +- %.4f (truth %.4f)\n", ratio.value, ratio.sigma, k.hidden[0].parameter);
  EXPECT_LE(std::abs(ratio.value - k.hidden[0].parameter), 3 * ratio.sigma);
  EXPECT_EQ(parameter_named(d.effects.front(), "axis_cycle").value, 1.0);
  EXPECT_EQ(r.scores.families.at("natural").right, 1);
}

}  // namespace test_natural_misses
