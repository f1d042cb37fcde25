#include "validation/diagnosis/internal/next_runs.hpp"

#include <algorithm>
#include <cmath>
#include <exception>
#include <set>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "validation/diagnosis/gaussian_likelihood.hpp"
#include "validation/diagnosis/internal/tabulate.hpp"

namespace vrelab::validation::internal {

namespace {

// The coefficients' correction the runs estimate under a table, and its remaining covariance.
struct Correction {
  Eigen::VectorXd dc;
  Eigen::MatrixXd cov;
};
Correction correction(const CampaignModel& m, const Table& t) {
  const FactoredCovariance f = factored(m.data, t.G, m.all);
  if (!f.ok()) throw std::invalid_argument("next runs: the runs' covariance cannot be factored");
  return {f.conditional_mean(m.data.measured - t.pred), f.conditional_covariance()};
}

// The best estimate at the runs `at` of the hypothesis at values v: its prediction there plus
// the coefficients' correction the campaign's runs estimate under it.
Eigen::VectorXd best_at(const CampaignModel& m, const Effect* e, const std::vector<double>& v, const std::vector<RunRecord>& at,
                        ResponseCache& at_cache, Eigen::MatrixXd* cov_out = nullptr, Eigen::MatrixXd* G_out = nullptr) {
  const Table runs = tabulate(m.plant, m.campaign.runs, e, v, m.cache, m.absorbed);
  const Table there = tabulate(m.plant, at, e, v, at_cache, m.absorbed);
  const Correction c = correction(m, runs);
  if (cov_out) *cov_out = c.cov;
  if (G_out) *G_out = there.G;
  return there.pred + there.G * c.dc;
}

}  // namespace

Conditional conditional(const CampaignModel& m, const Effect* e, const EffectFit* fit, const std::vector<RunRecord>& at) {
  ResponseCache at_cache;  // the tables of the runs `at` (a cache holds one set of runs)
  const std::vector<double> v = fit ? fit->values() : std::vector<double>{};
  Eigen::MatrixXd cov, G;
  Conditional out;
  out.mean = best_at(m, e, v, at, at_cache, &cov, &G);
  // The coefficients' remaining uncertainty along each run's gradient.
  out.variance = ((G * cov).array() * G.array()).rowwise().sum().matrix();
  if (!fit) return out;
  // Each fitted parameter moved by its sigma (within its range, one-sided at an edge), the
  // correction re-estimated: what the parameter's uncertainty leaves open at the runs `at`.
  for (std::size_t j = 0; j < fit->parameters.size(); ++j) {
    const FittedParameter& q = fit->parameters[j];
    if (q.status != ParameterStatus::fitted || !(q.sigma > 0) || !std::isfinite(q.sigma)) continue;
    Eigen::VectorXd side[2];
    int sides = 0;
    for (int sign : {-1, 1}) {
      std::vector<double> w = v;
      w[j] = v[j] + sign * q.sigma;
      if (w[j] < q.lower || w[j] > q.upper) continue;
      try {
        Eigen::VectorXd there = best_at(m, e, w, at, at_cache);
        side[sides++] = std::move(there);
      } catch (const std::invalid_argument&) {  // the plant refuses the value: the other side alone
      }
    }
    if (sides == 2) out.variance += ((side[1] - side[0]) / 2).array().square().matrix();
    else if (sides == 1) out.variance += (side[0] - out.mean).array().square().matrix();
  }
  return out;
}

double rival_rise_sigma(double mean_truth, double var_truth, double mean_rival, double var_rival, double s2) {
  const double d = mean_truth - mean_rival, v = s2 + var_rival;
  return std::sqrt(std::max(0.0, d * d / v + (s2 + var_truth) / v - 1));
}

namespace {

// Two runs are one experiment when they share the shaker's frequency and direction (a run
// re-mounted or at another level is the same test again), or three of frequency, direction,
// amplitude and static orientation.
bool same_experiment(const NextRun& x, const NextRun& y) {
  const bool f = x.frequency_Hz == y.frequency_Hz, u = (x.direction - y.direction).norm() < 1e-9;
  const int alike = f + u + (x.amplitude_g == y.amplitude_g) + ((x.orientation_g - y.orientation_g).norm() < 1e-9);
  return (f && u) || alike >= 3;
}

// The best three of `options` (best first), each a distinct experiment from those before it.
void take_distinct(std::vector<NextRun> options, Diagnosis& d) {
  std::stable_sort(options.begin(), options.end(),
                   [](const NextRun& x, const NextRun& y) { return x.separation_sigma > y.separation_sigma; });
  for (const NextRun& nr : options) {
    if (d.next_runs.size() == 3) break;
    if (std::none_of(d.next_runs.begin(), d.next_runs.end(), [&](const NextRun& x) { return same_experiment(x, nr); }))
      d.next_runs.push_back(nr);
  }
}

// The campaign's sine runs' median sigma (all runs' when none is a sine run), g.
double median_sigma(const Campaign& c) {
  std::vector<double> sig;
  for (const RunRecord& run : c.runs)
    if (!run.random) sig.push_back(run.sigma_g);
  if (sig.empty())
    for (const RunRecord& run : c.runs) sig.push_back(run.sigma_g);
  std::nth_element(sig.begin(), sig.begin() + static_cast<std::ptrdiff_t>(sig.size() / 2), sig.end());
  return sig[sig.size() / 2];
}

NextRun run_to_add(double f, double a, const Vec3& dir, const Vec3& o, double sigma, std::string between, std::string purpose) {
  NextRun nr;
  nr.frequency_Hz = f, nr.amplitude_g = a, nr.direction = dir, nr.orientation_g = o, nr.separation_sigma = sigma;
  nr.between = std::move(between), nr.purpose = std::move(purpose);
  return nr;
}

RunRecord sine_run(double f, double a, const Vec3& dir, const Vec3& o) {
  RunRecord run;
  run.frequency_Hz = f, run.amplitude_g = a, run.direction = dir, run.orientation_g = o;
  return run;
}

// Ambiguous: the runs where the tied effects, each at its fitted values and given every run,
// are furthest apart: the rival's rise (rival_rise_sigma) with either as the truth, the
// smaller side, and the smallest over the pairs of them.
void separating_runs(const CampaignModel& m, Diagnosis& d) {
  const Campaign& c = m.campaign;
  double amax = 0;
  for (const RunRecord& run : c.runs) amax = std::max(amax, run.amplitude_g);
  std::vector<RunRecord> at;
  const std::vector<Vec3> dirs = {Vec3(1, 0, 0), Vec3(0, 1, 0), Vec3(0, 0, 1), Vec3(1, 1, 0).normalized(),
                                  Vec3(1, 0, 1).normalized(), Vec3(0, 1, 1).normalized()};
  const std::vector<Vec3> orients = {Vec3(1, 0, 1).normalized(), Vec3(-1, 0, 1).normalized(), Vec3(1, 0, 0), Vec3(0, 1, 0)};
  for (const Vec3& dir : dirs)
    for (const Vec3& o : orients)
      for (double a : {amax / 4, amax / 2, amax})
        for (double f : {10.0, 30.0, 100.0, 300.0, 1000.0, 2000.0}) at.push_back(sine_run(f, a, dir, o));
  std::vector<std::pair<std::string, Conditional>> cand;
  for (const std::string& name : d.ambiguous_with)
    for (const EffectFit& f : d.effects)
      if (f.name == name) try {
          cand.emplace_back(name, conditional(m, find_effect(name), &f, at));
        } catch (const std::exception&) {  // a candidate the plant cannot take at some run: not one to separate
        }
  if (cand.size() < 2) return;
  // A run's own variance: the campaign's median sigma and the simulation's accuracy at the
  // nominal best estimate there (as the diagnosis would weigh the run).
  const Conditional nominal = conditional(m, nullptr, nullptr, at);
  const double s_run = median_sigma(c);
  std::vector<NextRun> options;
  for (std::size_t k = 0; k < at.size(); ++k) {
    const double s2 = s_run * s_run + std::pow(m.simulation_rel_accuracy * nominal.mean(static_cast<Eigen::Index>(k)), 2);
    NextRun nr = run_to_add(at[k].frequency_Hz, at[k].amplitude_g, at[k].direction, at[k].orientation_g, INFINITY, "", "separates");
    const auto K = static_cast<Eigen::Index>(k);
    for (std::size_t i = 0; i < cand.size(); ++i)
      for (std::size_t j = i + 1; j < cand.size(); ++j) {
        const Conditional &a = cand[i].second, &b = cand[j].second;
        const double if_a = rival_rise_sigma(a.mean(K), a.variance(K), b.mean(K), b.variance(K), s2);
        const double if_b = rival_rise_sigma(b.mean(K), b.variance(K), a.mean(K), a.variance(K), s2);
        if (std::min(if_a, if_b) < nr.separation_sigma) {
          nr.separation_sigma = std::min(if_a, if_b), nr.if_first_sigma = if_a, nr.if_second_sigma = if_b;
          nr.between = cand[i].first + " vs " + cand[j].first;
        }
      }
    if (std::isfinite(nr.separation_sigma)) options.push_back(nr);
  }
  take_distinct(std::move(options), d);
}

// Not explained: where the gap is, beside its largest sine run (frequency f, amplitude a,
// direction u, orientation o, gap z): the same run along a direction the campaign's sine runs
// lack (an axis, else a diagonal of u's axis with another), at the
// frequency beside f towards the larger neighbouring gap (an octave out at the design's edge),
// and at an amplitude the campaign lacks. Each expects the gap the campaign's scaling laws
// carry there, |z| (A'/a)^p (f'/f)^q (p, q: the diagnosis' amplitude and frequency powers);
// the axis run expects nothing (NaN): it tells whether the gap lives there.
void locating_runs(const CampaignModel& m, Diagnosis& d) {
  const Campaign& c = m.campaign;
  int peak = -1;
  for (std::size_t k = 0; k < c.runs.size(); ++k)
    if (!c.runs[k].random && (peak < 0 || std::abs(d.runs[k].z) > std::abs(d.runs[static_cast<std::size_t>(peak)].z)))
      peak = static_cast<int>(k);
  if (peak < 0) return;
  const RunRecord& p = c.runs[static_cast<std::size_t>(peak)];
  const double zp = std::abs(d.runs[static_cast<std::size_t>(peak)].z);
  const auto expect = [&](double a, double f) {
    return zp * std::pow(a / p.amplitude_g, d.amplitude_power) * std::pow(f / p.frequency_Hz, d.frequency_power);
  };
  std::vector<NextRun> runs;
  // Which axis: the first direction no sine run used (either sign) of: the other axes, the
  // diagonals of the peak's axis with each other axis (the one with the larger rms z first),
  // the same with the other sign.
  const auto used = [&](const Vec3& u) {
    return std::any_of(c.runs.begin(), c.runs.end(), [&](const RunRecord& r) {
      return !r.random && std::abs(std::abs(r.direction.normalized().dot(u)) - 1) < 1e-9;
    });
  };
  int lead = 0;
  for (int i = 1; i < 3; ++i)
    if (std::abs(p.direction[i]) > std::abs(p.direction[lead])) lead = i;
  static const char* kAxisNames[3] = {"IA", "PA", "OA"};
  const auto rms_z = [&](int i) {
    for (const auto& [name, z] : d.rms_z_by_direction)
      if (name == kAxisNames[i]) return z;
    return 0.0;
  };
  std::vector<int> others;
  for (int i = 0; i < 3; ++i)
    if (i != lead) others.push_back(i);
  if (rms_z(others[1]) > rms_z(others[0])) std::swap(others[0], others[1]);
  std::vector<Vec3> tries;
  for (int i : others) tries.push_back(Vec3::Unit(i));
  for (int i : others) tries.push_back((Vec3::Unit(lead) + Vec3::Unit(i)).normalized());
  for (int i : others) tries.push_back((Vec3::Unit(lead) - Vec3::Unit(i)).normalized());
  Vec3 dir = tries.back();
  for (const Vec3& u : tries)
    if (!used(u)) {
      dir = u;
      break;
    }
  runs.push_back(run_to_add(p.frequency_Hz, p.amplitude_g, dir, p.orientation_g, NAN, "which axis", "locates"));
  // Which band: the group of the peak (its direction, amplitude, orientation) over frequency.
  std::vector<std::pair<double, double>> group;  // (frequency, |z|)
  for (std::size_t k = 0; k < c.runs.size(); ++k) {
    const RunRecord& r = c.runs[k];
    if (!r.random && (r.direction - p.direction).norm() < 1e-9 && r.amplitude_g == p.amplitude_g &&
        (r.orientation_g - p.orientation_g).norm() < 1e-9)
      group.emplace_back(r.frequency_Hz, std::abs(d.runs[k].z));
  }
  std::sort(group.begin(), group.end());
  const auto at = std::find_if(group.begin(), group.end(), [&](const auto& x) { return x.first == p.frequency_Hz; });
  double f_band = p.frequency_Hz * 2;
  if (at != group.end()) {
    const bool has_lo = at != group.begin(), has_hi = std::next(at) != group.end();
    if (!has_hi) f_band = p.frequency_Hz * 2;
    else if (!has_lo) f_band = p.frequency_Hz / 2;
    else f_band = std::sqrt(p.frequency_Hz * (std::prev(at)->second > std::next(at)->second ? std::prev(at)->first : std::next(at)->first));
  }
  f_band = std::clamp(f_band, 5.0, 5000.0);
  runs.push_back(run_to_add(f_band, p.amplitude_g, p.direction, p.orientation_g, expect(p.amplitude_g, f_band), "which frequency band", "locates"));
  // Which amplitude law: the peak's run at the amplitude furthest (in ratio) from the campaign's.
  std::set<double> amps;
  for (const RunRecord& r : c.runs)
    if (!r.random) amps.insert(r.amplitude_g);
  double a_new = p.amplitude_g / 2, far = 0;
  for (double a : {p.amplitude_g / 4, p.amplitude_g / 2, p.amplitude_g * 3 / 4, p.amplitude_g * 1.5}) {
    double nearest = INFINITY;
    for (double b : amps) nearest = std::min(nearest, std::abs(std::log(a / b)));
    if (nearest > far + 1e-12) far = nearest, a_new = a;
  }
  runs.push_back(run_to_add(p.frequency_Hz, a_new, p.direction, p.orientation_g, expect(a_new, p.frequency_Hz), "which amplitude law", "locates"));
  d.next_runs = std::move(runs);
}

}  // namespace

void suggest_next_runs(const CampaignModel& m, Diagnosis& d) {
  if (!d.gap_significant) return;
  if (!d.ambiguous_with.empty()) separating_runs(m, d);
  else if (!d.explained()) locating_runs(m, d);
}

}  // namespace vrelab::validation::internal
