// RandomExcitation's blocks are made by a synthesiser that keeps the bins' amplitudes, the
// FFT plan and the overlap weights between blocks (vibration/sampled.cpp, for speed): its
// stream must equal, bit for bit, the overlap-add of random_phase_block's blocks as
// vibration/sampled.hpp defines it (the documented synthesis, vibration/random.hpp).
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <utility>
#include <vector>

#include "vibration/detail.hpp"
#include "vibration/sampled.hpp"

namespace test_random_synthesis {

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

TEST(RandomExcitation, WantedAxesDrawTheSamePhases) {
  // draw_block_phases with a mask of wanted axes: each wanted axis gets the numbers the full
  // draw gives it (an unwanted axis before a wanted one is discarded from the engine, not
  // skipped: a skip would shift the later axis's phases); the unwanted ones are not filled.
  for (AxisCoupling coupling : {AxisCoupling::common, AxisCoupling::independent}) {
    std::array<std::vector<double>, 3> all, some;
    detail::draw_block_phases(coupling, 42, 3, 500, all);
    for (const std::array<bool, 3> wanted : {std::array<bool, 3>{false, false, true}, std::array<bool, 3>{true, false, false},
                                             std::array<bool, 3>{false, true, false}}) {
      some = {};
      detail::draw_block_phases(coupling, 42, 3, 500, some, wanted);
      for (int a = 0; a < 3; ++a) {
        if (wanted[static_cast<std::size_t>(a)]) {
          EXPECT_EQ(some[static_cast<std::size_t>(a)], all[static_cast<std::size_t>(a)]) << "axis " << a;
        } else if (!(coupling == AxisCoupling::common && a == 0)) {
          EXPECT_TRUE(some[static_cast<std::size_t>(a)].empty()) << "axis " << a;
        }
      }
    }
    // The axes' phases differ with independent coupling (the comparison above can fail).
    if (coupling == AxisCoupling::independent) {
      EXPECT_NE(all[2], all[0]);
    }
  }
}

// samples_into writes into storage a previous window left behind: windows that grow, shrink
// and move (across block edges and back before 0) into one SampledSignal whose vectors start
// full of another window's values (and longer, and with a value on the axis without a PSD).
// Each window is checked against random_phase_block's overlap-add (reference_sample, which
// shares no storage or cache with the stream) on a spread of samples, every sample of the axis
// without a PSD is +0, and the lengths are the window's: stale samples or a stale length fail.
TEST(RandomExcitation, SamplesIntoReusedStorageEqualSamples) {
  RandomProfile p;
  p.psd[IA] = PsdTable{{PsdRow::level(20, 0.04), PsdRow::level(500, 0.04)}};
  p.psd[OA] = PsdTable{{PsdRow::level(50, 0.01), PsdRow::level(400, 0.02)}};
  const double fs = 4000;
  const std::size_t m = 1024;
  const RandomExcitation r(p, fs, 7, m);
  SampledSignal reused;
  reused.sample_rate_Hz = 1.0;
  for (auto& axis : reused.samples_g) axis.assign(3000, 0.125);  // stale: not a stream value
  const std::vector<std::pair<std::int64_t, std::size_t>> windows = {{0, 1500}, {900, 700}, {-300, 2600}, {5000, 1}, {-1200, 1100}};
  for (const auto& [first, count] : windows) {
    r.samples_into(first, count, reused);
    EXPECT_EQ(reused.sample_rate_Hz, fs);
    for (int a = 0; a < 3; ++a) ASSERT_EQ(reused.samples_g[a].size(), count) << first << " axis " << a;
    // Every 97th sample, the first and the last: across both blocks' halves of each window.
    std::vector<std::size_t> at = {0, count - 1};
    for (std::size_t i = 97; i < count; i += 97) at.push_back(i);
    for (std::size_t i : at) {
      const std::int64_t n = first + static_cast<std::int64_t>(i);
      for (int a : {IA, OA}) EXPECT_EQ(reused.samples_g[a][i], reference_sample(p, fs, 7, m, n, a)) << "sample " << n << " axis " << a;
    }
    EXPECT_EQ(reused.samples_g[PA], std::vector<double>(count, 0.0)) << first;
    if (count > 100) {
      EXPECT_NE(reused.samples_g[OA][100], 0.0);
    }
  }
}

}  // namespace test_random_synthesis
