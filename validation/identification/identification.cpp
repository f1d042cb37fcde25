#include "validation/identification/identification.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <set>
#include <sstream>
#include <stdexcept>

#include <fmt/format.h>

#include <Eigen/Dense>
#include <Eigen/SVD>

namespace vrelab::validation {
namespace {

using plant::Basis;
using plant::kNumCoefficients;
using enum plant::Coef;
constexpr int N = kNumCoefficients;
// Singular values below this fraction of the largest count as zero. The column-scaled
// design of an exactly confounded set has its smallest singular value at ~1e-16; a
// set that is merely ill-conditioned (e.g. positions 1 degree apart) stays above 1e-6.
constexpr double kRankTolerance = 1e-10;
// The rank is decided first on the unscaled, unweighted design: its entries are the basis
// values of model (1) in g^n (a coefficient in its natural unit moves a reading by K1 times
// the entry), so an entry or a direction of size 1e-10 g^n is one that a coefficient of 1
// in its unit (far beyond any accelerometer: k2 = 1/g rectifies 1 g per g^2) would change a
// reading by 1e-10 g: below any reading noise a lab can reach (>= ~1e-8 g, 0.01 ug), so the
// coefficient's uncertainty along it would exceed its whole physical range (sigma_g / 1e-10
// > 1). Rounding in an orientation (cos 90 deg = 6e-17) lies 6 orders below; real geometry
// (positions 1 degree apart) 4 orders above. Column scaling alone would make a rounding
// column full size and report it identifiable (issue 13, item 1).
constexpr double kUnscaledRankTolerance = 1e-10;

struct Design {
  std::vector<int> params;  // theta indices being estimated (0 = K1)
  Eigen::MatrixXd A;        // rows: readings (or positions), cols: params
  Eigen::VectorXd offset;   // known part of each row's U (when K1 is fixed)
};

Design design(const std::vector<Position>& positions, const std::vector<int>& rows, const FixedSet& fixed) {
  Design d;
  const bool k1_free = !fixed[K1];
  if (k1_free) d.params.push_back(0);
  for (int i = 1; i < N; ++i)
    if (!fixed[i]) d.params.push_back(i);
  d.A.resize(static_cast<Eigen::Index>(rows.size()), static_cast<Eigen::Index>(d.params.size()));
  d.offset = Eigen::VectorXd::Zero(static_cast<Eigen::Index>(rows.size()));
  for (std::size_t r = 0; r < rows.size(); ++r) {
    const Basis f = plant::basis(positions.at(rows[r]).nominal_g);
    double known = f[0];  // the part multiplied by K1: a_IA + sum of fixed k_i f_i
    for (int i = 1; i < N; ++i)
      if (fixed[i]) known += *fixed[i] * f[i];
    for (std::size_t c = 0; c < d.params.size(); ++c)
      d.A(static_cast<Eigen::Index>(r), static_cast<Eigen::Index>(c)) = d.params[c] == 0 ? known : f[d.params[c]];
    if (!k1_free) d.offset[static_cast<Eigen::Index>(r)] = *fixed[K1] * known;
  }
  return d;
}

// Reduced row echelon form of the rows of m (each row a null direction), pivots scaled to 1.
Eigen::MatrixXd rref(Eigen::MatrixXd m) {
  Eigen::Index lead = 0;
  for (Eigen::Index r = 0; r < m.rows() && lead < m.cols(); ++r, ++lead) {
    Eigen::Index best = r;
    while (true) {
      for (Eigen::Index i = r; i < m.rows(); ++i)
        if (std::abs(m(i, lead)) > std::abs(m(best, lead))) best = i;
      if (std::abs(m(best, lead)) > 1e-9) break;
      if (++lead == m.cols()) return m;
      best = r;
    }
    m.row(r).swap(m.row(best));
    m.row(r) /= m(r, lead);
    for (Eigen::Index i = 0; i < m.rows(); ++i)
      if (i != r) m.row(i) -= m(i, lead) * m.row(r);
  }
  return m;
}

std::string format_factor(double x) {
  std::ostringstream s;
  s.precision(4);
  s << x;
  return s.str();
}

std::string describe(const std::array<double, N>& v, const std::vector<Position>& positions) {
  std::vector<int> idx;
  for (int i = 0; i < N; ++i)
    if (std::abs(v[i]) > 1e-9) idx.push_back(i);
  auto label = [](int i) { return i == K1 ? std::string("K1 (relative)") : std::string(plant::coefficient_name(i)); };
  std::ostringstream out;
  bool unit_pattern = idx.size() >= 2;
  for (std::size_t n = 1; n < idx.size(); ++n)
    unit_pattern = unit_pattern && std::abs(std::abs(v[idx[n]]) - 1) < 1e-9 &&
                   (v[idx[n]] > 0) == (v[idx[1]] > 0) && std::abs(v[idx[0]] - 1) < 1e-9;
  if (unit_pattern && idx.size() > 2) {
    out << label(idx[0]) << " and a common shift of ";
    for (std::size_t n = 1; n < idx.size(); ++n) out << (n > 1 ? ", " : "") << label(idx[n]);
  } else {
    for (std::size_t n = 0; n < idx.size(); ++n)
      out << (n == 0 ? "" : n + 1 == idx.size() ? " and " : ", ") << label(idx[n]);
  }
  if (idx.size() == 1) {
    out << " affects no reading in this position set";
    return out.str();
  }
  out << " cannot be told apart: ";
  for (std::size_t n = 0; n < idx.size(); ++n) {
    const double f = v[idx[n]];
    out << (n ? ", " : "") << label(idx[n]) << (f < 0 ? " - " : " + ")
        << (std::abs(std::abs(f) - 1) < 1e-9 ? "" : format_factor(std::abs(f)) + "*") << "c";
  }
  out << " leave every reading unchanged";
  // Name the cause where it is one of the two known ones.
  const bool sphere = std::abs(v[k0]) > 1e-9 && (std::abs(v[k2]) > 1e-9 || std::abs(v[k_PP]) > 1e-9 ||
                                                 std::abs(v[k_OO]) > 1e-9);
  if (sphere) out << " (in every static position a_IA^2 + a_PA^2 + a_OA^2 = 1 g^2)";
  if (std::abs(v[k1_asym]) > 1e-9) {
    std::set<long long> levels;
    for (const Position& p : positions) levels.insert(std::llround(std::abs(p.nominal_g[IA]) * 1e9));
    out << " (|a_IA| takes only " << levels.size() << " distinct values in this position set)";
  }
  return out.str();
}

struct Solved {
  Eigen::VectorXd theta;  // over Design::params
  Identifiability id;
};

int unscaled_rank(const Eigen::MatrixXd& a) {
  if (a.cols() == 0 || a.rows() == 0) return 0;
  Eigen::JacobiSVD<Eigen::MatrixXd> svd(a);
  svd.setThreshold(kUnscaledRankTolerance);  // relative to the largest singular value
  return static_cast<int>(svd.rank());
}

Solved solve(const Design& d, const Eigen::VectorXd& y, const Eigen::VectorXd& w,
             const std::vector<Position>& positions) {
  const Eigen::VectorXd sw = w.cwiseSqrt();
  Eigen::MatrixXd aw = sw.asDiagonal() * d.A;
  const Eigen::Index p = aw.cols();
  const int rank_unscaled = unscaled_rank(d.A);
  // Column scaling conditions the solution of a well-posed set; when the unscaled problem
  // has a smaller rank, scaling would blow rounding columns up, so the set is solved and its
  // null directions found unscaled.
  Eigen::VectorXd scale = Eigen::VectorXd::Ones(p);
  const bool scaled = rank_unscaled == p;
  if (scaled)
    for (Eigen::Index c = 0; c < p; ++c) {
      scale[c] = aw.col(c).norm();
      if (scale[c] == 0) scale[c] = 1;  // an all-zero column: a null direction by itself
      aw.col(c) /= scale[c];
    }
  Eigen::JacobiSVD<Eigen::MatrixXd> svd(aw, Eigen::ComputeThinU | Eigen::ComputeFullV);
  const Eigen::VectorXd s = svd.singularValues();
  Solved out;
  Identifiability& id = out.id;
  id.parameters = static_cast<int>(p);
  for (int i : d.params) id.free[i] = true;
  const double smax = p > 0 ? s[0] : 0.0;
  int rank = 0;
  for (Eigen::Index i = 0; i < s.size(); ++i)
    if (s[i] > kRankTolerance * smax) ++rank;
  rank = std::min(rank, rank_unscaled);
  id.rank = rank;
  id.condition_number = rank == p && rank > 0 ? smax / s[p - 1] : std::numeric_limits<double>::infinity();
  id.condition_number_identifiable = rank > 0 ? smax / s[rank - 1] : std::numeric_limits<double>::infinity();

  // Minimum-norm solution in scaled coordinates, then two steps of iterative refinement
  // with the residual accumulated in long double: the small coefficients are differences
  // of readings of order K1, and refinement keeps their error at the readings' rounding.
  Eigen::VectorXd theta = Eigen::VectorXd::Zero(p);
  if (rank > 0 && y.size() > 0) {
    const auto pseudo_solve = [&](const Eigen::VectorXd& rhs_weighted) {
      const Eigen::VectorXd uty = svd.matrixU().leftCols(rank).transpose() * rhs_weighted;
      return Eigen::VectorXd((svd.matrixV().leftCols(rank) * uty.cwiseQuotient(s.head(rank))).cwiseQuotient(scale));
    };
    theta = pseudo_solve(sw.cwiseProduct(y));
    Eigen::VectorXd residual(y.size());
    for (int step = 0; step < 2; ++step) {
      for (Eigen::Index i = 0; i < y.size(); ++i) {
        long double acc = y[i];
        for (Eigen::Index c = 0; c < p; ++c) acc -= static_cast<long double>(d.A(i, c)) * theta[c];
        residual[i] = static_cast<double>(acc);
      }
      theta += pseudo_solve(sw.cwiseProduct(residual));
    }
  }
  out.theta = theta;

  // Null space in unscaled parameter coordinates.
  const Eigen::MatrixXd null_scaled = svd.matrixV().rightCols(p - rank);
  Eigen::VectorXd col_residual(p);
  // (No null space, no columns: a row of an empty matrix would offset a null pointer; found by fuzz_lab_data.)
  for (Eigen::Index c = 0; c < p; ++c) col_residual[c] = rank < p ? null_scaled.row(c).norm() : 0.0;
  for (Eigen::Index c = 0; c < p; ++c) {
    const int param = d.params[static_cast<std::size_t>(c)];
    id.identifiable[param] = col_residual[c] < 1e-8;
  }
  if (p - rank > 0) {
    Eigen::MatrixXd null = null_scaled;
    for (Eigen::Index c = 0; c < p; ++c) null.row(c) /= scale[c];
    const Eigen::MatrixXd basis_rows = rref(null.transpose());
    for (Eigen::Index r = 0; r < basis_rows.rows(); ++r) {
      std::array<double, N> v{};
      for (Eigen::Index c = 0; c < p; ++c) {
        const double x = basis_rows(r, c);
        v[d.params[static_cast<std::size_t>(c)]] = std::abs(x) < 1e-9 ? 0.0 : x;
      }
      id.null_directions.push_back(v);
      id.confounded.push_back(describe(v, positions));
    }
  }
  // k_i = theta_i / K1: not identifiable if K1 is not.
  if (!d.params.empty() && d.params[0] == 0 && !id.identifiable[K1])
    for (int i : d.params) id.identifiable[i] = false;
  return out;
}

std::vector<int> all_rows(std::size_t n) {
  std::vector<int> r(n);
  for (std::size_t i = 0; i < n; ++i) r[i] = static_cast<int>(i);
  return r;
}

}  // namespace

LeastSquaresResult least_squares(const std::vector<Position>& positions,
                                 const std::vector<Reading>& readings,
                                 const std::vector<double>& weights, const FixedSet& fixed) {
  if (readings.empty()) throw std::invalid_argument("least squares needs at least one reading");
  if (!weights.empty() && weights.size() != readings.size())
    throw std::invalid_argument("least squares: one weight per reading is needed");
  std::vector<int> rows;
  rows.reserve(readings.size());
  for (const Reading& r : readings) rows.push_back(r.position);
  const Design d = design(positions, rows, fixed);
  Eigen::VectorXd y(static_cast<Eigen::Index>(readings.size()));
  for (std::size_t i = 0; i < readings.size(); ++i) y[static_cast<Eigen::Index>(i)] = readings[i].output;
  y -= d.offset;
  const Eigen::VectorXd w = weights.empty() ? Eigen::VectorXd::Ones(y.size())
                                            : Eigen::Map<const Eigen::VectorXd>(weights.data(), y.size()).eval();
  const Solved s = solve(d, y, w, positions);

  LeastSquaresResult out;
  out.identifiability = s.id;
  Estimate& e = out.estimate;
  double k1 = fixed[K1] ? *fixed[K1] : 0.0;
  for (std::size_t c = 0; c < d.params.size(); ++c)
    if (d.params[c] == 0) k1 = s.theta[static_cast<Eigen::Index>(c)];
  e.value[K1] = k1;
  for (std::size_t c = 0; c < d.params.size(); ++c)
    if (d.params[c] != 0) e.value[d.params[c]] = s.theta[static_cast<Eigen::Index>(c)] / k1;
  for (int i = 0; i < N; ++i) {
    e.available[i] = true;
    if (fixed[i]) {
      e.value[i] = *fixed[i];
      e.assumed[i] = true;
    }
  }
  return out;
}

FitCheck check_fit(const std::vector<Position>& positions, const std::vector<Reading>& readings,
                   const Estimate& e, const std::vector<double>& variance, int free_parameters) {
  FitCheck out;
  const double k1 = e.value[K1];
  for (int i = 0; i < N; ++i)
    if (!std::isfinite(e.value[i])) {
      out.problem = std::string(plant::coefficient_name(i)) + " is not a finite number";
      return out;
    }
  if (!(k1 > 0)) {
    out.problem = fmt::format("K1 = {:g} is not positive", k1);
    return out;
  }
  for (int i = 1; i < N; ++i)
    if (std::abs(e.value[i]) > kAbsurdCoefficient) {
      out.problem = fmt::format("{} = {:.3g} lies beyond any accelerometer's range (|{}| <= {:g} in its unit)",
                                plant::coefficient_name(i), e.value[i], plant::coefficient_name(i), kAbsurdCoefficient);
      return out;
    }
  const double floor = std::pow(k1 * kFitFloor_g, 2);
  double chi2 = 0, worst = 0;
  std::size_t worst_i = 0;
  for (std::size_t i = 0; i < readings.size(); ++i) {
    const double r = readings[i].output - plant::output(e.value, positions.at(readings[i].position).nominal_g);
    const double var = std::max(i < variance.size() ? variance[i] : 0.0, floor);
    chi2 += r * r / var;
    if (std::abs(r) > out.max_abs_residual) out.max_abs_residual = std::abs(r);
    if (r * r / var > worst) worst = r * r / var, worst_i = i;
  }
  const int dof = std::max<int>(1, static_cast<int>(readings.size()) - free_parameters);
  out.chi2_per_dof = chi2 / dof;
  if (!(out.chi2_per_dof <= kMaxChi2PerDof))
    out.problem = fmt::format(
        "the estimate does not reproduce its readings: chi^2 per degree of freedom {:.3g} (at most {:g}); "
        "the worst is reading {} (position {}) off by {:.3g} sigma",
        out.chi2_per_dof, kMaxChi2PerDof, worst_i + 1, readings[worst_i].position + 1, std::sqrt(worst));
  return out;
}

Identifiability identifiability(const std::vector<Position>& positions, const FixedSet& fixed) {
  const Design d = design(positions, all_rows(positions.size()), fixed);
  return solve(d, Eigen::VectorXd(), Eigen::VectorXd::Ones(d.A.rows()), positions).id;
}

std::optional<PaperTable> paper_table(const std::vector<Position>& positions,
                                      const std::vector<Reading>& readings) {
  if (!is_paper_set(positions)) return std::nullopt;
  PaperTable sum{}, count{};
  for (const Reading& r : readings) {
    sum[r.position / 8][r.position % 8] += r.output;
    count[r.position / 8][r.position % 8] += 1;
  }
  for (int s = 0; s < 3; ++s)
    for (int j = 0; j < 8; ++j) {
      if (count[s][j] == 0) return std::nullopt;
      sum[s][j] /= count[s][j];
    }
  return sum;
}

namespace {

// U(s, j) with the paper's 1-based indices: U_sj.
struct OneBasedTable {
  const PaperTable& t;
  double operator()(int s, int j) const { return t[s - 1][j - 1]; }
};

Estimate paper_common(const OneBasedTable& U, double k1_tilde, double K, bool corrected, double kpp = 0,
                      double koo = 0) {
  constexpr double r2 = std::numbers::sqrt2;
  Estimate e;
  e.value[K1] = K;
  e.value[k1_asym] = k1_tilde;
  // At these 12 positions a_PA^2 + a_OA^2 sums to 6 for each of k_PP and k_OO.
  e.value[k0] = (U(1, 3) + U(2, 3) + U(1, 7) + U(2, 7) + U(3, 1) + U(3, 2) + U(3, 3) + U(3, 4) + U(3, 5) +
                 U(3, 6) + U(3, 7) + U(3, 8)) / (12 * K) - (kpp + koo) / 2;
  const double sum45 = U(1, 2) + U(1, 4) + U(1, 6) + U(1, 8);
  if (corrected) {
    // a_PA^2 = 1/2 at the four 45 deg positions of series 1 and 0 at j = 1, 5.
    e.value[k2] = (sum45 - (U(1, 1) + U(1, 5)) / 2) / K - 3 * e.value[k0] + (1 - 2 * r2) / 2 * k1_tilde - 2 * kpp;
    e.value[k4] = (U(1, 1) + U(1, 5) - sum45) / K + 2 * e.value[k0] + (r2 - 1) * k1_tilde + 2 * kpp;
    const double d1 = (U(1, 5) - U(1, 1)) / 2;
    const double d2 = ((U(1, 4) + U(1, 6)) - (U(1, 2) + U(1, 8))) / 4;
    e.value[k3] = 2 * (d1 - r2 * d2) / K;
    e.value[delta_OA] = (U(1, 7) - U(1, 3)) / (2 * K);
    e.value[delta_PA] = (U(2, 7) - U(2, 3)) / (2 * K);
  } else {
    // As printed: the sum for k2 runs over j = 2..8, k4 carries (2 sqrt2 - 1) k1', and k3
    // uses the slope K~1 that ignores k3.
    double sum_2_8 = 0;
    for (int j = 2; j <= 8; ++j) sum_2_8 += U(1, j);
    e.value[k2] = (sum_2_8 - (U(1, 1) + U(1, 5)) / 2) / K - 3 * e.value[k0] + (1 - 2 * r2) / 2 * k1_tilde;
    e.value[k4] = (U(1, 1) + U(1, 5) - sum45) / K + 2 * e.value[k0] + (2 * r2 - 1) * k1_tilde;
    e.value[k3] = r2 / K * (U(1, 6) - U(1, 2) - r2 / 2 * (U(1, 7) - U(1, 3))) - 2;
  }
  e.value[k_IP] = (U(1, 2) + U(1, 6) - (U(1, 4) + U(1, 8))) / (2 * K);
  e.value[k_IO] = (U(2, 2) + U(2, 6) - (U(2, 4) + U(2, 8))) / (2 * K);
  e.value[k_PO] = (U(3, 2) + U(3, 6) - (U(3, 4) + U(3, 8))) / (2 * K);
  for (int i = 0; i < N; ++i) e.available[i] = true;
  e.value[k_PP] = kpp;  // the paper's silent assumption is 0
  e.value[k_OO] = koo;
  e.assumed[k_PP] = e.assumed[k_OO] = e.assumed[k1_asym] = true;
  if (!corrected) e.available[delta_OA] = e.available[delta_PA] = false;  // not printed
  return e;
}

}  // namespace

Estimate paper_printed(const PaperTable& t, double k1_tilde) {
  const OneBasedTable U{t};
  constexpr double r2 = std::numbers::sqrt2;
  const double k1 = ((U(1, 5) - U(1, 1)) + r2 * (U(1, 4) + U(1, 6)) - r2 * (U(1, 2) + U(1, 8))) / 6;
  return paper_common(U, k1_tilde, k1, false);
}

Estimate paper_corrected(const PaperTable& t, double k1_tilde, double kpp, double koo) {
  const OneBasedTable U{t};
  constexpr double r2 = std::numbers::sqrt2;
  const double d1 = (U(1, 5) - U(1, 1)) / 2;
  const double d2 = ((U(1, 4) + U(1, 6)) - (U(1, 2) + U(1, 8))) / 4;
  return paper_common(U, k1_tilde, 2 * r2 * d2 - d1, true, kpp, koo);
}

}  // namespace vrelab::validation
