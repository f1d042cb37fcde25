// Continuous-time excitations from samples (vibration/sampled.hpp): the quintic B-spline
// interpolant's accuracy on pure tones, exactness at the samples, what happens past the
// ends, and the block stream's interpolant against a one-shot spline of the same samples.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <random>
#include <stdexcept>

#include "support/constants.hpp"
#include "vibration/sampled.hpp"

namespace test_vibration_sampled {

using namespace vrelab;
using namespace vrelab::vibration;
using vrelab::test::kPi;

namespace {

SampledSignal tone(double fs, std::size_t n, double f, double amplitude, double phase) {
  SampledSignal s;
  s.sample_rate_Hz = fs;
  for (auto& v : s.samples_g) v.assign(n, 0.0);
  for (std::size_t i = 0; i < n; ++i)
    s.samples_g[IA][i] = amplitude * std::sin(2 * kPi * f * static_cast<double>(i) / fs + phase);
  return s;
}

// Worst |interpolant - tone| / amplitude over 40000 instants spread over the record with
// fractions u = frac(i x golden ratio) (dense in [0, 1), every phase of the tone visited).
double worst_tone_error(double fraction_of_fs) {
  const double fs = 8000, f = fraction_of_fs * fs, a = 2.5;
  const std::size_t n = 4096;  // whole number of cycles for fs/8 and fs/16: periodic, seamless
  const SampledExcitation e(tone(fs, n, f, a, 0.4));
  double worst = 0;
  for (int i = 0; i < 40000; ++i) {
    const double u = std::fmod(i * 0.6180339887498949, 1.0);
    const double t = (static_cast<double>(i % n) + u) / fs;
    worst = std::max(worst, std::abs(e.acceleration_g(t)[IA] - a * std::sin(2 * kPi * f * t + 0.4)));
  }
  return worst / a;
}

}  // namespace

// The quintic B-spline interpolant of a sampled tone A sin(w n + phi) is exactly
// A Im[e^{i(w t + phi)} sum_m beta5(t - m) e^{-i w (t - m)} / B5(w)], B5(w) = sum_k beta5(k)
// e^{-i w k} = (66 + 52 cos w + 2 cos 2w) / 120; its worst error over the tone's phase is
// A |S(u) - e^{i w u}|, S the sum without the phase factor. numpy on 20001 fractions u: the
// supremum is at u = 1/2, 2.0786e-5 A at fs/8 and 2.5879e-7 A at fs/16 (the header's
// figures). The measured worst over 40000 instants must sit just below those suprema:
// within [0.9, 1.001] of them (a grid misses the exact maximum by O(grid^2); a kernel of
// another order would be off by a factor ~10 or more either way).
TEST(SampledExcitation, ToneErrorBelowFs8) {
  const double e8 = worst_tone_error(1.0 / 8), e16 = worst_tone_error(1.0 / 16);
  std::printf("[ spline ] worst tone error / amplitude: fs/8 %.3e, fs/16 %.3e\n", e8, e16);
  EXPECT_LE(e8, 2.0786e-5 * 1.001);
  EXPECT_GE(e8, 2.0786e-5 * 0.9);
  EXPECT_LE(e16, 2.5879e-7 * 1.001);
  EXPECT_GE(e16, 2.5879e-7 * 0.9);
}

// At t = n / fs the interpolant returns sample n (prefilter truncation 3e-18, rounding of a
// 6-term sum of coefficients up to ~3x the samples: 1e-13 absolute for unit samples). Past
// the end, periodic: s(t + N/fs) = s(t) to rounding; zero: exactly 0 from 48 samples + 3 past
// either end (no coefficient reaches further) and small but non-zero ringing right after.
TEST(SampledExcitation, PassesThroughSamplesAndDefinesTheEnds) {
  std::mt19937_64 rng(1);
  std::normal_distribution<double> normal;
  SampledSignal s;
  s.sample_rate_Hz = 1000;
  for (auto& v : s.samples_g) {
    v.resize(300);
    for (double& x : v) x = normal(rng);
  }
  const SampledExcitation per(s, EndBehaviour::periodic), zero(s, EndBehaviour::zero, 400);
  EXPECT_EQ(zero.max_frequency_Hz(), 400);
  EXPECT_EQ(per.max_frequency_Hz(), 500);
  for (std::size_t i = 0; i < 300; ++i) {
    const double t = static_cast<double>(i) / 1000;
    for (int a = 0; a < 3; ++a) {
      ASSERT_NEAR(per.acceleration_g(t)[a], s.samples_g[a][i], 1e-13) << i;
      ASSERT_NEAR(zero.acceleration_g(t)[a], s.samples_g[a][i], 1e-13) << i;
    }
  }
  for (double t : {0.0123, 0.1, 0.2991, -0.0457}) {
    EXPECT_NEAR((per.acceleration_g(t + 0.3) - per.acceleration_g(t)).norm(), 0, 1e-12);
    EXPECT_NEAR((per.acceleration_g(t - 0.3) - per.acceleration_g(t)).norm(), 0, 1e-12);
  }
  EXPECT_EQ(zero.acceleration_g(0.3 + 0.052).norm(), 0.0);
  EXPECT_EQ(zero.acceleration_g(-0.052).norm(), 0.0);
  EXPECT_GT(zero.acceleration_g(0.3005).norm(), 1e-3);
  EXPECT_THROW(SampledExcitation(tone(1000, 5, 10, 1, 0)), std::invalid_argument);
  EXPECT_THROW(SampledExcitation(s, EndBehaviour::zero, 600), std::invalid_argument);
}

// The stream's interpolant is computed in stretches of H = M/2 samples, each prefiltered with
// 48 samples of margin. It must equal a one-shot spline of the same stream samples (built as
// a SampledExcitation with zero ends, long enough that its ends are > 100 samples away), at
// arbitrary instants including around stretch boundaries and before t = 0: 1e-11 g. The two
// differ by the margin truncation (3e-18 relative) and by rounding in the recursions, whose
// intermediate values reach ~120 x the samples (the prefilter gain; samples up to ~15 g
// here): 2e3 x 2.2e-16 x a few ~ 1e-12 g (measured 1.2e-12 g).
TEST(RandomExcitation, InterpolantEqualsOneShotSplineAcrossStretches) {
  RandomProfile p;
  p.psd[IA] = PsdTable{{PsdRow::level(20, 0.04), PsdRow::level(500, 0.04)}};
  p.psd[OA] = PsdTable{{PsdRow::level(50, 0.01), PsdRow::level(400, 0.02)}};
  p.coupling = AxisCoupling::independent;
  const double fs = 4000;
  const RandomExcitation r(p, fs, 42, 1024);  // H = 512 samples
  const std::int64_t first = -1500;
  const SampledSignal s = r.samples(first, 5000);
  const SampledExcitation ref(s, EndBehaviour::zero);
  double worst = 0;
  for (std::int64_t n : {-1024, -512, -1, 0, 1, 511, 512, 513, 1023, 1024, 2048, 3000}) {
    for (double u : {-0.5, -0.01, 0.0, 0.3, 0.999}) {
      const double t = (static_cast<double>(n) + u) / fs;
      const Vec3 d = r.acceleration_g(t) - ref.acceleration_g(t - static_cast<double>(first) / fs);
      worst = std::max(worst, d.cwiseAbs().maxCoeff());
    }
  }
  EXPECT_LT(worst, 1e-11);
  EXPECT_EQ(r.acceleration_g(0.1)[PA], 0.0);
  // Memory does not depend on the run's length: 4 blocks + 3 stretches, 3 axes, 8 bytes.
  EXPECT_EQ(r.memory_bytes(), (4 * 3 * 1024 + 3 * 3 * 512) * sizeof(double));
  EXPECT_LT(RandomExcitation(p, 20000, 1, 32768).memory_bytes(), 4.5e6);
}

// A turned excitation (a fixture holding the sensor turned) is the unturned one's motion times
// the matrix, sample by sample and between samples (the interpolant is linear in the samples):
// to rounding (1e-14 g on samples of a few g). An axis at rest in the profile moves once
// turned; the identity leaves the stream bit for bit as it was.
TEST(RandomExcitation, ATurnedExcitationIsTheMatrixTimesTheUnturnedMotion) {
  RandomProfile p;
  p.psd[IA] = PsdTable{{PsdRow::level(20, 0.04), PsdRow::level(500, 0.04)}};
  p.psd[PA] = PsdTable{{PsdRow::level(50, 0.01), PsdRow::level(400, 0.02)}};
  p.coupling = AxisCoupling::independent;
  const double fs = 4000;
  Eigen::Matrix3d turn;
  turn << 0.99, -0.1, 0.02, 0.1, 0.99, 0.0, -0.02, 0.0, 1.0;
  const RandomExcitation plain(p, fs, 42, 1024), turned(p, fs, 42, 1024, turn), same(p, fs, 42, 1024, Eigen::Matrix3d::Identity());
  const SampledSignal a = plain.samples(-700, 3000), b = turned.samples(-700, 3000), c = same.samples(-700, 3000);
  double worst = 0, oa = 0;
  for (std::size_t n = 0; n < a.size(); ++n) {
    const Vec3 x(a.samples_g[IA][n], a.samples_g[PA][n], a.samples_g[OA][n]);
    const Vec3 y(b.samples_g[IA][n], b.samples_g[PA][n], b.samples_g[OA][n]);
    worst = std::max(worst, (y - turn * x).cwiseAbs().maxCoeff());
    oa = std::max(oa, std::abs(y[OA]));
    for (int k = 0; k < 3; ++k) ASSERT_EQ(c.samples_g[k][n], a.samples_g[k][n]);
  }
  for (double t : {-0.1, 0.0, 0.01234, 0.3, 0.49}) worst = std::max(worst, (turned.acceleration_g(t) - turn * plain.acceleration_g(t)).cwiseAbs().maxCoeff());
  EXPECT_LT(worst, 1e-14);
  EXPECT_GT(oa, 0.01);  // OA at rest in the profile, moved by the turn
  EXPECT_NE(turned.describe().find("turned"), std::string::npos);
  Eigen::Matrix3d bad = turn;
  bad(1, 2) = NAN;
  EXPECT_THROW(RandomExcitation(p, fs, 42, 1024, bad), std::invalid_argument);
}

}  // namespace test_vibration_sampled
