// Eq. (3), corrected, against independent numerical averages of model (1):
//  - sine: the period average of U/K1 by piecewise Gauss-Legendre (split where a_IA or the
//    clipped signal has a kink), to 1e-12 g;
//  - Gaussian: the expectation by Gauss-Hermite (polynomial part, exact for degree < 20)
//    and by piecewise Gauss-Legendre against the normal density (|.| and clipping), 1e-12 g.
// Tolerance: the terms reach ~25 g at the extremes drawn (k4 = 1e-2 at 9 g) and the reference
// quadratures are converged to the rounding of such sums (~1e-14 g), so 1e-12 g leaves a
// margin of ~40, while every erratum of the printed formula is far larger (checked below).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <random>

#include "plant/model1.hpp"
#include "rectification/prediction/eq3.hpp"
#include "support/constants.hpp"
#include "support/quadrature.hpp"
#include "support/random_coefficients.hpp"

namespace test_eq3 {

using namespace vrelab;
using namespace vrelab::plant;
using namespace vrelab::rectification;
using vrelab::test::kPi;

namespace {

// <U/K1(a + w sin(t + phi))> - U/K1(a) over one period, numerically.
double period_average(const Coefficients& c, const Vec3& a, const vibration::SineVibration& v) {
  auto acc = [&](double t) {
    Vec3 x;
    for (int i = 0; i < 3; ++i) x[i] = a[i] + v.amplitude_g[i] * std::sin(t + v.phase_rad[i]);
    return x;
  };
  const double mean = test::integrate_piecewise([&](double t) { return output_g(c, acc(t)); }, 0, 2 * kPi,
                                                {[&](double t) { return acc(t)[IA]; }}) / (2 * kPi);
  return mean - output_g(c, a);
}


struct Draw {
  Coefficients c;
  Vec3 a;
  vibration::SineVibration v;
};

Draw draw(std::mt19937_64& rng, int n) {
  std::uniform_real_distribution<double> u(-1, 1), amp(0, 8), phase(-kPi, kPi);
  Draw d;
  d.c = test::random_coefficients(rng);
  d.a = Vec3(u(rng), u(rng), u(rng)).normalized();
  for (int i = 0; i < 3; ++i) d.v.amplitude_g[i] = amp(rng);
  // Every third draw has |a_IA| < |w_IA| for sure, where the asymmetry term acts.
  if (n % 3 == 0) d.v.amplitude_g[IA] = std::abs(d.a[IA]) + 0.1 + amp(rng);
  if (n % 2 == 0) d.v.phase_rad = Vec3(phase(rng), phase(rng), phase(rng));
  return d;
}

}  // namespace

TEST(Eq3SineCampaign, EachTermEqualsThePeriodAverageOfModel1) {
  std::mt19937_64 rng(21);
  int asymmetry_inside = 0;
  for (int n = 0; n < 60; ++n) {
    const Draw d = draw(rng, n);
    if (std::abs(d.a[IA]) < d.v.amplitude_g[IA]) ++asymmetry_inside;
    for (int i = k1_asym; i < kNumCoefficients; ++i) {
      const int t = term_of_coefficient(i);
      if (t < 0) continue;  // odd and linear terms: zero mean (checked in the total below)
      Coefficients only;
      only[K1] = d.c[K1];
      only[i] = d.c[i];
      const Eq3Terms terms = sine_rectification(only, d.a, d.v);
      EXPECT_NEAR(terms.g[t], period_average(only, d.a, d.v), 1e-12)
          << coefficient_name(i) << " draw " << n;
      EXPECT_NEAR(terms.total_g(), terms.g[t], 1e-18) << "only one term may be non-zero";
    }
  }
  EXPECT_GE(asymmetry_inside, 20);
}

TEST(Eq3Sine, TotalEqualsThePeriodAverageWithEveryCoefficientAndPhases) {
  std::mt19937_64 rng(22);
  for (int n = 0; n < 60; ++n) {
    const Draw d = draw(rng, n);
    EXPECT_NEAR(sine_rectification(d.c, d.a, d.v).total_g(), period_average(d.c, d.a, d.v), 1e-12);
  }
}

TEST(Eq3Sine, PrintedFormIsWrongWhereTheNotesSay) {
  // Asymmetry alone, |a| < |w|, a != 0: the printed term lacks the factor a before asin.
  Coefficients c;
  c[K1] = 1;
  c[k1_asym] = 1e-3;
  vibration::SineVibration v;
  v.amplitude_g = Vec3(2, 0, 0);
  const Vec3 a(0.7, 0.71414284285, 0);
  const double truth = period_average(c, a, v);
  EXPECT_NEAR(sine_rectification(c, a, v).total_g(), truth, 1e-14);
  // Printed minus corrected = (k1'/pi)(1 - a) asin(a/w): 3.4e-5 g here.
  EXPECT_NEAR(sine_rectification_as_printed(c, a, v) - truth, 1e-3 / kPi * (1 - 0.7) * std::asin(0.35), 1e-14);
  // k_PP alone: the printed form omits it.
  Coefficients p;
  p[K1] = 1;
  p[k_PP] = 2e-5;
  v.amplitude_g = Vec3(0, 3, 0);
  EXPECT_NEAR(period_average(p, a, v), 2e-5 * 9 / 2, 1e-15);
  EXPECT_EQ(sine_rectification_as_printed(p, a, v), 0.0);
  EXPECT_NEAR(sine_rectification(p, a, v).omitted_by_paper_g(), 2e-5 * 9 / 2, 1e-15);
}

TEST(Eq3Sine, ClippingEqualsThePeriodAverageOfTheClippedInput) {
  std::mt19937_64 rng(23);
  std::uniform_real_distribution<double> ua(-1, 1), uw(0, 12), ur(0.5, 8);
  for (int n = 0; n < 200; ++n) {
    // Every tenth draw has |a| > R: the static input is clipped too (baseline clip(a)).
    const double r = ur(rng), a = n % 10 == 0 ? r * (1.0 + 0.5 * ua(rng) * ua(rng)) * (n % 20 == 0 ? -1 : 1) : ua(rng),
                 w = uw(rng);
    auto x = [&](double t) { return a + w * std::sin(t); };
    const double ref = test::integrate_piecewise([&](double t) { return std::clamp(x(t), -r, r); }, 0, 2 * kPi,
                                                 {[&](double t) { return x(t) - r; }, [&](double t) { return x(t) + r; }}) /
                           (2 * kPi) -
                       std::clamp(a, -r, r);
    EXPECT_NEAR(clipping_sine(a, w, r), ref, 1e-12) << "a " << a << " w " << w << " R " << r;
  }
}

namespace {

// E[f(a + X)] for X ~ N(0, sigma^2), f with kinks where the `kinks` functions change sign:
// piecewise Gauss-Legendre against the density over +-14 sigma (tail mass < 1e-44).
double gaussian_expectation(const std::function<double(double)>& f, double sigma,
                            const std::vector<std::function<double(double)>>& kinks) {
  auto integrand = [&](double z) { return f(sigma * z) * std::exp(-z * z / 2) / std::sqrt(2 * kPi); };
  std::vector<std::function<double(double)>> kz;
  for (const auto& k : kinks) kz.push_back([&, k](double z) { return k(sigma * z); });
  return test::integrate_piecewise(integrand, -14, 14, kz);
}

}  // namespace

TEST(Eq3Random, PolynomialTermsEqualTheGaussHermiteExpectation) {
  std::mt19937_64 rng(24);
  std::uniform_real_distribution<double> u(-1, 1), rms(0, 5);
  const auto gh = test::gauss_hermite(10);
  for (int n = 0; n < 40; ++n) {
    Coefficients c = test::random_coefficients(rng);
    c[k1_asym] = 0;  // the |.| term is checked separately
    const Vec3 a = Vec3(u(rng), u(rng), u(rng)).normalized();
    vibration::RandomVibration v;
    v.rms_g = Vec3(rms(rng), rms(rng), rms(rng));
    // A random valid correlation matrix: normalised Gram matrix of random vectors.
    Eigen::Matrix3d m = Eigen::Matrix3d::NullaryExpr([&](Eigen::Index, Eigen::Index) { return u(rng); });
    Eigen::Matrix3d gram = m * m.transpose();
    const Eigen::Vector3d d = gram.diagonal().cwiseSqrt().cwiseInverse();
    v.correlation = d.asDiagonal() * gram * d.asDiagonal();
    // X = L z with L L^T = covariance; product rule over three independent N(0,1).
    const Eigen::Matrix3d l = v.covariance_g2().llt().matrixL();
    double expect = 0;
    for (const auto& [z0, w0] : gh)
      for (const auto& [z1, w1] : gh)
        for (const auto& [z2, w2] : gh) expect += w0 * w1 * w2 * output_g(c, a + l * Eigen::Vector3d(z0, z1, z2));
    expect -= output_g(c, a);
    EXPECT_NEAR(random_rectification(c, a, v).total_g(), expect, 1e-12) << "draw " << n;
  }
}

TEST(Eq3Random, AsymmetryAndClippingEqualTheNumericalExpectation) {
  std::mt19937_64 rng(25);
  std::uniform_real_distribution<double> ua(-1, 1), us(0.05, 6), ur(0.5, 8);
  for (int n = 0; n < 100; ++n) {
    const double a = ua(rng), s = us(rng), r = ur(rng);
    const double abs_ref =
        gaussian_expectation([&](double x) { return std::abs(a + x) / 2; }, s, {[&](double x) { return a + x; }}) -
        std::abs(a) / 2;
    EXPECT_NEAR(asymmetry_gaussian(a, s), abs_ref, 1e-12);
    const double clip_ref = gaussian_expectation([&](double x) { return std::clamp(a + x, -r, r); }, s,
                                                 {[&](double x) { return a + x - r; }, [&](double x) { return a + x + r; }}) -
                            std::clamp(a, -r, r);
    EXPECT_NEAR(clipping_gaussian(a, s, r), clip_ref, 1e-12);
  }
}

TEST(Eq3Random, MatchesTheNotesClosedFormsForOneAxis) {
  // paper-notes.md: k2 -> k2 s^2, k3 -> 3 k3 a s^2, k4 -> 6 k4 a^2 s^2 + 3 k4 s^4.
  Coefficients c;
  c[K1] = 1;
  c[k2] = 1e-5;
  c[k3] = 2e-6;
  c[k4] = 3e-7;
  vibration::RandomVibration v;
  v.rms_g = Vec3(2, 0, 0);
  const Vec3 a(0.6, 0.8, 0);
  const Eq3Terms t = random_rectification(c, a, v);
  EXPECT_NEAR(t.g[t_k2], 1e-5 * 4, 1e-18);
  EXPECT_NEAR(t.g[t_k3], 3 * 2e-6 * 0.6 * 4, 1e-18);
  EXPECT_NEAR(t.g[t_k4], 3e-7 * (6 * 0.36 * 4 + 3 * 16), 1e-18);
}

}  // namespace test_eq3
