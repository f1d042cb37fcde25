// The table every fit reads (validation/diagnosis/internal/tabulate.hpp) against each run's
// prediction made on its own (predict_run_g: no response cache, no memo, the loop responses
// computed afresh for the run). The table shares work between runs: the loop responses (the
// cache), a squeeze film's balance and a distorted or rocking table's harmonics (runs that
// differ only in orientation). Whatever it shares, each row must be its own run's prediction.
// Runs: sine runs at three frequencies, two amplitudes and two directions, each at two static
// orientations (the pairs the memos share work across). Effects: a 2nd harmonic, the fixture's
// rocking (its motion turns gravity: the orientation must be in what it shares), a squeeze
// film, a mode (the responses' key), and none. Tolerance: 1e-12 of the largest prediction
// (both paths compute the same function of the same numbers; the bound allows rounding only,
// while a row taken from another run is off by a run's own change).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "support/instrument.hpp"
#include "validation/diagnosis/effect.hpp"
#include "validation/diagnosis/internal/tabulate.hpp"

namespace test_tabulate {

using namespace vrelab;
using namespace vrelab::validation;

namespace {

std::vector<RunRecord> pairs_of_runs() {
  std::vector<RunRecord> runs;
  for (double f : {40.0, 300.0, 1500.0})
    for (double a : {2.0, 6.0})
      for (const Vec3& d : {Vec3(1, 0, 0), Vec3(1, 1, 0)})
        for (const Vec3& o : {Vec3(1, 0, 1), Vec3(-1, 0, 1)}) {
          RunRecord r;
          r.id = "r" + std::to_string(runs.size());
          r.frequency_Hz = f, r.amplitude_g = a, r.direction = d.normalized(), r.orientation_g = o.normalized();
          runs.push_back(r);
        }
  return runs;
}

}  // namespace

TEST(Tabulate, EveryRowIsItsOwnRunsPrediction) {
  const plant::PlantConfig plant = test::paper_like_plant();
  const std::vector<RunRecord> runs = pairs_of_runs();
  internal::ResponseCache cache;
  const internal::Absorbed absorbed;  // no effect here acts at rest
  struct Case {
    std::string effect;
    double value;
  };
  for (const Case& c : {Case{"", 0}, Case{"shaker_harmonic_distortion", 0.2}, Case{"fixture_rocking", 5e-6},
                        Case{"squeeze_film_damping", 800}, Case{"mechanical_mode", 900}}) {
    const Effect* e = c.effect.empty() ? nullptr : find_effect(c.effect);
    if (!c.effect.empty()) {
      ASSERT_NE(e, nullptr) << c.effect;
    }
    ASSERT_TRUE(!e || !e->acts_at_rest) << c.effect << " acts at rest: it would need what the static test took up";
    const std::vector<double> values = e ? e->values_at(c.value) : std::vector<double>{};
    const internal::Table t = internal::tabulate(plant, runs, e, values, cache, absorbed);
    ASSERT_EQ(t.pred.size(), static_cast<Eigen::Index>(runs.size()));
    double largest = 0, worst = 0, pair_gap = 0;
    std::vector<double> own(runs.size());
    for (std::size_t k = 0; k < runs.size(); ++k) {
      own[k] = e ? predict_run_g(plant, runs[k], *e, values) : predict_run_g(plant, runs[k], nullptr, 0);
      largest = std::max(largest, std::abs(own[k]));
      worst = std::max(worst, std::abs(t.pred(static_cast<Eigen::Index>(k)) - own[k]));
      if (k % 2 == 1) pair_gap = std::max(pair_gap, std::abs(own[k] - own[k - 1]));
    }
    std::printf("  %-28s largest %.4g ug, |table - own| <= %.2e g, orientation pairs differ by up to %.3g ug\n",
                c.effect.empty() ? "(nominal)" : c.effect.c_str(), largest * 1e6, worst, pair_gap * 1e6);
    EXPECT_LE(worst, 1e-12 * largest) << c.effect;
    // A row taken from its pair's other orientation would be off by far more than the bound.
    EXPECT_GT(pair_gap, 1e6 * 1e-12 * largest) << c.effect;
  }
}

}  // namespace test_tabulate
