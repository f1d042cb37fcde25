// The effect fitter's numerics (validation/diagnosis/internal/effect_fitter.hpp) on synthetic
// problems whose answer is known without the fitter: predictions linear in the parameters,
// pred = f0 + S theta, with a constant coefficient gradient G, so that V = diag(s2) + G Sigma G^T
// does not depend on the parameters and -2 ln L + the further parameters' priors is the
// quadratic (r - S theta)^T V^-1 (r - S theta) + sum_j w_j (theta_j - nominal_j)^2 + const.
// Its minimum and covariance are the generalised least squares solution with the priors as
// pseudo-observations, computed here with Eigen in long double:
//   theta* = (S^T V^-1 S + W)^-1 (S^T V^-1 r + W theta_nominal),  C = (S^T V^-1 S + W)^-1,
// the covariance being the inverse of half the objective's Hessian, as the fitter defines it.
// The cases: a two-parameter fit; a narrow valley (correlation below -0.998) from a start far off it;
// a parameter whose optimum lies outside its range (it ends on the edge, at_bound); and held
// parameters (a slope in the span of another's; a slope the data cannot pin within the prior).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <random>
#include <string>
#include <vector>

#include <Eigen/Dense>

#include "validation/diagnosis/effect.hpp"
#include "validation/diagnosis/internal/effect_fitter.hpp"
#include "validation/diagnosis/internal/likelihood.hpp"

namespace test_effect_fitter {

using namespace vrelab::validation;
using namespace vrelab::validation::internal;

namespace {

using MatrixL = Eigen::Matrix<long double, Eigen::Dynamic, Eigen::Dynamic>;
using VectorL = Eigen::Matrix<long double, Eigen::Dynamic, 1>;

// A synthetic campaign: n runs, the predictions f0 + S theta (g), two coefficient columns in G
// with a correlated Sigma (V is not diagonal), measured = f0 + S theta_true + noise.
struct Problem {
  Eigen::VectorXd f0;
  Eigen::MatrixXd S;  // n x k: d pred / d theta
  Table nominal;
  Data data;
  std::vector<int> all;
};

Problem make_problem(const Eigen::MatrixXd& S, const Eigen::VectorXd& theta_true, unsigned seed) {
  const Eigen::Index n = S.rows();
  Problem p;
  p.S = S;
  p.f0.resize(n);
  Eigen::MatrixXd G(n, 2);
  p.data.sigma2.resize(n);
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> n01;
  for (Eigen::Index k = 0; k < n; ++k) {
    const double x = 1 + 0.25 * static_cast<double>(k);
    p.f0(k) = 1e-3 * x;
    G(k, 0) = 1, G(k, 1) = x * x;
    p.data.sigma2(k) = std::pow(0.05 * (1 + 0.1 * static_cast<double>(k % 3)), 2);
  }
  p.data.Sigma.resize(2, 2);
  p.data.Sigma << 0.02 * 0.02, 0.5 * 0.02 * 0.003, 0.5 * 0.02 * 0.003, 0.003 * 0.003;
  p.nominal = {p.f0, G};
  // The measured values: the truth plus noise of V (the runs' own and the coefficients' shared).
  const Eigen::MatrixXd Lc = p.data.Sigma.llt().matrixL();
  Eigen::Vector2d c;
  c << n01(rng), n01(rng);
  const Eigen::VectorXd shared = G * (Lc * c);
  p.data.measured.resize(n);
  for (Eigen::Index k = 0; k < n; ++k) p.data.measured(k) = p.f0(k) + S.row(k).dot(theta_true) + shared(k) + std::sqrt(p.data.sigma2(k)) * n01(rng);
  for (Eigen::Index k = 0; k < n; ++k) p.all.push_back(static_cast<int>(k));
  return p;
}

// The model the fitter sees: the predictions at theta (one value per parameter), G constant.
EffectFitter::TableAt model_of(const Problem& p) {
  return [&p](const std::vector<double>& v) {
    Eigen::VectorXd theta(static_cast<Eigen::Index>(v.size()));
    for (std::size_t j = 0; j < v.size(); ++j) theta(static_cast<Eigen::Index>(j)) = v[j];
    return Table{p.f0 + p.S * theta, p.nominal.G};
  };
}

// The closed-form answer in long double: theta* and C (see the file's head). prior_weight[j]:
// w_j (0 for the first parameter, which has no prior).
struct Gls {
  VectorL theta;
  MatrixL cov;
};
Gls gls(const Problem& p, const std::vector<long double>& prior_weight, const std::vector<long double>& nominal) {
  const Eigen::Index n = p.S.rows(), k = p.S.cols();
  MatrixL V = (p.nominal.G * p.data.Sigma * p.nominal.G.transpose()).cast<long double>();
  for (Eigen::Index i = 0; i < n; ++i) V(i, i) += p.data.sigma2(i);
  const MatrixL S = p.S.cast<long double>();
  const VectorL r = (p.data.measured - p.f0).cast<long double>();
  const Eigen::LDLT<MatrixL> ldlt(V);
  MatrixL A = S.transpose() * ldlt.solve(S);
  VectorL b = S.transpose() * ldlt.solve(r);
  for (Eigen::Index j = 0; j < k; ++j) {
    A(j, j) += prior_weight[static_cast<std::size_t>(j)];
    b(j) += prior_weight[static_cast<std::size_t>(j)] * nominal[static_cast<std::size_t>(j)];
  }
  Gls g;
  g.cov = A.inverse();
  g.theta = g.cov * b;
  return g;
}

EffectParameter linear_first(double lower, double upper) {
  EffectParameter q("size", "1");
  q.nominal = 0, q.linear = true, q.unit_value = 1, q.lower = lower, q.upper = upper;
  return q;
}
EffectParameter further(double lower, double upper, double prior_sigma, double step) {
  EffectParameter q("form", "1");
  q.nominal = 0, q.lower = lower, q.upper = upper, q.prior_sigma = prior_sigma, q.step = step;
  return q;
}

Effect effect_of(std::vector<EffectParameter> parameters) {
  Effect e;
  e.name = "synthetic";
  e.parameters = std::move(parameters);
  e.hypothesis_accuracy = 0;
  return e;
}

}  // namespace

// One linear parameter: the fit (a scan, then parabolic refinement of an exactly quadratic
// -2 ln L) and its sigma (the curvature's second difference) against GLS. The parabola through
// three points of a quadratic lands on its vertex up to the rounding of -2 ln L (~1e-14 of
// its ~100 size, moving the vertex by ~1e-12 sigma); 1e-6 sigma is a wide margin that a wrong
// V (a dropped coefficient term shifts theta by ~0.1 sigma here) or a wrong sigma still fails.
TEST(EffectFitter, OneParameterEqualsGeneralisedLeastSquares) {
  Eigen::MatrixXd S(20, 1);
  for (Eigen::Index k = 0; k < 20; ++k) S(k, 0) = 0.1 * std::sin(0.7 * static_cast<double>(k)) + 0.02 * static_cast<double>(k);
  Eigen::VectorXd truth(1);
  truth << 1.5;
  const Problem p = make_problem(S, truth, 11);
  const Effect e = effect_of({linear_first(-100, 100)});
  const EffectFitter fitter(e, p.nominal, model_of(p));
  const EffectFitter::Multi mf = fitter.fit_all(p.data, p.all);
  const Gls g = gls(p, {0}, {0});
  const double sigma = std::sqrt(static_cast<double>(g.cov(0, 0)));
  ASSERT_EQ(mf.values.size(), 1u);
  EXPECT_NEAR(mf.values[0], static_cast<double>(g.theta(0)), 1e-6 * sigma);
  EXPECT_NEAR(mf.sigma[0], sigma, 1e-6 * sigma);
  EXPECT_EQ(mf.status[0], ParameterStatus::fitted);
  // The same fit through fit(): the one-parameter path.
  const auto [value, s] = fitter.fit(p.data, p.all);
  EXPECT_EQ(value, mf.values[0]);
  EXPECT_EQ(s, mf.sigma[0]);
}

// Beside another effect that changes the coefficients' gradient (a pair's G_A - G_0): the fit
// with dG added to every table's G is GLS with V = diag(s2) + (G + dG) Sigma (G + dG)^T, the
// pair's covariance; here dG moves the estimate by half its sigma (1.197 against 1.267 alone,
// sigma 0.145), so a fit that left dG out fails by 10^5 times the tolerance of 1e-6 sigma (the
// one-parameter test's above).
TEST(EffectFitter, AFitBesideAnotherEffectTakesItsGradient) {
  Eigen::MatrixXd S(20, 1);
  for (Eigen::Index k = 0; k < 20; ++k) S(k, 0) = 0.1 * std::sin(0.7 * static_cast<double>(k)) + 0.02 * static_cast<double>(k);
  Eigen::VectorXd truth(1);
  truth << 1.5;
  const Problem p = make_problem(S, truth, 11);
  Eigen::MatrixXd dG = Eigen::MatrixXd::Zero(p.nominal.G.rows(), p.nominal.G.cols());
  for (Eigen::Index k = 0; k < dG.rows(); ++k) dG(k, 0) = 2 * static_cast<double>(k) / 19, dG(k, 1) = -0.5 * p.nominal.G(k, 1) * (k % 2);
  const Effect e = effect_of({linear_first(-100, 100)});
  const EffectFitter fitter(e, p.nominal, model_of(p));
  Problem q = p;
  q.nominal.G += dG;
  const Gls beside = gls(q, {0}, {0}), alone = gls(p, {0}, {0});
  const double sigma = std::sqrt(static_cast<double>(beside.cov(0, 0)));
  const auto [value, s] = fitter.fit_beside(p.data, p.all, dG);
  std::printf("  beside %.6f +- %.6f (GLS %.6f +- %.6f; alone %.6f)\n", value, s, static_cast<double>(beside.theta(0)), sigma,
              static_cast<double>(alone.theta(0)));
  EXPECT_GT(std::abs(static_cast<double>(beside.theta(0) - alone.theta(0))), 0.3 * sigma);  // the case tests something
  EXPECT_NEAR(value, static_cast<double>(beside.theta(0)), 1e-6 * sigma);
  EXPECT_NEAR(s, sigma, 1e-6 * sigma);
}

// Two parameters (the first linear, a further continuous one with a weak prior): Levenberg-
// Marquardt's end and the Hessian covariance against GLS with the prior. Tolerances: the
// descent stops when every move is below 1e-3 of the parameter's conditional sigma, and each of
// its nearly Newton steps (lambda <= 1e-3) leaves much less than the move it made, so 1e-3 of
// the marginal sigma bounds the values' error; the covariance is a second difference of an
// exact quadratic (rounding ~1e-12 relative), checked to 1e-6.
TEST(EffectFitter, TwoParametersEqualGeneralisedLeastSquaresWithThePrior) {
  Eigen::MatrixXd S(24, 2);
  for (Eigen::Index k = 0; k < 24; ++k) {
    const double x = static_cast<double>(k);
    S(k, 0) = 0.05 + 0.01 * x, S(k, 1) = 0.08 * std::cos(0.5 * x);
  }
  Eigen::VectorXd truth(2);
  truth << 2.0, -1.0;
  const Problem p = make_problem(S, truth, 12);
  const double prior_sigma = 5;
  const Effect e = effect_of({linear_first(-100, 100), further(-20, 20, prior_sigma, 1e-3)});
  const EffectFitter fitter(e, p.nominal, model_of(p));
  const EffectFitter::Multi mf = fitter.fit_all(p.data, p.all);
  const Gls g = gls(p, {0, 1 / (static_cast<long double>(prior_sigma) * prior_sigma)}, {0, 0});
  ASSERT_EQ(mf.status.size(), 2u);
  EXPECT_EQ(mf.status[0], ParameterStatus::fitted);
  EXPECT_EQ(mf.status[1], ParameterStatus::fitted);
  ASSERT_EQ(mf.cov.rows(), 2);
  for (int j = 0; j < 2; ++j) {
    const double sj = std::sqrt(static_cast<double>(g.cov(j, j)));
    EXPECT_NEAR(mf.values[static_cast<std::size_t>(j)], static_cast<double>(g.theta(j)), 1e-3 * sj) << "parameter " << j;
    EXPECT_NEAR(mf.sigma[static_cast<std::size_t>(j)], sj, 1e-6 * sj) << "parameter " << j;
    for (int i = 0; i < 2; ++i)
      EXPECT_NEAR(mf.cov(i, j), static_cast<double>(g.cov(i, j)), 1e-6 * std::sqrt(static_cast<double>(g.cov(i, i) * g.cov(j, j))));
  }
}

// A narrow valley: the two slopes nearly collinear, the estimates correlated beyond -0.998
// (checked on the closed form), and the further parameter's difference step (0.5) more than
// twice its conditional sigma, where differences straddle the valley (the valley step's case).
// The start, the first parameter fitted with the second at its nominal 0, lies far off the
// optimum (the truth 40 is ~20 marginal sigma from 0; asserted: -2 ln L at the start exceeds
// the minimum by more than 100). The end must be the GLS
// optimum: within 1e-3 of each marginal sigma (the descent's stopping rule, as above).
TEST(EffectFitter, FindsTheOptimumOfANarrowValleyFromFarOff) {
  const Eigen::Index n = 30;
  Eigen::MatrixXd S(n, 2);
  for (Eigen::Index k = 0; k < n; ++k) {
    const double x = static_cast<double>(k) / static_cast<double>(n - 1);
    S(k, 0) = 0.2 + 0.3 * x, S(k, 1) = 0.2 + 0.3 * x + 0.012 * std::sin(6 * x);
  }
  Eigen::VectorXd truth(2);
  truth << 3.0, 40.0;
  const Problem p = make_problem(S, truth, 13);
  const double prior_sigma = 50;
  const Effect e = effect_of({linear_first(-200, 200), further(-100, 100, prior_sigma, 0.5)});
  const Gls g = gls(p, {0, 1 / (static_cast<long double>(prior_sigma) * prior_sigma)}, {0, 0});
  const double s0 = std::sqrt(static_cast<double>(g.cov(0, 0))), s1 = std::sqrt(static_cast<double>(g.cov(1, 1)));
  const double rho = static_cast<double>(g.cov(0, 1)) / (s0 * s1);
  ASSERT_LT(rho, -0.998) << "the valley is not as narrow as the test says";
  const double conditional_sigma1 = s1 * std::sqrt(1 - rho * rho);
  ASSERT_GT(0.5, 2 * conditional_sigma1) << "the difference step does not straddle the valley";
  const EffectFitter fitter(e, p.nominal, model_of(p));
  // The start: the one-parameter fit at the second's nominal, and how far above the minimum it is.
  const double p0_start = fitter.fit(p.data, p.all).first;
  const auto objective = [&](double a, double b) {
    const Eigen::VectorXd pred = p.f0 + p.S.col(0) * a + p.S.col(1) * b;
    return likelihood(p.data, pred, p.nominal.G, p.all).m2logl + b * b / (prior_sigma * prior_sigma);
  };
  ASSERT_GT(objective(p0_start, 0) - objective(static_cast<double>(g.theta(0)), static_cast<double>(g.theta(1))), 100);
  const EffectFitter::Multi mf = fitter.fit_all(p.data, p.all);
  ASSERT_EQ(mf.status.size(), 2u);
  EXPECT_EQ(mf.status[1], ParameterStatus::fitted);
  EXPECT_NEAR(mf.values[0], static_cast<double>(g.theta(0)), 1e-3 * s0);
  EXPECT_NEAR(mf.values[1], static_cast<double>(g.theta(1)), 1e-3 * s1);
  EXPECT_NEAR(mf.sigma[1], s1, 1e-3 * s1);
}

// A curved valley (Rosenbrock's banana): -2 ln L = K [ratio (b - a^2)^2 + (a - 1)^2] + the prior
// on a, b the first (linear) parameter, a the further one. Runs 0..9 see ratio x (b - a^2),
// runs 10..19 see a (the predictions' coefficients chosen so), with exact data at a = b = 1, G
// zero (V = diag(sigma^2), ln det V constant). The closed form: for each a the best b is a^2
// (the first term vanishes), so a* = (K + w a0) / (K + w) (w the prior's weight, a0 its
// nominal) and b* = a*^2; the marginal sigmas from the Hessian there. From the start (a at its
// nominal 0, b fitted there: 0, the bottom of the floor) the floor bends up to (1, 1); b's
// difference step is about 6 of its conditional sigma, so the differences straddle the walls.
// Levenberg-Marquardt's damped steps creep along the bend and stop short within their 15
// iterations (seen with the valley step switched off: 1.2 marginal sigma short in a and b);
// the valley step (Newton's step on the local Hessian, backtracked) follows the floor to its
// end (seen: 7e-4 sigma). The descent stops when its step is below 1e-3 of each conditional
// sigma, which in this valley leaves more in the marginal one: 1e-2 of the marginal sigma.
TEST(EffectFitter, FollowsACurvedValleyToItsOptimum) {
  const Eigen::Index n = 20, half = 10;
  const double sigma = 0.05, K = 4000, ratio = 100;
  // sum over each half of (coefficient / sigma)^2: ratio K and K.
  const double c_floor = std::sqrt(ratio * K / half) * sigma, c_a = std::sqrt(K / half) * sigma;
  Problem p;
  p.f0 = Eigen::VectorXd::Constant(n, 1e-3);
  p.S = Eigen::MatrixXd::Zero(n, 2);
  p.data.sigma2 = Eigen::VectorXd::Constant(n, sigma * sigma);
  p.data.Sigma = Eigen::MatrixXd::Identity(2, 2);
  const auto pred_at = [&](double b, double a) {
    Eigen::VectorXd pr = p.f0;
    pr.head(half).array() += c_floor * (b - a * a);
    pr.tail(n - half).array() += c_a * a;
    return pr;
  };
  const double a0 = 0, prior_sigma = 10, w = 1 / (prior_sigma * prior_sigma);
  p.nominal = {pred_at(0, a0), Eigen::MatrixXd::Zero(n, 2)};  // the parameters at their nominal
  p.data.measured = pred_at(1, 1);
  for (Eigen::Index k = 0; k < n; ++k) p.all.push_back(static_cast<int>(k));
  EffectParameter a_par = further(-5, 5, prior_sigma, 0.01);
  a_par.nominal = a0;
  const Effect e = effect_of({linear_first(-10, 10), a_par});
  const EffectFitter fitter(e, p.nominal, [&](const std::vector<double>& v) { return Table{pred_at(v[0], v[1]), p.nominal.G}; });
  const long double a_opt = (static_cast<long double>(K) + w * a0) / (K + w), b_opt = a_opt * a_opt;
  // The marginal sigmas from the Hessian at the optimum, half of it being
  // [[R, -2 a R], [-2 a R, 4 a^2 R + K + w]] with R = ratio K (b first).
  const long double R = static_cast<long double>(ratio) * K;
  MatrixL Hh(2, 2);
  Hh << R, -2 * a_opt * R, -2 * a_opt * R, 4 * a_opt * a_opt * R + K + w;
  const MatrixL C = Hh.inverse();
  const double sb = std::sqrt(static_cast<double>(C(0, 0))), sa = std::sqrt(static_cast<double>(C(1, 1)));
  const EffectFitter::Multi mf = fitter.fit_all(p.data, p.all);
  ASSERT_EQ(mf.status.size(), 2u);
  EXPECT_EQ(mf.status[1], ParameterStatus::fitted);
  std::printf("  end a %.9g b %.9g; closed form a %.9g b %.9g (sigma %.3g, %.3g)\n", mf.values[1], mf.values[0],
              static_cast<double>(a_opt), static_cast<double>(b_opt), sa, sb);
  EXPECT_NEAR(mf.values[1], static_cast<double>(a_opt), 1e-2 * sa);
  EXPECT_NEAR(mf.values[0], static_cast<double>(b_opt), 1e-2 * sb);
}

// The unconstrained optimum outside the range: the first parameter ends on its upper edge
// (the scan's last point, lo + (hi - lo), equal to the edge up to one rounding), with no
// curvature there (sigma not finite), and fitted_parameters reports at_bound.
TEST(EffectFitter, AnOptimumBeyondTheRangeEndsOnItsEdge) {
  Eigen::MatrixXd S(20, 1);
  for (Eigen::Index k = 0; k < 20; ++k) S(k, 0) = 0.1 + 0.01 * static_cast<double>(k);
  Eigen::VectorXd truth(1);
  truth << 8.0;
  const Problem p = make_problem(S, truth, 14);
  const Gls g = gls(p, {0}, {0});
  const double upper = 5;
  // The optimum well beyond the edge (many sigma), so the edge is not a rounding matter.
  ASSERT_GT(static_cast<double>(g.theta(0)) - upper, 5 * std::sqrt(static_cast<double>(g.cov(0, 0))));
  const Effect e = effect_of({linear_first(-5, upper)});
  const EffectFitter fitter(e, p.nominal, model_of(p));
  const EffectFitter::Multi mf = fitter.fit_all(p.data, p.all);
  EXPECT_NEAR(mf.values[0], upper, 1e-12 * upper);
  EXPECT_FALSE(std::isfinite(mf.sigma[0]));
  const std::vector<FittedParameter> fp = fitted_parameters(e, mf);
  ASSERT_EQ(fp.size(), 1u);
  EXPECT_TRUE(fp[0].at_bound);
  EXPECT_EQ(fp[0].upper, upper);
}

// A linear effect that changes the coefficients' gradient (an input-placed nonlinearity: the
// loop's k2 sees the current, the input's the motion): G(p) = G0 + p (G1 - G0), the residual
// the signature plus what the coefficients' error makes through G1 (the truth at p = 1). The
// fitter brackets the optimum from the likelihood at the nominal covariance (G0 = 0 here,
// which judges the G1 part as signal): that estimate falls well short of the optimum (checked
// below with the bracket's own rule), and the scan must grow its bracket until the optimum
// lies inside. The reference: -2 ln L on a fine scan of the physical range (the likelihood
// itself has its own tests); the fit within one of its steps, interior (sigma finite).
TEST(EffectFitter, ALinearEffectsBracketGrowsToTheOptimum) {
  const Eigen::Index n = 24;
  Eigen::VectorXd s(n), f0(n);
  Eigen::MatrixXd G0 = Eigen::MatrixXd::Zero(n, 2), G1(n, 2);
  Data d;
  d.sigma2 = Eigen::VectorXd::Constant(n, 1e-4);
  d.Sigma = Eigen::Matrix2d::Identity();
  for (Eigen::Index k = 0; k < n; ++k) {
    const double x = static_cast<double>(k) / static_cast<double>(n - 1);
    f0(k) = 0, s(k) = 1 + x, G1(k, 0) = 1, G1(k, 1) = x * x;
  }
  const Eigen::Vector2d dc(-1.2, -0.8);  // the coefficients' error, about one sigma of Sigma
  d.measured = s + G1 * dc;
  const Table t0{f0, G0}, t1{f0 + s, G1};
  const EffectFitter::TableAt model = [&](const std::vector<double>& v) {
    return v.front() == 0 ? t0 : t1;  // (the fitter interpolates a linear effect itself)
  };
  EffectParameter q("fraction", "1");
  q.nominal = 0, q.linear = true, q.unit_value = 1, q.lower = -0.5, q.upper = 1.5;
  const Effect e = effect_of({q});
  std::vector<int> all;
  for (Eigen::Index k = 0; k < n; ++k) all.push_back(static_cast<int>(k));
  // The bracket's first estimate (the fitter's rule: u0 +- 3 |u0| + 20 su at the nominal V).
  const Eigen::VectorXd w = d.sigma2.cwiseInverse();
  const double info = s.dot(w.asDiagonal() * s), u0 = s.dot(w.asDiagonal() * d.measured) / info;
  const double first_hi = u0 + 3 * std::abs(u0) + 20 / std::sqrt(info);
  double best = 0, lbest = INFINITY;
  for (int k = 0; k <= 20000; ++k) {
    const double p = q.lower + (q.upper - q.lower) * k / 20000.0;
    const double l = likelihood(d, f0 + p * s, G0 + p * (G1 - G0), all).m2logl;
    if (l < lbest) best = p, lbest = l;
  }
  std::printf("  first bracket ends at %.3f; the optimum %.4f\n", first_hi, best);
  ASSERT_LT(first_hi, best - 0.1);
  ASSERT_LT(best, q.upper - 0.1);
  const EffectFitter fitter(e, t0, model);
  const auto [value, sigma] = fitter.fit(d, all);
  EXPECT_NEAR(value, best, 2 * (q.upper - q.lower) / 20000.0);
  EXPECT_TRUE(std::isfinite(sigma));
}

// Held parameters (EffectFitter::unpinned): a further parameter whose slope is twice the
// first's (in its span: the whitened Jacobian has rank 1) is held at its nominal, and the
// result is the one-parameter fit (no covariance, the first parameter's GLS value). Likewise a
// further parameter whose slope is so small that its sigma from the data (~8 here, computed
// below) is not below its prior width (1): held.
TEST(EffectFitter, HoldsAParameterTheDataDoNotPin) {
  const Eigen::Index n = 20;
  Eigen::MatrixXd S1(n, 1);
  for (Eigen::Index k = 0; k < n; ++k) S1(k, 0) = 0.1 + 0.02 * static_cast<double>(k);
  for (const bool collinear : {true, false}) {
    Eigen::MatrixXd S(n, 2);
    S.col(0) = S1.col(0);
    for (Eigen::Index k = 0; k < n; ++k) S(k, 1) = collinear ? 2 * S1(k, 0) : 1e-3 * std::cos(static_cast<double>(k));
    Eigen::VectorXd truth(2);
    truth << 1.0, 0.0;
    const Problem p = make_problem(S, truth, 15);
    const double prior_sigma = 1;
    const Effect e = effect_of({linear_first(-100, 100), further(-4, 4, prior_sigma, 1e-3)});
    if (!collinear) {  // the data alone leave the slope's parameter looser than its prior
      const Problem q = make_problem(S, truth, 15);
      const Gls data_only = gls(q, {0, 0}, {0, 0});
      ASSERT_GT(std::sqrt(static_cast<double>(data_only.cov(1, 1))), prior_sigma);
    }
    const EffectFitter fitter(e, p.nominal, model_of(p));
    const EffectFitter::Multi mf = fitter.fit_all(p.data, p.all);
    ASSERT_EQ(mf.status.size(), 2u);
    EXPECT_EQ(mf.status[1], ParameterStatus::held) << (collinear ? "collinear" : "loose");
    EXPECT_EQ(mf.values[1], 0.0);
    EXPECT_TRUE(std::isnan(mf.sigma[1]));
    EXPECT_EQ(mf.cov.size(), 0);
    // The one-parameter fit: GLS on the first slope alone (1e-6 sigma: as in the first test).
    Problem first_only = p;
    first_only.S = S1;
    const Gls g = gls(first_only, {0}, {0});
    const double sigma = std::sqrt(static_cast<double>(g.cov(0, 0)));
    EXPECT_NEAR(mf.values[0], static_cast<double>(g.theta(0)), 1e-6 * sigma);
    EXPECT_NEAR(mf.sigma[0], sigma, 1e-6 * sigma);
  }
}

}  // namespace test_effect_fitter
