// Lab nuisances are not effects (issue 15): a bias drift over the campaign's time, and a stated
// sigma that is too small; both on small simulated campaigns (the ODE plant, no hidden
// effect), the nuisance applied to the runs' summaries as a lab's acquisition would. Seeds
// 151-153 were not used to develop the diagnosis (its thresholds: blind seeds 100, 101).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <random>
#include <set>
#include <string>

#include <nlohmann/json.hpp>

#include "io/services/diagnosis_json.hpp"
#include "support/instrument.hpp"
#include "validation/diagnosis/blind.hpp"
#include "support/small_design.hpp"
#include "validation/diagnosis/campaign.hpp"
#include "validation/diagnosis/diagnose.hpp"
#include "validation/diagnosis/diagnosis_text.hpp"

namespace test_nuisances {

using namespace vrelab;
using namespace vrelab::validation;
using vrelab::test::small_design;

namespace {

// The same clean campaign for every test here (simulated once).
const Campaign& clean_campaign() {
  static const Campaign c = simulate_campaign(test::paper_like_plant(), {}, small_design(), 151, 2);
  return c;
}

// Each run 0.1 h after the last; rest readings with noise rest_sigma; the drift in both.
Campaign with_drift(double drift_g_per_h, double rest_sigma_g, bool log_rest = true) {
  Campaign c = clean_campaign();
  std::mt19937_64 rng(152);
  std::normal_distribution<double> n01;
  for (std::size_t k = 0; k < c.runs.size(); ++k) {
    RunRecord& r = c.runs[k];
    r.time_h = 0.1 * static_cast<double>(k);
    r.measured_g += drift_g_per_h * r.time_h;
    if (log_rest) r.rest_g = drift_g_per_h * r.time_h + rest_sigma_g * n01(rng);
  }
  return c;
}

// A truth as blind draws it (validation/diagnosis/blind.hpp).
plant::PlantConfig blind_like_truth(std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  return blind_truth(rng);
}

}  // namespace

TEST(NuisancesCampaign, ADriftIsEstimatedFromTheRestReadingsRemovedAndNotCalledAnEffect) {
  // Noise-free rest readings: the line through them is the drift itself (to rounding).
  {
    const Diagnosis d = diagnose(with_drift(2e-6, 0));
    const Nuisance* x = d.nuisance("bias_drift");
    ASSERT_NE(x, nullptr);
    EXPECT_TRUE(x->estimated && x->applied);
    EXPECT_NEAR(x->value, 2.0, 1e-9);
    EXPECT_EQ(x->unit, "ug/h");
  }
  // Rest readings with the runs' own noise (0.3 ug over 3.5 h): the rate within 3 of its sigma;
  // its sigma as a line fit's, sigma_rest / sqrt(sum (t - mean t)^2), within 30 % (the scatter
  // is estimated from 36 readings).
  const Campaign c = with_drift(2e-6, 0.3e-6);
  const Diagnosis d = diagnose(c);
  const Nuisance* x = d.nuisance("bias_drift");
  ASSERT_NE(x, nullptr);
  double tm = 0, stt = 0;
  for (const auto& r : c.runs) tm += r.time_h / static_cast<double>(c.runs.size());
  for (const auto& r : c.runs) stt += (r.time_h - tm) * (r.time_h - tm);
  EXPECT_NEAR(x->sigma, 0.3 / std::sqrt(stt), 0.3 * 0.3 / std::sqrt(stt));
  EXPECT_NEAR(x->value, 2.0, 3 * x->sigma);
  EXPECT_FALSE(d.explained()) << verdict_text(d);
  EXPECT_FALSE(d.gap_significant) << verdict_text(d);
  EXPECT_NE(verdict_text(d).find("bias drift"), std::string::npos) << verdict_text(d);
  // The same drift without the rest readings is a gap the diagnosis sees (the test can fail).
  const Diagnosis blind_to_it = diagnose(with_drift(2e-6, 0.3e-6, false));
  EXPECT_TRUE(blind_to_it.gap_significant);
  EXPECT_FALSE(blind_to_it.nuisance("bias_drift")->estimated);
}

TEST(NuisancesCampaign, AStatedSigmaTooSmallIsFlaggedAndTheGapJudgedWithTheCorrectedOne) {
  // The clean campaign's runs scatter 2.5 times their stated sigma.
  Campaign c = clean_campaign();
  std::mt19937_64 rng(153);
  std::normal_distribution<double> n01;
  for (auto& r : c.runs) r.measured_g += std::sqrt(2.5 * 2.5 - 1) * r.sigma_g * n01(rng);
  const Diagnosis d = diagnose(c);
  const Nuisance* x = d.nuisance("sigma_scale");
  ASSERT_NE(x, nullptr);
  EXPECT_TRUE(x->applied) << verdict_text(d) << "; " << x->note;
  // k from 36 gaps: sigma ~ k / sqrt(72) = 0.3; allow 3 of it.
  EXPECT_NEAR(x->value, 2.5, 3 * x->sigma) << x->note;
  EXPECT_FALSE(d.explained()) << verdict_text(d);
  EXPECT_NE(verdict_text(d).find("sigma understated"), std::string::npos) << verdict_text(d);
  // Unscaled, the clean campaign is not flagged.
  const Diagnosis clean = diagnose(clean_campaign());
  EXPECT_FALSE(clean.nuisance("sigma_scale")->applied);
  EXPECT_FALSE(clean.gap_significant);
  // Repeated runs measure the scatter directly: every run again, with new excess scatter (the
  // simulation's own noise, sigma, is shared by both copies): their pooled scatter is
  // (2.5^2 - 1) sigma^2 per copy, so k = sqrt(5.25) from the repeats.
  Campaign twice = c;
  for (const auto& r : clean_campaign().runs) {
    RunRecord again = r;
    again.id += "b";
    again.measured_g += std::sqrt(2.5 * 2.5 - 1) * r.sigma_g * n01(rng);
    twice.runs.push_back(again);
  }
  const Diagnosis d_twice = diagnose(twice);  // y points into it
  const Nuisance* y = d_twice.nuisance("sigma_scale");
  ASSERT_NE(y, nullptr);
  EXPECT_NE(y->note.find("repeated runs"), std::string::npos) << y->note;
  EXPECT_NEAR(y->value, std::sqrt(2.5 * 2.5 - 1), 3 * y->sigma) << y->note;
}

TEST(NuisancesCampaign, JsonCarriesEachNuisanceWithItsNameValueSigmaAndUnit) {
  const Campaign c = with_drift(1e-6, 0.3e-6);
  const nlohmann::json j = io::to_json(diagnose(c), c);
  for (const char* key : {"gap_significant", "verdict", "explained", "chosen", "effects", "shrinkage", "where", "nuisances",
                          "ambiguous_with", "next_runs"})
    EXPECT_TRUE(j.contains(key)) << key;
  std::set<std::string> names;
  for (const auto& x : j["nuisances"]) {
    for (const char* key : {"name", "value", "sigma", "unit"}) EXPECT_TRUE(x.contains(key)) << key;
    names.insert(x["name"].get<std::string>());
  }
  EXPECT_TRUE(names.count("bias_drift") && names.count("sigma_scale"));
}

// A physical gap is not a nuisance (issue 15): a squeeze film (its truth through the ODE,
// gap 1.04 mrad, as blind draws it) in the default design with the stated sigma right. Its
// gap is mostly taken up by the coefficients' errors and what is left is weakly structured,
// so the scatter test alone took it for understated sigma (blind --seed 8001: x1.50 and x1.97
// applied on its two squeeze films). Seed 160 was not used to develop the diagnosis.
TEST(NuisancesCampaign, ASqueezeFilmWithTheStatedSigmaRightIsNotCalledSigmaUnderstated) {
  const std::vector<HiddenEffect> film{{"squeeze_film_damping", 1 / 1.02e-3}};
  const std::uint64_t seed = 162;
  Campaign c = simulate_campaign(blind_like_truth(seed), film, default_design(), seed, 2);
  // The lab's log as blind writes it: 3 min a run, a rest reading (sigma 0.3 ug) before each.
  std::mt19937_64 rng(seed + 29);
  std::normal_distribution<double> n01;
  for (std::size_t k = 0; k < c.runs.size(); ++k) c.runs[k].time_h = 0.05 * static_cast<double>(k), c.runs[k].rest_g = 0.3e-6 * n01(rng);
  const Diagnosis d = diagnose(c);
  const Nuisance* x = d.nuisance("sigma_scale");
  ASSERT_NE(x, nullptr);
  std::printf("verdict: %s\nsigma_scale: %.3f +- %.3f, applied %d; %s\nbest: %s evidence %.1f\n", verdict_text(d).c_str(), x->value,
              x->sigma, x->applied ? 1 : 0, x->note.c_str(), d.effects.empty() ? "-" : d.effects[0].name.c_str(),
              d.effects.empty() ? 0.0 : d.effects[0].evidence);
  EXPECT_FALSE(x->applied) << verdict_text(d) << "; " << x->note;
  EXPECT_EQ(verdict_text(d).find("sigma understated"), std::string::npos) << verdict_text(d);
  EXPECT_TRUE(d.gap_significant) << verdict_text(d);  // the film is seen (the test can fail)
}

// A stray magnetic field's bias is not scatter (issue 30): it grows with the table's
// displacement squared, 0.14 ug (A / 1 g)^2 (10 Hz / f)^4, added to a clean default-design
// campaign's measured values (the ODE without it: the truth comes from outside the diagnosis).
// Only the 10 Hz runs see it (0.14 to 2.2 ug; 40 Hz already 256 x less), so neighbouring runs,
// 10 against 40 Hz, are not alike (a neighbour correlation of 2.4 sigma on the CLI's default
// case, below its 3) and the overdispersion alone said "sigma understated x1.49" (no gap once
// judged with it). The gaps' spread over frequency says it is structure: not applied, and the
// gap stays unexplained (here: neighbours 2.0 sigma, k 1.70, the spreads over frequency 8.5
// sigma). Seed 163 was not used to develop the structure tests.
TEST(NuisancesCampaign, AStrayFieldsLowFrequencyBiasIsNotCalledSigmaUnderstated) {
  const std::uint64_t seed = 163;
  Campaign c = simulate_campaign(blind_like_truth(seed), {}, default_design(), seed, 2);
  for (RunRecord& r : c.runs) r.measured_g += 0.14e-6 * r.amplitude_g * r.amplitude_g * std::pow(10 / r.frequency_Hz, 4);
  const Diagnosis d = diagnose(c);
  const Nuisance* x = d.nuisance("sigma_scale");
  ASSERT_NE(x, nullptr);
  std::printf("verdict: %s\nsigma_scale: %.3f +- %.3f, applied %d; %s\n", verdict_text(d).c_str(), x->value, x->sigma,
              x->applied ? 1 : 0, x->note.c_str());
  EXPECT_FALSE(x->applied) << x->note;
  EXPECT_NE(x->note.find("over frequency"), std::string::npos) << x->note;
  EXPECT_TRUE(d.gap_significant) << verdict_text(d);
  EXPECT_FALSE(d.explained()) << verdict_text(d);
}

// The drift test's false-alarm rate, by Monte Carlo: rest readings that are independent normal
// draws (blind's lab log: 3 min a run, sigma 0.3 ug) with no drift are flagged at the
// nuisances' level, 2 (1 - Phi(3)) = 0.270 % two-sided, at any number of readings. 40 000 logs
// each: 108 flags expected, a binomial sd of 10.4; the window is +-4.5 sd (a false failure
// once in 1.5e5 runs). A threshold from the normal quantile (3.0) instead of Student's t (4.28
// for 8 degrees of freedom) would flag 1.7 % of 10-reading logs (683 expected: fails; seen 635)
// and 0.31 % of 168-reading ones (125: inside the window, t(166) being nearly normal).
TEST(NuisancesCampaign, TheDriftTestFlagsNoDriftAtItsStatedRate) {
  const double level = std::erfc(3 / std::sqrt(2.0));  // 2 (1 - Phi(3)), not the code's constant
  constexpr int kTrials = 40000;
  for (const int readings : {10, 168}) {
    Campaign c;
    c.runs.resize(static_cast<std::size_t>(readings));
    std::mt19937_64 rng(153 + static_cast<std::uint64_t>(readings));
    std::normal_distribution<double> n01;
    int flagged = 0;
    for (int trial = 0; trial < kTrials; ++trial) {
      for (std::size_t j = 0; j < c.runs.size(); ++j) {
        RunRecord& r = c.runs[j];
        r.time_h = 0.05 * static_cast<double>(j);
        r.rest_g = 0.3e-6 * n01(rng);
        r.measured_g = 0, r.sigma_g = 1e-6;
      }
      const Nuisance x = remove_drift(c);
      ASSERT_TRUE(x.estimated);
      flagged += x.significant;
    }
    const double expected = level * kTrials, sd = std::sqrt(expected * (1 - level));
    EXPECT_NEAR(flagged, expected, 4.5 * sd) << readings << " readings: " << flagged << " of " << kTrials << " flagged";
  }
}

}  // namespace test_nuisances
