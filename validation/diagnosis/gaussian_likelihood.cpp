#include "validation/diagnosis/gaussian_likelihood.hpp"

#include <array>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <vector>

namespace vrelab::validation {

namespace {

// Sigma = B B^T, B = D U Lambda^1/2 (gaussian_likelihood.hpp), for a Sigma with finite entries
// and a non-negative diagonal.
struct SigmaRoot {
  bool filled = false, ok = false;
  Eigen::MatrixXd Sigma, B;
};
SigmaRoot compute_root(const Eigen::MatrixXd& Sigma) {
  SigmaRoot root;
  root.filled = true, root.Sigma = Sigma;
  const Eigen::Index m = Sigma.rows();
  // Sigma = D C D over the coefficients it does not hold (Sigma_jj > 0): C is a correlation
  // matrix (unit diagonal, eigenvalues in [0, q]) whatever the coefficients' units.
  std::vector<Eigen::Index> kept;
  for (Eigen::Index j = 0; j < m; ++j)
    if (Sigma(j, j) > 0) kept.push_back(j);
  const auto q = static_cast<Eigen::Index>(kept.size());
  root.B = Eigen::MatrixXd::Zero(m, 0);
  root.ok = true;
  if (q == 0) return root;
  Eigen::VectorXd d(q);
  for (Eigen::Index a = 0; a < q; ++a) d(a) = std::sqrt(Sigma(kept[a], kept[a]));
  Eigen::MatrixXd C(q, q);
  for (Eigen::Index a = 0; a < q; ++a)
    for (Eigen::Index b = 0; b < q; ++b) C(a, b) = 0.5 * (Sigma(kept[a], kept[b]) + Sigma(kept[b], kept[a])) / (d(a) * d(b));
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> es(C);
  if (es.info() != Eigen::Success) {
    root.ok = false;
    return root;
  }
  // Over the positive eigenvalues (a negative one within rounding of C's largest is a positive
  // semi-definite Sigma's direction without variance; one beyond it, a Sigma that is no
  // covariance: not ok, every result NaN).
  if (es.eigenvalues()(0) < -1e-8 * es.eigenvalues()(q - 1)) {
    root.ok = false;
    return root;
  }
  std::vector<Eigen::Index> positive;
  for (Eigen::Index k = 0; k < q; ++k)
    if (es.eigenvalues()(k) > 0) positive.push_back(k);
  const auto p = static_cast<Eigen::Index>(positive.size());
  root.B = Eigen::MatrixXd::Zero(m, p);
  for (Eigen::Index c = 0; c < p; ++c) {
    const double sqrt_lambda = std::sqrt(es.eigenvalues()(positive[static_cast<std::size_t>(c)]));
    for (Eigen::Index a = 0; a < q; ++a)
      root.B(kept[a], c) = d(a) * es.eigenvectors()(a, positive[static_cast<std::size_t>(c)]) * sqrt_lambda;
  }
  return root;
}
// The diagnosis asks thousands of likelihoods of one Sigma (or a few: a fold's fitted
// parameters beside it): the last few roots per thread, by Sigma's exact entries (the same
// root as computed afresh, bit for bit).
const SigmaRoot& sigma_root(const Eigen::MatrixXd& Sigma) {
  thread_local std::array<SigmaRoot, 4> memo;
  thread_local std::size_t next = 0;
  for (const SigmaRoot& r : memo)
    if (r.filled && r.Sigma.rows() == Sigma.rows() && r.Sigma.cols() == Sigma.cols() && r.Sigma == Sigma) return r;
  SigmaRoot& slot = memo[next];
  next = (next + 1) % memo.size();
  slot = compute_root(Sigma);
  return slot;
}

}  // namespace

FactoredCovariance::FactoredCovariance(const Eigen::VectorXd& s2, const Eigen::MatrixXd& G, const Eigen::MatrixXd& Sigma)
    : n_(s2.size()), m_(Sigma.rows()) {
  if (G.rows() != n_ || G.cols() != m_ || Sigma.cols() != m_)
    throw std::invalid_argument("FactoredCovariance: G must be n x m and Sigma m x m");
  ok_ = s2.allFinite() && G.allFinite() && Sigma.allFinite() && (s2.array() > 0).all() && (Sigma.diagonal().array() >= 0).all();
  const double nan = std::numeric_limits<double>::quiet_NaN();
  if (!ok_) {
    log_det_ = nan;
    return;
  }
  inv_sqrt_s2_ = s2.array().sqrt().inverse();
  log_det_ = s2.array().log().sum();
  const SigmaRoot& root = sigma_root(Sigma);
  if (!root.ok) {
    ok_ = false, log_det_ = nan;
    return;
  }
  B_ = root.B;
  const Eigen::Index p = B_.cols();
  if (p == 0) return;
  Eigen::MatrixXd A(n_ + p, p);
  A.topRows(n_) = inv_sqrt_s2_.asDiagonal() * (G * B_);
  A.bottomRows(p).setIdentity();
  qr_.compute(A);
  log_det_ += 2 * qr_.matrixQR().diagonal().head(p).array().abs().log().sum();
}

Eigen::MatrixXd FactoredCovariance::beyond_range(const Eigen::MatrixXd& y) const {
  if (y.rows() != n_) throw std::invalid_argument("FactoredCovariance: y must have n rows");
  const Eigen::Index p = B_.cols();
  Eigen::MatrixXd b = Eigen::MatrixXd::Zero(n_ + p, y.cols());
  b.topRows(n_) = inv_sqrt_s2_.asDiagonal() * y;
  if (p > 0) {
    b.applyOnTheLeft(qr_.householderQ().adjoint());
    b.topRows(p).setZero();
  }
  return b;
}

Eigen::MatrixXd FactoredCovariance::whitened(const Eigen::MatrixXd& y) const {
  if (!ok_) return Eigen::MatrixXd::Constant(n_ + B_.cols(), y.cols(), std::numeric_limits<double>::quiet_NaN());
  Eigen::MatrixXd e = beyond_range(y);
  if (B_.cols() > 0) e.applyOnTheLeft(qr_.householderQ());
  return e;
}

double FactoredCovariance::chi2(const Eigen::VectorXd& y) const {
  if (!ok_) return std::numeric_limits<double>::quiet_NaN();
  return beyond_range(y).squaredNorm();
}

// (I + W W^T)^-1 S^-1/2 y is the top of the least-squares residual e: V^-1 y = S^-1/2 e_top.
Eigen::MatrixXd FactoredCovariance::solve(const Eigen::MatrixXd& y) const {
  if (!ok_) return Eigen::MatrixXd::Constant(n_, y.cols(), std::numeric_limits<double>::quiet_NaN());
  return inv_sqrt_s2_.asDiagonal() * whitened(y).topRows(n_);
}

// Sigma G^T V^-1 y = B W^T (I + W W^T)^-1 S^-1/2 y = B (I + W^T W)^-1 W^T S^-1/2 y = B z*, and
// the residual's bottom rows are -z*.
Eigen::VectorXd FactoredCovariance::conditional_mean(const Eigen::VectorXd& y) const {
  if (!ok_) return Eigen::VectorXd::Constant(m_, std::numeric_limits<double>::quiet_NaN());
  const Eigen::Index p = B_.cols();
  if (p == 0) return Eigen::VectorXd::Zero(m_);
  return -(B_ * whitened(y).bottomRows(p).col(0));
}

Eigen::MatrixXd FactoredCovariance::conditional_covariance() const {
  if (!ok_) return Eigen::MatrixXd::Constant(m_, m_, std::numeric_limits<double>::quiet_NaN());
  const Eigen::Index p = B_.cols();
  if (p == 0) return Eigen::MatrixXd::Zero(m_, m_);
  const Eigen::MatrixXd X =
      qr_.matrixQR().topLeftCorner(p, p).triangularView<Eigen::Upper>().transpose().solve(B_.transpose());
  return X.transpose() * X;
}

GaussianLikelihood gaussian_likelihood(const Eigen::VectorXd& y, const Eigen::VectorXd& s2, const Eigen::MatrixXd& G,
                                       const Eigen::MatrixXd& Sigma) {
  const FactoredCovariance v(s2, G, Sigma);
  GaussianLikelihood l;
  l.chi2 = v.chi2(y);
  l.m2logl = l.chi2 + v.log_det();
  return l;
}

}  // namespace vrelab::validation
