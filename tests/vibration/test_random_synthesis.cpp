// RandomExcitation's blocks are made by a synthesiser that keeps the bins' amplitudes, the
// FFT plan and the overlap weights between blocks (vibration/sampled.cpp, for speed): its
// stream must equal, bit for bit, the overlap-add of random_phase_block's blocks as
// vibration/sampled.hpp defines it (the documented synthesis, vibration/random.hpp).
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "vibration/sampled.hpp"

using namespace vrelab;
using namespace vrelab::vibration;

namespace {

// Sample n of the stream from random_phase_block itself: blocks c and c + 1 around it.
double reference_sample(const RandomProfile& p, double fs, std::uint64_t seed, std::size_t m, std::int64_t n, int axis) {
  const auto h = static_cast<std::int64_t>(m / 2);
  const std::int64_t c = n >= 0 ? n / h : -((-n + h - 1) / h);
  const std::int64_t r = n - c * h;
  const SampledSignal b0 = random_phase_block(p, m, fs, seed, c), b1 = random_phase_block(p, m, fs, seed, c + 1);
  const double theta = std::numbers::pi * static_cast<double>(r) / static_cast<double>(m);
  return std::cos(theta) * b0.samples_g[axis][static_cast<std::size_t>(r + h)] +
         std::sin(theta) * b1.samples_g[axis][static_cast<std::size_t>(r)];
}

}  // namespace

TEST(RandomExcitation, BlocksEqualRandomPhaseBlockBitForBit) {
  for (AxisCoupling coupling : {AxisCoupling::common, AxisCoupling::independent}) {
    RandomProfile p;
    p.psd[IA] = PsdTable{{PsdRow::level(20, 0.04), PsdRow::level(500, 0.04)}};
    p.psd[OA] = PsdTable{{PsdRow::level(50, 0.01), PsdRow::level(400, 0.02)}};
    p.coupling = coupling;
    const double fs = 4000;
    const std::size_t m = 1024;
    const RandomExcitation r(p, fs, 42, m);
    const std::int64_t first = -700;
    const SampledSignal s = r.samples(first, 2600);  // blocks -2 .. 4, across the block edges
    for (std::int64_t n : {-700L, -513L, -512L, -511L, -1L, 0L, 1L, 255L, 511L, 512L, 513L, 1023L, 1024L, 1899L}) {
      for (int axis : {IA, PA, OA}) {
        const double got = s.samples_g[axis][static_cast<std::size_t>(n - first)];
        const double want = axis == PA ? 0.0 : reference_sample(p, fs, 42, m, n, axis);
        EXPECT_EQ(got, want) << "sample " << n << " axis " << axis;
      }
    }
    EXPECT_NE(s.samples_g[IA][800], 0.0);
    // The synthesiser's fixed tables: amplitudes of the bins with power, FFT buffers, the
    // overlap weights; independent of the run's length.
    EXPECT_GT(r.synthesis_bytes(), 0u);
    EXPECT_LT(r.synthesis_bytes(), 64 * m);
  }
}
