// The frequency-dependent prediction of random and sine-on-random motion
// (rectification/prediction/random.hpp) against independent computations: eq. (3)'s random form
// where the loop does not filter (input-placed terms; a band far below the loop), the
// time-domain second moments of a multisine filtered bin by bin, and the ODE on the virtual
// shaker (within its statistical sigma and the first-order model's tolerance).
#include <array>
#include <cmath>
#include <numbers>
#include <random>

#include <gtest/gtest.h>

#include "plant/effects/effects.hpp"
#include "rectification/prediction/eq3.hpp"
#include "rectification/prediction/random.hpp"
#include "rectification/simulation/shake.hpp"
#include "rectification/simulation/shaker_motion.hpp"
#include "support/instrument.hpp"
#include "support/vibrations.hpp"

namespace test_random_prediction {

using namespace vrelab;
using namespace vrelab::plant;

namespace {

vibration::PsdTable table(std::vector<std::pair<double, double>> rows) {
  vibration::PsdTable t;
  for (auto [f, p] : rows) t.rows.push_back(vibration::PsdRow::level(f, p));
  return t;
}

// Two axes with common phases and different shapes (correlation < 1), one independent case.
vibration::RandomProfile two_axes(vibration::AxisCoupling coupling, double scale_Hz) {
  vibration::RandomProfile p;
  p.psd[IA] = table({{20 * scale_Hz, 0.01}, {80 * scale_Hz, 0.04}, {350 * scale_Hz, 0.04}, {2000 * scale_Hz, 0.007}});
  p.psd[PA] = table({{20 * scale_Hz, 0.02}, {150 * scale_Hz, 0.02}, {1000 * scale_Hz, 0.005}});
  p.coupling = coupling;
  return p;
}

double rel(double x, double y) { return std::abs(x - y) / std::max(std::abs(y), 1e-300); }

}  // namespace

// Terms at the input see the case's motion unfiltered (no mechanical mode): each term is
// eq. (3)'s random form for the profile's Gaussian equivalent, at any band. Tolerance 1e-6
// relative: the equivalent's cross integral is a 20000-point trapezoid (~1e-8), the loop's
// DC gain is evaluated at 0.01 Hz (1 within ~1e-9), the Gauss-Legendre integral ~1e-12.
TEST(RandomAtFrequency, InputTermsAreEq3RandomFormAtAnyBand) {
  const Vec3 a(0.5, std::sqrt(0.75), 0);
  PlantConfig cfg = test::paper_like_plant();
  cfg.coefficients[k_PP] = 4e-6, cfg.coefficients[k_OO] = 2e-6;
  for (int c = 0; c < kNumCoefficients; ++c) cfg.location[c] = Location::input;
  for (auto coupling : {vibration::AxisCoupling::common, vibration::AxisCoupling::independent}) {
    const auto p = two_axes(coupling, 1.0);
    const auto fp = rectification::random_rectification_at_frequency(cfg, a, p);
    const auto eq3 = rectification::random_rectification(cfg.coefficients, a, vibration::gaussian_equivalent(p));
    for (int t = 0; t < rectification::kNumTerms; ++t)
      EXPECT_NEAR(fp.terms.g[t], eq3.g[t], 1e-6 * std::abs(eq3.g[t]) + 1e-15) << rectification::term_name(t);
    EXPECT_LT(rel(fp.total_g(), eq3.total_g()), 1e-6);
    if (coupling == vibration::AxisCoupling::independent) EXPECT_EQ(fp.terms.g[rectification::t_k_IP], 0.0);
    else EXPECT_GT(std::abs(fp.terms.g[rectification::t_k_IP]), 1e-5);
  }
}

// A band far below the loop (0.2 - 20 Hz, crossover 500 Hz): the loop passes the motion, so
// the terms in the loop and at the output are eq. (3)'s random form too, within the loop's
// low-frequency departure |H|^2 - 1 = O((f/f_c)^2) ~ 1e-3 at the band top (k4 twice that);
// bound 5e-3 relative. Sine on random (a 5 Hz tone) likewise against eq3's sine-on-random.
TEST(RandomAtFrequency, LowFrequencyBandIsEq3RandomFormThroughTheLoop) {
  const Vec3 a(0.5, std::sqrt(0.75), 0);
  PlantConfig cfg = test::paper_like_plant();
  cfg.coefficients[k_PP] = 4e-6;
  const auto p = two_axes(vibration::AxisCoupling::common, 0.01);
  const auto g = vibration::gaussian_equivalent(p);
  const auto fp = rectification::random_rectification_at_frequency(cfg, a, p);
  const auto eq3 = rectification::random_rectification(cfg.coefficients, a, g);
  for (int t = 0; t < rectification::kNumTerms; ++t)
    EXPECT_NEAR(fp.terms.g[t], eq3.g[t], 5e-3 * std::abs(eq3.g[t]) + 1e-15) << rectification::term_name(t);
  vibration::SineVibration s;
  s.amplitude_g = Vec3(1.5, 0.5, 0);
  s.phase_rad = Vec3(0, 0.4, 0);
  s.frequency_Hz = 5;
  const auto sr = rectification::sine_on_random_rectification_at_frequency(cfg, a, s, p);
  const auto eq3sr = rectification::sine_on_random_rectification(cfg.coefficients, a, s, g);
  EXPECT_LT(rel(sr.total_g(), eq3sr.total_g()), 5e-3);
  // And a pure sine (random at a negligible level) is the sine prediction at its frequency.
  vibration::RandomProfile tiny = p;
  for (auto& t : tiny.psd)
    if (t)
      for (auto& r : t->rows) *r.psd_g2_per_Hz *= 1e-12;
  s.frequency_Hz = 300;
  const auto sine_only = rectification::sine_on_random_rectification_at_frequency(cfg, a, s, tiny);
  const auto sine_pred = rectification::sine_rectification_at_frequency(cfg, a, s);
  EXPECT_LT(rel(sine_only.total_g(), sine_pred.total_g()), 1e-6);
}

// A distorted tone on random (a shaker's 2nd and 3rd harmonics, on IA and PA) with every term
// placed at the input, where the case's motion is the table's (no mechanical mode): each term
// is the period's average of the Gaussian expectation of its basis function at a + s(t) + G,
// less its static value, computed here afresh: 1024 points of the period, the Gaussian by the
// trapezoid rule on 4001 points over +-10 sigma (spectrally exact for the polynomial terms;
// the |a_IA| of k1' converges as h^2, ~1e-7 relative). Bound 1e-6 relative: the random
// part's covariance by the PSD quadrature (~1e-8) and the loop's DC gain (1 within ~1e-9).
// And the same tone without its harmonics is the single-tone closed form (eq3.hpp).
TEST(RandomAtFrequency, ADistortedToneOnRandomIsThePeriodsAverageOfTheGaussianExpectation) {
  const Vec3 a(0.6, 0.8, 0);
  PlantConfig cfg = test::paper_like_linear_plant();
  cfg.coefficients[K1] = 1;
  cfg.coefficients[k1_asym] = 4e-5, cfg.coefficients[k2] = 1e-5, cfg.coefficients[k3] = -2e-6, cfg.coefficients[k4] = 3e-7;
  cfg.coefficients[k_IP] = 5e-6, cfg.coefficients[k_PP] = 2e-6;
  for (int c = 0; c < kNumCoefficients; ++c) cfg.location[c] = Location::input;
  vibration::RandomProfile p;
  p.psd[IA] = test::flat_psd(20, 500, 4.0 / 480);  // 2 g rms
  const auto rr = rectification::random_response(cfg, p);
  const double sigma = std::sqrt(rr.input_covariance_g2(IA, IA));
  rectification::PeriodicInput in;
  in.frequency_Hz = 120;
  in.tones = {{1, Eigen::Vector3cd(std::polar(3.0, 0.0), std::polar(1.0, 0.4), 0)},
              {2, Eigen::Vector3cd(std::polar(0.6, 0.7), std::polar(0.2, -1.0), 0)},
              {3, Eigen::Vector3cd(std::polar(0.45, -2.0), 0, 0)}};
  const rectification::ResponseAt response = [&cfg](double f) { return rectification::loop_response(cfg, f); };
  const auto fp = rectification::random_rectification_at_frequency(cfg, a, rr, in, response);

  constexpr int kT = 1024, kZ = 4001;
  const double hz = 20.0 / (kZ - 1);
  std::array<double, kNumCoefficients> mean{};
  const Basis b0 = plant::basis(a);
  for (int k = 0; k < kT; ++k) {
    const double t = 2 * std::numbers::pi * k / kT;
    Vec3 s = a;
    for (const auto& [h, w] : in.tones)
      for (int i = 0; i < 3; ++i) s[i] += std::imag(w[i] * std::polar(1.0, h * t));
    for (int n = 0; n < kZ; ++n) {
      const double z = -10 + n * hz;
      const double weight = (n == 0 || n == kZ - 1 ? 0.5 : 1.0) * hz * std::exp(-z * z / 2) / std::sqrt(2 * std::numbers::pi);
      const Basis b = plant::basis(s + Vec3(sigma * z, 0, 0));
      for (int c = 0; c < kNumCoefficients; ++c) mean[c] += weight * b[c] / kT;
    }
  }
  for (int c : {k1_asym, k2, k3, k4, k_IP, k_PP}) {
    const int t = rectification::term_of_coefficient(c);
    const double expected = cfg.coefficients[c] * (mean[c] - b0[c]);
    EXPECT_NEAR(fp.terms.g[t], expected, 1e-6 * std::abs(expected)) << rectification::term_name(t);
  }
  // The harmonics matter here (the check has teeth), and without them the closed form holds.
  rectification::PeriodicInput tone = in;
  tone.tones.resize(1);
  const auto single = rectification::random_rectification_at_frequency(cfg, a, rr, tone, response);
  EXPECT_GT(std::abs(single.total_g() - fp.total_g()), 0.05 * std::abs(fp.total_g()));
  // The general path with a silent harmonic: the same but for k1', whose closed form averages
  // the kinked E_G|x + G| - |x| over 64 phases (O(1/64^2) of its term; here 5e-4) where the
  // general path averages a smooth function.
  tone.tones.push_back({2, Eigen::Vector3cd::Zero()});
  const auto general = rectification::random_rectification_at_frequency(cfg, a, rr, tone, response);
  for (int t = 0; t < rectification::kNumTerms; ++t)
    EXPECT_NEAR(general.terms.g[t], single.terms.g[t], (t == rectification::t_k1_asym ? 1e-3 : 1e-9) * std::abs(single.terms.g[t]))
        << rectification::term_name(t);
}

// The covariances against the time domain: a multisine on 1 Hz bins (20 - 1000 Hz), common
// phases on IA and PA with the profile's amplitudes sqrt(2 G df), each bin through the loop
// response at its frequency, summed in time over one period (4096 samples). The period mean
// of a product is the bins' Parseval sum exactly, so it differs from the integral only by the
// Riemann sum's error on the 1 Hz grid: bound 2e-3 of sqrt(C_yy C_zz) (the PSD's kinks and
// the band edges carry the O(df) part).
TEST(RandomAtFrequency, CovariancesMatchAFilteredMultisineInTheTimeDomain) {
  PlantConfig cfg = test::paper_like_linear_plant();
  vibration::RandomProfile p;
  p.psd[IA] = table({{20, 0.01}, {80, 0.04}, {350, 0.04}, {1000, 0.02}});
  p.psd[PA] = table({{20, 0.02}, {150, 0.02}, {1000, 0.005}});
  const auto rr = rectification::random_response(cfg, p);
  const double fs = 4096, df = 1;
  const int n = 4096;
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> u(0, 2 * std::numbers::pi);
  std::vector<std::array<double, 5>> y(static_cast<std::size_t>(n), std::array<double, 5>{});
  for (int k = 20; k <= 1000; ++k) {
    const double f = k * df;
    const double w = (k == 20 || k == 1000) ? 0.5 : 1.0;  // trapezoid ends
    const auto r = rectification::loop_response(cfg, f);
    const double phi = u(rng);
    std::array<std::complex<double>, 5> c{};
    for (int j : {IA, PA}) {
      const double amp = std::sqrt(2 * w * vibration::psd_g2_per_Hz(*p.psd[static_cast<std::size_t>(j)], f) * df);
      const std::complex<double> x = std::polar(amp, phi);
      c[static_cast<std::size_t>(j)] += r.mechanical[static_cast<std::size_t>(j)] * x;
      c[3] += r.current[static_cast<std::size_t>(j)] * x;
      c[4] += r.angle_rad[static_cast<std::size_t>(j)] * x;
    }
    for (int t = 0; t < n; ++t) {
      const std::complex<double> e = std::polar(1.0, 2 * std::numbers::pi * f * t / fs);
      for (std::size_t m = 0; m < 5; ++m) y[static_cast<std::size_t>(t)][m] += std::real(c[m] * e);
    }
  }
  for (int i = 0; i < 5; ++i)
    for (int j = 0; j < 5; ++j) {
      double mean = 0;
      for (const auto& s : y) mean += s[static_cast<std::size_t>(i)] * s[static_cast<std::size_t>(j)] / n;
      const double scale = std::sqrt(rr.covariance(i, i) * rr.covariance(j, j));
      if (scale == 0) continue;
      EXPECT_NEAR(mean, rr.covariance(i, j), 2e-3 * scale) << i << "," << j;
    }
  EXPECT_NEAR(rr.covariance(0, 0), vibration::rms_g(*p.psd[IA]) * vibration::rms_g(*p.psd[IA]), 1e-9 * rr.covariance(0, 0));
}

namespace {

struct OdeCheck {
  double predicted_g, measured_g, sigma_g;
};

OdeCheck ode_check(const PlantConfig& cfg, const Vec3& a, const rectification::VibrationRequest& v, double measure_s,
                   std::uint64_t seed) {
  const auto motion = rectification::shaker_motion(v, {}, a, 9.81, seed);
  rectification::ShakeSettings s;
  s.relative_tolerance = 1e-4;  // the record's own scatter dominates (cases/shake-random-gevs.toml)
  s.blocks = 16;
  const auto r = rectification::shake_excitation(cfg, a, *motion.motion, measure_s, s);
  const double pred = v.type == rectification::VibrationKind::random
                          ? rectification::random_rectification_at_frequency(cfg, a, *v.psd).total_g()
                          : rectification::sine_on_random_rectification_at_frequency(cfg, a, v.sine, *v.psd).total_g();
  return {pred, r.measured_g, r.sigma_g};
}

}  // namespace

// The ODE on the virtual shaker. The prediction is first order in the nonlinearities: the
// next order is ~ k2 * 2 sigma_I ~ 4e-4 relative for these coefficients at 14 g rms, so the
// model tolerance is 1 % of the prediction; the ODE's statistical sigma (batch means over
// 16 blocks of a 4 s record) is added at 3 sigma.
TEST(RandomAtFrequencyCampaign, MatchesTheOdeForGevsAndSineOnRandom) {
  const Vec3 a(0.5, std::sqrt(0.75), 0);
  PlantConfig cfg = test::paper_like_plant();
  cfg.coefficients[k_PP] = 4e-6;
  {
    rectification::VibrationRequest v;  // cases/shake-random-gevs.toml
    v.type = rectification::VibrationKind::random;
    v.psd = test::gevs_on_ia();
    const OdeCheck c = ode_check(cfg, a, v, 4.0, 1);
    EXPECT_NEAR(c.measured_g, c.predicted_g, 3 * c.sigma_g + 0.01 * std::abs(c.predicted_g)) << "GEVS";
    // And eq. (3) quasi-static is excluded by the same bound (27.4 mg vs 21.5 mg measured).
    const double eq3 = rectification::random_rectification(cfg.coefficients, a, vibration::gaussian_equivalent(*v.psd)).total_g();
    EXPECT_GT(std::abs(c.measured_g - eq3), 3 * c.sigma_g + 0.01 * std::abs(c.predicted_g));
  }
  {
    rectification::VibrationRequest v;  // cases/shake-sine-on-random.toml
    v.type = rectification::VibrationKind::sine_on_random;
    v.sine.amplitude_g = Vec3(2, 0, 0);
    v.sine.frequency_Hz = 300;
    v.psd = two_axes(vibration::AxisCoupling::common, 1.0);
    const OdeCheck c = ode_check(cfg, a, v, 4.0, 1);
    EXPECT_NEAR(c.measured_g, c.predicted_g, 3 * c.sigma_g + 0.01 * std::abs(c.predicted_g)) << "sine on random";
  }
}

// The effects beyond (1) under random motion on IA and PA: the pickoff nonlinearity and the
// pendulum geometry (second moments of the angle), and a quadratic readout (Gauss-Hermite).
TEST(RandomAtFrequencyCampaign, EffectsMatchTheOde) {
  const Vec3 a(0.5, std::sqrt(0.75), 0);
  rectification::VibrationRequest v;
  v.type = rectification::VibrationKind::random;
  v.psd = two_axes(vibration::AxisCoupling::common, 0.25);  // 5 - 500 Hz: where the angle is large
  {
    PlantConfig cfg = test::paper_like_linear_plant();
    cfg.effects.push_back(std::make_shared<PickoffNonlinearity>(20.0));
    cfg.effects.push_back(std::make_shared<PendulumGeometry>());
    const OdeCheck c = ode_check(cfg, a, v, 12.0, 2);  // the product F_PA theta scatters: a longer record
    EXPECT_NEAR(c.measured_g, c.predicted_g, 3 * c.sigma_g + 0.01 * std::abs(c.predicted_g)) << "pickoff + geometry";
    EXPECT_GT(std::abs(c.predicted_g), 5 * c.sigma_g);  // the check has teeth
  }
  {
    PlantConfig cfg = test::paper_like_linear_plant();
    cfg.effects.push_back(std::make_shared<OutputPolynomial>("readout", std::array<double, 7>{0, 0, 2e-5, 0, 3e-7, 0, 0}));
    const OdeCheck c = ode_check(cfg, a, v, 4.0, 3);
    EXPECT_NEAR(c.measured_g, c.predicted_g, 3 * c.sigma_g + 0.01 * std::abs(c.predicted_g)) << "readout polynomial";
    EXPECT_GT(std::abs(c.predicted_g), 10 * c.sigma_g);  // the check has teeth
  }
}

}  // namespace test_random_prediction
