#include "rectification/prediction/random.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <complex>
#include <functional>
#include <numbers>
#include <stdexcept>
#include <string>
#include <vector>

namespace vrelab::rectification {

using plant::Coefficients;
using plant::Dynamics;
using plant::Location;
using plant::PlantConfig;
using plant::kNumCoefficients;
using enum plant::Coef;

namespace {

// 8-point Gauss-Legendre on [-1, 1].
constexpr std::array<double, 8> kGlX{-0.9602898564975363, -0.7966664774136267, -0.5255324099163290, -0.1834346424956498,
                                     0.1834346424956498,  0.5255324099163290,  0.7966664774136267,  0.9602898564975363};
constexpr std::array<double, 8> kGlW{0.1012285362903763, 0.2223810344533745, 0.3137066458778873, 0.3626837833783620,
                                     0.3626837833783620, 0.3137066458778873, 0.2223810344533745, 0.1012285362903763};

// Probabilists' Gauss-Hermite rule (weight exp(-x^2/2)/sqrt(2 pi)) by Golub-Welsch: the
// Jacobi matrix has off-diagonal sqrt(k); nodes its eigenvalues, weights the squared first
// components of the eigenvectors.
struct HermiteRule {
  std::vector<double> x, w;
};
const HermiteRule& hermite_rule() {
  static const HermiteRule rule = [] {
    constexpr int n = 24;
    Eigen::MatrixXd j = Eigen::MatrixXd::Zero(n, n);
    for (int k = 1; k < n; ++k) j(k, k - 1) = j(k - 1, k) = std::sqrt(static_cast<double>(k));
    const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> es(j);
    HermiteRule r;
    for (int k = 0; k < n; ++k) {
      r.x.push_back(es.eigenvalues()[k]);
      r.w.push_back(es.eigenvectors()(0, k) * es.eigenvectors()(0, k));
    }
    return r;
  }();
  return rule;
}

}  // namespace

vibration::RandomVibration gaussian_of(const Eigen::Matrix3d& c) {
  vibration::RandomVibration v;
  v.correlation = Eigen::Matrix3d::Identity();
  for (int i = 0; i < 3; ++i) v.rms_g[i] = std::sqrt(std::max(0.0, c(i, i)));
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j)
      if (i != j && v.rms_g[i] > 0 && v.rms_g[j] > 0)
        v.correlation(i, j) = std::clamp(c(i, j) / (v.rms_g[i] * v.rms_g[j]), -1.0, 1.0);
  return v;
}

namespace {

// The profile's tables as the quadrature reads them: a table of levels only (a lab's PSD file,
// a measured PSD of 10^6 rows) in place, a table with slope rows (a case file's, a few rows)
// resolved. Each frequency then costs a bisection in a table, not a pass over it: the
// diagnosis evaluates a random run's PSD thousands of times.
struct PreparedTables {
  std::array<const vibration::PsdTable*, 3> levels{};
  std::array<std::optional<vibration::ResolvedPsd>, 3> resolved;
};

// Up to this many rows a table of levels is checked whole at every call (one pass, no copy);
// a longer one (read and validated whole by its reader: io::read_psd_file) at its ends here and
// at each bracket the bisection lands on (level_at), so that a call costs O(log rows).
constexpr std::size_t kWholeCheckRows = 65536;

bool valid_level_row(const vibration::PsdRow& r) {
  return r.psd_g2_per_Hz && !r.slope_dB_per_octave && std::isfinite(r.frequency_Hz) && r.frequency_Hz > 0 &&
         std::isfinite(*r.psd_g2_per_Hz) && *r.psd_g2_per_Hz > 0;
}

// True when `t` is a table of levels that vibration::validate accepts (a long one: at its ends).
bool valid_levels(const vibration::PsdTable& t) {
  const auto& rows = t.rows;
  if (rows.size() < 2) return false;
  if (rows.size() > kWholeCheckRows)
    return valid_level_row(rows.front()) && valid_level_row(rows.back()) && rows.front().frequency_Hz < rows.back().frequency_Hz;
  double previous = 0;
  for (const vibration::PsdRow& r : rows) {
    if (!valid_level_row(r) || !(r.frequency_Hz > previous)) return false;
    previous = r.frequency_Hz;
  }
  return true;
}

// Validates the profile (vibration::validate's checks and messages) and prepares its tables.
PreparedTables prepared_tables(const vibration::RandomProfile& p) {
  PreparedTables r;
  bool any = false, valid = true;
  for (std::size_t i = 0; i < 3; ++i) {
    if (!p.psd[i]) continue;
    any = true;
    if (valid_levels(*p.psd[i])) {
      r.levels[i] = &*p.psd[i];
      continue;
    }
    try {
      r.resolved[i] = vibration::resolve(*p.psd[i]);
    } catch (const std::invalid_argument&) {
      valid = false;
    }
  }
  if (!any || !valid || p.measured) vibration::validate(p);  // throws its message (or checks the measured matrix)
  return r;
}

// The table's PSD at f, g^2/Hz: vibration::psd_g2_per_Hz's interpolation, on the rows in place.
// A bracket that is not two level rows in increasing frequency (a long table's flaw the ends
// did not show) is the table's validation error.
double level_at(const vibration::PsdTable& t, double f) {
  const auto& rows = t.rows;
  if (!(f >= rows.front().frequency_Hz && f <= rows.back().frequency_Hz)) return 0.0;
  const auto above = std::upper_bound(rows.begin(), rows.end(), f,
                                      [](double x, const vibration::PsdRow& row) { return x < row.frequency_Hz; });
  const std::size_t k = std::min(static_cast<std::size_t>(above - rows.begin()), rows.size() - 1) - 1;
  if (!valid_level_row(rows[k]) || !valid_level_row(rows[k + 1]) || !(rows[k].frequency_Hz < rows[k + 1].frequency_Hz) ||
      !(rows[k].frequency_Hz <= f && f <= rows[k + 1].frequency_Hz)) {
    vibration::validate(t);  // throws, naming the row
    throw std::invalid_argument("PSD table: rows " + std::to_string(k + 1) + " and " + std::to_string(k + 2) + " are not in order");
  }
  const double f0 = rows[k].frequency_Hz, p0 = *rows[k].psd_g2_per_Hz, p1 = *rows[k + 1].psd_g2_per_Hz;
  const double b = std::log(p1 / p0) / std::log(rows[k + 1].frequency_Hz / f0);
  return p0 * std::pow(f / f0, b);
}

// The lowest and highest frequency of the tables, and every breakpoint when `all` (else only those two).
std::vector<double> table_frequencies(const PreparedTables& r, bool all) {
  std::vector<double> knots;
  for (std::size_t i = 0; i < 3; ++i) {
    if (r.levels[i]) {
      const auto& rows = r.levels[i]->rows;
      if (all)
        for (const auto& row : rows) knots.push_back(row.frequency_Hz);
      else
        knots.insert(knots.end(), {rows.front().frequency_Hz, rows.back().frequency_Hz});
    } else if (r.resolved[i]) {
      const auto& fs = r.resolved[i]->frequency_Hz;
      if (all) knots.insert(knots.end(), fs.begin(), fs.end());
      else knots.insert(knots.end(), {fs.front(), fs.back()});
    }
  }
  return knots;
}

Eigen::Matrix3cd cross_spectral_matrix(const vibration::RandomProfile& p, const PreparedTables& r, double f) {
  if (p.measured) return p.measured->at(f);
  Eigen::Matrix3cd s = Eigen::Matrix3cd::Zero();
  std::array<double, 3> g{};
  for (std::size_t i = 0; i < 3; ++i)
    if (r.levels[i]) g[i] = level_at(*r.levels[i], f);
    else if (r.resolved[i]) g[i] = vibration::psd_g2_per_Hz(*r.resolved[i], f);
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j)
      if (i == j) s(i, i) = g[static_cast<std::size_t>(i)];
      else if (p.coupling == vibration::AxisCoupling::common)
        s(i, j) = std::sqrt(g[static_cast<std::size_t>(i)] * g[static_cast<std::size_t>(j)]);
  return s;
}

}  // namespace

Eigen::Matrix3cd cross_spectral_matrix_g2_per_Hz(const vibration::RandomProfile& p, double f) {
  return cross_spectral_matrix(p, p.measured ? PreparedTables{} : prepared_tables(p), f);
}

std::vector<Eigen::Matrix3cd> cross_spectral_matrices_g2_per_Hz(const vibration::RandomProfile& p, const std::vector<double>& f) {
  const PreparedTables tables = p.measured ? PreparedTables{} : prepared_tables(p);
  std::vector<Eigen::Matrix3cd> out;
  out.reserve(f.size());
  for (const double x : f) out.push_back(cross_spectral_matrix(p, tables, x));
  return out;
}

Eigen::Matrix3d cross_spectrum_g2_per_Hz(const vibration::RandomProfile& p, double f) {
  return cross_spectral_matrix_g2_per_Hz(p, f).real();
}

namespace {
// rho - 1, rho = Theta(zeta0) / Theta(2 zeta0) on the axis the angle answers most (the same
// ratio on every axis: damped_response); 0 where the angle does not answer.
std::complex<double> rho_minus_one(const LoopResponse& at_zeta0, const LoopResponse& at_twice) {
  std::size_t j = 0;
  for (std::size_t i = 1; i < 3; ++i)
    if (std::abs(at_zeta0.angle_rad[i]) > std::abs(at_zeta0.angle_rad[j])) j = i;
  return at_twice.angle_rad[j] != 0.0 ? at_zeta0.angle_rad[j] / at_twice.angle_rad[j] - 1.0 : 0.0;
}
}  // namespace

RandomGrid random_grid(const vibration::RandomProfile& p, const RandomQuadrature& q) {
  const PreparedTables tables = prepared_tables(p);
  if (!(q.max_log_step > 0)) throw std::invalid_argument("random_response: max_log_step must be positive");
  // Every table's breakpoints: the PSD is a power law between them (smooth in ln f), and
  // it jumps to 0 outside a table's band. (The common grid needs only the band's ends.)
  std::vector<double> knots = table_frequencies(tables, !q.common_grid || p.measured);
  // A measured matrix: its bins' edges (each bin a step; the tables' rows 0.1 % of a bin
  // inside them are left out, so that no piece straddles a step). Not on the common grid: a
  // piece of it would sample several steps at a few points.
  if (p.measured) {
    knots.clear();
    const vibration::CrossSpectralMatrix& m = *p.measured;
    for (std::size_t k = 0; k <= m.frequency_Hz.size(); ++k)
      knots.push_back(m.from_Hz() + static_cast<double>(k) * m.resolution_Hz);
    if (knots.front() <= 0) knots.front() = 1e-3 * m.resolution_Hz;
  }
  std::sort(knots.begin(), knots.end());
  knots.erase(std::unique(knots.begin(), knots.end()), knots.end());
  RandomGrid grid;
  grid.from_Hz = knots.front(), grid.to_Hz = knots.back();
  if (q.common_grid && !p.measured) {  // the global grid exp(k h), cut at the band's ends only
    const double h = q.max_log_step, l0 = std::log(grid.from_Hz), l1 = std::log(grid.to_Hz);
    knots = {grid.from_Hz};
    for (double k = std::floor(l0 / h) + 1; k * h < l1; ++k) knots.push_back(std::exp(k * h));
    knots.push_back(grid.to_Hz);
  }
  for (std::size_t k = 0; k + 1 < knots.size(); ++k) {
    const double l0 = std::log(knots[k]), l1 = std::log(knots[k + 1]);
    const int pieces = std::max(1, static_cast<int>(std::ceil((l1 - l0) / q.max_log_step - 1e-9)));
    const double h = (l1 - l0) / pieces;
    // A measured matrix is constant over each piece (a bin or part of one): only the loop's
    // responses vary there, smoothly over a bin (<= 0.1 in ln f) for the loop alone, so 2-point
    // Gauss-Legendre (exact for cubics in ln f) does with a quarter of the responses (and of the
    // response cache's memory). A kept lightly damped mode is not smooth over a bin: at a mode
    // of 503 Hz on 7.8 Hz bins its resonance's integral errs by 0.7 % at damping 0.01 and 5 %
    // at 0.005 (the 8-point path on 0.1-wide pieces: 1.9 % and 6.5 %).
    static constexpr std::array<double, 2> kGl2X{-0.5773502691896258, 0.5773502691896258}, kGl2W{1.0, 1.0};
    const bool two = static_cast<bool>(p.measured);
    const std::size_t points = two ? kGl2X.size() : kGlX.size();
    for (int m = 0; m < pieces; ++m) {
      const double mid = l0 + (m + 0.5) * h;
      for (std::size_t n = 0; n < points; ++n) {
        const double f = std::exp(mid + 0.5 * h * (two ? kGl2X[n] : kGlX[n]));
        const double weight = 0.5 * h * (two ? kGl2W[n] : kGlW[n]) * f;  // df = f d(ln f)
        grid.frequency_Hz.push_back(f);
        grid.weight_Hz.push_back(weight);
        grid.csd_g2_per_Hz.push_back(cross_spectral_matrix(p, tables, f));
      }
    }
  }
  return grid;
}

RandomGrid turned_grid(const RandomGrid& grid, const Eigen::Matrix3d& turn) {
  if (!turn.allFinite()) throw std::invalid_argument("random_response: turn must be finite");
  const bool turned = !turn.isIdentity(0.0);
  RandomGrid out;
  out.from_Hz = grid.from_Hz, out.to_Hz = grid.to_Hz;
  for (std::size_t k = 0; k < grid.frequency_Hz.size(); ++k) {
    Eigen::Matrix3cd s = grid.csd_g2_per_Hz[k];
    if (turned) s = turn * s * turn.transpose();
    if (s.isZero(0.0)) continue;
    out.frequency_Hz.push_back(grid.frequency_Hz[k]);
    out.weight_Hz.push_back(grid.weight_Hz[k]);
    out.csd_g2_per_Hz.push_back(s);
  }
  return out;
}

namespace {
// The responses' transfer to each input axis at one point (rows: F_IA, F_PA, F_OA, I, Theta).
using ResponseRows = Eigen::Matrix<std::complex<double>, 5, 3>;
ResponseRows response_rows(const LoopResponse& r) {
  ResponseRows hm = ResponseRows::Zero();
  for (int j = 0; j < 3; ++j) {
    const auto sj = static_cast<std::size_t>(j);
    hm(j, j) = r.mechanical[sj];
    hm(RandomResponse::kCurrent, j) = r.current[sj];
    hm(RandomResponse::kAngle, j) = r.angle_rad[sj];
  }
  return hm;
}
// C_yz = integral Re(sum_ij H_yi S_ij conj(H_zj)) df: the response y's spectrum row H_y X, its
// cross-spectrum with z is H_y S H_z^H; a real signal's covariance is the real part of the
// one-sided cross-spectrum's integral.
//
// H's felt rows are diagonal (F_i = T_i x_i), so of H S H^H's terms only those with a nonzero
// factor are summed: T = H S is T_i. = T_i S_i. on the felt rows, and (H S H^H)_ab =
// sum_k T_ak conj(H_bk) has one term for a felt b. The terms left out are exact zeros.
void add_point(RandomResponse& out, double weight, const LoopResponse& r, const Eigen::Matrix3cd& s) {
  ++out.frequencies;
  // In real arithmetic, as the complex products compute them (x y: Re = xr yr - xi yi, Im =
  // xr yi + xi yr; Re(x conj(y)) = xr yr + xi yi), without their NaN checks or the imaginary
  // parts only the real part is taken of: the same numbers.
  double hr[5][3] = {}, hi[5][3] = {}, tr[5][3], ti[5][3];  // H and H S, rows F_IA, F_PA, F_OA, I, Theta
  for (std::size_t j = 0; j < 3; ++j) {
    hr[j][j] = r.mechanical[j].real(), hi[j][j] = r.mechanical[j].imag();
    hr[RandomResponse::kCurrent][j] = r.current[j].real(), hi[RandomResponse::kCurrent][j] = r.current[j].imag();
    hr[RandomResponse::kAngle][j] = r.angle_rad[j].real(), hi[RandomResponse::kAngle][j] = r.angle_rad[j].imag();
  }
  double sr[3][3], si[3][3];
  for (Eigen::Index a = 0; a < 3; ++a)
    for (Eigen::Index b = 0; b < 3; ++b) sr[a][b] = s(a, b).real(), si[a][b] = s(a, b).imag();
  for (std::size_t b = 0; b < 3; ++b) {
    for (std::size_t a = 0; a < 3; ++a)
      tr[a][b] = hr[a][a] * sr[a][b] - hi[a][a] * si[a][b], ti[a][b] = hr[a][a] * si[a][b] + hi[a][a] * sr[a][b];
    for (std::size_t a = 3; a < 5; ++a) {
      const double r0 = hr[a][0] * sr[0][b] - hi[a][0] * si[0][b], i0 = hr[a][0] * si[0][b] + hi[a][0] * sr[0][b];
      const double r1 = hr[a][1] * sr[1][b] - hi[a][1] * si[1][b], i1 = hr[a][1] * si[1][b] + hi[a][1] * sr[1][b];
      const double r2 = hr[a][2] * sr[2][b] - hi[a][2] * si[2][b], i2 = hr[a][2] * si[2][b] + hi[a][2] * sr[2][b];
      tr[a][b] = r0 + (r1 + r2), ti[a][b] = i0 + (i1 + i2);
    }
  }
  for (std::size_t a = 0; a < 5; ++a)
    for (std::size_t b = 0; b < 5; ++b) {
      const double re = b < 3 ? tr[a][b] * hr[b][b] + ti[a][b] * hi[b][b]
                              : (tr[a][0] * hr[b][0] + ti[a][0] * hi[b][0]) +
                                    ((tr[a][1] * hr[b][1] + ti[a][1] * hi[b][1]) + (tr[a][2] * hr[b][2] + ti[a][2] * hi[b][2]));
      out.covariance(static_cast<Eigen::Index>(a), static_cast<Eigen::Index>(b)) += weight * re;
    }
  out.input_covariance_g2 += weight * s.real();
  out.dc_gain = r.dc_gain;
}
}  // namespace

RandomResponse random_response(const vibration::RandomProfile& p, const ResponseAt& response, const RandomQuadrature& q,
                               const Eigen::Matrix3d& turn) {
  const RandomGrid grid = turned_grid(random_grid(p, q), turn);
  RandomResponse out;
  for (std::size_t k = 0; k < grid.frequency_Hz.size(); ++k)
    add_point(out, grid.weight_Hz[k], response(grid.frequency_Hz[k]), grid.csd_g2_per_Hz[k]);
  out.from_Hz = grid.from_Hz, out.to_Hz = grid.to_Hz;
  return out;
}

RandomResponse with_pickoff_moments(RandomResponse rr, const PlantConfig& plant, const vibration::RandomProfile& p,
                                    const ResponseAt& response, const Eigen::Matrix3d& turn) {
  if (pickoff_p2_per_rad(plant) != 0) rr.pickoff = gaussian_pickoff_moments(plant, p, response, turn);
  return rr;
}

RandomResponse random_response(const RandomGrid& grid, const std::vector<const LoopResponse*>& responses) {
  if (responses.size() != grid.frequency_Hz.size())
    throw std::invalid_argument("random_response: one loop response per grid point is needed");
  RandomResponse out;
  for (std::size_t k = 0; k < grid.frequency_Hz.size(); ++k) add_point(out, grid.weight_Hz[k], *responses[k], grid.csd_g2_per_Hz[k]);
  out.from_Hz = grid.from_Hz, out.to_Hz = grid.to_Hz;
  return out;
}

DampedRandomSpectrum damped_random_spectrum(const vibration::RandomProfile& p, const ResponseAt& at_zeta0, const ResponseAt& at_twice,
                                            const RandomQuadrature& q, const Eigen::Matrix3d& turn) {
  const RandomGrid grid = turned_grid(random_grid(p, q), turn);
  DampedRandomSpectrum out;
  RandomResponse& r = out.at_zeta0;
  for (std::size_t k = 0; k < grid.frequency_Hz.size(); ++k) {
    const double f = grid.frequency_Hz[k], weight = grid.weight_Hz[k];
    const Eigen::Matrix3cd& s = grid.csd_g2_per_Hz[k];
    const LoopResponse h = at_zeta0(f);
    add_point(r, weight, h, s);
    const ResponseRows hm = response_rows(h);
    out.frequency_Hz.push_back(f);
    out.loop_rows.push_back(weight * (hm.bottomRows<2>() * s * hm.adjoint()));
    out.rho_minus_1.push_back(rho_minus_one(h, at_twice(f)));
  }
  r.from_Hz = grid.from_Hz, r.to_Hz = grid.to_Hz;
  return out;
}

RandomResponse random_response_at_damping(const DampedRandomSpectrum& s, double x) {
  RandomResponse out = s.at_zeta0;
  auto& c = out.covariance;
  c.bottomRows<2>().setZero();
  c.rightCols<2>().setZero();
  // The current's and the angle's rows scale by 1 / (1 + x (rho - 1)) (damped_response): their
  // entries with the base's motion once, with each other twice (its modulus squared).
  for (std::size_t k = 0; k < s.frequency_Hz.size(); ++k) {
    const std::complex<double> sc = 1.0 / (1.0 + x * s.rho_minus_1[k]);
    const auto& rows = s.loop_rows[k];
    for (int a = 0; a < 2; ++a) {
      for (int j = 0; j < 3; ++j) c(3 + a, j) += (sc * rows(a, j)).real();
      for (int b = 0; b < 2; ++b) c(3 + a, 3 + b) += std::norm(sc) * rows(a, 3 + b).real();
    }
  }
  for (int a = 3; a < 5; ++a)
    for (int j = 0; j < 3; ++j) c(j, a) = c(a, j);
  return out;
}

RandomResponse random_response(const PlantConfig& plant, const vibration::RandomProfile& p, const RandomQuadrature& q) {
  return random_response(p, [&plant](double f) { return loop_response(plant, f); }, q);
}

LoopResponse damped_response(const LoopResponse& at_zeta0, const LoopResponse& at_twice, double x) {
  const std::complex<double> scale = 1.0 / (1.0 + x * rho_minus_one(at_zeta0, at_twice));
  LoopResponse out = at_zeta0;
  for (std::size_t i = 0; i < 3; ++i) out.angle_rad[i] *= scale, out.current[i] *= scale;
  return out;
}

double random_linearised_damping(const PlantConfig& config, const DampedRandomSpectrum& spectrum,
                                 const std::optional<vibration::SineVibration>& sine, const ResponseAt& at_zeta0,
                                 const ResponseAt& at_twice) {
  std::vector<const plant::Effect*> films;
  for (const auto& e : config.effects)
    if (e->amplitude_dependent_damping()) films.push_back(e.get());
  const Dynamics& d0 = config.dynamics;
  const double zeta0 = d0.pendulum_damping_ratio;
  if (films.empty()) return zeta0;
  const double two_wp = 2 * 2 * std::numbers::pi * d0.pendulum_frequency_Hz;
  // The angle's spectrum at zeta0, point by point: at x = zeta / zeta0 - 1 a point's variance
  // is its share at zeta0 over |1 + x (rho - 1)|^2 (damped_response), its rate's (2 pi f)^2
  // times that.
  const std::vector<double>& freq = spectrum.frequency_Hz;
  const std::vector<std::complex<double>>& rho_minus_1 = spectrum.rho_minus_1;
  std::vector<double> angle_var;
  for (const auto& rows : spectrum.loop_rows) angle_var.push_back(rows(1, 4).real());
  std::complex<double> sine_theta0 = 0, sine_rho_minus_1 = 0;
  if (sine) {
    const LoopResponse r0 = at_zeta0(sine->frequency_Hz);
    for (std::size_t i = 0; i < 3; ++i) sine_theta0 += r0.angle_rad[i] * std::polar(sine->amplitude_g[i], sine->phase_rad[i]);
    sine_rho_minus_1 = rho_minus_one(r0, at_twice(sine->frequency_Hz));
  }
  const auto extra_at = [&](double zeta) {  // the films' damping ratio beyond zeta0 at the angle of damping zeta
    const double x = (zeta - zeta0) / zeta0;
    double var = 0, rate_var = 0;
    for (std::size_t k = 0; k < freq.size(); ++k) {
      const double v = angle_var[k] / std::norm(1.0 + x * rho_minus_1[k]), w = 2 * std::numbers::pi * freq[k];
      var += v, rate_var += w * w * v;
    }
    const double theta = sine ? std::abs(sine_theta0 / (1.0 + x * sine_rho_minus_1)) : 0.0;
    const double rate = sine ? 2 * std::numbers::pi * sine->frequency_Hz * theta : 0.0;
    double extra = 0;
    for (const auto* f : films)
      extra += f->extra_damping_on_random_per_s(theta, rate, std::sqrt(std::max(0.0, var)), std::sqrt(std::max(0.0, rate_var)),
                                                d0.angle_gain_rad_per_s2_per_g);
    return extra / two_wp;
  };
  // g(zeta) = zeta0 + extra(zeta) - zeta falls with zeta (more damping, less angle, less
  // film); g(zeta0) >= 0, and the film's law is held at 0.95 theta_gap, so the extra is
  // bounded and g < 0 far enough out: bracket by doubling, then regula falsi.
  double lo = zeta0, g_lo = extra_at(zeta0);
  if (!(g_lo > 0)) return zeta0;
  double hi = zeta0 + 2 * g_lo, g_hi = zeta0 + extra_at(hi) - hi;
  for (int k = 0; g_hi > 0; ++k) {
    if (k == 60 || !std::isfinite(g_hi))
      throw std::runtime_error("random_linearised_damping: the squeeze film's equivalent damping has no bracket");
    lo = hi, g_lo = g_hi, hi = zeta0 + 2 * (hi - zeta0), g_hi = zeta0 + extra_at(hi) - hi;
  }
  int side = 0;
  for (int it = 0; it < 200; ++it) {
    const double z = (lo * g_hi - hi * g_lo) / (g_hi - g_lo);
    const double gz = zeta0 + extra_at(z) - z;
    if (std::abs(gz) < 1e-10 * z || hi - lo < 1e-10 * z) return z;
    if (gz > 0) {
      lo = z, g_lo = gz;
      if (side == 1) g_hi *= 0.5;  // Illinois: the end that stays is halved
      side = 1;
    } else {
      hi = z, g_hi = gz;
      if (side == -1) g_lo *= 0.5;
      side = -1;
    }
  }
  throw std::runtime_error("random_linearised_damping: the squeeze film's equivalent damping did not converge");
}

namespace {

using R = RandomResponse;
using Locations = std::array<Location, kNumCoefficients>;

// What the terms of (1) see of the random part: the felt motion's covariance, and the same
// with IA the current (the loop-placed terms).
struct GaussianParts {
  vibration::RandomVibration felt, through_loop;
};
GaussianParts gaussian_parts(const RandomResponse& rr) {
  const auto& c5 = rr.covariance;
  const Eigen::Matrix3d felt_cov = c5.topLeftCorner<3, 3>();
  Eigen::Matrix3d loop_cov = felt_cov;
  loop_cov(IA, IA) = c5(R::kCurrent, R::kCurrent);
  for (int j : {PA, OA}) loop_cov(IA, j) = loop_cov(j, IA) = c5(R::kCurrent, j);
  return {gaussian_of(felt_cov), gaussian_of(loop_cov)};
}

// The output's oscillation U = I + slope . F: the slope of the output-placed cross terms.
Vec3 readout_slope(const Coefficients& coefficients, const Locations& location, const Vec3& a) {
  Coefficients cross_out;
  cross_out[K1] = 1;
  for (int c = delta_OA; c < kNumCoefficients; ++c)
    if (location[c] == Location::output) cross_out[c] = coefficients[c];
  return plant::output_gradient(cross_out, a) - Vec3::UnitX();
}
double readout_sigma(const RandomResponse& rr, const Vec3& slope) {
  Eigen::Matrix<double, 5, 1> u_row = Eigen::Matrix<double, 5, 1>::Zero();
  u_row[R::kCurrent] = 1;
  for (int i = 0; i < 3; ++i) u_row[i] = slope[i];
  return std::sqrt(std::max(0.0, u_row.dot(rr.covariance * u_row)));
}

// Each coefficient of (1) that rectifies (not k0 or the misalignments; not zero) alone beside
// K1 = 1, and whether it sees the loop's current on IA (in the loop or at the output: k2..k4
// not at the input).
template <class Visit>
void for_each_rectifying_term(const Coefficients& coefficients, const Locations& location, Visit&& visit) {
  for (int c = k0; c < kNumCoefficients; ++c) {
    if (c == k0 || c == delta_OA || c == delta_PA || coefficients[c] == 0) continue;
    Coefficients only;
    only[K1] = 1;
    only[c] = coefficients[c];
    visit(c, only, c <= k4 && location[c] != Location::input);
  }
}

// A periodic part with harmonics, a mean or tones inside the loop, on random. With s(t) the
// periodic part at a term's place and G the random part's, independent of it, each term is
//   <E_G f(a + s(t) + G)> - f(a) = <[E_G f(a + s + G) - f(a + s)] + [f(a + s) - f(a)]>,
// the Gaussian expectation (eq3.hpp random_rectification) at the point s(t) moves the static
// orientation to plus the term there, averaged over the period on periodic_rectification's
// points: the sum is smooth in s (the Gaussian smooths k1's |a_IA|), so the average converges
// spectrally, and is exact for the polynomial terms. The rest (the input's mean, the angle's
// moments of the periodic part) as periodic_rectification has it; the random part's angle
// moments add; a readout polynomial is averaged jointly (the period's points, Gauss-Hermite
// in U).
}  // namespace

// (What does not depend on the coefficients prepared once: the periodic part's rectification
// and its points, the random part's Gaussian description.)
class PreparedRandomRectification::PeriodicOnRandom {
 public:
  PeriodicOnRandom(const PlantConfig& config, const Vec3& a, const RandomResponse& rr, const PeriodicInput& in,
                   const ResponseAt& response)
      : periodic_(config, a, in, response, true, false),  // (no second order on random)
        location_(config.location),
        effects_(config.effects),
        dynamics_(config.dynamics),
        a_(a),
        rr_(rr),
        mean_g_(in.mean_g),
        g_(gaussian_parts(rr)),
        b0_(plant::basis(a)) {
    for (const auto& e : effects_) {
      p2_ += e->pickoff_p2_per_rad();
      geometry_ = geometry_ || e->vibropendulous();
      readout_ = readout_ || e->readout_averaged_in_prediction();
    }
    struct Tone {
      int h;
      Eigen::Vector3cd F;
      std::complex<double> I;
    };
    std::vector<Tone> tones;
    int h_max = 1;
    for (const auto& [h, W] : in.tones) {
      const LoopResponse r = response(h * in.frequency_Hz);
      Tone t{h, Eigen::Vector3cd::Zero(), 0.0};
      for (int j = 0; j < 3; ++j) {
        const auto sj = static_cast<std::size_t>(j);
        t.F[j] = r.mechanical[sj] * W[j];
        t.I += r.current[sj] * W[j];
      }
      tones.push_back(t);
      h_max = std::max(h_max, h);
    }
    for (const PeriodicInput::LoopTone& l : in.loop) tones.push_back({l.h, Eigen::Vector3cd::Zero(), l.current_g}), h_max = std::max(h_max, l.h);
    points_ = std::max(64, 6 * h_max + 1);
    a_mean_ = a + in.mean_g;
    felt_at_.resize(static_cast<std::size_t>(points_)), loop_at_.resize(felt_at_.size()), current_at_.resize(felt_at_.size());
    for (int k = 0; k < points_; ++k) {
      const double phi = 2 * std::numbers::pi * k / points_;
      Vec3 felt = a_mean_;
      double current = 0;
      for (const Tone& t : tones) {
        const std::complex<double> e = std::polar(1.0, t.h * phi);
        for (int i = 0; i < 3; ++i) felt[i] += std::imag(t.F[i] * e);
        current += std::imag(t.I * e);
      }
      const auto sk = static_cast<std::size_t>(k);
      felt_at_[sk] = loop_at_[sk] = felt;
      loop_at_[sk][IA] = a_mean_[IA] + current;
      current_at_[sk] = current;
    }
  }

  FrequencyPrediction operator()(const Coefficients& coefficients) const {
    FrequencyPrediction out = periodic_(coefficients);
    out.terms = {};
    const double p2 = p2_;
    const bool geometry = geometry_, readout = readout_;
    out.second_order_left_out = p2 != 0;
    const int points = points_;
    const double dc_gain = out.loop_dc_gain;
    for_each_rectifying_term(coefficients, location_, [&](int c, const Coefficients& only, bool filtered) {
      const double gain = location_[c] == Location::output ? 1.0 : dc_gain;
      const int term = term_of_coefficient(c);
      for (std::size_t k = 0; k < felt_at_.size(); ++k) {
        const Vec3& x = filtered ? loop_at_[k] : felt_at_[k];
        Eq3Terms t = random_rectification(only, x, filtered ? g_.through_loop : g_.felt);
        t.g[term] += coefficients[c] * (plant::basis(x)[c] - b0_[c]);
        for (int j = 0; j < kNumTerms; ++j) out.terms.g[j] += gain * t.g[j] / points;
      }
    });
    const auto& c5 = rr_.covariance;
    const Dynamics& d = dynamics_;
    const double wp = 2 * std::numbers::pi * d.pendulum_frequency_Hz;
    out.pickoff_g += wp * wp / d.angle_gain_rad_per_s2_per_g * p2 * c5(R::kAngle, R::kAngle);
    if (geometry) out.pendulum_geometry_g += dc_gain * (-c5(R::kF_PA, R::kAngle) - a_mean_[IA] * c5(R::kAngle, R::kAngle) / 2);
    if (readout) {  // as PreparedPeriodicRectification's, with U's Gaussian part at every point
      const Vec3 slope = readout_slope(coefficients, location_, a_);
      const double sigma_u = readout_sigma(rr_, slope);
      const double u0 = plant::output_g(coefficients, a_);
      const double u_mean = u0 + mean_g_[IA] + slope.dot(mean_g_);
      const HermiteRule& gh = hermite_rule();
      out.readout_g = 0;
      for (std::size_t k = 0; k < felt_at_.size(); ++k) {
        const double u = u_mean + current_at_[k] + slope.dot(felt_at_[k] - a_mean_);
        for (const auto& e : effects_) {
          if (!e->readout_averaged_in_prediction()) continue;
          for (std::size_t n = 0; n < gh.x.size(); ++n) {
            const double un = u + sigma_u * gh.x[n];
            out.readout_g += gh.w[n] * (e->readout(un) - un) / points;
          }
        }
      }
      for (const auto& e : effects_)
        if (e->readout_averaged_in_prediction()) out.readout_g -= e->readout(u0) - u0;
    }
    return out;
  }

 private:
  PreparedPeriodicRectification periodic_;
  Locations location_;
  std::vector<std::shared_ptr<const plant::Effect>> effects_;
  Dynamics dynamics_;
  Vec3 a_;
  RandomResponse rr_;
  Vec3 mean_g_;
  GaussianParts g_;
  plant::Basis b0_;
  Vec3 a_mean_;
  double p2_ = 0.0;  // the effects' pickoff p2 (1/rad), summed
  bool geometry_ = false, readout_ = false;
  int points_ = 0;
  std::vector<Vec3> felt_at_, loop_at_;
  std::vector<double> current_at_;
};

PreparedRandomRectification::PreparedRandomRectification(const PlantConfig& config, const Vec3& a, const RandomResponse& rr,
                                                         const std::optional<PeriodicInput>& periodic, const ResponseAt& response,
                                                         std::optional<double> range_g)
    : config_(config), a_(a), rr_(rr) {
  if (periodic && !response) throw std::invalid_argument("random_rectification_at_frequency: a periodic part needs the loop's response");
  if (periodic && !(periodic->frequency_Hz > 0))
    throw std::invalid_argument("random_rectification_at_frequency: the periodic part's frequency_Hz must be positive");
  if (periodic && !periodic->single_tone()) {  // several tones: prepared once (PeriodicOnRandom)
    periodic_ = std::make_shared<const PeriodicOnRandom>(config, a, rr, *periodic, response);
    return;
  }
  // Random alone, or a single tone on it (the sine's terms in closed form, eq3.hpp).
  std::optional<vibration::SineVibration> sine;
  std::optional<LoopResponse> sine_response;
  if (periodic) {
    vibration::SineVibration v;
    v.frequency_Hz = periodic->frequency_Hz;
    const Eigen::Vector3cd& w = periodic->tones.front().second;
    for (int i = 0; i < 3; ++i) v.amplitude_g[i] = std::abs(w[i]), v.phase_rad[i] = std::arg(w[i]);
    sine = v, sine_response = response(v.frequency_Hz);
  }
  double p2 = 0.0;
  bool geometry = false;
  for (const auto& e : config.effects) {
    p2 += e->pickoff_p2_per_rad();
    geometry = geometry || e->vibropendulous();
    readout_ = readout_ || e->readout_averaged_in_prediction();
  }
  const auto& c5 = rr.covariance;
  const GaussianParts parts = gaussian_parts(rr);
  felt_ = parts.felt, through_loop_ = parts.through_loop;

  // The sine, as in sine_rectification_at_frequency.
  Eigen::Vector3cd Fs = Eigen::Vector3cd::Zero();
  std::complex<double> Is = 0.0, Ths = 0.0;
  if (sine) {
    const LoopResponse& h = *sine_response;
    sine_felt_ = *sine;
    for (int i = 0; i < 3; ++i) {
      const auto si = static_cast<std::size_t>(i);
      const std::complex<double> W = std::polar(sine->amplitude_g[i], sine->phase_rad[i]);
      Fs[i] = h.mechanical[si] * W;
      Is += h.current[si] * W;
      Ths += h.angle_rad[si] * W;
      sine_felt_.amplitude_g[i] = std::abs(Fs[i]);
      sine_felt_.phase_rad[i] = std::arg(Fs[i]);
    }
    sine_loop_ = sine_felt_;
    sine_loop_.amplitude_g[IA] = std::abs(Is);
    sine_loop_.phase_rad[IA] = std::arg(Is);
    // The sine's phase points once for every term and call (the same numbers as each term's own).
    points_felt_ = sine_phase_points(a, sine_felt_), points_loop_ = sine_phase_points(a, sine_loop_);
  }
  Fs_ = Fs, Is_ = Is;
  dc_gain_ = sine ? sine_response->dc_gain : rr.dc_gain;
  fixed_.loop_dc_gain = dc_gain_;
  fixed_.current_amplitude_g = Is;
  fixed_.angle_amplitude_rad = Ths;
  if (range_g) {
    Coefficients unit;
    unit[K1] = 1;
    const Eq3Terms t = sine ? sine_on_random_rectification(unit, a, sine_loop_, *points_loop_, through_loop_, range_g)
                            : random_rectification(unit, a, through_loop_, range_g);
    clipping_g_ = t.g[t_clipping];
  }
  // Effects beyond (1): second moments of the angle (the sine's and the random's add).
  const Dynamics& d = config.dynamics;
  const double wp = 2 * std::numbers::pi * d.pendulum_frequency_Hz;
  const double theta2 = c5(R::kAngle, R::kAngle) + std::norm(Ths) / 2;
  const double pa_theta = c5(R::kF_PA, R::kAngle) + std::real(Fs[PA] * std::conj(Ths)) / 2;
  fixed_.pickoff_g = wp * wp / d.angle_gain_rad_per_s2_per_g * p2 * theta2;
  if (geometry) fixed_.pendulum_geometry_g = dc_gain_ * (-pa_theta - a[IA] * theta2 / 2);
  if (p2 != 0) {
    if (!sine && rr.pickoff)
      second_order_ = gaussian_second_order(*rr.pickoff, config.dynamics, p2, c5(R::kCurrent, R::kCurrent), c5(R::kAngle, R::kAngle), a[IA]);
    else
      fixed_.second_order_left_out = true;
  }
}

FrequencyPrediction PreparedRandomRectification::operator()(const Coefficients& coefficients) const {
  if (periodic_) return (*periodic_)(coefficients);
  const bool sine = points_felt_.has_value();
  const Vec3& a = a_;
  const vibration::RandomVibration &felt = felt_, &through_loop = through_loop_;
  FrequencyPrediction out = fixed_;
  for_each_rectifying_term(coefficients, config_.location, [&](int c, const Coefficients& only, bool filtered) {
    const Eq3Terms t = sine ? sine_on_random_rectification(only, a, filtered ? sine_loop_ : sine_felt_,
                                                           filtered ? *points_loop_ : *points_felt_, filtered ? through_loop : felt)
                            : random_rectification(only, a, filtered ? through_loop : felt);
    const double gain = config_.location[c] == Location::output ? 1.0 : dc_gain_;
    for (int k = 0; k < kNumTerms; ++k) out.terms.g[k] += gain * t.g[k];
  });
  if (clipping_g_) out.terms.g[t_clipping] = *clipping_g_;
  if (second_order_) {
    out.second_order_g = second_order_->g(coefficients, config_.location, dc_gain_);
    out.second_order_error_g = second_order_->error_g(coefficients, config_.location, dc_gain_);
  }
  // A readout polynomial: E over the output's Gaussian part (Gauss-Hermite), averaged over the
  // sine's phase (32 points: exact for a trigonometric polynomial of degree < 32).
  if (readout_) {
    const Vec3 slope = readout_slope(coefficients, config_.location, a);
    const double sigma_u = readout_sigma(rr_, slope);
    const std::complex<double> Us = Is_ + slope[IA] * Fs_[IA] + slope[PA] * Fs_[PA] + slope[OA] * Fs_[OA];
    const double u0 = plant::output_g(coefficients, a);
    const HermiteRule& gh = hermite_rule();
    const int phases = sine ? 32 : 1;
    for (const auto& e : config_.effects) {
      if (!e->readout_averaged_in_prediction()) continue;
      double mean = 0;
      for (int k = 0; k < phases; ++k) {
        const double us = std::real(Us * std::polar(1.0, 2 * std::numbers::pi * k / phases));
        for (std::size_t n = 0; n < gh.x.size(); ++n) mean += gh.w[n] * e->readout(u0 + us + sigma_u * gh.x[n]) / phases;
      }
      out.readout_g += mean - e->readout(u0);
    }
  }
  return out;
}

FrequencyPrediction random_rectification_at_frequency(const PlantConfig& config, const Vec3& a, const RandomResponse& rr,
                                                      const std::optional<PeriodicInput>& periodic, const ResponseAt& response,
                                                      std::optional<double> range_g) {
  return PreparedRandomRectification(config, a, rr, periodic, response, range_g)(config.coefficients);
}

FrequencyPrediction random_rectification_at_frequency(const PlantConfig& plant, const Vec3& a, const vibration::RandomProfile& p,
                                                      std::optional<double> range_g) {
  const LoopResponder responder(plant);
  const ResponseAt h = std::cref(responder);
  return random_rectification_at_frequency(plant, a, with_pickoff_moments(random_response(p, h), plant, p, h), std::nullopt, nullptr,
                                           range_g);
}

FrequencyPrediction sine_on_random_rectification_at_frequency(const PlantConfig& plant, const Vec3& a,
                                                              const vibration::SineVibration& sine,
                                                              const vibration::RandomProfile& p, std::optional<double> range_g) {
  vibration::validate(sine);
  if (!(sine.frequency_Hz > 0)) throw std::invalid_argument("sine_on_random: the sine's frequency_Hz must be positive");
  const LoopResponse at_sine = loop_response(plant, sine.frequency_Hz);
  return random_rectification_at_frequency(plant, a, random_response(plant, p), periodic_input(sine),
                                           [&at_sine](double) { return at_sine; }, range_g);
}

}  // namespace vrelab::rectification
