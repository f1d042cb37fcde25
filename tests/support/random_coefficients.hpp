#pragma once
// Random coefficient sets for the tests. Magnitudes are log-uniform with random sign over
// ranges a little wider than navigation accelerometers show (small-nonlinearity regime).
#include <cmath>
#include <random>

#include "plant/model1.hpp"

namespace vrelab::test {

inline double log_uniform(std::mt19937_64& rng, double lo, double hi) {
  std::uniform_real_distribution<double> u(std::log(lo), std::log(hi));
  std::bernoulli_distribution sign(0.5);
  return (sign(rng) ? 1 : -1) * std::exp(u(rng));
}

inline plant::Coefficients random_coefficients(std::mt19937_64& rng, double lo = 1e-5, double hi = 1e-2) {
  plant::Coefficients c;
  c[plant::K1] = std::uniform_real_distribution<double>(0.5, 2.0)(rng);
  for (int i = 1; i < plant::kNumCoefficients; ++i) c[i] = log_uniform(rng, lo, hi);
  return c;
}

}  // namespace vrelab::test
