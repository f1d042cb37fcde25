#include "validation/identification/uncertainty.hpp"

#include <algorithm>
#include <cmath>
#include <random>
#include <stdexcept>

namespace vrelab::validation {

Propagation propagate_first_order(const Estimator& estimator, const std::vector<Reading>& readings,
                                  const ReadingBudget& budget) {
  if (budget.variance.size() != readings.size() || budget.bias.size() != readings.size())
    throw std::invalid_argument("propagate_first_order: one budget entry per reading is needed");
  // Step: small against the readings (the estimators are linear or nearly so in U, so the
  // truncation error is negligible) and large against their rounding.
  double scale = 0;
  for (const Reading& r : readings) scale = std::max(scale, std::abs(r.output));
  const double h = 1e-6 * (scale > 0 ? scale : 1.0);
  CoefArray bias{};
  std::array<CoefArray, plant::kNumCoefficients> cov{};
  CoefArray j{};
  std::vector<Reading> work = readings;
  for (std::size_t i = 0; i < readings.size(); ++i) {
    work[i].output = readings[i].output + h;
    const Estimate up = estimator(work);
    work[i].output = readings[i].output - h;
    const Estimate down = estimator(work);
    work[i].output = readings[i].output;
    for (int k = 0; k < plant::kNumCoefficients; ++k) {
      j[k] = (up.value[k] - down.value[k]) / (2 * h);
      bias[k] += j[k] * budget.bias[i];
    }
    for (int k = 0; k < plant::kNumCoefficients; ++k)
      for (int l = 0; l < plant::kNumCoefficients; ++l) cov[k][l] += j[k] * j[l] * budget.variance[i];
  }
  Propagation p;
  for (int k = 0; k < plant::kNumCoefficients; ++k) {
    p.sigma[k] = std::sqrt(cov[k][k]);
    p.bias[k] = bias[k];
  }
  p.covariance = cov;
  return p;
}

std::vector<MonteCarloStats> monte_carlo(const std::vector<Estimator>& estimators,
                                         const plant::Coefficients& truth, const OutputSource& source,
                                         const std::vector<Position>& positions,
                                         const StaticTestErrors& errors, int n, std::uint64_t seed) {
  if (n < 2) throw std::invalid_argument("Monte Carlo needs at least 2 trials");
  std::mt19937_64 rng(seed);
  std::vector<MonteCarloStats> stats(estimators.size());
  std::vector<CoefArray> m2(estimators.size(), CoefArray{});
  for (int t = 1; t <= n; ++t) {
    const std::vector<Reading> readings = simulate_static_test(source, truth[plant::K1], positions, errors, rng);
    for (std::size_t e = 0; e < estimators.size(); ++e) {
      const Estimate est = estimators[e](readings);
      MonteCarloStats& s = stats[e];
      for (int k = 0; k < plant::kNumCoefficients; ++k) {  // Welford's running mean/variance
        const double x = est.value[k] - truth[k];
        const double d = x - s.mean_error[k];
        s.mean_error[k] += d / t;
        m2[e][k] += d * (x - s.mean_error[k]);
      }
    }
  }
  for (std::size_t e = 0; e < estimators.size(); ++e) {
    stats[e].n = n;
    for (int k = 0; k < plant::kNumCoefficients; ++k) stats[e].std[k] = std::sqrt(m2[e][k] / (n - 1));
  }
  return stats;
}

}  // namespace vrelab::validation
