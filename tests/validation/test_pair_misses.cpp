// Pairs of hidden effects from blind's draws, each campaign made as `blind` makes it
// (blind_lab_campaign: simulated on the ODE plant through the effects' truth hooks, handed to
// the lab) and diagnosed with blind's settings: the truth is the key's, never the diagnosis'
// hypothesis. Each diagnoses a 168-run campaign (20-40 s in Release): label "campaign".
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <string>

#include "validation/diagnosis/blind.hpp"
#include "validation/diagnosis/diagnosis_text.hpp"

namespace test_pair_misses {

using namespace vrelab;
using namespace vrelab::validation;

// Seed 12301, campaign 195: a readout nonlinearity (q2 3.77e-5 /g) and a squeeze film
// (1 / gap 860 /rad), the film's need over the readout's gap 18.0 sigma as the nominal model
// sees it (blind's size of the pair, through the ODE). The readout alone removes 96 % of the held-out gap rms, which "explained" asks, so the
// pair was never tried and the film went unnamed. A second effect is now tried beside an A
// that explains, and chosen when the pair's held-out evidence beats A's by 25.
TEST(PairCampaign, AFilmBesideAReadoutThatExplainsAloneIsNamed) {
  const BlindCampaign k = blind_key(195, 12301);
  ASSERT_EQ(k.category, "two");
  ASSERT_EQ(k.hidden.at(0).name, "readout_nonlinearity");
  ASSERT_EQ(k.hidden.at(1).name, "squeeze_film_damping");
  const Diagnosis d = diagnose(blind_lab_campaign(k), BlindSettings{}.diagnose);
  std::printf("  %s\n", verdict_text(d).c_str());
  ASSERT_FALSE(d.pairs.empty());
  for (const PairFit& p : d.pairs)
    std::printf("  pair %s %.4g + %s %.4g: evidence %.1f, held-out chi2 %.1f, all-run chi2 %.1f\n", p.a.c_str(), p.pa, p.b.c_str(),
                p.pb, p.evidence, p.heldout_chi2, p.insample_chi2);
  EXPECT_TRUE(d.explained()) << verdict_text(d);
  EXPECT_EQ(to_string(d.chosen), "readout_nonlinearity + squeeze_film_damping") << verdict_text(d);
  // The pair is fitted on its own likelihood, from where A alone stands: on every run it fits
  // better than A alone (the alternating fits it replaced could end far worse: 3594 against
  // A's 214 on campaign 159 of the same seed).
  const EffectFit& a = d.effects.front();
  ASSERT_EQ(a.name, "readout_nonlinearity");
  const auto chosen = std::find_if(d.pairs.begin(), d.pairs.end(), [](const PairFit& p) { return p.b == "squeeze_film_damping"; });
  ASSERT_NE(chosen, d.pairs.end());
  EXPECT_LT(chosen->insample_chi2, a.insample_chi2);
  EXPECT_GT(chosen->evidence, a.evidence + 25);
  // q2 within 3 % of the key's: the film's part is the smaller (first-order additivity).
  EXPECT_NEAR(chosen->pa, 3.773e-5, 0.03 * 3.773e-5);
}

// The other side: a strong single effect whose hypothesis leaves a small misfit must not take
// in a second effect. Seed 12301: campaign 57, a pickoff of -21.9 /rad (2211 sigma); campaign
// 81, a mode at 752 Hz (8562 sigma), whose hypothesis leaves an all-run chi^2 of 4635 for 166
// runs. Screened with -2 ln L not taken as the pair takes it (the coefficients' errors with
// G_0, not G_A), they were tried and called pickoff + k5 and mode + servo_dynamics (the k5's
// part 2.9 sigma against 1 % of the pickoff's; the servo trimming the misfit to 4358). Each is
// its single effect.
TEST(PairCampaign, AStrongSingleEffectTakesInNoSecond) {
  for (const int index : {57, 81}) {
    const BlindCampaign k = blind_key(index, 12301);
    ASSERT_EQ(k.category, "single");
    const Diagnosis d = diagnose(blind_lab_campaign(k), BlindSettings{}.diagnose);
    std::printf("  campaign %d, %s = %.4g: %s\n", index, k.hidden.at(0).name.c_str(), k.hidden.at(0).parameter, verdict_text(d).c_str());
    for (const PairFit& p : d.pairs)
      std::printf("    pair %s %.4g + %s %.4g: evidence %.1f, held-out chi2 %.1f, all-run chi2 %.1f\n", p.a.c_str(), p.pa, p.b.c_str(),
                  p.pb, p.evidence, p.heldout_chi2, p.insample_chi2);
    EXPECT_TRUE(d.explained()) << verdict_text(d);
    EXPECT_EQ(to_string(d.chosen), k.hidden.at(0).name) << verdict_text(d);
  }
}

namespace {

Diagnosis diagnosed(int index, std::uint64_t seed, const char* first, const char* second) {
  const BlindCampaign k = blind_key(index, seed);
  EXPECT_EQ(k.category, "two");
  EXPECT_EQ(k.hidden.at(0).name, first);
  EXPECT_EQ(k.hidden.at(1).name, second);
  Diagnosis d = diagnose(blind_lab_campaign(k), BlindSettings{}.diagnose);
  std::printf("  %s\n", verdict_text(d).c_str());
  for (const PairFit& p : d.pairs)
    std::printf("  pair %s %.4g + %s %.4g: evidence %.1f, held-out chi2 %.1f, all-run chi2 %.1f\n", p.a.c_str(), p.pa, p.b.c_str(),
                p.pb, p.evidence, p.heldout_chi2, p.insample_chi2);
  return d;
}

bool names(const Diagnosis& d, const std::string& a, const std::string& b) {
  const auto& c = d.chosen.names;
  return c.size() == 2 && ((c[0] == a && c[1] == b) || (c[0] == b && c[1] == a));
}

}  // namespace

// Seed 12801, campaign 183: a pickoff nonlinearity (7.56 /rad) with k1'..k4 wholly at the input
// (732 sigma). Alone, `servo_dynamics` leads (evidence 9.3e5; the pickoff is eighth), and with
// it as the first effect no second explains: "not explained". Each of the three best singles is
// now a first effect in turn, and the input placement's seconds are fitted along its gradient.
TEST(PairCampaign, APairWhoseBestSingleIsAThirdEffectIsFound) {
  const Diagnosis d = diagnosed(183, 12801, "pickoff_nonlinearity", "nonlinearity_at_input");
  EXPECT_EQ(d.verdict, Verdict::explained);
  EXPECT_TRUE(names(d, "pickoff_nonlinearity", "nonlinearity_at_input")) << verdict_text(d);
}

// Seed 12801, campaign 75: a 2nd harmonic (ratio 0.165) with k_PP (7.25e-7 /g). The pair was
// tried and fits (held-out chi^2 163 for 168 runs) but took the held-out rms from 2.42 to 1.63
// ug only: the floor (noise and the coefficients' extrapolation) is most of that. Judged above
// the floor, in the runs' sigma, it is the verdict; the harmonic's ratio within 3 % of the key's.
TEST(PairCampaign, APairThatLeavesOnlyTheFloorIsTheVerdict) {
  const Diagnosis d = diagnosed(75, 12801, "shaker_harmonic_distortion", "quadratic_cross_axis");
  EXPECT_EQ(d.verdict, Verdict::explained);
  ASSERT_TRUE(names(d, "quadratic_cross_axis", "shaker_harmonic_distortion")) << verdict_text(d);
  const PairFit& p = d.pairs.front();
  ASSERT_EQ(p.b, "shaker_harmonic_distortion");
  EXPECT_NEAR(p.pb, 0.1648, 0.03 * 0.1648);
}

// Seed 12801, campaign 15: k6 (1.44e-8 /g^5) with a misalignment of -0.0387 rad about OA. The
// second was fitted to what the misalignment leaves along the nominal gradient, where the
// misalignment turns the table's motion and so the coefficients' gradient: k6's drop fell
// behind a 3rd harmonic's and the servo's, and the pair was never tried ("not explained").
// Fitted along G_A + G_B - G_0, k6 ranks first. (A transverse motion IA -> OA with k6 comes
// within 1 of the pair's evidence, the two motions no sine run separates: docs/diagnose.md,
// "Known misses"; it does not halve the held-out gap above its floor, so no ambiguity.)
TEST(PairCampaign, ASecondIsFittedAlongTheFirstsGradient) {
  const Diagnosis d = diagnosed(15, 12801, "higher_order_k6", "mounting_misalignment");
  EXPECT_EQ(d.verdict, Verdict::explained);
  EXPECT_TRUE(names(d, "mounting_misalignment", "higher_order_k6")) << verdict_text(d);
  const PairFit& p = d.pairs.front();
  ASSERT_EQ(p.b, "higher_order_k6");
  // Within 15 %: the pair's two parameters trade over the 4 g runs (the angle fitted 13 % large,
  // k6 10 % small), and the pair reports no sigma to judge them by.
  EXPECT_NEAR(p.pb, 1.444e-8, 0.15 * 1.444e-8);
}

}  // namespace test_pair_misses
