#include "validation/diagnosis/internal/gap.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <set>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

namespace vrelab::validation::internal {
namespace {

std::string fmt_peak(const RunRecord& run, const std::string& dir, const std::string& orient, double z) {
  std::ostringstream o;
  o.precision(3);
  o << run.id << " (" << run.frequency_Hz << " Hz, " << run.amplitude_g << " g along " << dir << ", static " << orient
    << ", z = " << z << ")";
  return o.str();
}

std::string vec_name(const Vec3& v) {
  char b[64];
  std::snprintf(b, sizeof b, "[%.2g, %.2g, %.2g]", v[0], v[1], v[2]);
  return std::string(b);
}

// The significant runs' span and the groups their gaps' power laws are fitted in.
struct Span {
  std::set<std::string> dirs;
  double f_lo = INFINITY, f_hi = 0, a_lo = INFINITY, a_hi = 0;
  // ln |adj| against ln A within each (direction, frequency, orientation), and against ln f
  // within each (direction, amplitude, orientation): one intercept per group.
  std::map<std::string, std::vector<std::pair<double, double>>> over_amplitude, over_frequency;
};

// Each run's prediction, gap and z; the peak, the significant runs and their span.
Span per_run(const CampaignModel& m, double threshold_sigma, const Eigen::VectorXd& r, const Eigen::VectorXd& adj,
             const Eigen::VectorXd& vinv_diag, Diagnosis& d) {
  const Campaign& c = m.campaign;
  const Data& data = m.data;
  const Table& nominal = m.nominal;
  const int n = m.n;
  Span sp;
  std::set<std::string>& dirs = sp.dirs;
  double &f_lo = sp.f_lo, &f_hi = sp.f_hi, &a_lo = sp.a_lo, &a_hi = sp.a_hi;
  auto &over_amplitude = sp.over_amplitude, &over_frequency = sp.over_frequency;
  std::map<std::string, std::pair<double, int>> z2_by_direction;
  for (int k = 0; k < n; ++k) {
    RunDiagnosis& rd = d.runs[static_cast<std::size_t>(k)];
    const RunRecord& run = c.runs[static_cast<std::size_t>(k)];
    rd.predicted_g = nominal.pred(k);
    rd.sigma_predicted_g = std::sqrt(std::max(0.0, (nominal.G.row(k) * data.Sigma * nominal.G.row(k).transpose())(0, 0)));
    rd.gap_g = r(k);
    rd.sigma_g = std::sqrt(data.sigma2(k) + rd.sigma_predicted_g * rd.sigma_predicted_g);  // V's diagonal
    rd.adjusted_gap_g = adj(k);
    rd.z = adj(k) / std::sqrt(data.sigma2(k));
    rd.sigma_simulation_g = std::sqrt(std::max(0.0, data.sigma2(k) - std::pow(run.sigma_g, 2)));
    rd.sigma_adjusted_g = data.sigma2(k) * std::sqrt(std::max(0.0, vinv_diag(k)));
    const std::string dir = vec_name(run.direction), orient = vec_name(run.orientation_g);
    z2_by_direction[dir].first += rd.z * rd.z, ++z2_by_direction[dir].second;
    if (std::abs(rd.z) > d.max_abs_z) {
      d.max_abs_z = std::abs(rd.z);
      d.peak = fmt_peak(run, dir, orient, rd.z);
    }
    if (std::abs(rd.z) >= threshold_sigma) {
      ++d.significant_runs;
      dirs.insert(dir);
      f_lo = std::min(f_lo, run.frequency_Hz), f_hi = std::max(f_hi, run.frequency_Hz);
      a_lo = std::min(a_lo, run.amplitude_g), a_hi = std::max(a_hi, run.amplitude_g);
      const double y = std::log(std::abs(adj(k)));
      over_amplitude[dir + orient + std::to_string(run.frequency_Hz)].emplace_back(std::log(run.amplitude_g), y);
      over_frequency[dir + orient + std::to_string(run.amplitude_g)].emplace_back(std::log(run.frequency_Hz), y);
    }
  }
  for (const auto& [dir, z2] : z2_by_direction) d.rms_z_by_direction.emplace_back(dir, std::sqrt(z2.first / z2.second));
  return sp;
}

// Odd or even in the static a_IA: runs alike but for the sign of a_IA, where either is
// significant; the share of the pairs' gap power in (z1 - z2) / 2 (NaN without such pairs).
double odd_in_a_IA_fraction(const Campaign& c, const Diagnosis& d, double threshold_sigma) {
  const int n = static_cast<int>(c.runs.size());
  double odd = 0, even = 0;
  for (int k = 0; k < n; ++k)
    for (int j = k + 1; j < n; ++j) {
      const RunRecord &a = c.runs[static_cast<std::size_t>(k)], &b = c.runs[static_cast<std::size_t>(j)];
      const Vec3 mirrored(-a.orientation_g[0], a.orientation_g[1], a.orientation_g[2]);
      if (a.frequency_Hz != b.frequency_Hz || a.amplitude_g != b.amplitude_g || (a.direction - b.direction).norm() > 1e-6 ||
          (mirrored - b.orientation_g).norm() > 1e-3 || std::abs(a.orientation_g[0]) < 0.1)
        continue;
      const double za = d.runs[static_cast<std::size_t>(k)].z, zb = d.runs[static_cast<std::size_t>(j)].z;
      if (std::max(std::abs(za), std::abs(zb)) < threshold_sigma) continue;
      odd += std::pow((za - zb) / 2, 2), even += std::pow((za + zb) / 2, 2);
    }
  return odd + even > 0 ? odd / (odd + even) : NAN;
}

// The slope of ln |gap| within groups, pooled.
double pooled_slope(const std::map<std::string, std::vector<std::pair<double, double>>>& groups) {
  double sxy = 0, sxx = 0;
  for (const auto& [key, pts] : groups) {
    if (pts.size() < 2) continue;
    double mx = 0, my = 0;
    for (auto [x, y] : pts) mx += x, my += y;
    mx /= static_cast<double>(pts.size()), my /= static_cast<double>(pts.size());
    for (auto [x, y] : pts) sxy += (x - mx) * (y - my), sxx += (x - mx) * (x - mx);
  }
  return sxx > 0 ? sxy / sxx : 0.0;
}

// The summary of where the gap lies (Diagnosis::where).
std::string where_text(const Diagnosis& d, const Span& sp, double chi2_sigma, int n, double threshold_sigma) {
  std::ostringstream w;
  w.precision(3);
  w << "chi^2 " << d.chi2_nominal << " for " << n << " runs (" << chi2_sigma << " sigma); ";
  if (d.significant_runs > 0) {
    w << d.significant_runs << " run(s) with a gap beyond " << threshold_sigma
      << " sigma that the coefficients cannot take up: " << sp.f_lo << "-" << sp.f_hi << " Hz, " << sp.a_lo << "-" << sp.a_hi
      << " g, direction(s)";
    for (const auto& x : sp.dirs) w << " " << x;
    w << "; largest at " << d.peak << "; |gap| ~ amplitude^" << d.amplitude_power << ", ~ frequency^"
      << d.frequency_power << " (pooled within groups); rms z by direction:";
    for (const auto& [dir, z] : d.rms_z_by_direction) w << " " << dir << " " << z;
    if (std::isfinite(d.odd_in_a_IA_fraction))
      w << "; share of the gap odd in the static a_IA: " << d.odd_in_a_IA_fraction;
  } else {
    w << "no single run beyond " << threshold_sigma << " sigma";
  }
  return w.str();
}

}  // namespace

Eigen::VectorXd locate_gap(const CampaignModel& m, const GapOptions& o, Diagnosis& d) {
  const Data& data = m.data;
  const Table& nominal = m.nominal;
  const std::vector<int>& all = m.all;
  const int n = m.n;
  const Eigen::VectorXd r = data.measured - nominal.pred;
  const FactoredCovariance v = factored(data, nominal.G, all);
  d.chi2_nominal = v.chi2(r);
  // The adjusted gap r - G dc* = S V^-1 r has covariance S V^-1 S: each run's own sd with no
  // gap is s2_k sqrt((V^-1)_kk) (what the nuisances' structure tests divide by).
  const Eigen::VectorXd vinv_diag = v.solve(Eigen::MatrixXd(Eigen::MatrixXd::Identity(n, n))).diagonal();
  const double chi2_sigma = chi2_as_sigma(d.chi2_nominal, n);
  d.runs.resize(static_cast<std::size_t>(n));
  // Where: each run's gap that the static test's coefficient errors cannot take up (r - G dc*,
  // dc* from all runs and the static prior), in units of the run's own sigma (measurement and
  // simulation accuracy). The raw gap is dominated by the coefficient errors at several g
  // and would point everywhere.
  const Eigen::VectorXd adj = adjusted_residual(data, nominal.pred, nominal.G, all, all);
  const Span sp = per_run(m, o.threshold_sigma, r, adj, vinv_diag, d);
  // Odd or even in the static a_IA.
  d.odd_in_a_IA_fraction = odd_in_a_IA_fraction(m.campaign, d, o.threshold_sigma);
  d.gap_significant = d.significant_runs > 0 || chi2_sigma >= o.threshold_sigma;
  d.amplitude_power = pooled_slope(sp.over_amplitude);
  d.frequency_power = pooled_slope(sp.over_frequency);
  d.where = where_text(d, sp, chi2_sigma, n, o.threshold_sigma);
  return r;
}

}  // namespace vrelab::validation::internal
