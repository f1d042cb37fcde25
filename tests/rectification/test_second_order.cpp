// The pickoff nonlinearity beyond first order (rectification/prediction/second_order.hpp).
//  - Gaussian moments: the convolution integrals against a Monte Carlo of the same linear
//    responses (random-phase Gaussian records, the pickoff's error filtered by FFT), which shares
//    nothing with the integrals but the loop's responses.
//  - Periodic motion: the harmonic balance against the ODE (below); Gaussian motion: the shipped
//    case against the ODE (tests/validation/test_second_order_ode.cpp).
#include <gtest/gtest.h>

#include <cmath>
#include <complex>
#include <memory>
#include <numbers>
#include <cstdio>
#include <random>
#include <vector>

#include <unsupported/Eigen/FFT>

#include "plant/effects/effects.hpp"
#include "rectification/prediction/frequency.hpp"
#include "rectification/prediction/random.hpp"
#include "rectification/prediction/second_order.hpp"
#include "rectification/simulation/shake.hpp"
#include "support/instrument.hpp"
#include "support/vibrations.hpp"
#include "vibration/random.hpp"

namespace test_second_order {

using namespace vrelab;
using cd = std::complex<double>;

namespace {

plant::PlantConfig pickoff_plant(double p2) {
  plant::PlantConfig cfg = test::paper_like_linear_plant();
  cfg.effects.push_back(std::make_shared<plant::PickoffNonlinearity>(p2));
  cfg.effects.push_back(std::make_shared<plant::MechanicalMode>(620.0, 0.05, Vec3(1, 0, 0)));
  return cfg;
}

// A real signal's spectrum (two-sided FFT bins) through a transfer H(f) (H(-f) = conj H(f)).
std::vector<double> filtered(Eigen::FFT<double>& fft, const std::vector<double>& x, const std::vector<cd>& H) {
  std::vector<cd> X;
  fft.fwd(X, x);
  const std::size_t n = X.size();
  for (std::size_t k = 0; k < n; ++k) {
    if (k == 0) X[k] *= H[0];
    else if (k <= n / 2) X[k] *= H[k];
    else X[k] *= std::conj(H[n - k]);
  }
  std::vector<cd> y;
  fft.inv(y, X);
  std::vector<double> out(n);
  for (std::size_t k = 0; k < n; ++k) out[k] = y[k].real();
  return out;
}

}  // namespace

// Monte Carlo: records of 2^19 samples at 8192 Hz (64 s), 6 of them, of a Gaussian motion
// along IA (flat 0.03 g^2/Hz, 20-2000 Hz) behind a 620 Hz mode. The mode's ~60 Hz makes ~2e4
// independent bins: each moment's estimate has a relative standard error of about 0.6 %
// (second moments) to 2 % (K, K2: sixth moments); seen within 0.25 % (K2 1.3 %); the bar is 4 %
// (6 % for K2), the grid's error (4096 points) below 0.1 % (against twice as fine). A dropped
// factor of 2 or a conjugate moves them by 50 % or more.
TEST(GaussianPickoffMoments, TheConvolutionIntegralsAreTheMonteCarloMoments) {
  const double p2 = 40;
  plant::PlantConfig cfg = pickoff_plant(p2);
  cfg.servo = plant::design_servo(cfg.dynamics);
  const rectification::LoopResponder responder(cfg);
  vibration::RandomProfile profile;
  profile.psd[0] = test::flat_psd(20, 2000, 0.03);
  const rectification::GaussianPickoffMoments m = rectification::gaussian_pickoff_moments(cfg, profile, std::cref(responder));
  const rectification::GaussianPickoffMoments fine =
      rectification::gaussian_pickoff_moments(cfg, profile, std::cref(responder), Eigen::Matrix3d::Identity(), 8192);
  EXPECT_NEAR(m.J, fine.J, 1e-3 * std::abs(fine.J));
  EXPECT_NEAR(m.K, fine.K, 1e-3 * std::abs(fine.K));
  EXPECT_NEAR(m.angle_var, fine.angle_var, 1e-3 * std::abs(fine.angle_var));

  const std::size_t n = std::size_t{1} << 19;
  const double fs = 8192, df = fs / static_cast<double>(n);
  // Per positive bin: the case's motion X, the current H_z, angle H_theta, T_ze, G_e, H_thetaF.
  std::vector<cd> Hz(n / 2 + 1), Ht(n / 2 + 1), T(n / 2 + 1), Ge(n / 2 + 1), HtF(n / 2 + 1);
  for (std::size_t k = 1; k <= n / 2; ++k) {
    const rectification::LoopResponse r = responder(static_cast<double>(k) * df);
    Hz[k] = r.current[0], Ht[k] = r.angle_rad[0];
    T[k] = rectification::pickoff_error_current(cfg.dynamics, r);
    Ge[k] = -r.current[0] / r.mechanical[0], HtF[k] = r.angle_rad[0] / r.mechanical[0];
  }
  T[0] = rectification::pickoff_error_current(cfg.dynamics, responder(1e-3 * df)), Ge[0] = -1.0;
  Eigen::FFT<double> fft;
  std::mt19937_64 rng(20261129);
  std::normal_distribution<double> normal;
  double zz2 = 0, z2z2 = 0, ZZz2z2 = 0, s2 = 0, th2th2 = 0, th1th3 = 0, slope = 0, W = 0, zz3 = 0, z3z3 = 0, cslope = 0;
  const int records = 6;
  for (int rec = 0; rec < records; ++rec) {
    std::vector<cd> X(n, 0.0);
    for (std::size_t k = 1; k < n / 2; ++k) {
      const double f = static_cast<double>(k) * df;
      if (f < 20 || f > 2000) continue;
      // x = Re sum c_k e^{j w_k t}, c_k complex Gaussian with E|c_k|^2 = 2 G df: E[x^2] = G df per bin.
      const cd c = std::sqrt(0.03 * df) * cd(normal(rng), normal(rng));
      X[k] = c * static_cast<double>(n) / 2.0, X[n - k] = std::conj(X[k]);
    }
    std::vector<cd> xc;
    fft.inv(xc, X);
    std::vector<double> x(n);
    for (std::size_t k = 0; k < n; ++k) x[k] = xc[k].real();
    const std::vector<double> z1 = filtered(fft, x, Hz), th1 = filtered(fft, x, Ht);
    std::vector<double> e(n);
    double mean = 0;
    for (std::size_t k = 0; k < n; ++k) mean += th1[k] * th1[k] / static_cast<double>(n);
    for (std::size_t k = 0; k < n; ++k) e[k] = th1[k] * th1[k] - mean;  // per unit p2
    const std::vector<double> z2 = filtered(fft, e, T), th2 = filtered(fft, e, Ge);
    std::vector<double> cross(n);
    for (std::size_t k = 0; k < n; ++k) cross[k] = 2 * th1[k] * th2[k];  // per unit p2^2
    const std::vector<double> th3 = filtered(fft, cross, Ge), gth1 = filtered(fft, th1, Ge), hz1 = filtered(fft, z1, HtF);
    const std::vector<double> z3 = filtered(fft, cross, T), tth1 = filtered(fft, th1, T);
    double r_s2 = 0, r_z2 = 0;
    for (std::size_t k = 0; k < n; ++k) r_s2 += z1[k] * z1[k], r_z2 += z2[k] * z2[k];
    r_s2 /= static_cast<double>(n), r_z2 /= static_cast<double>(n);
    for (std::size_t k = 0; k < n; ++k) {
      zz2 += z1[k] * z1[k] * z2[k];
      ZZz2z2 += (z1[k] * z1[k] - r_s2) * (z2[k] * z2[k] - r_z2);
      th2th2 += th2[k] * th2[k], th1th3 += th1[k] * th3[k];
      slope += th1[k] * gth1[k], W += th1[k] * hz1[k];
      zz3 += z1[k] * z3[k], z3z3 += z1[k] * z1[k] * z1[k] * z3[k], cslope += z1[k] * tth1[k];
    }
    s2 += r_s2, z2z2 += r_z2;
  }
  const double N = static_cast<double>(n) * records;
  s2 /= records, z2z2 /= records;
  EXPECT_NEAR(s2, m.current_var, 0.01 * m.current_var);
  std::printf("MC/integral - 1: J %+.4f z2 %+.4f K %+.4f angle %+.4f slope %+.4f W %+.4f B %+.4f K2 %+.4f cslope %+.4f\n",
              zz2 / N / 2 / m.J - 1, z2z2 / m.z2_var - 1, ZZz2z2 / N / 8 / m.K - 1, (th2th2 + 2 * th1th3) / N / m.angle_var - 1,
              slope / N / m.loop_slope - 1, W / N / m.angle_force - 1, 2 * zz3 / N / m.current_z3 - 1,
              (z3z3 / N - 3 * s2 * zz3 / N) / 12 / m.K2 - 1, cslope / N / m.current_slope - 1);
  EXPECT_NEAR(zz2 / N / 2, m.J, 0.04 * std::abs(m.J));                  // E[z_1^2 z_2] = 2 p2 J
  EXPECT_NEAR(z2z2, m.z2_var, 0.04 * m.z2_var);                         // E[z_2^2] / p2^2
  EXPECT_NEAR(ZZz2z2 / N / 8, m.K, 0.04 * std::abs(m.K));               // cov(Z^2, z_2^2) = 8 p2^2 K
  EXPECT_NEAR((th2th2 + 2 * th1th3) / N, m.angle_var, 0.04 * std::abs(m.angle_var));
  EXPECT_NEAR(slope / N, m.loop_slope, 0.02 * std::abs(m.loop_slope));
  EXPECT_NEAR(W / N, m.angle_force, 0.02 * std::abs(m.angle_force));
  EXPECT_NEAR(2 * zz3 / N, m.current_z3, 0.04 * std::abs(m.current_z3));          // 2 E[z_1 z_3] / p2^2
  EXPECT_NEAR((z3z3 / N - 3 * s2 * zz3 / N) / 12, m.K2, 0.06 * std::abs(m.K2));   // E[Z^3 z_3] - 3 s^2 E[Z z_3] = 12 p2^2 K2
  EXPECT_NEAR(cslope / N, m.current_slope, 0.02 * std::abs(m.current_slope));
}

// Periodic motion: the harmonic balance against the ODE in its periodic steady state (exact to
// CVODE's 1e-10), a sine along IA at 45 deg behind the 620 Hz mode, p2 = 40 /rad and every IA
// term in the loop (k1' 2e-5, k2 1.5e-5, k3 -1.03e-6, k4 2e-7): 8 g at 100 and 300 Hz, 2 g
// at the mode (600 Hz). Seen: 1.5e-6, 6e-7 and 1.3e-7 of the error; bar 2e-5 (the balance's
// harmonics cut at 4 h, CVODE). The first-order prediction is 2.8 %, 1.6 % and 0.46 % off.
TEST(PeriodicPickoffBalance, IsTheOdeInItsPeriodicSteadyState) {
  plant::PlantConfig cfg = pickoff_plant(40);
  cfg.coefficients[plant::k1_asym] = 2e-5, cfg.coefficients[plant::k2] = 1.5e-5;
  cfg.coefficients[plant::k3] = -1.03e-6, cfg.coefficients[plant::k4] = 2e-7;
  const Vec3 a(std::sqrt(0.5), 0, std::sqrt(0.5));
  rectification::ShakeSettings s;
  s.relative_tolerance = 1e-10;
  for (const auto& [f, amplitude] : {std::pair{100.0, 8.0}, {300.0, 8.0}, {600.0, 2.0}}) {
    vibration::SineVibration v;
    v.amplitude_g = {amplitude, 0.0, 0.0}, v.frequency_Hz = f;
    const double ode = rectification::shake_sine(cfg, a, v, s).measured_g;
    const rectification::FrequencyPrediction p = rectification::sine_rectification_at_frequency(cfg, a, v);
    EXPECT_NEAR(p.total_g(), ode, 2e-5 * std::abs(ode)) << f << " Hz";
    EXPECT_GT(std::abs(p.total_g() - p.second_order_g - ode), 2e-3 * std::abs(ode)) << f << " Hz: first order";
  }
}

}  // namespace test_second_order

