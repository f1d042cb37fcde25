#include "validation/diagnosis/internal/effect_fitter.hpp"

#include <algorithm>
#include <limits>
#include <stdexcept>

namespace vrelab::validation::internal {

void EffectFitter::add_model_error(const Data& d, const std::vector<int>& idx, Multi& mf) const {
  const double f = e_.hypothesis_accuracy;
  if (!(f > 0)) return;
  const std::vector<double> v = mf.values;
  std::vector<int> which;
  Table t;
  try {
    t = at(v);
    if (mf.cov.size() > 0) {
      which = mf.free;
    } else {
      const double sp = mf.sigma.front();
      if (!std::isfinite(sp) || !(sp > 0)) return;
      which = {0};
    }
  } catch (const std::invalid_argument&) {
    return;
  }
  const Eigen::Index k = static_cast<Eigen::Index>(which.size());
  const Eigen::VectorXd delta = f * (t.pred - nominal_.pred);  // over every run
  // The refit on the data shifted by sign f Delta: the parameters' change, or none where the
  // descent failed; `edge` says which ended on a bound.
  const Eigen::MatrixXd info = last_info_;  // (levenberg_marquardt overwrites it)
  const auto refit = [&](double sign, std::vector<bool>& edge) -> std::optional<Eigen::VectorXd> {
    Data shifted = d;
    shifted.measured += sign * delta;
    try {
      const std::vector<double> w = levenberg_marquardt(shifted, idx, v, which);
      Eigen::VectorXd dv(k);
      edge.assign(which.size(), false);
      for (std::size_t a = 0; a < which.size(); ++a) {
        const int j = which[a];
        const auto [lo, hi] = range(j);
        const double x = w[static_cast<std::size_t>(j)];
        if (!std::isfinite(x)) return std::nullopt;
        const bool wraps = j > 0 && e_.parameters[static_cast<std::size_t>(j)].periodic;
        double dx = x - v[static_cast<std::size_t>(j)];
        if (wraps) dx = std::remainder(dx, hi - lo);
        else edge[a] = x <= lo || x >= hi;
        dv(static_cast<Eigen::Index>(a)) = dx;
      }
      return dv;
    } catch (const std::invalid_argument&) {
      return std::nullopt;
    }
  };
  std::vector<bool> edge_up, edge_down;
  const std::optional<Eigen::VectorXd> up = refit(+1, edge_up), down = refit(-1, edge_down);
  last_info_ = info;
  Eigen::VectorXd b = Eigen::VectorXd::Zero(k);
  bool first_order = false;
  for (Eigen::Index a = 0; a < k; ++a) {
    const auto ua = static_cast<std::size_t>(a);
    const bool u = up && !edge_up[ua], w = down && !edge_down[ua];
    if (u && w) {
      b(a) = ((*up)(a) - (*down)(a)) / 2;  // (each shift already wrapped: a spread is not folded back)
    } else if (u) {
      b(a) = (*up)(a);
    } else if (w) {
      b(a) = -(*down)(a);
    } else {
      first_order = true;
    }
  }
  if (first_order) {
    // Neither refit usable: the first-order shift b = C J^T V^-1 f Delta for what is left.
    Eigen::MatrixXd C, J;
    if (mf.cov.size() > 0) {
      C = mf.cov, J = rows(mf.slopes, idx);
    } else {
      const double sp = mf.sigma.front();
      std::vector<double> hi = v, lo = v;
      hi.front() += sp, lo.front() -= sp;
      try {
        const Eigen::VectorXd slope = (at(hi).pred - at(lo).pred) / (2 * sp);
        C = Eigen::MatrixXd::Constant(1, 1, sp * sp), J = sub(slope, idx);
      } catch (const std::invalid_argument&) {
        C.resize(0, 0);
      }
    }
    if (C.size() > 0) {
      const Eigen::LDLT<Eigen::MatrixXd> ldlt(covariance(d, t.G, idx));
      const Eigen::VectorXd b1 = C * (ldlt.solve(J).transpose() * sub(delta, idx));
      for (Eigen::Index a = 0; a < k; ++a) {
        const auto ua = static_cast<std::size_t>(a);
        if (!((up && !edge_up[ua]) || (down && !edge_down[ua]))) b(a) = b1(a);
      }
    }
  }
  const Eigen::MatrixXd extra = b * b.transpose();
  for (std::size_t a = 0; a < which.size(); ++a) {
    const auto j = static_cast<std::size_t>(which[a]);
    if (std::isfinite(mf.sigma[j])) mf.sigma[j] = std::sqrt(mf.sigma[j] * mf.sigma[j] + extra(static_cast<Eigen::Index>(a), static_cast<Eigen::Index>(a)));
  }
  if (mf.cov.size() > 0) mf.cov += extra;
}

void EffectFitter::add_held_spread(const Data& d, const std::vector<int>& idx, Multi& mf) const {
  const std::vector<int> which = fitted_set(mf);
  if (!std::isfinite(mf.sigma.front())) return;  // the first at its bound: no sigma to widen
  const Eigen::Index k = static_cast<Eigen::Index>(which.size());
  Eigen::MatrixXd spread = Eigen::MatrixXd::Zero(k, k);
  for (std::size_t j = 1; j < e_.parameters.size(); ++j) {
    const EffectParameter& q = e_.parameters[j];
    if (q.discrete || mf.status[j] != ParameterStatus::held || !(std::isfinite(q.lower) && std::isfinite(q.upper))) continue;
    std::vector<double> xs;
    for (int i = 0; i < kHeldPoints; ++i)
      xs.push_back(q.periodic ? q.lower + (q.upper - q.lower) * i / kHeldPoints
                              : q.lower + (q.upper - q.lower) * i / (kHeldPoints - 1));
    const std::vector<ProfilePoint> pts = profile(d, idx, mf, static_cast<int>(j), xs);
    double fmin = INFINITY;
    for (const ProfilePoint& p : pts) fmin = std::min(fmin, p.objective);
    if (!std::isfinite(fmin)) continue;
    double wsum = 0;
    Eigen::MatrixXd m = Eigen::MatrixXd::Zero(k, k);
    for (const ProfilePoint& p : pts) {
      if (!std::isfinite(p.objective)) continue;
      const double w = std::exp(-(p.objective - fmin) / 2);
      Eigen::VectorXd dv(k);
      for (Eigen::Index a = 0; a < k; ++a) {
        const int i = which[static_cast<std::size_t>(a)];
        const double dx = p.values[static_cast<std::size_t>(i)] - mf.values[static_cast<std::size_t>(i)];
        dv(a) = wraps(i) ? std::remainder(dx, range(i).second - range(i).first) : dx;
      }
      m += w * dv * dv.transpose(), wsum += w;
    }
    spread += m / wsum;
  }
  for (std::size_t a = 0; a < which.size(); ++a) {
    const auto i = static_cast<std::size_t>(which[a]);
    const double s2 = spread(static_cast<Eigen::Index>(a), static_cast<Eigen::Index>(a));
    if (std::isfinite(mf.sigma[i]) && s2 > 0) mf.sigma[i] = std::sqrt(mf.sigma[i] * mf.sigma[i] + s2);
  }
  if (mf.cov.size() > 0) mf.cov += spread;
}

std::vector<EffectFitter::ProfilePoint> EffectFitter::profile(const Data& d, const std::vector<int>& idx, const Multi& mf, int j,
                                                const std::vector<double>& xs) const {
  std::vector<int> which = fitted_set(mf);
  which.erase(std::remove(which.begin(), which.end(), j), which.end());
  std::vector<int> with_j = which;
  with_j.push_back(j);
  const Eigen::MatrixXd info = last_info_;
  std::vector<ProfilePoint> out;
  for (double x : xs) {
    ProfilePoint p;
    p.x = x;
    std::vector<double> v = mf.values;
    v[static_cast<std::size_t>(j)] = x;
    try {
      v.front() = fit_first(d, idx, v).first;
      p.values = which.size() > 1 ? levenberg_marquardt(d, idx, v, which) : v;
      p.objective = objective_at(d, idx, p.values, with_j);
    } catch (const std::invalid_argument&) {
      p.values = v;
    }
    out.push_back(p);
  }
  last_info_ = info;
  return out;
}

Eigen::MatrixXd EffectFitter::covariance_at(const Data& d, const std::vector<int>& idx, const std::vector<double>& v,
                                            const std::vector<int>& free, const Eigen::MatrixXd& slopes) const {
  const Eigen::Index k = static_cast<Eigen::Index>(free.size());
  cov_never_definite_ = false;
  const Eigen::MatrixXd fallback = last_info_.rows() == k ? Eigen::MatrixXd(last_info_.inverse())
                                                          : Eigen::MatrixXd::Constant(k, k, std::numeric_limits<double>::quiet_NaN());
  Eigen::MatrixXd A;
  try {
    const Table t = at(v);
    const Eigen::LDLT<Eigen::MatrixXd> ldlt(covariance(d, t.G, idx));
    const Eigen::MatrixXd Ji = rows(slopes, idx);
    A = Ji.transpose() * ldlt.solve(Ji);
  } catch (const std::invalid_argument&) {
    return fallback;
  }
  std::vector<double> h(free.size());
  for (std::size_t a = 0; a < free.size(); ++a) {
    const int j = free[a];
    const Eigen::Index ia = static_cast<Eigen::Index>(a);
    const double info = A(ia, ia) + (a > 0 ? prior_weight(j) : 0.0);
    const auto [lo, hi] = range(j);
    const double x = v[static_cast<std::size_t>(j)];
    h[a] = std::max(step(v, j), info > 0 ? 0.5 / std::sqrt(info) : 0.0);
    if (e_.parameters[static_cast<std::size_t>(j)].periodic && j > 0) {
      h[a] = std::min(h[a], 0.125 * (hi - lo));
    } else {
      h[a] = std::min({h[a], x - lo, hi - x});
      if (!(h[a] >= step(v, j))) return fallback;
    }
  }
  const auto f_at = [&](std::size_t a, double sa, std::size_t b, double sb) {
    std::vector<double> w = v;
    w[static_cast<std::size_t>(free[a])] += sa * h[a];
    if (b < free.size()) w[static_cast<std::size_t>(free[b])] += sb * h[b];
    return objective_at(d, idx, w, free);
  };
  const double f0 = objective_at(d, idx, v, free);
  // Where -2 ln L is that flat over the steps that its rounding makes the Hessian indefinite
  // (a phase the data barely pin, seen at 0.0024 rad: the fallback then said +- 0.013 where
  // -2 ln L is level over +-0.4 rad), the steps widen fourfold, twice (a phase's at most to
  // pi/4; within the range otherwise): the secant curvature over the wider steps.
  for (int widen = 0; widen < 3; ++widen) {
    if (widen > 0) {
      for (std::size_t a = 0; a < free.size(); ++a) {
        const int j = free[a];
        const auto [lo, hi] = range(j);
        const double x = v[static_cast<std::size_t>(j)];
        h[a] = e_.parameters[static_cast<std::size_t>(j)].periodic && j > 0 ? std::min(4 * h[a], 0.125 * (hi - lo))
                                                                            : std::min({4 * h[a], x - lo, hi - x});
      }
    }
    Eigen::MatrixXd H(k, k);
    for (std::size_t a = 0; a < free.size(); ++a) {
      H(static_cast<Eigen::Index>(a), static_cast<Eigen::Index>(a)) =
          (f_at(a, 1, free.size(), 0) - 2 * f0 + f_at(a, -1, free.size(), 0)) / (h[a] * h[a]);
      for (std::size_t b = a + 1; b < free.size(); ++b) {
        const double x = (f_at(a, 1, b, 1) - f_at(a, 1, b, -1) - f_at(a, -1, b, 1) + f_at(a, -1, b, -1)) / (4 * h[a] * h[b]);
        H(static_cast<Eigen::Index>(a), static_cast<Eigen::Index>(b)) = H(static_cast<Eigen::Index>(b), static_cast<Eigen::Index>(a)) = x;
      }
    }
    if (!H.allFinite()) return fallback;
    const Eigen::LLT<Eigen::MatrixXd> llt(H / 2);
    if (llt.info() == Eigen::Success) return llt.solve(Eigen::MatrixXd::Identity(k, k));
  }
  cov_never_definite_ = true;
  return fallback;
}

}  // namespace vrelab::validation::internal
