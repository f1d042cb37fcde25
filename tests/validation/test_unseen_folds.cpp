// A fold whose training runs do not see a nonlinear effect is scored over the effect's grid
// (validation/diagnosis/internal/evidence.hpp, Scorer::unseen_forms; docs/diagnose.md,
// section 7).
//
// Fast: on a synthetic campaign (predictions f0 + S p^2, a constant coefficient gradient G),
// the mixture's held-out score equals the ratio of the grid's marginal likelihoods,
// -2 ln p(test | train) = -2 ln sum_g L_all(g) + 2 ln sum_g L_train(g) (uniform weights on the
// grid's points; p(test | train, g) = L_all(g) / L_train(g)), assembled here in long double
// from the likelihoods alone; and the grid is taken only where the fold's fit does not stand
// (a nonlinear effect the training runs do not see, on a fold).
// Campaign: the squeeze film of blind seed 12801, campaign 95, replayed (the truth through the
// ODE plant and the film's truth hook).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <map>
#include <random>
#include <vector>

#include <Eigen/Dense>

#include "plant/model1.hpp"
#include "support/blind_replay.hpp"
#include "support/diagnosis_lookup.hpp"
#include "support/two_fold_model.hpp"
#include "validation/diagnosis/diagnosis_text.hpp"
#include "validation/diagnosis/effect.hpp"
#include "validation/diagnosis/internal/effect_fitter.hpp"
#include "validation/diagnosis/internal/evidence.hpp"
#include "validation/diagnosis/internal/likelihood.hpp"

namespace test_unseen_folds {

using namespace vrelab::validation;
using namespace vrelab::validation::internal;

namespace {

// 24 runs: 12 at "1 g" (fold key 1) that barely feel the effect, 12 at "4 g" (fold key 4) that
// feel it strongly; pred = f0 + S p^2, the truth p = 2 (at "4 g" 16 x 0.05 = 0.8 against a sigma
// of 0.05, at "1 g" 0.2 sigma).
struct Synthetic : vrelab::test::TwoFoldModel {
  Eigen::VectorXd S;
};

void make(Synthetic& s, unsigned seed) {
  const int n = Synthetic::kRuns;
  s.S.resize(n);
  Eigen::VectorXd f0(n);
  // The coefficients' gradient has the plant's kNumCoefficients columns (the scorer's layout);
  // two carry the runs' shared errors, the others are zero.
  Eigen::MatrixXd G = Eigen::MatrixXd::Zero(n, vrelab::plant::kNumCoefficients);
  for (int k = 0; k < n; ++k) {
    const double x = 1 + 0.25 * (k % 12);
    f0(k) = 1e-3 * x, G(k, 0) = 1, G(k, 1) = x * x;
    s.S(k) = Synthetic::second_fold(k) ? 0.05 : 0.0006 * x;
  }
  s.set(f0, G, 0.05);
  s.m.data.Sigma(0, 0) = 1e-6;
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> n01;
  s.m.data.measured.resize(n);
  for (int k = 0; k < n; ++k) s.m.data.measured(k) = f0(k) + 4 * s.S(k) + 0.05 * n01(rng);
}

Effect nonlinear_effect() {
  Effect e;
  e.name = "synthetic";
  EffectParameter q("size", "1");
  q.nominal = 0;
  for (int i = 0; i <= 12; ++i) q.grid.push_back(0.25 * i);
  e.parameters = {q};
  e.hypothesis_accuracy = 0;
  return e;
}

EffectFitter::TableAt model_of(const Synthetic& s) {
  return [&s](const std::vector<double>& v) { return Table{s.m.nominal.pred + s.S * v[0] * v[0], s.m.nominal.G}; };
}

long double log_sum_exp(const std::vector<long double>& x) {
  long double top = x.front(), sum = 0;
  for (long double v : x) top = std::max(top, v);
  for (long double v : x) sum += std::exp(v - top);
  return top + std::log(sum);
}

}  // namespace

// The mixture's algebra (the forms' log-sum-exps, the conditional likelihoods, the nominal's
// held-out score) against the marginal likelihoods' ratio. Both are sums of the same
// likelihood() values (~-100 each), assembled differently; rounding moves them by ~1e-12, and a
// wrong weight (the test likelihood left out of the posterior, the training's counted twice)
// moves the evidence by units.
TEST(UnseenFolds, TheGridMixtureIsTheRatioOfTheGridsMarginalLikelihoods) {
  Synthetic s;
  make(s, 7);
  const Effect e = nonlinear_effect();
  const EffectFitter fitter(e, s.m.nominal, model_of(s));
  const Scorer scorer(s.m, s.folds);
  const Data& d = s.m.data;
  const auto grid_forms = [&](const std::vector<int>& train) {
    std::vector<Scorer::Form> forms;
    for (double p : fitter.grid()) {
      const Table t = fitter.at(p);
      forms.push_back({Fitted{t, Eigen::MatrixXd(s.m.n, 0), Eigen::MatrixXd(0, 0)}, likelihood(d, t.pred, t.G, train).m2logl});
    }
    return forms;
  };
  Scored sc;
  scorer.score_forms(grid_forms, sc);
  long double expected = 0;
  for (const auto& [key, test] : s.folds.test) {
    const std::vector<int> train = s.folds.train(key);
    std::vector<long double> l_all, l_train;
    for (double p : fitter.grid()) {
      const Table t = fitter.at(p);
      l_all.push_back(-0.5L * likelihood(d, t.pred, t.G, s.m.all).m2logl);
      l_train.push_back(-0.5L * likelihood(d, t.pred, t.G, train).m2logl);
    }
    const long double nominal = likelihood(d, s.m.nominal.pred, s.m.nominal.G, s.m.all).m2logl -
                                likelihood(d, s.m.nominal.pred, s.m.nominal.G, train).m2logl;
    expected += nominal - (-2 * log_sum_exp(l_all) + 2 * log_sum_exp(l_train));
  }
  std::printf("  evidence %.12f, from the marginal likelihoods %.12Lf\n", sc.fit.evidence, expected);
  EXPECT_NEAR(sc.fit.evidence, static_cast<double>(expected), 1e-8);
  EXPECT_GT(sc.fit.evidence, 10);  // the effect is there (0.8 / 0.05 at every "4 g" run)
}

// The grid is taken on the fold whose training runs ("1 g") do not see the effect (-2 ln L
// falls by 0.2^2 x 12 ~ 0.5 from no effect, far below kSeen's 25), never where they see it
// ("4 g" in training: ~3000), on every run (in-sample), or for a linear effect.
TEST(UnseenFolds, TheGridIsTakenOnlyWhereTheTrainingRunsDoNotSeeANonlinearEffect) {
  Synthetic s;
  make(s, 11);
  const Effect e = nonlinear_effect();
  const EffectFitter fitter(e, s.m.nominal, model_of(s));
  const Scorer scorer(s.m, s.folds);
  const Data& d = s.m.data;
  const std::vector<int> weak = s.folds.train(4.0), strong = s.folds.train(1.0);
  EXPECT_EQ(scorer.unseen_forms(fitter, fitter.fit_all(d, weak), d, weak).size(), fitter.grid().size());
  EXPECT_TRUE(scorer.unseen_forms(fitter, fitter.fit_all(d, strong), d, strong).empty());
  EXPECT_TRUE(scorer.unseen_forms(fitter, fitter.fit_all(d, s.m.all), d, s.m.all).empty());
  Effect lin = e;
  lin.parameters.front().linear = true, lin.parameters.front().grid.clear();
  lin.parameters.front().lower = -10, lin.parameters.front().upper = 10;
  const EffectFitter linear(lin, s.m.nominal, model_of(s));
  EXPECT_TRUE(scorer.unseen_forms(linear, linear.fit_all(d, weak), d, weak).empty());
}

// Seed 12801, campaign 95: a squeeze film of 878.7 /rad (15.9 sigma; its gap in the 4 g runs at
// 100-200 Hz along IA). Scored with the Gaussian about the fit of the fold that leaves 4 g out
// (a noise minimum of the 1 and 2 g runs), the film's evidence fell below a 3rd harmonic's
// (ratio 0.110), which `blind` called with confidence. Over the grid of that fold the film
// leads: 270 against the harmonic's 245 (the harmonic's own, linear in its ratio, unchanged).
TEST(UnseenFoldsCampaign, ASqueezeFilmNearContactIsNotCalledAThirdHarmonic) {
  const BlindResult r = vrelab::test::replay_blind_campaign(12801, 95);
  const BlindCampaign& k = r.campaigns.at(95);
  ASSERT_EQ(k.category, "single");
  ASSERT_EQ(k.hidden.at(0).name, "squeeze_film_damping");
  const Diagnosis& dg = k.diagnosis;
  std::printf("  %s\n", verdict_text(dg).c_str());
  EXPECT_EQ(k.called, "squeeze_film_damping");
  ASSERT_EQ(dg.effects.front().name, "squeeze_film_damping");
  const FittedParameter& p = vrelab::test::parameter_named(dg.effects.front(), "inverse_gap_angle");
  std::printf("  inverse gap %.1f +- %.1f /rad (truth %.1f)\n", p.value, p.sigma, k.hidden[0].parameter);
  EXPECT_LE(std::abs(p.value - k.hidden[0].parameter), 3 * p.sigma);
  EXPECT_EQ(r.scores.families.at("single").right, 1);
}

}  // namespace test_unseen_folds
