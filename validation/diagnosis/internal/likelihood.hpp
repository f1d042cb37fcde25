#pragma once
// validation/diagnosis/internal/likelihood.hpp -- the runs' data and their Gaussian likelihood,
// the diagnosis' shared arithmetic (docs/diagnose.md, "3. The gap and where it lies":
// "Covariance" and "The factored likelihood").
//
// Takes: the runs' measured vibration errors (g) and variances (g^2: the run's own plus the
//        simulation's, (its relative accuracy x best estimate)^2), the static test's coefficient
//        covariance Sigma (coefficient units^2), a table of predictions (g) and their gradient
//        G in the coefficients (g per coefficient unit), and a subset of the runs (indices).
// Gives: the residual's covariance V = diag(sigma2) + G Sigma G^T on the subset, -2 ln L and
//        chi^2 = r^T V^-1 r there, and the residual the coefficient errors cannot take up.
#include <vector>

#include <Eigen/Dense>

#include "validation/diagnosis/gaussian_likelihood.hpp"

namespace vrelab::validation::internal {

// The entries idx of v; the rows idx of m.
Eigen::VectorXd sub(const Eigen::VectorXd& v, const std::vector<int>& idx);
Eigen::MatrixXd rows(const Eigen::MatrixXd& m, const std::vector<int>& idx);

// The simulation of every run under one effect value: pred = f0 + G c (exact: the
// prediction is linear in the coefficients), evaluated at the identified coefficients.
struct Table {
  Eigen::VectorXd pred;  // at the identified coefficients, g
  Eigen::MatrixXd G;     // d pred / d coefficient, n x kNumCoefficients
};

// -2 log(likelihood) of the runs `idx` (up to a constant), with the residual's covariance
// V = diag(sigma_run^2 + (f_model best)^2) + G Sigma G^T; and chi^2 = r^T V^-1 r.
struct Likelihood {
  double m2logl = 0, chi2 = 0;
};
struct Data {
  Eigen::VectorXd measured, sigma2;  // sigma2: the run's variance plus the simulation's own, (f_model best_estimate)^2
  Eigen::MatrixXd Sigma;
};

// V of the runs idx (the lower triangle a product, the upper its mirror).
Eigen::MatrixXd covariance(const Data& d, const Eigen::MatrixXd& G, const std::vector<int>& idx);
// V of the runs idx factored without forming it (gaussian_likelihood.hpp).
FactoredCovariance factored(const Data& d, const Eigen::MatrixXd& G, const std::vector<int>& idx);
Likelihood likelihood(const Data& d, const Eigen::VectorXd& pred, const Eigen::MatrixXd& G, const std::vector<int>& idx);
// The residual the static test's coefficient errors cannot take up: r - G dc*, with dc* the
// coefficients' correction estimated from the runs `from` (and the static test's prior), at
// the runs `at`.
Eigen::VectorXd adjusted_residual(const Data& d, const Eigen::VectorXd& pred, const Eigen::MatrixXd& G,
                                  const std::vector<int>& from, const std::vector<int>& at);
// The runs' vibration error (g) as best the nominal model and every run know it: the nominal
// prediction with the coefficients' correction that the runs (their variances d.sigma2) and
// the static test's prior (d.Sigma) estimate, pred + G dc*. The static test alone pins k2..k4
// poorly: its prediction at several g can be off by orders more than the runs' sigma.
Eigen::VectorXd best_estimate(const Data& d, const Table& nominal);
// The simulation's own accuracy joins each run's variance: sigma2 += (f best_estimate)^2, the
// same for every effect, so that no effect can lower chi^2 by inflating its predictions
// (docs/diagnose.md, "Covariance"). d.sigma2 holds the runs' own variances on entry.
void add_simulation_accuracy(Data& d, const Table& nominal, double f);
// chi^2 with n degrees of freedom as a normal deviate (Wilson-Hilferty).
double chi2_as_sigma(double chi2, int n);

}  // namespace vrelab::validation::internal
