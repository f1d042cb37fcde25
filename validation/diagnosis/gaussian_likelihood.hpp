#pragma once
// The runs' Gaussian likelihood with the static test's coefficient errors shared between them:
// the residual r has covariance V = S + G Sigma G^T (S = diag(s2), each run's own variance;
// G = d pred / d coefficient, n x m; Sigma the coefficients' m x m covariance), and
// -2 ln L = r^T V^-1 r + ln det V (up to a constant).
//
// V is never formed. Sigma = B B^T with B = D U Lambda^1/2 (D = diag(sqrt(Sigma_jj)), C = D^-1
// Sigma D^-1 its correlation, C = U Lambda U^T with Lambda clamped at 0; columns with
// Sigma_jj = 0 dropped), W = S^-1/2 G B (n x p), so V = S^1/2 (I + W W^T) S^1/2, and the
// Householder QR of the stacked [W; I_p] = Q R (R^T R = I + W^T W) gives
//   ln det V  = sum ln s2 + ln det(I_n + W W^T) = sum ln s2 + 2 sum ln |R_jj|
//               (the matrix determinant lemma: det(I_n + W W^T) = det(I_p + W^T W));
//   r^T V^-1 r = min_z |S^-1/2 r - W z|^2 + |z|^2   (Woodbury: (I + W W^T)^-1 = I - W (I + W^T W)^-1 W^T),
//               the squared norm of the least-squares residual e of [W; I] z = [S^-1/2 r; 0],
//               taken from Q^T [S^-1/2 r; 0] below R's rows (no difference of large numbers).
// Why: a slope column of G can be 1e5 g per unit of a parameter whose sigma puts it 1e10 run
// sigma above S (a mechanical mode fitted on other runs, sitting on a run's frequency); V's
// entries then hold S below their rounding, and a factorisation of V itself can meet negative
// pivots (ln det V = -inf). Here the column's scale cancels in G D (a slope times its own sigma), R^T R >= I
// holds whatever W is, and Householder QR is backward stable column by column, so each
// column's rounding is relative to its own size. Cost O(n p^2), against O(n^3) for a dense V.
#include <Eigen/Dense>

namespace vrelab::validation {

class FactoredCovariance {
 public:
  // s2 > 0 (n), G (n x m), Sigma (m x m, symmetric positive semi-definite). Not finite inputs,
  // s2 <= 0 or a negative variance on Sigma's diagonal: ok() is false and every result NaN.
  FactoredCovariance(const Eigen::VectorXd& s2, const Eigen::MatrixXd& G, const Eigen::MatrixXd& Sigma);

  bool ok() const { return ok_; }
  double log_det() const { return log_det_; }  // ln det V
  // The whitened residual E ((n + p) x k) of the columns of y (n x k): E^T E = y^T V^-1 y
  // (n x k of NaN when not ok()).
  Eigen::MatrixXd whitened(const Eigen::MatrixXd& y) const;
  double chi2(const Eigen::VectorXd& y) const;   // y^T V^-1 y
  Eigen::MatrixXd solve(const Eigen::MatrixXd& y) const;  // V^-1 y
  Eigen::VectorXd solve(const Eigen::VectorXd& y) const { return solve(Eigen::MatrixXd(y)).col(0); }
  // The coefficients' conditional mean given y: Sigma G^T V^-1 y (= B z*, z* the least-squares
  // solution above), m entries.
  Eigen::VectorXd conditional_mean(const Eigen::VectorXd& y) const;
  // The coefficients' conditional covariance given the runs: Sigma - Sigma G^T V^-1 G Sigma
  // = B (I + W^T W)^-1 B^T = (R^-T B^T)^T (R^-T B^T), m x m (no difference of large numbers).
  Eigen::MatrixXd conditional_covariance() const;

 private:
  // [S^-1/2 y; 0] and its Q^T, the first p rows zeroed (what R's columns cannot reach).
  Eigen::MatrixXd beyond_range(const Eigen::MatrixXd& y) const;
  bool ok_ = true;
  Eigen::Index n_ = 0, m_ = 0;
  Eigen::VectorXd inv_sqrt_s2_;
  Eigen::MatrixXd B_;                    // m x p: Sigma = B B^T
  Eigen::HouseholderQR<Eigen::MatrixXd> qr_;  // of [W; I_p]
  double log_det_ = 0;
};

// -2 ln L = y^T V^-1 y + ln det V and chi^2 = y^T V^-1 y through FactoredCovariance.
struct GaussianLikelihood {
  double m2logl = 0, chi2 = 0;
};
GaussianLikelihood gaussian_likelihood(const Eigen::VectorXd& y, const Eigen::VectorXd& s2, const Eigen::MatrixXd& G,
                                       const Eigen::MatrixXd& Sigma);

}  // namespace vrelab::validation
