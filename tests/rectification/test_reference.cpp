// Reference channels (rectification/measurement/reference.hpp) against analytic signals: a
// sine with known harmonics and a transverse part, and random signals of known PSD (an AR(1)
// process and a coherent transverse copy), each within its own statistical sigma.
#include <gtest/gtest.h>

#include <cmath>
#include <complex>
#include <numbers>
#include <random>

#include "rectification/measurement/reference.hpp"
#include "support/constants.hpp"

namespace test_reference {

using namespace vrelab;
using rectification::ReferenceAnalyzer;
using rectification::ReferenceWindow;

using vrelab::test::kPi;

TEST(Reference, SineHarmonicsAndTransversePartWithinTheirSigma) {
  // IA: 2 g at 80 Hz, phase 0.3, 2nd harmonic 5 % at phase 1.1, 3rd 2 % at -0.4; PA: 10 % of
  // the fundamental in phase; OA: at rest. White noise 0.02 g per sample on each axis.
  const double fs = 4000, f = 80, A = 2, sn = 0.02;
  std::mt19937_64 rng(7);
  std::normal_distribution<double> noise(0, sn);
  ReferenceWindow w;
  w.from_s = 0.5, w.to_s = 0.5 + 100 / f, w.frequency_Hz = f;  // whole periods
  ReferenceAnalyzer an(w);
  const std::array<bool, 3> present{true, true, true};
  for (long k = 0; k < static_cast<long>(2.0 * fs); ++k) {
    const double t = k / fs, th = 2 * kPi * f * t;
    const double fund = A * std::sin(th + 0.3);
    const double ia = fund + 0.05 * A * std::sin(2 * th + 1.1) + 0.02 * A * std::sin(3 * th - 0.4) + noise(rng);
    an.add(t, {ia, 0.1 * fund + noise(rng), noise(rng)}, present);
  }
  const auto a = an.finish();
  EXPECT_EQ(a.samples, 5000);
  EXPECT_NEAR(a.sample_rate_Hz, fs, 1e-6);
  // sigma of Re/Im of W_h: sn sqrt(2/N) = 4e-4 g; the estimate of it within 5 % (N = 5000).
  const double s = sn * std::sqrt(2.0 / 5000);
  EXPECT_NEAR(a.amplitude_sigma_g[0], s, 0.05 * s);
  // Whole periods, uniformly sampled: the single-bin DFT has no leakage; the error is the noise.
  const std::complex<double> W1 = std::polar(A, 0.3), W2 = std::polar(0.05 * A, 1.1), W3 = std::polar(0.02 * A, -0.4);
  EXPECT_LT(std::abs(a.harmonic_g[1][0] - W1), 5 * s);
  EXPECT_LT(std::abs(a.harmonic_g[2][0] - W2), 5 * s);
  EXPECT_LT(std::abs(a.harmonic_g[3][0] - W3), 5 * s);
  EXPECT_LT(std::abs(a.harmonic_g[1][1] - 0.1 * W1), 5 * s);
  EXPECT_LT(std::abs(a.harmonic_g[1][2]), 5 * s);
  EXPECT_NEAR(a.residual_rms_g[0], sn, 0.05 * sn);
  // The departure from a command of 2 g along IA.
  const auto d = rectification::sine_departure(a, Vec3(A, 0, 0));
  EXPECT_NEAR(d.transverse_ratio, 0.1, 5 * d.transverse_sigma);
  EXPECT_LT(d.transverse_sigma, 0.002);
  EXPECT_NEAR(d.transverse_axis_ratio[1], 0.1, 5 * d.transverse_sigma);
  // |W2| / |W1| over the axes: the fundamental's norm includes PA's 10 %.
  EXPECT_NEAR(d.harmonic2_ratio, 0.05 / std::sqrt(1.01), 5 * d.harmonic2_sigma);
  EXPECT_NEAR(d.harmonic3_ratio, 0.02 / std::sqrt(1.01), 5 * d.harmonic3_sigma);
  EXPECT_NEAR(d.fundamental_ratio, 1.0, 5 * s / A);
  // rms: the motion's magnitude (IA with harmonics, PA, noise on all three) against A/sqrt 2.
  const double rms = std::sqrt(A * A / 2 * (1 + 0.0025 + 0.0004 + 0.01) + 3 * sn * sn);
  EXPECT_NEAR(d.measured_rms_g, rms, 1e-3 * rms);
  EXPECT_NEAR(d.rms_ratio, rms / (A / std::sqrt(2.0)), 1e-3);
}

TEST(Reference, WelchPsdOfAnAr1ProcessAndItsCoherentTransverseCopy) {
  // x_n = phi x_{n-1} + e_n (e white, variance s^2): one-sided PSD 2 s^2 / fs / |1 - phi e^{-j w/fs}|^2.
  // PA = 0.1 x + white noise of variance q^2: PSD 0.01 G_x + 2 q^2 / fs, cross-spectrum 0.1 G_x.
  const double fs = 2000, phi = 0.8, se = 1.0, q = 0.05;
  std::mt19937_64 rng(11);
  std::normal_distribution<double> e(0, se), u(0, q);
  ReferenceWindow w;
  w.from_s = 1, w.to_s = 9;  // 16000 samples: L = 1024 (df 1.95 Hz), 30 segments
  ReferenceAnalyzer an(w);
  double x = 0;
  for (long k = 0; k < static_cast<long>(10 * fs); ++k) {
    x = phi * x + e(rng);
    an.add(k / fs, {x, 0.1 * x + u(rng), 0}, {true, true, false});
  }
  const auto a = an.finish();
  EXPECT_EQ(a.segment_samples, 1024);
  EXPECT_EQ(a.segments, 30);
  EXPECT_NEAR(a.dof, 2 * 30 / (1 + 2 * 0.167 * 0.167), 1e-9);
  const auto G = [&](double f) { return 2 * se * se / fs / std::norm(1.0 - phi * std::polar(1.0, -2 * kPi * f / fs)); };
  // Band averages of 16 bins: each bin chi^2 with nu dof (relative sigma sqrt(2/nu) = 0.19);
  // adjacent Hann bins are correlated, so 16 bins count as at least 8 independent ones:
  // relative sigma <= 0.19 / sqrt(8) = 0.067; 4.5 sigma = 0.30 (over 31 bands, a false alarm
  // ~ 2e-4). The Hann window's bias is second order in the PSD's curvature over a bin (< 1e-3 here).
  const double rel = std::sqrt(2 / a.dof) / std::sqrt(8.0);
  int bands = 0;
  for (std::size_t k0 = 0; k0 + 16 <= a.bin_Hz.size(); k0 += 16) {
    double est = 0, ref = 0, cross = 0;
    for (std::size_t k = k0; k < k0 + 16; ++k)
      est += a.psd_g2_per_Hz[0][k], ref += G(a.bin_Hz[k]), cross += a.csd_g2_per_Hz[0][k].real();
    EXPECT_NEAR(est / ref, 1.0, 4.5 * rel) << "band from " << a.bin_Hz[k0] << " Hz";
    // The cross-spectrum's real part: 0.1 G plus the noise's correlation with x (zero mean).
    EXPECT_NEAR(cross / ref, 0.1, 4.5 * rel * 0.1 + 4.5 * rel * std::sqrt(0.1 * 0.1 + 2 * q * q / fs / (ref / 16)))
        << "band from " << a.bin_Hz[k0] << " Hz";
    ++bands;
  }
  EXPECT_EQ(bands, 31);
  // The covariance from the spectra against the process's: var x = s^2 / (1 - phi^2).
  const double var = se * se / (1 - phi * phi);
  const Eigen::Matrix3d C = a.band_covariance_g2();
  // The sample variance of 16000 AR(1) samples counts N (1 - phi) / (1 + phi) = 1778
  // independent ones: relative sigma sqrt(2 / 1778) = 0.034; 4.5 sigma.
  EXPECT_NEAR(C(0, 0) / var, 1.0, 0.15);
  EXPECT_NEAR(C(0, 1) / var, 0.1, 0.02);
  EXPECT_NEAR(a.rms_g[0], std::sqrt(var), 0.08 * std::sqrt(var));
  // Transverse: sqrt(0.01 var + q^2) / sqrt(var) along a command on IA.
  Eigen::Matrix3d cmd = Eigen::Matrix3d::Zero();
  cmd(0, 0) = var;
  const auto d = rectification::random_departure(a, cmd);
  const double tr = std::sqrt(0.01 * var + q * q) / std::sqrt(var);
  EXPECT_NEAR(d.transverse_ratio, tr, 0.05 * tr);
  EXPECT_NEAR(d.rms_ratio, std::sqrt(1.01 + q * q / var), 0.08);
  // The PSD table a prediction takes: one row per bin in the band.
  const auto t = rectification::welch_table(a, 0, 20, 500);
  EXPECT_NEAR(t.rows.front().frequency_Hz, a.bin_Hz[10] - 0.499 * a.resolution_Hz, 1e-9);
  EXPECT_LE(t.rows.back().frequency_Hz, 500 + a.resolution_Hz / 2);
  // Its integral is Welch's sum of the bins (steps), to the 0.2 % of a bin between steps.
  double sum = 0;
  for (std::size_t k = 10; k < a.bin_Hz.size() && a.bin_Hz[k] <= 500; ++k) sum += a.psd_g2_per_Hz[0][k] * a.resolution_Hz;
  EXPECT_NEAR(vibration::rms_g(t), std::sqrt(sum), 2e-3 * std::sqrt(sum));
}

// A sine on random run whose axis is almost all sine: 2 g at 123.4 Hz sampled at 5 kHz (not a
// whole number of samples a period) over white noise of 1e-4 g on every axis. The random part's
// spectrum must hold the noise's power, sigma^2 (one-sided white PSD 2 sigma^2 / fs up to
// Nyquist; DC and Nyquist bins left out: 2 of 512 bins). Two ways to fail: a mean square from
// rms^2 - |W_1|^2 / 2 (a difference of numbers 4e8 times larger), or a fundamental from the
// single-bin DFT, whose O(1/N) bias when a period is not a whole number of samples left a
// residual tone of 22 % of the noise's power (the least-squares fit leaves none).
// Tolerance 15 %: Welch's integral over ~40 segments (relative sigma ~ sqrt(2 / (dof x bins)),
// < 1 %) and the fitted sine's removal per segment; a wrong scale misses by orders of magnitude.
TEST(Reference, ASineOnRandomAxisThatIsMostlySineKeepsTheNoisesPower) {
  const double fs = 5000, f = 123.4, A = 2, sn = 1e-4;
  std::mt19937_64 rng(5);
  std::normal_distribution<double> n(0, sn);
  ReferenceWindow w;
  w.from_s = 0.5, w.to_s = 0.5 + 500 / f;  // 500 whole periods, 20259 samples
  w.frequency_Hz = f;
  w.sine_on_random = true;
  w.segment_samples = 1024;
  ReferenceAnalyzer an(w);
  for (long k = 0; k < static_cast<long>(5 * fs); ++k) {
    const double t = k / fs;
    an.add(t, {A * std::sin(2 * kPi * f * t) + n(rng), n(rng), n(rng)}, {true, true, true});
  }
  const auto a = an.finish();
  ASSERT_TRUE(a.sine_removed);
  EXPECT_NEAR(std::abs(a.harmonic_g[1][0]), A, 1e-4);
  for (int i = 0; i < 3; ++i) {
    double sum = 0;
    for (double v : a.psd_g2_per_Hz[static_cast<std::size_t>(i)]) {
      EXPECT_GT(v, 0.0);
      sum += v * a.resolution_Hz;
    }
    EXPECT_NEAR(sum / (sn * sn), 1.0, 0.15) << "axis " << i;
  }
}

TEST(Reference, BadChannelsAreRefused) {
  ReferenceWindow w;
  w.from_s = 0, w.to_s = 1, w.frequency_Hz = 10;
  {
    ReferenceAnalyzer an(w);
    an.add(0, {0, 0, 0}, {true, false, false});
    an.add(0.001, {0, 0, 0}, {true, false, false});
    EXPECT_THROW(an.add(0.003, {0, 0, 0}, {true, false, false}), std::invalid_argument);  // another rate
    EXPECT_THROW(an.add(0.004, {0, 0, 0}, {true, true, false}), std::invalid_argument);   // other axes
    EXPECT_THROW(an.add(0.004, {NAN, 0, 0}, {true, false, false}), std::invalid_argument);
  }
  {
    // A random run shorter than two Welch segments.
    ReferenceWindow r;
    r.from_s = 0, r.to_s = 0.04;  // 80 samples: one segment of 64
    ReferenceAnalyzer an(r);
    for (int k = 0; k < 100; ++k) an.add(k / 2000.0, {std::sin(k * 0.3), 0, 0}, {true, false, false});
    EXPECT_THROW(an.finish(), std::invalid_argument);
  }
}

}  // namespace test_reference
