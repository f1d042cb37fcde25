// Pairs of hidden effects from blind's draws, each campaign made as `blind` makes it
// (blind_lab_campaign: simulated on the ODE plant through the effects' truth hooks, handed to
// the lab) and diagnosed with blind's settings: the truth is the key's, never the diagnosis'
// hypothesis. Each diagnoses a 168-run campaign (20-40 s in Release): label "campaign".
#include <gtest/gtest.h>

#include <algorithm>
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

}  // namespace test_pair_misses
