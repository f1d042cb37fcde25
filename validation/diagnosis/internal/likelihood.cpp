#include "validation/diagnosis/internal/likelihood.hpp"

#include <cmath>

namespace vrelab::validation::internal {

Eigen::VectorXd sub(const Eigen::VectorXd& v, const std::vector<int>& idx) {
  Eigen::VectorXd s(idx.size());
  for (std::size_t i = 0; i < idx.size(); ++i) s(i) = v(idx[i]);
  return s;
}
Eigen::MatrixXd rows(const Eigen::MatrixXd& m, const std::vector<int>& idx) {
  Eigen::MatrixXd s(idx.size(), m.cols());
  for (std::size_t i = 0; i < idx.size(); ++i) s.row(i) = m.row(idx[i]);
  return s;
}

// (Only the lower triangle is a product, the upper its mirror: every use factorises V, which
// reads the lower triangle, or takes its diagonal. Each entry is the same sum in the same
// order as the full product's, so the factorisations equal the full product's bit for bit, at
// half its work.)
Eigen::MatrixXd covariance(const Data& d, const Eigen::MatrixXd& G, const std::vector<int>& idx) {
  const Eigen::MatrixXd Gi = rows(G, idx);
  const Eigen::MatrixXd GS = Gi * d.Sigma;
  const auto n = static_cast<Eigen::Index>(idx.size());
  Eigen::MatrixXd V(n, n);
  V.triangularView<Eigen::Lower>() = GS * Gi.transpose();
  V.triangularView<Eigen::StrictlyUpper>() = V.transpose();
  for (std::size_t i = 0; i < idx.size(); ++i) V(i, i) += d.sigma2(idx[i]);
  return V;
}

// V of the runs idx factored without forming it (gaussian_likelihood.hpp: V in double cannot
// hold the runs' variances beneath a slope column's G Sigma G^T of 1e20 times them).
FactoredCovariance factored(const Data& d, const Eigen::MatrixXd& G, const std::vector<int>& idx) {
  return FactoredCovariance(sub(d.sigma2, idx), rows(G, idx), d.Sigma);
}

Likelihood likelihood(const Data& d, const Eigen::VectorXd& pred, const Eigen::MatrixXd& G, const std::vector<int>& idx) {
  const GaussianLikelihood g = gaussian_likelihood(sub(d.measured, idx) - sub(pred, idx), sub(d.sigma2, idx), rows(G, idx), d.Sigma);
  return {g.m2logl, g.chi2};
}

// The residual the static test's coefficient errors cannot take up: r - G dc*, with dc* the
// coefficients' correction estimated from the runs `from` (and the static test's prior).
Eigen::VectorXd adjusted_residual(const Data& d, const Eigen::VectorXd& pred, const Eigen::MatrixXd& G,
                                  const std::vector<int>& from, const std::vector<int>& at) {
  const Eigen::VectorXd rf = sub(d.measured, from) - sub(pred, from);
  const Eigen::VectorXd dc = factored(d, G, from).conditional_mean(rf);
  return sub(d.measured, at) - sub(pred, at) - rows(G, at) * dc;
}

Eigen::VectorXd best_estimate(const Data& d, const Table& nominal) {
  std::vector<int> all(static_cast<std::size_t>(d.measured.size()));
  for (std::size_t k = 0; k < all.size(); ++k) all[k] = static_cast<int>(k);
  const Eigen::VectorXd dc = factored(d, nominal.G, all).conditional_mean(d.measured - nominal.pred);
  return nominal.pred + nominal.G * dc;
}

void add_simulation_accuracy(Data& d, const Table& nominal, double f) {
  if (f == 0) return;
  d.sigma2 = d.sigma2.array() + (f * best_estimate(d, nominal).array()).square();
}

// chi^2 with n degrees of freedom as a normal deviate (Wilson-Hilferty).
double chi2_as_sigma(double chi2, int n) {
  const double v = 2.0 / (9.0 * n);
  return (std::cbrt(chi2 / n) - (1 - v)) / std::sqrt(v);
}

}  // namespace vrelab::validation::internal
