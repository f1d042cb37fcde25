#pragma once
// A synthetic campaign model for the scorer's tests (tests/validation/test_unseen_folds.cpp,
// test_fold_valleys.cpp): 24 runs in two folds of 12, keys 1 (runs 0-11) and 4 (runs 12-23),
// what a Scorer and an EffectFitter read of a campaign: the nominal table (predictions and the
// coefficients' gradient, kNumCoefficients columns), each run's variance, the coefficients'
// covariance (1e-8 I unless a test sets it) and the folds. The measured values are the test's.
#include <Eigen/Dense>

#include "plant/model1.hpp"
#include "validation/diagnosis/internal/evidence.hpp"
#include "validation/diagnosis/internal/identification.hpp"

namespace vrelab::test {

struct TwoFoldModel {
  static constexpr int kRuns = 24;
  static bool second_fold(int k) { return k >= kRuns / 2; }

  validation::Campaign campaign;
  validation::internal::ResponseCache cache;
  validation::internal::CampaignModel m{campaign, 0.0, cache};
  validation::internal::Folds folds;

  // f0, G: the nominal table (kRuns rows); sigma_g: every run's sigma.
  void set(const Eigen::VectorXd& f0, const Eigen::MatrixXd& G, double sigma_g) {
    m.n = kRuns;
    m.nominal = {f0, G};
    m.data.sigma2 = Eigen::VectorXd::Constant(kRuns, sigma_g * sigma_g);
    m.data.Sigma = 1e-8 * Eigen::MatrixXd::Identity(plant::kNumCoefficients, plant::kNumCoefficients);
    for (int k = 0; k < kRuns; ++k) {
      const double key = second_fold(k) ? 4.0 : 1.0;
      folds.key.push_back(key);
      folds.test[key].push_back(k);
      m.all.push_back(k);
    }
    folds.description = "synthetic";
  }
};

}  // namespace vrelab::test
