// The nuisances stage's statistics (validation/diagnosis/internal/nuisances.hpp) against hand
// computations on a few runs: the repeats' pooled chi^2 about their weighted means, and the
// correlation of neighbouring runs' gaps (repeats are not neighbours).
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "validation/diagnosis/diagnose.hpp"
#include "validation/diagnosis/internal/nuisances.hpp"

namespace test_diagnosis_nuisances_stats {

using namespace vrelab::validation;

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

}  // namespace test_diagnosis_nuisances_stats
