// Lab nuisances reported whatever the gap's verdict (issue 15), on campaigns whose truth is
// drawn through blind's own path (validation::blind_truth) with a known drift or a known
// scatter over the stated sigma, and on clean ones; and the blind result line that carries
// the nuisances to the scoring (a line without them would have blind --seed 8101 score its
// drift and sigma-understated campaigns "no gap"). Seeds 9000-9019 were picked for these
// tests and not used to develop the thresholds (those are distribution quantiles:
// docs/diagnose.md, "Lab nuisances").
#include <gtest/gtest.h>

#include <cmath>
#include <map>
#include <random>
#include <string>

#include "support/result_line.hpp"
#include "validation/diagnosis/blind.hpp"
#include "support/small_design.hpp"
#include "validation/diagnosis/campaign.hpp"
#include "validation/diagnosis/diagnose.hpp"
#include "validation/diagnosis/diagnosis_text.hpp"

namespace test_nuisances_blind {

using namespace vrelab;
using namespace vrelab::validation;
using vrelab::test::small_design;

namespace {

constexpr double kRunSigma_g = 0.3e-6, kRestSigma_g = 0.3e-6, kRunTime_h = 0.05;

// A clean campaign on blind's truth for `seed`, simulated without the runs' noise (the ODE's
// own error is ~1e-9 g): each test draws the runs' noise itself, so several noise draws
// share one simulation.
const Campaign& noiseless(std::uint64_t seed) {
  static std::map<std::uint64_t, Campaign> cache;
  auto it = cache.find(seed);
  if (it == cache.end()) {
    std::mt19937_64 rng(seed);
    CampaignDesign d = small_design();
    d.run_sigma_g = 0;
    Campaign c = simulate_campaign(blind_truth(rng), {}, d, seed, 2);
    for (RunRecord& r : c.runs) r.sigma_g = kRunSigma_g;
    it = cache.emplace(seed, std::move(c)).first;
  }
  return it->second;
}

// The lab's log as blind writes it (3 min a run, a rest reading of sigma 0.3 ug before each),
// the runs' noise scaled by noise_scale over the stated sigma, and a drift in both.
Campaign lab_campaign(std::uint64_t seed, std::uint64_t noise_seed, double noise_scale, double drift_g_per_h) {
  Campaign c = noiseless(seed);
  std::mt19937_64 rng(noise_seed);
  std::normal_distribution<double> n01;
  for (std::size_t j = 0; j < c.runs.size(); ++j) {
    RunRecord& r = c.runs[j];
    r.time_h = kRunTime_h * static_cast<double>(j);
    r.rest_g = drift_g_per_h * r.time_h + kRestSigma_g * n01(rng);
    r.measured_g += drift_g_per_h * r.time_h + noise_scale * r.sigma_g * n01(rng);
  }
  return c;
}

}  // namespace

// blind's lower end of the drift (0.2 ug/h): over 72 runs (3.55 h) the rate's sigma is
// 0.3 ug / sqrt(sum (t - mean t)^2) = 0.034 ug/h, so 0.2 ug/h is 6 of it: reported,
// significant, within 3 sigma of the truth, and no effect called.
TEST(NuisancesBlindCampaign, ADriftAtBlindsLowerEndIsReportedWhateverTheGapsVerdict) {
  for (const double drift_ug_per_h : {0.2, -0.2}) {
    const Diagnosis d = diagnose(lab_campaign(9000, 9001, 1.0, drift_ug_per_h * 1e-6));
    const Nuisance* x = d.nuisance("bias_drift");
    ASSERT_NE(x, nullptr);
    EXPECT_TRUE(x->significant) << x->value << " +- " << x->sigma << "; " << verdict_text(d);
    EXPECT_NEAR(x->value, drift_ug_per_h, 3 * x->sigma);
    EXPECT_FALSE(d.explained()) << verdict_text(d);
    EXPECT_NE(verdict_text(d).find("bias drift"), std::string::npos) << verdict_text(d);
    // Not a nuisance it is not.
    EXPECT_FALSE(d.nuisance("sigma_scale")->significant) << d.nuisance("sigma_scale")->note;
  }
}

// blind's lower end of the scatter (1.8 x the stated sigma) and a milder 1.65 x: flagged
// either way, never explained by an effect, the scale within 3 of its sigma. From the gaps the
// excess is tested at a 4-sigma tail (internal/nuisances.hpp): an estimate beyond 1.35 x on 72
// runs. The estimates fall ~12 % short of the truth (the coefficients take up part of the
// scatter): 1.59 +- 0.13 and 1.46 +- 0.12 on these draws, 2 and 0.9 of their sigma above the
// threshold (a 1.5 x draw, estimated 1.32, is not flagged).
TEST(NuisancesBlindCampaign, AnUnderstatedSigmaIsFlaggedWhateverTheGapsVerdict) {
  for (const double k : {1.8, 1.65}) {
    const Diagnosis d = diagnose(lab_campaign(9002, 9003, k, 0));
    const Nuisance* x = d.nuisance("sigma_scale");
    ASSERT_NE(x, nullptr);
    EXPECT_TRUE(x->significant && x->applied) << k << ": " << x->value << "; " << x->note << "; " << verdict_text(d);
    std::printf("  x %.2f: estimated %.3f +- %.3f; %s\n", k, x->value, x->sigma, verdict_text(d).c_str());
    EXPECT_NEAR(x->value, k, 3 * x->sigma) << x->note;
    EXPECT_FALSE(d.explained()) << verdict_text(d);
    EXPECT_NE(verdict_text(d).find("sigma understated"), std::string::npos) << verdict_text(d);
    EXPECT_FALSE(d.nuisance("bias_drift")->significant);
  }
}

// Clean campaigns (two truths, five noise draws each): no gap and no nuisance. Each nuisance
// is tested at a 3-sigma tail (drift: 0.27 % two-sided; sigma: 0.135 %), so 10 clean
// campaigns all pass with probability 0.96 when the thresholds are what they claim; a
// threshold set by chance-level structure (say 2 sigma: 7 % a campaign) fails here with
// probability 0.5. (A Monte Carlo sharp enough for the 2 % is blind's, not a test's.)
TEST(NuisancesBlindCampaign, CleanCampaignsFlagNoNuisance) {
  int flagged = 0, judged = 0;
  for (const std::uint64_t seed : {9004, 9005})
    for (std::uint64_t draw = 0; draw < 5; ++draw) {
      const Diagnosis d = diagnose(lab_campaign(seed, 9010 + draw, 1.0, 0));
      // Both nuisances are looked for and estimated (the log has rest readings and stated
      // sigmas), so "none flagged" is a judgement, not an empty list.
      for (const char* name : {"bias_drift", "sigma_scale"}) {
        const Nuisance* x = d.nuisance(name);
        ASSERT_NE(x, nullptr) << name;
        EXPECT_TRUE(x->estimated) << name << ": " << x->note;
        ++judged;
      }
      for (const Nuisance& x : d.nuisances) {
        flagged += x.significant;
        EXPECT_FALSE(x.significant) << "truth " << seed << " draw " << draw << ": " << x.name << " " << x.value << " +- " << x.sigma
                                    << "; " << x.note;
      }
      EXPECT_FALSE(d.gap_significant) << verdict_text(d);
    }
  EXPECT_EQ(judged, 2 * 10);
  EXPECT_EQ(flagged, 0);
}

// The result line of a blind campaign (what a thread or an MPI rank hands to the scoring)
// carries the verdict, the ambiguity and every nuisance with its significance; the verdict in
// words read back is what was written (the nuisances applied said after it).
TEST(NuisanceTransport, BlindResultLineCarriesTheVerdictAmbiguityAndNuisances) {
  BlindCampaign k;
  k.called = "clean", k.top = "pickoff_nonlinearity";
  Diagnosis& d = k.diagnosis;
  d.verdict = Verdict::no_significant_gap;
  d.ambiguous_with = {"servo_dynamics", "nonlinearity_at_input"};
  EffectFit e;
  e.name = "pickoff_nonlinearity", e.value = 0.125;
  d.effects = {e};
  Nuisance drift;
  drift.name = "bias_drift", drift.unit = "ug/h", drift.value = -0.595, drift.sigma = 0.0096;
  drift.estimated = drift.applied = drift.significant = true, drift.note = "the rest readings' line\nover 168 runs";
  Nuisance scale;
  scale.name = "sigma_scale", scale.unit = "1", scale.value = 2.21, scale.sigma = NAN, scale.estimated = true;
  scale.note = "from the gaps;\tnot applied";
  d.nuisances = {drift, scale};
  BlindCampaign back;
  read_campaign_result(campaign_result_text(k), back);
  EXPECT_EQ(back.diagnosis.verdict, d.verdict);
  EXPECT_EQ(verdict_text(back.diagnosis), "no significant gap (bias drift -0.595 +- 0.0096 ug/h removed)");
  EXPECT_EQ(back.diagnosis.ambiguous_with, d.ambiguous_with);
  ASSERT_EQ(back.diagnosis.nuisances.size(), 2u);
  const Nuisance* x = back.diagnosis.nuisance("bias_drift");
  ASSERT_NE(x, nullptr);
  EXPECT_EQ(x->value, -0.595);
  EXPECT_EQ(x->sigma, 0.0096);
  EXPECT_TRUE(x->estimated && x->applied && x->significant);
  EXPECT_EQ(x->note, drift.note);
  EXPECT_EQ(x->unit, "ug/h");
  const Nuisance* y = back.diagnosis.nuisance("sigma_scale");
  ASSERT_NE(y, nullptr);
  EXPECT_TRUE(std::isnan(y->sigma));
  EXPECT_FALSE(y->applied || y->significant);
  EXPECT_EQ(y->note, scale.note);
  EXPECT_EQ(back.top, "pickoff_nonlinearity");
  // A line cut short is refused, not read as fewer nuisances.
  test::expect_refused_not_outdated(test::cut_before_gap(campaign_result_text(k)), "a line cut short");
}

}  // namespace test_nuisances_blind
