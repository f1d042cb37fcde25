#include "validation/diagnosis/internal/effect_fitter.hpp"

#include <algorithm>
#include <limits>
#include <stdexcept>

namespace vrelab::validation::internal {

Eigen::MatrixXd EffectFitter::jacobian(const std::vector<double>& v, const std::vector<int>& free) const {
  const Eigen::Index n = nominal_.pred.size();
  Eigen::MatrixXd J = Eigen::MatrixXd::Zero(n, static_cast<Eigen::Index>(free.size()));
  for (std::size_t a = 0; a < free.size(); ++a) {
    const int j = free[a];
    const double h = step(v, j);
    const std::pair<double, double> bounds = range(j);
    const double lo = bounds.first, hi = bounds.second;  // (named: a lambda captures them)
    const auto pred_at = [&](double x) -> std::optional<Eigen::VectorXd> {
      if (wraps(j)) x = wrapped(j, x);
      else if (x < lo || x > hi) return std::nullopt;
      try {
        std::vector<double> w = v;
        w[static_cast<std::size_t>(j)] = x;
        return at(w).pred;
      } catch (const std::invalid_argument&) {
        return std::nullopt;
      }
    };
    const double x = v[static_cast<std::size_t>(j)];
    const auto up = pred_at(x + h), down = pred_at(x - h);
    if (up && down) J.col(static_cast<Eigen::Index>(a)) = (*up - *down) / (2 * h);
    else if (up) J.col(static_cast<Eigen::Index>(a)) = (*up - at(v).pred) / h;
    else if (down) J.col(static_cast<Eigen::Index>(a)) = (at(v).pred - *down) / h;
  }
  return J;
}

std::vector<int> EffectFitter::unpinned(const Data& d, const std::vector<int>& idx, const std::vector<double>& v,
                                        const std::vector<int>& free) const {
  const Table t = at(v);
  const Eigen::LLT<Eigen::MatrixXd> llt(covariance(d, t.G, idx));
  Eigen::MatrixXd W = llt.matrixL().solve(rows(jacobian(v, free), idx));
  Eigen::VectorXd scale(W.cols());
  for (Eigen::Index a = 0; a < W.cols(); ++a) {
    scale(a) = W.col(a).norm();
    if (scale(a) > 0) W.col(a) /= scale(a);
  }
  std::vector<int> held;
  Eigen::ColPivHouseholderQR<Eigen::MatrixXd> qr(W);
  qr.setThreshold(1e-6);
  if (qr.rank() < W.cols()) {
    for (Eigen::Index a = qr.rank(); a < W.cols(); ++a) {
      const int j = free[static_cast<std::size_t>(qr.colsPermutation().indices()(a))];
      if (j > 0) held.push_back(j);
    }
    if (held.empty()) held.push_back(free.back());  // the first parameter's own column: hold the last further one
    return held;
  }
  const Eigen::MatrixXd A = W.transpose() * W;
  const Eigen::MatrixXd C = A.inverse();
  for (std::size_t a = 1; a < free.size(); ++a) {
    const double sd = std::sqrt(std::max(0.0, C(static_cast<Eigen::Index>(a), static_cast<Eigen::Index>(a)))) /
                      scale(static_cast<Eigen::Index>(a));
    if (!(sd < e_.parameters[static_cast<std::size_t>(free[a])].prior_width())) held.push_back(free[a]);
  }
  return held;
}

std::optional<bool> EffectFitter::valley_step(const Data& d, const std::vector<int>& idx, const std::vector<int>& free,
                                              std::vector<double>& v, double& f, const Eigen::VectorXd& steps,
                                              const Eigen::VectorXd& curv) const {
  const Eigen::Index k = static_cast<Eigen::Index>(free.size());
  bool narrow = false;
  Eigen::VectorXd h(k);
  for (Eigen::Index a = 0; a < k; ++a) {
    if (!(curv(a) > 0)) return std::nullopt;  // one-sided or not convex: the trust step's case
    const double sigma = 1 / std::sqrt(curv(a));
    narrow = narrow || steps(a) > kNarrowSigmas * sigma;
    h(a) = std::min(steps(a), kLocalSigmas * sigma);
  }
  if (!narrow) return std::nullopt;
  const auto moved = [&](std::vector<double> w, Eigen::Index a, double by) {
    const int j = free[static_cast<std::size_t>(a)];
    const double x = w[static_cast<std::size_t>(j)] + by;
    w[static_cast<std::size_t>(j)] = wraps(j) ? wrapped(j, x) : std::clamp(x, range(j).first, range(j).second);
    return w;
  };
  const auto f_at = [&](Eigen::Index a, double sa, Eigen::Index b, double sb) {
    std::vector<double> w = moved(v, a, sa * h(a));
    if (b >= 0) w = moved(w, b, sb * h(b));
    return objective_at(d, idx, w, free);
  };
  Eigen::VectorXd g(k);
  Eigen::MatrixXd H(k, k);  // half the objective's Hessian, as J^T V^-1 J
  for (Eigen::Index a = 0; a < k; ++a) {
    const double fu = f_at(a, 1, -1, 0), fd = f_at(a, -1, -1, 0);
    g(a) = -(fu - fd) / (4 * h(a));
    H(a, a) = (fu - 2 * f + fd) / (h(a) * h(a)) / 2;
    for (Eigen::Index b = 0; b < a; ++b)
      H(a, b) = H(b, a) = (f_at(a, 1, b, 1) - f_at(a, 1, b, -1) - f_at(a, -1, b, 1) + f_at(a, -1, b, -1)) / (8 * h(a) * h(b));
  }
  if (!H.allFinite() || !g.allFinite()) return std::nullopt;
  const Eigen::LLT<Eigen::MatrixXd> llt(H);
  if (llt.info() != Eigen::Success) return std::nullopt;
  last_info_ = H;
  const Eigen::VectorXd newton = llt.solve(g);
  double t = 1;
  for (int tries = 0; tries < 10; ++tries, t /= 2) {
    std::vector<double> w = v;
    for (Eigen::Index a = 0; a < k; ++a) w = moved(w, a, t * newton(a));
    const double fw = objective_at(d, idx, w, free);
    if (!(fw < f)) continue;
    bool converged = true;
    for (Eigen::Index a = 0; a < k; ++a)
      if (std::abs(newton(a)) > 1e-3 / std::sqrt(H(a, a))) converged = false;  // the full step, not the halved one
    v = w, f = fw;
    return converged;
  }
  return std::nullopt;  // no decrease along Newton's direction: Levenberg-Marquardt's step
}

std::vector<double> EffectFitter::levenberg_marquardt(const Data& d, const std::vector<int>& idx, std::vector<double> v,
                                                      const std::vector<int>& free) const {
  const auto objective = [&](const std::vector<double>& w) { return objective_at(d, idx, w, free); };
  const Eigen::Index k = static_cast<Eigen::Index>(free.size());
  double f = objective(v), lambda = 1e-3;
  for (int it = 0; it < 15; ++it) {
    const Table t = at(v);
    const Eigen::LDLT<Eigen::MatrixXd> ldlt(covariance(d, t.G, idx));
    const Eigen::MatrixXd Ji = rows(jacobian(v, free), idx);
    const Eigen::VectorXd r = sub(d.measured, idx) - sub(t.pred, idx);
    // The Gauss-Newton matrix J^T V^-1 J (+ the priors); the gradient of the whole objective
    // (-2 ln L with its ln det V, which the parameters change through G, and the priors) by
    // central differences: J^T V^-1 r alone ignores ln det V and pointed a phase away from
    // its optimum (seen: every step rejected).
    Eigen::MatrixXd A = Ji.transpose() * ldlt.solve(Ji);
    Eigen::VectorXd g = Ji.transpose() * ldlt.solve(r);
    // scale: the objective's curvature (reported through last_info_); step: that, or where
    // the objective is not convex along a further parameter, the trust step's.
    Eigen::VectorXd scale = Eigen::VectorXd::Ones(k), step_scale = Eigen::VectorXd::Ones(k);
    // Each parameter's difference step and the objective's curvature along it over that step
    // (half the second difference; NaN where the difference is not central).
    Eigen::VectorXd steps(k), curv = Eigen::VectorXd::Constant(k, std::numeric_limits<double>::quiet_NaN());
    for (Eigen::Index a = 0; a < k; ++a) {
      const int j = free[static_cast<std::size_t>(a)];
      if (a > 0) A(a, a) += prior_weight(j);
      const double h = step(v, j);
      steps(a) = h;
      const auto [lo, hi] = range(j);
      std::vector<double> up = v, down = v;
      const double x = v[static_cast<std::size_t>(j)];
      // A phase's differences are taken round the circle (central at +-pi too): clamped at
      // the range's ends, they would be one-sided there and without the curvature's rescaling,
      // so steps of Gauss-Newton's hundredfold curvature would creep along (seed 9301, campaign
      // 54: from the start at -pi, 15 such steps end at 3.13 rad, 63 above the valley at 2.55).
      const double x_up = wraps(j) ? x + h : std::min(x + h, hi), x_down = wraps(j) ? x - h : std::max(x - h, lo);
      up[static_cast<std::size_t>(j)] = wraps(j) ? wrapped(j, x_up) : x_up;
      down[static_cast<std::size_t>(j)] = wraps(j) ? wrapped(j, x_down) : x_down;
      const double span = x_up - x_down;
      const double fu = objective(up), fd = objective(down);
      if (span > 0 && std::isfinite(fu) && std::isfinite(fd)) {
        g(a) = -(fu - fd) / (2 * span);
        // The objective's own curvature along j (half its second difference, central only):
        // the row and column of A rescaled to it, the correlations kept from J^T V^-1 J.
        // (Central: both sides h away, not clipped by the range; tested on the bounds, not by
        // comparing x_up - x with x - x_down, which rounding makes unequal for some x.)
        if (wraps(j) || (x + h <= hi && x - h >= lo)) {
          const double c = (fu - 2 * f + fd) / (h * h) / 2;
          curv(a) = c;
          if (c > 0 && A(a, a) > 0) {
            scale(a) = step_scale(a) = std::sqrt(c / A(a, a));
          } else if (j > 0 && A(a, a) > 0 && std::isfinite(hi - lo)) {
            // Not convex along j here (the flank of a valley, past its inflection): no
            // curvature to step by, and J^T V^-1 J's (hundredfold a phase's) crept along
            // (seed 8901, campaign 90: from pi/2 the phase stopped at 1.52 rad on a slope of
            // 50 per rad, its valley at 0.9 rad 24 lower). The curvature that makes the step
            // along j a sixteenth of its range (a quarter of its prior width), when that is
            // less than J^T V^-1 J's; the steps' acceptance (and lambda) judges it. A further
            // parameter only (the first one's fit starts from its grid's best). Not information:
            // the covariance (last_info_) keeps J^T V^-1 J along j.
            const double trust = (hi - lo) / 16, target = std::abs(g(a)) / trust;
            if (target > 0 && target < A(a, a)) step_scale(a) = std::sqrt(target / A(a, a));
          }
        }
      }
    }
    if (const std::optional<bool> stop = valley_step(d, idx, free, v, f, steps, curv)) {
      if (*stop) break;
      continue;
    }
    last_info_ = scale.asDiagonal() * A * scale.asDiagonal();
    A = step_scale.asDiagonal() * A * step_scale.asDiagonal();
    bool accepted = false, converged = false;
    for (int tries = 0; tries < 8 && !accepted; ++tries) {
      Eigen::MatrixXd Al = A;
      for (Eigen::Index a = 0; a < k; ++a) Al(a, a) *= 1 + lambda;
      const Eigen::VectorXd delta = Al.ldlt().solve(g);
      std::vector<double> w = v;
      for (Eigen::Index a = 0; a < k; ++a) {
        const int j = free[static_cast<std::size_t>(a)];
        const auto [lo, hi] = range(j);
        double x = w[static_cast<std::size_t>(j)] + delta(a);
        w[static_cast<std::size_t>(j)] = wraps(j) ? wrapped(j, x) : std::clamp(x, lo, hi);
      }
      const double fw = objective(w);
      if (fw < f) {
        converged = true;
        for (Eigen::Index a = 0; a < k; ++a) {
          const int j = free[static_cast<std::size_t>(a)];
          const double moved = w[static_cast<std::size_t>(j)] - v[static_cast<std::size_t>(j)];
          // (a phase's move across +-pi is its short way round)
          const double by = wraps(j) ? std::remainder(moved, range(j).second - range(j).first) : moved;
          if (std::abs(by) > 1e-3 / std::sqrt(std::max(A(a, a), 1e-300))) converged = false;
        }
        v = w, f = fw, lambda = std::max(lambda / 3, 1e-6), accepted = true;
      } else {
        lambda *= 10;
      }
    }
    if (!accepted || converged) break;
  }
  return v;
}

}  // namespace vrelab::validation::internal
