// The nuisances stage's statistics (validation/diagnosis/internal/nuisances.hpp) against hand
// computations on a few runs: the repeats' pooled chi^2 about their weighted means, the
// correlation of neighbouring runs' gaps (repeats are not neighbours), and the structure tests'
// statistics against scipy, their level by Monte Carlo.
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

#include "validation/diagnosis/diagnose.hpp"
#include "validation/diagnosis/internal/nuisances.hpp"

namespace test_diagnosis_nuisances_stats {

using namespace vrelab::validation;
using vrelab::Vec3;

namespace {

RunRecord run(double frequency_Hz, double amplitude_g, double measured_g, double sigma_g) {
  RunRecord r;
  r.frequency_Hz = frequency_Hz, r.amplitude_g = amplitude_g, r.measured_g = measured_g, r.sigma_g = sigma_g;
  return r;
}

}  // namespace

// Three repeats (measured 1, 2, 4; sigma 1, 1, 2): weighted mean (1 + 2 + 4/4) / (1 + 1 + 1/4)
// = 16/9, chi^2 = (7/9)^2 + (2/9)^2 + (10/9)^2 = 153/81, 2 degrees of freedom; two repeats
// (0 and 3, sigma 1): mean 3/2, chi^2 = 9/2, 1 degree of freedom; a single run adds nothing.
// Total 153/81 + 9/2 with 3. (Sums of a few doubles: 1e-12 relative.)
TEST(DiagnosisNuisances, RepeatScatterIsThePooledChi2AboutTheWeightedMeans) {
  Campaign c;
  c.runs = {run(10, 1, 1, 1), run(10, 1, 2, 1), run(10, 1, 4, 2), run(20, 1, 5, 1), run(10, 2, 0, 1), run(10, 2, 3, 1)};
  const auto [chi2, dof] = internal::repeat_scatter(c);
  EXPECT_NEAR(chi2, 153.0 / 81 + 4.5, 1e-12 * (153.0 / 81 + 4.5));
  EXPECT_EQ(dof, 3);
}

// Five runs along one direction and orientation, z = 1, 2, -1, 0.5, 3:
//   run 0: 10 Hz, 1 g; run 1: 20 Hz, 1 g; run 2: 40 Hz, 1 g; run 3: 10 Hz, 2 g; run 4: 10 Hz, 1 g
//   (a repeat of run 0).
// Neighbours in frequency at 1 g, in order 10 (runs 0, 4), 20, 40: the repeat pair is skipped,
// then (run 4, run 1) = (3, 2) and (run 1, run 2) = (2, -1); in amplitude at 10 Hz, in order
// 1 g (runs 0, 4), 2 g: (run 4, run 3) = (3, 0.5). sum xy = 6 - 2 + 1.5 = 5.5, sum x^2 = 22,
// sum y^2 = 5.25: rho = 5.5 / sqrt(22 x 5.25), 3 pairs.
TEST(DiagnosisNuisances, NeighbourCorrelationPairsRunsOneStepApart) {
  Campaign c;
  c.runs = {run(10, 1, 0, 1), run(20, 1, 0, 1), run(40, 1, 0, 1), run(10, 2, 0, 1), run(10, 1, 0, 1)};
  const std::vector<double> z = {1, 2, -1, 0.5, 3};
  const auto [rho, pairs] = internal::neighbour_correlation(c, z);
  EXPECT_NEAR(rho, 5.5 / std::sqrt(22 * 5.25), 1e-12);
  EXPECT_EQ(pairs, 3);
}

// Eight runs, 10 Hz (w = 3, 2.5, 3.5, 2.8) then 20 Hz (-0.1, 0.2, -0.3, 0.1), one amplitude,
// direction and orientation, no times (time order as listed: quarters of two runs). Testable:
// frequency (2 groups) and time order (4): four tests. scipy (chi2.sf, norm.isf) on the
// statistics written out by hand (s^2 = sum w^2 / N; means: sum n_g mean_g^2 / s^2 with G
// degrees of freedom; spreads: Bartlett about mean 0, N ln s^2 - sum n_g ln s_g^2 over
// 1 + (sum 1/n_g - 1/N) / (3 (G - 1)), G - 1): frequency's spreads 14.522, p = 1.38532e-4, the
// smallest; times 4, p = 5.54129e-4, deviate 3.2614962620. (Sums of a few doubles and Boost's
// quantiles: 1e-8.)
TEST(DiagnosisNuisances, ScatterStructureIsTheFamilysSmallestPAsADeviate) {
  Campaign c;
  const std::vector<double> w = {3, 2.5, 3.5, 2.8, -0.1, 0.2, -0.3, 0.1};
  for (int k = 0; k < 8; ++k) c.runs.push_back(run(k < 4 ? 10 : 20, 1, 0, 1));
  const internal::ScatterStructure st = internal::scatter_structure(c, w);
  EXPECT_EQ(st.tests, 4);
  EXPECT_EQ(st.factor, "frequency");
  EXPECT_EQ(st.test, "spreads");
  EXPECT_NEAR(st.sigma, 3.261496262037374, 1e-8);
}

// Its level: 2000 campaigns of the default design's 168 runs (7 frequencies x 3 amplitudes
// x 4 directions x 2 orientations, in that order) with w independent N(0, 1): the share at or
// beyond 3 sigma is at most the nuisances' tail, 1.35e-3 (Bonferroni over the 10 tests is
// conservative; Bartlett's chi^2 is an approximation), so at most 2.7 expected: 10 is 4.4
// Poisson sigma above that (20 000 draws while developing: 27, 1.35e-3). And its power: the 10 Hz runs biased by 2 sigma (a stray field's
// 1/f^4 bias at the lowest frequency) are found, over frequency, in every one of 200 draws.
TEST(DiagnosisNuisances, ScatterStructureKeepsItsLevelAndFindsALowFrequencyBias) {
  Campaign c;
  const std::vector<double> f = {10, 40, 100, 200, 400, 800, 1500}, a = {1, 2, 4};
  const std::vector<Vec3> dirs = {Vec3::UnitX(), Vec3::UnitY(), Vec3::UnitZ(), Vec3(1, 1, 0).normalized()};
  const std::vector<Vec3> orient = {Vec3(0.7071, 0, 0.7071), Vec3(-0.7071, 0, 0.7071)};
  for (const Vec3& o : orient)
    for (const Vec3& d : dirs)
      for (double fr : f)
        for (double am : a) {
          RunRecord r = run(fr, am, 0, 1);
          r.direction = d, r.orientation_g = o;
          c.runs.push_back(r);
        }
  std::mt19937_64 rng(4242);
  std::normal_distribution<double> n01;
  std::vector<double> w(c.runs.size());
  int flagged = 0, tests = 0;
  for (int draw = 0; draw < 2000; ++draw) {
    for (double& x : w) x = n01(rng);
    const internal::ScatterStructure st = internal::scatter_structure(c, w);
    flagged += st.sigma >= 3, tests = st.tests;
  }
  std::printf("  %d of 2000 white draws at or beyond 3 sigma (%d tests)\n", flagged, tests);
  EXPECT_EQ(tests, 10);
  EXPECT_LE(flagged, 10);
  int found = 0;
  for (int draw = 0; draw < 200; ++draw) {
    for (std::size_t k = 0; k < w.size(); ++k) w[k] = n01(rng) + (c.runs[k].frequency_Hz == 10 ? 2.0 : 0.0);
    const internal::ScatterStructure st = internal::scatter_structure(c, w);
    found += st.sigma >= 3 && st.factor == "frequency";
  }
  EXPECT_EQ(found, 200);
}

}  // namespace test_diagnosis_nuisances_stats
