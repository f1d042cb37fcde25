// Random vibration from a PSD (vibration/random.hpp, RandomExcitation of sampled.hpp):
//  - normalisation: cosine amplitude sqrt(2 G(f_k) fs / N) per bin, measured by a direct DFT
//    sum written here (no FFTW), and Parseval: mean square = sum_k G(f_k) fs / N;
//  - the Welch estimator itself on signals with known spectra (a tone, white noise from
//    std::normal_distribution);
//  - the synthesised signal (one FFT, and the block stream) against the GEVS spec: Welch
//    within +-1.5 dB across the band, rms within 1 %, Gaussian kurtosis and tails;
//  - seeds and axis coupling.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

#include "support/constants.hpp"
#include "support/vibrations.hpp"
#include "vibration/psd.hpp"
#include "vibration/random.hpp"
#include "vibration/sampled.hpp"

namespace test_vibration_random {

using namespace vrelab;
using namespace vrelab::vibration;
using vrelab::test::gevs_on_ia;
using vrelab::test::gevs_psd;
using vrelab::test::kPi;

namespace {

// Verification set-up shared by the spec tests: fs = 2.56 x 2000 Hz, 32 s, Welch segments
// of 1024 samples (5 Hz bins, 319 segments).
constexpr double kFs = 5120;
constexpr double kDuration = 32;
constexpr std::size_t kSegment = 1024;

struct BandCheck {
  double max_dev_dB = 0;
  std::size_t bins = 0;
};

// Worst |10 log10(Welch / spec)| over bins f in [f_lo + 2 df, f_hi - 2 df]. The Hann
// window's main lobe spans +-2 bins: a bin closer than that to a band edge averages in the
// empty region beyond the edge and reads low (about -3 dB at the edge bin itself), which is
// the estimator's resolution, not the signal's error. That excludes 20-25 Hz and
// 1995-2000 Hz (one 5 Hz bin at each end besides the edge bins).
BandCheck check_band(const PsdEstimate& est, const PsdTable& spec) {
  const ResolvedPsd r = resolve(spec);
  const double df = est.frequency_Hz[1];
  BandCheck c;
  for (std::size_t k = 0; k < est.frequency_Hz.size(); ++k) {
    const double f = est.frequency_Hz[k];
    if (f < r.frequency_Hz.front() + 2 * df || f > r.frequency_Hz.back() - 2 * df) continue;
    c.max_dev_dB = std::max(c.max_dev_dB, std::abs(10 * std::log10(est.psd_g2_per_Hz[k] / psd_g2_per_Hz(r, f))));
    ++c.bins;
  }
  return c;
}

struct Moments {
  double rms = 0, kurtosis = 0, tail1 = 0, tail2 = 0, tail3 = 0;
};
Moments moments(const std::vector<double>& x) {
  double m2 = 0, m4 = 0;
  for (double v : x) {
    m2 += v * v;
    m4 += v * v * v * v;
  }
  m2 /= static_cast<double>(x.size());
  m4 /= static_cast<double>(x.size());
  Moments m;
  m.rms = std::sqrt(m2);
  m.kurtosis = m4 / (m2 * m2);
  for (double v : x) {
    const double a = std::abs(v) / m.rms;
    m.tail1 += a > 1;
    m.tail2 += a > 2;
    m.tail3 += a > 3;
  }
  m.tail1 /= static_cast<double>(x.size());
  m.tail2 /= static_cast<double>(x.size());
  m.tail3 /= static_cast<double>(x.size());
  return m;
}

double correlation(const std::vector<double>& a, const std::vector<double>& b) {
  double ab = 0, aa = 0, bb = 0;
  for (std::size_t i = 0; i < a.size(); ++i) {
    ab += a[i] * b[i];
    aa += a[i] * a[i];
    bb += b[i] * b[i];
  }
  return ab / std::sqrt(aa * bb);
}

// The statistical checks of a 32 s, 20-2000 Hz Gaussian record. Independent samples in it:
// about N_eff = 2 B T = 2 x 1980 Hz x 32 s = 1.27e5. Standard errors for Gaussian data:
// kurtosis sqrt(24 / N_eff) = 0.014; tail fractions sqrt(p (1 - p) / N_eff): 0.0013 (1 sigma),
// 5.9e-4 (2 sigma), 1.5e-4 (3 sigma). Tolerances are 6 standard errors (the tail indicators
// are even functions, correlated as rho^2, so N_eff is if anything larger). A uniform
// signal (kurtosis 1.8) or a sine (1.5) fails by far.
void expect_gaussian(const Moments& m) {
  EXPECT_NEAR(m.kurtosis, 3.0, 0.084);
  EXPECT_NEAR(m.tail1, 0.317311, 0.008);
  EXPECT_NEAR(m.tail2, 0.045500, 0.0036);
  EXPECT_NEAR(m.tail3, 0.002700, 0.0009);
}

}  // namespace

// Normalisation, shown without FFTW: the cosine amplitude of bin k, 2/N |sum_n x[n]
// e^{-2 pi i k n / N}|, is sqrt(2 G(f_k) fs / N); 0 outside the band. The direct sum's
// rounding is ~1e-16 sqrt(N) of the signal: 1e-10 relative is a wide margin.
TEST(RandomSynthesis, BinAmplitudeIsSqrtTwoGfsOverN) {
  const double fs = 5120;
  const SampledSignal s = synthesize_random(gevs_on_ia(), 1.0, fs, 7);
  const std::vector<double>& x = s.samples_g[IA];
  const std::size_t n = x.size();
  ASSERT_EQ(n, 5120u);
  for (std::size_t k : {0u, 10u, 19u, 20u, 35u, 100u, 1000u, 1999u, 2000u, 2001u, 2559u}) {
    double re = 0, im = 0;
    for (std::size_t i = 0; i < n; ++i) {
      const double ph = 2 * kPi * static_cast<double>((k * i) % n) / static_cast<double>(n);
      re += x[i] * std::cos(ph);
      im -= x[i] * std::sin(ph);
    }
    const double measured = 2.0 / static_cast<double>(n) * std::hypot(re, im);
    const double expected = std::sqrt(2 * psd_g2_per_Hz(gevs_psd(), static_cast<double>(k) * fs / n) * fs / n);
    EXPECT_NEAR(measured, expected, 1e-10 * 0.6 + 1e-10 * expected) << "bin " << k;
  }
  for (double v : s.samples_g[PA]) ASSERT_EQ(v, 0.0);  // an axis without a table is at rest
}

// Parseval: the mean square over the period is exactly the Riemann sum of the spec (to
// rounding, 1e-12), which is the analytic mean square to O(df / band) = 1e-5 here.
TEST(RandomSynthesis, ParsevalMeanSquareIsTheSpecIntegral) {
  const SampledSignal s = synthesize_random(gevs_on_ia(), 4.0, kFs, 11);
  const std::size_t n = s.size();
  double sum_g = 0;
  for (std::size_t k = 1; 2 * k < n; ++k) sum_g += psd_g2_per_Hz(gevs_psd(), static_cast<double>(k) * kFs / n) * kFs / n;
  const double ms = moments(s.samples_g[IA]).rms * moments(s.samples_g[IA]).rms;
  EXPECT_NEAR(ms, sum_g, 1e-12 * sum_g);
  EXPECT_NEAR(std::sqrt(ms), rms_g(gevs_psd()), 1e-4 * rms_g(gevs_psd()));
}

// The estimator: a tone at an exact bin, amplitude A. Hann^2 = 3/8 - cos/2 + cos(2.)/8 has
// only bins 0, +-1, +-2, so sum_n w^2 sin^2 is exactly sum w^2 / 2 and sum_k P_k df = A^2/2
// to rounding (1e-12); the peak is at the tone's bin. White Gaussian noise of variance s^2
// has the one-sided level 2 s^2 / fs; the mean over 511 interior bins of 511 segments has a
// relative standard error of about 1/sqrt(511 x 511 / 2) = 0.3 %: 2 % is 7 of them.
TEST(Welch, ToneIntegratesToHalfSquareAmplitudeAndWhiteNoiseIsFlat) {
  const double fs = 5120, A = 3.0, f0 = 1000;
  std::vector<double> x(65536);
  for (std::size_t i = 0; i < x.size(); ++i) x[i] = A * std::sin(2 * kPi * f0 * static_cast<double>(i) / fs + 0.3);
  const PsdEstimate e = welch_psd(x, fs, 1024);
  double power = 0;
  for (double p : e.psd_g2_per_Hz) power += p * (fs / 1024);
  EXPECT_NEAR(power, A * A / 2, 1e-12 * A * A);
  EXPECT_EQ(std::max_element(e.psd_g2_per_Hz.begin(), e.psd_g2_per_Hz.end()) - e.psd_g2_per_Hz.begin(), 200);
  EXPECT_EQ(e.segments, 127u);

  std::mt19937_64 rng(5);
  std::normal_distribution<double> normal(0.0, 0.7);
  std::vector<double> w(262144);
  for (double& v : w) v = normal(rng);
  const PsdEstimate n = welch_psd(w, fs, 1024);
  double mean = 0;
  for (std::size_t k = 1; k < 512; ++k) mean += n.psd_g2_per_Hz[k] / 511;
  EXPECT_NEAR(mean, 2 * 0.49 / fs, 0.02 * 2 * 0.49 / fs);
  EXPECT_THROW(welch_psd(w, fs, 1023), std::invalid_argument);
  EXPECT_THROW(welch_psd(std::vector<double>(100), fs, 1024), std::invalid_argument);
}

// The one-FFT synthesis against GEVS. Welch bins are chi-square with about 2 x 319 x 0.95
// degrees of freedom (Hann, 50 % overlap): relative standard deviation 5.8 %; +-1.5 dB is
// -29 % / +41 %, 5 to 7 standard deviations, for 393 bins.
TEST(RandomSynthesis, GevsWelchWithin1p5dBRmsWithin1PercentGaussian) {
  const SampledSignal s = synthesize_random(gevs_on_ia(), kDuration, kFs, 2024);
  const PsdEstimate e = welch_psd(s.samples_g[IA], kFs, kSegment);
  const BandCheck c = check_band(e, gevs_psd());
  const Moments m = moments(s.samples_g[IA]);
  std::printf(
      "[ one FFT ] Welch max deviation %.3f dB over %zu bins (30-1990 Hz); rms %.5f g vs spec %.5f g "
      "(%+.4f %%); kurtosis %.4f; tails %.4f %.5f %.5f\n",
      c.max_dev_dB, c.bins, m.rms, rms_g(gevs_psd()), 100 * (m.rms / rms_g(gevs_psd()) - 1), m.kurtosis, m.tail1, m.tail2,
      m.tail3);
  EXPECT_EQ(c.bins, 393u);
  EXPECT_LT(c.max_dev_dB, 1.5);
  EXPECT_NEAR(m.rms, rms_g(gevs_psd()), 0.01 * rms_g(gevs_psd()));
  expect_gaussian(m);
}

// The block stream (blocks of 8192 samples = 1.6 s, sine cross-fades): the same checks.
// Its variance is the spec's at every sample in expectation, but per record the blocks'
// cross terms do not cancel exactly: rms within 1 % (about 20 blocks, each with ~3000
// bins of independent phases: the relative error of the mean square is ~1e-3).
TEST(RandomExcitation, StreamWelchWithin1p5dBRmsWithin1PercentGaussian) {
  const RandomExcitation r(gevs_on_ia(), kFs, 2024, 8192);
  const SampledSignal s = r.samples(-1000, static_cast<std::size_t>(kDuration * kFs));
  const PsdEstimate e = welch_psd(s.samples_g[IA], kFs, kSegment);
  const BandCheck c = check_band(e, gevs_psd());
  const Moments m = moments(s.samples_g[IA]);
  std::printf(
      "[ stream  ] Welch max deviation %.3f dB over %zu bins (30-1990 Hz); rms %.5f g vs spec %.5f g "
      "(%+.4f %%); kurtosis %.4f; tails %.4f %.5f %.5f\n",
      c.max_dev_dB, c.bins, m.rms, rms_g(gevs_psd()), 100 * (m.rms / rms_g(gevs_psd()) - 1), m.kurtosis, m.tail1, m.tail2,
      m.tail3);
  EXPECT_LT(c.max_dev_dB, 1.5);
  EXPECT_NEAR(m.rms, rms_g(gevs_psd()), 0.01 * rms_g(gevs_psd()));
  expect_gaussian(m);
  for (double v : s.samples_g[OA]) ASSERT_EQ(v, 0.0);
}

// Same seed: bit-identical samples (also when the stream is read in another order).
// Different seed: a different record -- correlation within 6 standard errors (1/sqrt(N_eff),
// N_eff ~ 2 B T = 7900 for 2 s) of zero, and not a rescaled copy.
TEST(RandomSynthesis, SeedsReproduceAndDiffer) {
  const SampledSignal a = synthesize_random(gevs_on_ia(), 2.0, kFs, 99);
  const SampledSignal b = synthesize_random(gevs_on_ia(), 2.0, kFs, 99);
  const SampledSignal c = synthesize_random(gevs_on_ia(), 2.0, kFs, 100);
  EXPECT_EQ(a.samples_g[IA], b.samples_g[IA]);
  EXPECT_NE(a.samples_g[IA], c.samples_g[IA]);
  EXPECT_LT(std::abs(correlation(a.samples_g[IA], c.samples_g[IA])), 6 / std::sqrt(7900.0));

  const RandomExcitation r1(gevs_on_ia(), kFs, 99, 2048), r2(gevs_on_ia(), kFs, 99, 2048);
  const SampledSignal late = r2.samples(40000, 3000);  // r2 reads far ahead first
  const SampledSignal s1 = r1.samples(0, 43000), s2 = r2.samples(0, 43000);
  EXPECT_EQ(s1.samples_g[IA], s2.samples_g[IA]);
  EXPECT_TRUE(std::equal(late.samples_g[IA].begin(), late.samples_g[IA].end(), s1.samples_g[IA].begin() + 40000));
  const RandomExcitation r3(gevs_on_ia(), kFs, 100, 2048);
  EXPECT_LT(std::abs(correlation(s1.samples_g[IA], r3.samples(0, 43000).samples_g[IA])), 6 / std::sqrt(2 * 1980 * 8.4));
}

// Coupling. Common phases with proportional tables (PA = 0.25 x IA in g^2/Hz): PA is
// exactly 0.5 x IA (one direction; rounding 1e-15). Independent axes: correlation within 6
// standard errors of 0 (N_eff = 2 x 1980 x 4 = 15840).
TEST(RandomSynthesis, CommonPhasesGiveOneDirectionIndependentAxesAreUncorrelated) {
  RandomProfile p = gevs_on_ia();
  PsdTable quarter = gevs_psd();
  for (auto& r : quarter.rows) *r.psd_g2_per_Hz *= 0.25;
  p.psd[PA] = quarter;
  p.coupling = AxisCoupling::common;
  const SampledSignal s = synthesize_random(p, 4.0, kFs, 3);
  for (std::size_t i = 0; i < s.size(); ++i) ASSERT_NEAR(s.samples_g[PA][i], 0.5 * s.samples_g[IA][i], 1e-13);
  p.coupling = AxisCoupling::independent;
  const SampledSignal t = synthesize_random(p, 4.0, kFs, 3);
  EXPECT_LT(std::abs(correlation(t.samples_g[IA], t.samples_g[PA])), 6 / std::sqrt(15840.0));
  EXPECT_NEAR(moments(t.samples_g[PA]).rms, 0.5 * rms_g(gevs_psd()), 1e-3 * rms_g(gevs_psd()));
  EXPECT_EQ(t.samples_g[IA], s.samples_g[IA]);  // IA draws first either way
}

TEST(RandomSynthesis, InvalidInputNamesTheField) {
  auto message = [](auto&& f) -> std::string {
    try {
      f();
    } catch (const std::invalid_argument& e) {
      return e.what();
    }
    return "(no exception)";
  };
  EXPECT_NE(message([] { synthesize_random(gevs_on_ia(), 1.0, 4000.0, 1); }).find("sample_rate_Hz"), std::string::npos);
  EXPECT_NE(message([] { synthesize_random(gevs_on_ia(), 0.0, kFs, 1); }).find("duration_s"), std::string::npos);
  EXPECT_NE(message([] { synthesize_random(RandomProfile{}, 1.0, kFs, 1); }).find("psd"), std::string::npos);
  RandomProfile bad = gevs_on_ia();
  bad.psd[PA] = gevs_psd();
  bad.psd[PA]->rows[1].psd_g2_per_Hz = -1.0;
  const std::string m = message([&] { synthesize_random(bad, 1.0, kFs, 1); });
  EXPECT_NE(m.find("psd[PA]"), std::string::npos) << m;
  EXPECT_NE(m.find("row 2"), std::string::npos) << m;
  EXPECT_NE(message([] { RandomExcitation(gevs_on_ia(), kFs, 1, 1000); }).find("block_length"), std::string::npos);
  // 5120 Hz / 1024 = 5 Hz bins: more than a quarter of the 20-50 Hz segment? No (7.5 Hz);
  // a 20-30 Hz segment (2.5 Hz allowed) is too narrow for it.
  RandomProfile narrow;
  narrow.psd[IA] = PsdTable{{PsdRow::level(20, 0.1), PsdRow::level(30, 0.1), PsdRow::level(2000, 0.1)}};
  EXPECT_NE(message([&] { RandomExcitation(narrow, kFs, 1, 1024); }).find("block_length"), std::string::npos);
  EXPECT_EQ(message([] { RandomExcitation(gevs_on_ia(), kFs, 1, 1024); }), "(no exception)");
}

}  // namespace test_vibration_random
