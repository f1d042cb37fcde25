#include "validation/diagnosis/diagnose.hpp"

#include <algorithm>
#include <array>
#include <bit>
#include <cstdint>
#include <complex>
#include <cstdio>
#include <numbers>
#include <cmath>
#include <functional>
#include <map>
#include <limits>
#include <tuple>
#include <memory>
#include <set>
#include <sstream>
#include <stdexcept>

#include <Eigen/Dense>
#include <boost/math/distributions/chi_squared.hpp>
#include <boost/math/distributions/students_t.hpp>

#include "rectification/prediction/frequency.hpp"
#include "rectification/prediction/gradient.hpp"
#include "rectification/prediction/random.hpp"
#include "rectification/simulation/shake.hpp"
#include "vibration/excitation.hpp"
#include "validation/diagnosis/gaussian_likelihood.hpp"

namespace vrelab::validation {
namespace {

using plant::Coefficients;
using plant::PlantConfig;

// Random runs: the PSD integral on a grid of 0.1 in ln f shared by every table of the same
// band (rectification/prediction/random.hpp, common_grid; 8 Gauss-Legendre points a piece):
// the loop responses are then cached across runs. Within 1e-5 of the fine default on GEVS.
const rectification::RandomQuadrature kRandomRunQuadrature{0.1, true};

// The table's motion as the prediction takes it: a pure sine exactly, else one period of
// the excitation resolved into harmonics.
rectification::PeriodicInput periodic_input(const TableMotion& m, double frequency_Hz) {
  return m.pure_sine() ? rectification::periodic_input(m.sine) : rectification::periodic_input(*m.excitation(), frequency_Hz);
}

// Reference channels (RunRecord::motion): a sine run's measured tones are its periodic input;
// a random run's Welch PSD its random part. The table-motion effects are measured in such a
// run, not applied to it.
bool measured_sine(const RunRecord& r) { return r.motion && !r.motion->tones.empty(); }
bool motion_used(const RunRecord& r) { return r.motion && r.motion->used(); }
const vibration::RandomProfile& run_random(const RunRecord& r) {
  return r.motion && r.motion->random ? *r.motion->random : *r.random;
}
rectification::PeriodicInput run_input(const RunRecord& r, const TableMotion& m) {
  if (!measured_sine(r)) return periodic_input(m, r.frequency_Hz);
  rectification::PeriodicInput in;
  in.frequency_Hz = r.frequency_Hz;
  in.tones = r.motion->tones;
  return in;
}
// (values: every parameter of e.) A run whose table motion was measured (reference channels)
// already holds what a table-motion effect does.
void apply_effect(const Effect* e, ParameterValues values, const RunRecord& r, PlantConfig& cfg, TableMotion& m) {
  if (!e || (motion_used(r) && e->acts_on == ActsOn::table_motion)) return;
  e->apply(values, cfg, m);  // a random run: what the effect does to the table's motion is not applied
}

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

// The simulation of every run under one effect value: pred = f0 + G c (exact: the
// prediction is linear in the coefficients), evaluated at the identified coefficients.
struct Table {
  Eigen::VectorXd pred;  // at the identified coefficients
  Eigen::MatrixXd G;     // d pred / d coefficient
};

// The loop responses, per (dynamics-changing effect value, frequency). A plant without a
// servo of its own gets the one its dynamics imply, designed once per dynamics here rather than
// in every loop_response (design_servo scans 3000 frequencies: it was ~85 % of a diagnosis with
// random runs, whose PSD grid asks for hundreds of frequencies per effect value). The servo is
// the same function of the same numbers, so the responses are bit for bit the same.
class ResponseCache {
 public:
  // The tables (tabulate) and what the static test takes up, per effect and value, for one
  // identified plant and one set of runs' physics (their sigma is not an input): the
  // diagnose() wrapper's second pass (the sigma scaled) asks for the same ones again. bind()
  // forgets everything when the plant differs from the one bound (exactly).
  void bind(const PlantConfig& plant) {
    const bool same = bound_ && plant.coefficients.v == plant_.coefficients.v && key(plant.dynamics) == key(plant_.dynamics);
    if (same) return;
    plant_ = plant, bound_ = true;
    tables_.clear(), absorbed_.clear(), cache_.clear(), responders_.clear();
  }
  std::map<std::string, std::shared_ptr<const Table>> tables_;
  std::map<std::string, plant::Coefficients> absorbed_;

  // (A response is computed for the first plant that asks for its key and frequency, as
  // loop_response would compute it; the plant is linearised once for every frequency asked of
  // a linear part alike (rectification::LoopResponder: the same numbers).)
  const rectification::LoopResponse& get(const PlantConfig& cfg, const std::string& key, double f) {
    // (By key, then frequency: the key is not copied for every look-up.)
    auto by_key = cache_.find(key);
    if (by_key == cache_.end()) by_key = cache_.emplace(key, std::map<double, rectification::LoopResponse>()).first;
    auto it = by_key->second.find(f);
    if (it == by_key->second.end()) {
      if (!(f > 0)) throw std::invalid_argument("frequency_Hz must be positive");
      if (cfg.servo) {
        it = by_key->second.emplace(f, responder(cfg, key)(f)).first;
      } else {
        PlantConfig with_servo = cfg;
        with_servo.servo = servo(cfg.dynamics);
        it = by_key->second.emplace(f, responder(with_servo, key)(f)).first;
      }
    }
    return it->second;
  }

 private:
  // Every field of plant::Dynamics (design_servo's only input).
  using DynamicsKey = std::tuple<double, double, double, double, double, bool, double, double>;
  static DynamicsKey key(const plant::Dynamics& d) {
    return {d.pendulum_frequency_Hz, d.pendulum_damping_ratio, d.angle_gain_rad_per_s2_per_g, d.loop_bandwidth_Hz,
            d.phase_margin_deg,      d.integrator,             d.integrator_zero_ratio,       d.antialias_Hz};
  }
  const plant::Servo& servo(const plant::Dynamics& d) {
    const DynamicsKey k = key(d);
    auto it = servos_.find(k);
    if (it == servos_.end()) it = servos_.emplace(k, plant::design_servo(d)).first;
    return it->second;
  }
  // What loop_response reads of a plant (with its servo): the coefficients its linear plant
  // keeps, the locations, the dynamics, the servo, and the linear effects (their
  // transmissibility at a probe frequency; the key names the effect and its values).
  static std::vector<double> linear_part(const PlantConfig& cfg) {
    std::vector<double> v;
    for (int c : {plant::K1, plant::k0, plant::delta_OA, plant::delta_PA}) v.push_back(cfg.coefficients[c]);
    for (const plant::Location l : cfg.location) v.push_back(static_cast<double>(l));
    const DynamicsKey d = key(cfg.dynamics);
    std::apply([&](auto... x) { (v.push_back(static_cast<double>(x)), ...); }, d);
    v.push_back(cfg.torquer_c2_per_g), v.push_back(cfg.torquer_c3_per_g2);
    const plant::Servo& sv = *cfg.servo;
    for (double x : {sv.gain_g_per_rad, sv.lead_zero_rad_per_s, sv.lead_pole_rad_per_s, sv.integrator_rad_per_s}) v.push_back(x);
    for (const auto& e : cfg.effects)
      if (e->kept_in_linearisation()) {
        for (int j = 0; j < 3; ++j) {
          const std::complex<double> t = e->transmissibility(j, 2 * std::numbers::pi * 1234.5);
          v.push_back(t.real()), v.push_back(t.imag());
        }
      }
    return v;
  }
  const rectification::LoopResponder& responder(const PlantConfig& cfg, const std::string& key) {
    auto k = std::make_pair(key, linear_part(cfg));
    auto it = responders_.find(k);
    if (it == responders_.end()) it = responders_.emplace(k, std::make_unique<rectification::LoopResponder>(cfg)).first;
    return *it->second;
  }
  std::map<std::string, std::map<double, rectification::LoopResponse>, std::less<>> cache_;
  std::map<std::pair<std::string, std::vector<double>>, std::unique_ptr<rectification::LoopResponder>> responders_;
  std::map<DynamicsKey, plant::Servo> servos_;
  PlantConfig plant_;
  bool bound_ = false;
};

// What the static test took up of an effect that acts at rest, per unit of (p - nominal)
// (taken_up_by_static_test): subtracted from the identified coefficients under the effect.
using Absorbed = std::map<std::string, Coefficients>;

Table tabulate_runs(const PlantConfig& nominal, const std::vector<RunRecord>& runs, const Effect* e,
                    const std::vector<double>& values, ResponseCache& cache, const Absorbed& absorbed);

// The table of every run under (e, values), computed once per plant the cache is bound to.
// (values: every parameter of e; empty without e.)
Table tabulate(const PlantConfig& nominal, const std::vector<RunRecord>& runs, const Effect* e, const std::vector<double>& values,
               ResponseCache& cache, const Absorbed& absorbed) {
  cache.bind(nominal);
  std::string key = e ? e->name : std::string("(nominal)");
  for (const double v : values) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "=%.17g", v);
    key += buf;
  }
  const auto it = cache.tables_.find(key);
  if (it != cache.tables_.end() && it->second->pred.size() == static_cast<Eigen::Index>(runs.size())) return *it->second;
  auto t = std::make_shared<const Table>(tabulate_runs(nominal, runs, e, values, cache, absorbed));
  cache.tables_[key] = t;
  return *t;
}

Table tabulate_runs(const PlantConfig& nominal, const std::vector<RunRecord>& runs, const Effect* e,
                    const std::vector<double>& values, ResponseCache& cache, const Absorbed& absorbed) {
  const double p = values.empty() ? 0.0 : values.front();
  const int n = static_cast<int>(runs.size());
  Table t{Eigen::VectorXd(n), Eigen::MatrixXd(n, plant::kNumCoefficients)};
  std::map<std::string, std::pair<PlantConfig, rectification::PeriodicInput>> film_memo;
  for (int k = 0; k < n; ++k) {
    const RunRecord& r = runs[static_cast<std::size_t>(k)];
    PlantConfig cfg = nominal;
    TableMotion m = table_motion(r);
    apply_effect(e, values, r, cfg, m);
    const PlantConfig with_films = cfg;
    // A film's linearisation and balance once per (plant, motion) in the table: runs that
    // differ only in orientation share them (the same function of the same numbers).
    const rectification::PeriodicInput motion = r.random ? rectification::PeriodicInput{} : run_input(r, m);
    const std::string film_key = r.random ? std::string() : rectification::film_balance_key(with_films, m.sine, motion);
    const auto memo = film_key.empty() ? film_memo.end() : film_memo.find(film_key);
    if (memo != film_memo.end()) cfg = memo->second.first;
    else if (!r.random) cfg = rectification::amplitude_linearised(cfg, m.sine);
    // The loop responses depend on the effect's value and, for an amplitude-dependent one,
    // on the run: the key says both.
    // (The name, a NUL and the numbers' bytes: the same numbers give the same key, as their
    // %.17g text did, without formatting them for every run of every table.)
    std::string key;
    if (e && e->changes_dynamics) {
      key = e->name;
      key += '\0';
      const auto put = [&key](double x) { key.append(reinterpret_cast<const char*>(&x), sizeof x); };
      put(p), put(cfg.dynamics.pendulum_damping_ratio);
      for (std::size_t j = 1; j < values.size(); ++j) put(values[j]);
    }
    // A squeeze film's linearised plant is this run's own (its damping is in the key): its
    // responses are kept for the run only, not in the cache (the same numbers: the plant
    // linearised once, each frequency solved once).
    const bool own = cfg.dynamics.pendulum_damping_ratio != with_films.dynamics.pendulum_damping_ratio && cfg.servo;
    std::optional<rectification::LoopResponder> own_responder;
    std::map<double, rectification::LoopResponse> own_responses;
    const rectification::ResponseAt h = [&](double f) {
      if (!own) return cache.get(cfg, key, f);
      auto it = own_responses.find(f);
      if (it == own_responses.end()) {
        if (!(f > 0)) throw std::invalid_argument("frequency_Hz must be positive");
        if (!own_responder) own_responder.emplace(cfg);
        it = own_responses.emplace(f, (*own_responder)(f)).first;
      }
      return it->second;
    };
    const rectification::PeriodicInput input = r.random                  ? rectification::PeriodicInput{}
                                               : memo != film_memo.end() ? memo->second.second
                                                                         : rectification::film_harmonic_balance(with_films, cfg, motion, h);
    if (!film_key.empty() && memo == film_memo.end()) film_memo.emplace(film_key, std::make_pair(cfg, input));
    // A random or sine-on-random run: the random part's covariances through the loop, once.
    std::optional<rectification::RandomResponse> rr;
    std::optional<vibration::SineVibration> sine;
    std::optional<rectification::LoopResponse> sine_h;
    if (r.random) {
      rr = rectification::random_response(run_random(r), h, kRandomRunQuadrature);
      if (r.sine_part) sine = measured_sine(r) ? m.sine : r.vibration(), sine_h = h(r.frequency_Hz);
    }
    // Coefficients as identified, then the effect's own change of them (if any) on top.
    const Coefficients shift = [&] {
      Coefficients z = nominal.coefficients;
      for (int i = 0; i < plant::kNumCoefficients; ++i) z[i] = cfg.coefficients[i] - nominal.coefficients[i];
      if (e && e->acts_at_rest) {
        for (int i = 0; i < plant::kNumCoefficients; ++i) z[i] -= (p - e->fitted().nominal) * absorbed.at(e->name)[i];
      }
      return z;
    }();
    // A periodic run: what does not depend on the coefficients (the motion through the loop,
    // the period's averages) once for the gradient's 12 evaluations (the same numbers).
    std::optional<rectification::PreparedPeriodicRectification> periodic;
    if (!rr) periodic.emplace(cfg, r.orientation_g, input, h);
    const auto f = [&](const Coefficients& co) {
      if (rr) {
        PlantConfig q = cfg;
        for (int i = 0; i < plant::kNumCoefficients; ++i) q.coefficients[i] = co[i] + shift[i];
        return rectification::random_rectification_at_frequency(q, r.orientation_g, *rr, sine, sine_h).total_g();
      }
      Coefficients q;
      for (int i = 0; i < plant::kNumCoefficients; ++i) q[i] = co[i] + shift[i];
      return (*periodic)(q).total_g();
    };
    const CoefArray g = rectification::prediction_gradient(f, nominal.coefficients);
    for (int i = 0; i < plant::kNumCoefficients; ++i) t.G(k, i) = g[i];
    t.pred(k) = f(nominal.coefficients);
  }
  return t;
}

// At one value of the effect's first parameter, the others nominal.
Table tabulate(const PlantConfig& nominal, const std::vector<RunRecord>& runs, const Effect* e, double p,
               ResponseCache& cache, const Absorbed& absorbed) {
  return tabulate(nominal, runs, e, e ? e->values_at(p) : std::vector<double>{}, cache, absorbed);
}

// -2 log(likelihood) of the runs `idx` (up to a constant), with the residual's covariance
// V = diag(sigma_run^2 + (f_model pred)^2) + G Sigma G^T; and chi^2 = r^T V^-1 r.
struct Likelihood {
  double m2logl = 0, chi2 = 0;
};
struct Data {
  Eigen::VectorXd measured, sigma2;  // sigma2: the run's variance plus the simulation's own, (f_model pred_nominal)^2
  Eigen::MatrixXd Sigma;
};

// The model-accuracy part is fixed at the nominal prediction: were it taken at each effect's
// prediction, an effect could lower chi^2 by inflating its predictions.
// (Only the lower triangle is a product, the upper its mirror: every use factorises V, which
// reads the lower triangle, or takes its diagonal. Each entry is the same sum in the same
// order as the full product's, so the factorisations are bit for bit as before, at half the
// product's work.)
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

// One effect: its tables (linear effects: nominal and unit, interpolated), the fit of its
// parameters on a set of runs, the model at any parameter value.
class EffectFitter {
 public:
  EffectFitter(const Effect& e, const Table& nominal, const PlantConfig& plant, const std::vector<RunRecord>& runs,
               ResponseCache& cache, const Absorbed& absorbed)
      : e_(e), nominal_(nominal), plant_(plant), runs_(runs), cache_(cache), absorbed_(absorbed) {
    for (const EffectParameter& q : e.parameters) nominal_values_.push_back(q.nominal);
    if (e.fitted().linear) {
      unit_ = tabulate(plant, runs, &e, e.fitted().unit_value, cache, absorbed);
    } else {
      // Values the plant cannot take (a servo the loop design refuses) leave the grid.
      for (double p : e.fitted().grid) {
        try {
          grid_.push_back(p == e.fitted().nominal ? nominal : tabulate(plant, runs, &e, p, cache, absorbed));
          values_.push_back(p);
        } catch (const std::invalid_argument&) {
        }
      }
    }
  }
  const Effect& effect() const { return e_; }
  Table at(double p) const {
    if (e_.fitted().linear) {
      const double u = (p - e_.fitted().nominal) / (e_.fitted().unit_value - e_.fitted().nominal);
      return {nominal_.pred + u * (unit_.pred - nominal_.pred), nominal_.G + u * (unit_.G - nominal_.G)};
    }
    // Nonlinear: the grid's tables, or the simulation at p itself (kept: the folds' fits
    // and the final one revisit the same values).
    const auto& g = values_;
    const auto node = std::find(g.begin(), g.end(), p);
    if (node != g.end()) return grid_[static_cast<std::size_t>(node - g.begin())];
    auto it = extra_.find(p);
    if (it == extra_.end()) it = extra_.emplace(p, tabulate(plant_, runs_, &e_, p, cache_, absorbed_)).first;
    return it->second;
  }
  // At every parameter's value (the further ones nominal: the tables above). A linear first
  // parameter stays linear at any value of the others.
  Table at(const std::vector<double>& v) const {
    if (further_nominal(v)) return at(v.front());
    if (e_.fitted().linear) {
      std::vector<double> v0 = v, v1 = v;
      v0.front() = e_.fitted().nominal, v1.front() = e_.fitted().unit_value;
      const Table t0 = table(v0), t1 = table(v1);
      const double u = (v.front() - e_.fitted().nominal) / (e_.fitted().unit_value - e_.fitted().nominal);
      return {t0.pred + u * (t1.pred - t0.pred), t0.G + u * (t1.G - t0.G)};
    }
    return table(v);
  }
  // d pred / d p at p: exact for linear effects, central over +-h for the others (a value the
  // plant refuses: one-sided).
  Eigen::VectorXd slope(double p, double h) const {
    if (e_.fitted().linear) return (unit_.pred - nominal_.pred) / (e_.fitted().unit_value - e_.fitted().nominal);
    const auto pred_at = [&](double x) -> std::optional<Eigen::VectorXd> {
      try {
        return at(x).pred;
      } catch (const std::invalid_argument&) {
        return std::nullopt;
      }
    };
    const auto up = pred_at(p + h), down = pred_at(p - h);
    if (up && down) return (*up - *down) / (2 * h);
    const Eigen::VectorXd mid = at(p).pred;
    if (up) return (*up - mid) / h;
    if (down) return (mid - *down) / h;
    return Eigen::VectorXd::Zero(mid.size());
  }
  // Maximum likelihood of the first parameter over the runs `idx`, the others nominal; sigma
  // from the curvature of -2 log L.
  std::pair<double, double> fit(const Data& d, const std::vector<int>& idx) const { return fit_first(d, idx, nominal_values_); }

  // Every parameter the runs `idx` pin (docs/diagnose.md, "Natural forms"): the first
  // parameter's fit at each start of the further ones (their `starts`, the nominal first); a
  // discrete parameter's value chosen by likelihood (held at nominal unless it lowers -2 ln L
  // by kDiscreteGain); then Levenberg-Marquardt on the first and the continuous further
  // parameters, on -2 ln L with the weak Gaussian priors of the further ones, each step's
  // covariance V at the current value (the coefficients' errors taken out as in the one-
  // parameter fit). A further parameter whose sigma from the data alone is not smaller than
  // its prior width, or whose slope the others' span (ColPivHouseholderQR's rank), is held at
  // its nominal. When every further parameter is held, the result is the one-parameter fit.
  struct Multi {
    std::vector<double> values;
    std::vector<int> free;         // the parameters fitted continuously (the first among them when any further is)
    Eigen::MatrixXd cov;           // their covariance (free.size() square); empty: the one-parameter fit
    std::vector<std::string> status;
    std::vector<double> sigma;     // per parameter (NaN: held or chosen)
    Eigen::MatrixXd slopes;        // n x free.size(), over every run
  };
  static constexpr double kDiscreteGain = 4, kSeen = 25;
  Multi fit_all(const Data& d, const std::vector<int>& idx) const {
    const std::size_t m = e_.parameters.size();
    Multi out;
    out.values = nominal_values_;
    out.status.assign(m, "held");
    out.sigma.assign(m, NAN);
    const auto [p0, s0] = fit(d, idx);
    out.values.front() = p0, out.status.front() = "fitted", out.sigma.front() = s0;
    if (m == 1) return out;
    // The starts: the nominal first, then every combination of the further parameters' starts.
    std::vector<std::vector<double>> bases = {nominal_values_};
    for (std::size_t j = 1; j < m; ++j) {
      const std::size_t nb = bases.size();
      for (double st : e_.parameters[j].starts) {
        if (st == e_.parameters[j].nominal) continue;
        for (std::size_t b = 0; b < nb; ++b) {
          std::vector<double> v = bases[b];
          v[j] = st;
          bases.push_back(v);
        }
      }
    }
    const auto m2logl = [&](const std::vector<double>& v) {
      try {
        const Table t = at(v);
        return likelihood(d, t.pred, t.G, idx).m2logl;
      } catch (const std::invalid_argument&) {
        return static_cast<double>(INFINITY);
      }
    };
    std::vector<double> start_l;
    std::vector<std::vector<double>> start_v;
    for (const auto& b : bases) {
      std::vector<double> v = b;
      v.front() = &b == &bases.front() ? p0 : fit_first(d, idx, b).first;
      start_l.push_back(m2logl(v)), start_v.push_back(v);
    }
    const auto discrete_nominal = [&](const std::vector<double>& v) {
      for (std::size_t j = 1; j < m; ++j)
        if (e_.parameters[j].discrete && v[j] != e_.parameters[j].nominal) return false;
      return true;
    };
    std::size_t best = 0, best_nominal = 0;
    for (std::size_t b = 0; b < bases.size(); ++b) {
      if (start_l[b] < start_l[best]) best = b;
      if (discrete_nominal(start_v[b]) && start_l[b] < start_l[best_nominal]) best_nominal = b;
    }
    // A discrete form is chosen only for an effect the runs see (against no effect, -2 ln L
    // falls by kSeen, the targeted test's 25) and when it beats the default form by
    // kDiscreteGain: on a clean campaign the best of three axes beats IA by more than 4 by
    // chance (seen: OA chosen, NaturalForm.ACleanCampaign...).
    const double l_none = likelihood(d, nominal_.pred, nominal_.G, idx).m2logl;
    if (!discrete_nominal(start_v[best]) &&
        (start_l[best_nominal] - start_l[best] < kDiscreteGain || l_none - start_l[best] < kSeen))
      best = best_nominal;
    std::vector<double> start = start_v[best];
    for (std::size_t j = 1; j < m; ++j)
      if (e_.parameters[j].discrete && start[j] != e_.parameters[j].nominal) out.status[j] = "chosen";
    // The continuous candidates: the first parameter and the further continuous ones.
    std::vector<int> free = {0};
    for (std::size_t j = 1; j < m; ++j)
      if (!e_.parameters[j].discrete) free.push_back(static_cast<int>(j));
    const auto hold_nominal = [&](std::vector<double>& v, const std::vector<int>& fr) {
      for (std::size_t j = 1; j < m; ++j)
        if (!e_.parameters[j].discrete && std::find(fr.begin(), fr.end(), static_cast<int>(j)) == fr.end())
          v[j] = e_.parameters[j].nominal;
    };
    // Levenberg-Marquardt from one start, the unpinned further parameters held (`fr` shrinks to
    // what is left); false when every continuous further parameter ended held.
    const auto descend = [&](const std::vector<double>& from, std::vector<int>& fr, Multi& res) {
      for (int round = 0; round < 4 && fr.size() > 1; ++round) {
        std::vector<double> v = from;
        hold_nominal(v, fr);
        if (v != from) v.front() = fit_first(d, idx, v).first;
        const std::vector<int> held = unpinned(d, idx, v, fr);
        if (!held.empty()) {
          for (int j : held) fr.erase(std::find(fr.begin(), fr.end(), j));
          continue;
        }
        v = levenberg_marquardt(d, idx, v, fr);
        const std::vector<int> held_after = unpinned(d, idx, v, fr);
        if (!held_after.empty()) {
          for (int j : held_after) fr.erase(std::find(fr.begin(), fr.end(), j));
          continue;
        }
        // Fitted: the covariance from the objective's own Hessian at the end (with the priors;
        // the Gauss-Newton information where that is not positive definite), the slopes over
        // every run.
        res.values = v, res.free = fr, res.slopes = jacobian(v, fr);
        res.cov = covariance_at(d, idx, v, fr, res.slopes);
        // The Hessian's sigma judged like the Gauss-Newton one (step 4): a further parameter
        // whose sigma is not below its prior width is not pinned (a phase level over the circle).
        // So is one whose variance is not a positive number, and every further one when the
        // Hessian was never positive definite (the Gauss-Newton fallback then understates it).
        std::vector<int> loose;
        for (std::size_t a = 1; a < fr.size(); ++a) {
          const double var = res.cov(static_cast<Eigen::Index>(a), static_cast<Eigen::Index>(a));
          if (cov_never_definite_ || !(var > 0) ||
              !(std::sqrt(var) < e_.parameters[static_cast<std::size_t>(fr[a])].prior_width()))
            loose.push_back(fr[a]);
        }
        if (!loose.empty()) {
          for (int j : loose) fr.erase(std::find(fr.begin(), fr.end(), j));
          continue;
        }
        for (std::size_t a = 0; a < fr.size(); ++a) {
          res.status[static_cast<std::size_t>(fr[a])] = "fitted";
          const double var = res.cov(static_cast<Eigen::Index>(a), static_cast<Eigen::Index>(a));
          res.sigma[static_cast<std::size_t>(fr[a])] = var > 0 ? std::sqrt(var) : std::numeric_limits<double>::quiet_NaN();
        }
        return true;
      }
      return false;
    };
    {
      std::vector<int> fr = free;
      Multi res = out;
      if (free.size() > 1 && descend(start, fr, res)) {
        // A phase's -2 ln L has a valley on each side of the circle, and a start's first-
        // parameter fit says little about where the descent ends (seen: the best start, 0 rad,
        // ended at 0.30 rad, 36 above the valley at 2.3 rad a start of pi/2 leads to). Every
        // other start with the same discrete values whose -2 ln L is within kSeen of the best
        // start's descends too; the lowest objective wins.
        double f_best = objective_at(d, idx, res.values, res.free);
        for (std::size_t b = 0; b < bases.size(); ++b) {
          if (b == best || start_l[b] - start_l[best] > kSeen) continue;
          bool same = true;
          for (std::size_t j = 1; j < m; ++j)
            if (e_.parameters[j].discrete && start_v[b][j] != start[j]) same = false;
          if (!same) continue;
          std::vector<int> fb = free;
          Multi rb = out;
          if (!descend(start_v[b], fb, rb)) continue;
          const double fb_obj = objective_at(d, idx, rb.values, rb.free);
          if (fb_obj < f_best) f_best = fb_obj, res = rb;
        }
        return res;
      }
      free = fr;
    }
    // Every continuous further parameter held: the one-parameter fit at the chosen discrete values.
    if (!discrete_nominal(start)) {
      std::vector<double> v = start;
      free = {0};
      hold_nominal(v, free);
      const auto [p, sp] = fit_first(d, idx, v);
      v.front() = p;
      out.values = v, out.sigma.front() = sp;
    }
    return out;
  }

  // The fitted parameters' sigma with the hypothesis' own error added: the change the effect
  // makes, Delta = pred(v) - pred(nominal), is right to hypothesis_accuracy f (not better:
  // test_effect_sweep.cpp). That error is systematic (the same approximation at every run,
  // smooth in frequency and amplitude), not noise: taken as one common relative error
  // e = eps f Delta, eps ~ N(0, 1), it moves the estimate by b eps, and the covariance gains
  // b b^T. b comes from two refits: the fit repeated on the data shifted by +f Delta and by
  // -f Delta (the effect's change scaled by 1 -+ f), each a Levenberg-Marquardt descent from the
  // fitted values over the same free parameters (not the multi-start: the shift is small), and
  // b = (v+ - v-) / 2 (each refit's shift of a phase taken the short way round, within +-pi). For a linear one-parameter
  // effect b = f p (the parameter known to f of itself); errors independent run by run would
  // give f p / sqrt(N) of N like runs, which a systematic error does not average down. A large
  // effect seen at hundreds of sigma had sigma from the noise only (a harmonic's phase 4 sigma
  // off its truth at 0.056 rad); a small one is left as it was (f Delta << sigma_run).
  // The first-order shift b = C J^T V^-1 f Delta it replaces mixed the objective's Hessian (C)
  // with the Gauss-Newton slopes J, which overstate a harmonic's phase curvature hundredfold:
  // phases within 0.04-0.39 rad of their truth were reported +- 5-12 rad (seeds 8801, 8901).
  // A refit that fails (the plant refuses a value) or ends on a non-periodic parameter's bound
  // is not used: the other side's shift alone (v -+ v, one-sided) stands for it, and with neither
  // the first-order shift does. Reported only: the folds' fits, the evidence and the verdict do
  // not use it.
  void add_model_error(const Data& d, const std::vector<int>& idx, Multi& mf) const {
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

  // What a held further parameter's uncertainty does to the fitted parameters (docs/diagnose.md,
  // "Natural forms"). Held at its nominal because the data do not pin it there, it is
  // not known to be there: the fitted parameters' values depend on where it is (a 2nd
  // harmonic's ratio fitted with its phase held at 0 came out 0.072 +- 0.015 for a truth of
  // 0.142 at 0.97 rad: seed 8901, campaign 90, before the descent's trust step). It is
  // marginalised over its range: at kHeldPoints values x spread evenly across the range (a
  // phase's round the circle, its nominal 0 among them), the fitted parameters are refitted
  // with it held at x (the first by its one-parameter fit, then the others with it by
  // Levenberg-Marquardt from there), and each x is weighted by its likelihood exp(-(F(x) -
  // F_min)/2), F the objective with the fitted parameters' and its own prior (a phase has none:
  // uniform round the circle) -- a quadrature of the marginal posterior, the Laplace factor
  // det C(x)^(1/2) left out. The weighted second moment of the refitted values about the
  // reported ones joins their covariance (a phase's differences taken round the circle). The
  // grid resolves what it marginalises: a held parameter's sigma from the data is at least its
  // prior width, a quarter of its range, and the grid's step is an eighth of it; a narrow
  // valley elsewhere that the grid misses weighs too little (a fit that missed it is the
  // descent's to find). Each held continuous parameter on its own, the others at their nominals,
  // their shares added; a discrete one held at its nominal is a choice (the Bayes factor of
  // step 2), not profiled. Reported only, as the hypothesis' accuracy: the folds, the evidence
  // and the verdict do not use it.
  static constexpr int kHeldPoints = 8;
  void add_held_spread(const Data& d, const std::vector<int>& idx, Multi& mf) const {
    const std::vector<int> which = fitted_set(mf);
    if (!std::isfinite(mf.sigma.front())) return;  // the first at its bound: no sigma to widen
    const Eigen::Index k = static_cast<Eigen::Index>(which.size());
    Eigen::MatrixXd spread = Eigen::MatrixXd::Zero(k, k);
    for (std::size_t j = 1; j < e_.parameters.size(); ++j) {
      const EffectParameter& q = e_.parameters[j];
      if (q.discrete || mf.status[j] != "held" || !(std::isfinite(q.lower) && std::isfinite(q.upper))) continue;
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

  // -2 ln L's profile over parameter j: at each x of xs, the other parameters of mf's fit
  // refitted with j held at x (the first by its one-parameter fit, robust to a far valley; the
  // further ones of mf's free set with it by Levenberg-Marquardt from there); the objective
  // with the priors of every further parameter among them and j's.
  struct ProfilePoint {
    double x = 0, objective = INFINITY;
    std::vector<double> values;
  };
  std::vector<ProfilePoint> profile(const Data& d, const std::vector<int>& idx, const Multi& mf, int j,
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

 private:
  // The parameters mf fitted: its free set, or the first alone (the one-parameter fit).
  static std::vector<int> fitted_set(const Multi& mf) { return mf.cov.size() > 0 ? mf.free : std::vector<int>{0}; }
  bool further_nominal(const std::vector<double>& v) const {
    for (std::size_t j = 1; j < v.size(); ++j)
      if (v[j] != nominal_values_[j]) return false;
    return true;
  }
  static std::vector<double> with_first(std::vector<double> v, double p) {
    v.front() = p;
    return v;
  }
  // The tabulation at v, kept (the folds and the final fit revisit the same values).
  Table table(const std::vector<double>& v) const {
    auto it = tables_.find(v);
    if (it == tables_.end()) it = tables_.emplace(v, tabulate(plant_, runs_, &e_, v, cache_, absorbed_)).first;
    return it->second;
  }
  // The weak Gaussian prior's weight 1 / width^2 of a further parameter (none on an angle
  // that wraps round: its range is the whole circle).
  double prior_weight(int j) const {
    const EffectParameter& q = e_.parameters[static_cast<std::size_t>(j)];
    return q.periodic ? 0.0 : 1 / std::pow(q.prior_width(), 2);
  }
  // The first parameter's range (its grid's for a nonlinear one) and each further one's.
  std::pair<double, double> range(int j) const {
    if (j == 0 && !e_.fitted().linear && !values_.empty()) return {values_.front(), values_.back()};
    return {e_.parameters[static_cast<std::size_t>(j)].lower, e_.parameters[static_cast<std::size_t>(j)].upper};
  }
  // A periodic further parameter (a phase) has no bound: x taken round into [lo, hi) (a phase
  // in [-pi, pi): +pi is -pi; a value inside is kept as it is, to the bit).
  bool wraps(int j) const { return j > 0 && e_.parameters[static_cast<std::size_t>(j)].periodic; }
  double wrapped(int j, double x) const {
    const auto [lo, hi] = range(j);
    if (x >= lo && x < hi) return x;
    const double w = lo + std::fmod(std::fmod(x - lo, hi - lo) + (hi - lo), hi - lo);
    return w < hi ? w : lo;  // (lo + a remainder just below the period can round to hi)
  }
  double step(const std::vector<double>& v, int j) const {
    if (j > 0) return e_.parameters[static_cast<std::size_t>(j)].fd_step();
    if (e_.fitted().linear) return std::max(1e-3 * std::abs(v[0]), std::abs(e_.fitted().unit_value - e_.fitted().nominal) * 1e-2);
    const auto [lo, hi] = range(0);
    return std::max(1e-3 * std::abs(v[0]), 1e-4 * (hi - lo));
  }
  // d pred / d v_j over every run for j in `free`: central differences (one-sided at a bound
  // or where the plant refuses a value; a phase's taken round the circle: it has no bound).
  Eigen::MatrixXd jacobian(const std::vector<double>& v, const std::vector<int>& free) const {
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
  // The further parameters of `free` the runs idx do not pin at v: a rank-deficient whitened
  // Jacobian (the first such column, in ColPivHouseholderQR's pivot order, beyond the rank),
  // else those whose sigma from the data alone is not below their prior width.
  std::vector<int> unpinned(const Data& d, const std::vector<int>& idx, const std::vector<double>& v,
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
  // -2 ln L over idx at v with the further parameters' priors (those in `free`).
  double objective_at(const Data& d, const std::vector<int>& idx, const std::vector<double>& w,
                      const std::vector<int>& free) const {
    try {
      const Table t = at(w);
      double f = likelihood(d, t.pred, t.G, idx).m2logl;
      for (std::size_t a = 1; a < free.size(); ++a) {
        const EffectParameter& q = e_.parameters[static_cast<std::size_t>(free[a])];
        f += prior_weight(free[a]) * std::pow(w[static_cast<std::size_t>(free[a])] - q.nominal, 2);
      }
      return f;
    } catch (const std::invalid_argument&) {
      return static_cast<double>(INFINITY);
    }
  }
  // The fitted parameters' covariance at v: the inverse of half the objective's Hessian
  // (-2 ln L with the priors), every entry by central differences, each parameter stepped by
  // half its Gauss-Newton sigma (J^T V^-1 J with the priors; J over every run, `slopes`). The
  // Levenberg-Marquardt information took its diagonal from second differences over the slopes'
  // step (1e-3 rad for a phase), where -2 ln L (about -4800 on 168 runs) changes by less than the
  // simulation's own rounding and tolerances: a harmonic's phase got 0.0094 rad where -2 ln L
  // rose by 0.13 over 0.1 rad (sigma ~0.28; the truth 0.076 rad away, 0.29 above the minimum:
  // "7.6 sigma off"). Falls back to that information where the Hessian is not positive
  // definite or a step would leave the range.
  Eigen::MatrixXd covariance_at(const Data& d, const std::vector<int>& idx, const std::vector<double>& v,
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
  // One descent step in a valley narrower than the differences (docs/diagnose.md, "Natural
  // forms", step 3): where a parameter's difference step spans more than kNarrowSigmas of its
  // conditional sigma 1/sqrt(c) (c the objective's curvature along it over that step: -2 ln L
  // rises by more than kNarrowSigmas^2 across the step), the differences straddle a curved
  // valley's walls and their slope can have the wrong sign (seed 9601, campaign 30: a mode's
  // frequency and damping, correlation -0.998, differences 50 and 10 conditional sigma wide;
  // the descent stopped 23.6 of -2 ln L above the truth). The gradient and the whole Hessian
  // (the mixed terms too: Gauss-Newton's correlations miss what the parameters do to V and the
  // prediction's curvature, and a valley's direction is the small difference of two large
  // numbers) are then taken by central differences over kLocalSigmas of each parameter's
  // conditional sigma (at most its usual step), and the step is Newton's, halved until the
  // objective falls (a backtracking line search: the descent stays monotone and follows the
  // valley instead of zig-zagging across it as Levenberg-Marquardt's damping towards the
  // gradient makes it). Over 0.3 sigma the differences' -2 ln L changes by ~0.1, far above its
  // rounding. v and f move to the accepted point. Returns nothing where the valley is not
  // narrow, the local Hessian is not positive definite or its step finds no decrease
  // (Levenberg-Marquardt's step then), else whether the descent stops (every move below 1e-3
  // conditional sigma).
  static constexpr double kNarrowSigmas = 1, kLocalSigmas = 0.3;
  std::optional<bool> valley_step(const Data& d, const std::vector<int>& idx, const std::vector<int>& free,
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
  // Levenberg-Marquardt on -2 ln L + the further parameters' priors over `free`, from v.
  std::vector<double> levenberg_marquardt(const Data& d, const std::vector<int>& idx, std::vector<double> v,
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
        // the range's ends, they were one-sided there and without the curvature's rescaling,
        // so steps of Gauss-Newton's hundredfold curvature crept along (seed 9301, campaign
        // 54: from the start at -pi, 15 steps ended at 3.13 rad, 63 above the valley at 2.55).
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
  // The first parameter's fit with the others at base's values. A function of its inputs
  // alone: kept per (data, runs, base), bit for bit (the folds' fits, the final fit, the
  // pairs' and the natural forms' starts ask for the same fits again).
  std::pair<double, double> fit_first(const Data& d, const std::vector<int>& idx, const std::vector<double>& base) const {
    std::vector<std::uint64_t> key;
    key.reserve(4 + idx.size() + base.size() + static_cast<std::size_t>(d.measured.size() + d.sigma2.size() + d.Sigma.size()));
    const auto put = [&key](double x) { key.push_back(std::bit_cast<std::uint64_t>(x)); };
    key.push_back(idx.size()), key.push_back(base.size());
    for (int i : idx) key.push_back(static_cast<std::uint64_t>(i));
    for (double x : base) put(x);
    key.push_back(static_cast<std::uint64_t>(d.measured.size())), key.push_back(static_cast<std::uint64_t>(d.Sigma.rows()));
    for (Eigen::Index i = 0; i < d.measured.size(); ++i) put(d.measured(i)), put(d.sigma2(i));
    for (Eigen::Index i = 0; i < d.Sigma.size(); ++i) put(d.Sigma.data()[i]);
    const auto it = fits_.find(key);
    if (it != fits_.end()) return it->second;
    const std::pair<double, double> f = fit_first_uncached(d, idx, base);
    fits_.emplace(std::move(key), f);
    return f;
  }
  std::pair<double, double> fit_first_uncached(const Data& d, const std::vector<int>& idx, const std::vector<double>& base) const {
    const bool nominal_base = further_nominal(base);
    const auto at_p = [&](double p) { return nominal_base ? at(p) : at(with_first(base, p)); };
    auto L = [&](double p) {  // a value the plant refuses (a servo the design cannot build) is no fit
      try {
        const Table t = at_p(p);
        return likelihood(d, t.pred, t.G, idx).m2logl;
      } catch (const std::invalid_argument&) {
        return static_cast<double>(INFINITY);
      }
    };
    std::vector<double> xs;
    if (e_.fitted().linear) {
      // A bracket from the fixed-covariance (nominal V) estimate, then a scan and a refinement.
      const Table t0 = nominal_base ? nominal_ : at_p(e_.fitted().nominal);
      const Table t1 = nominal_base ? unit_ : at_p(e_.fitted().unit_value);
      const Eigen::LDLT<Eigen::MatrixXd> ldlt(covariance(d, t0.G, idx));
      const double du = e_.fitted().unit_value - e_.fitted().nominal;
      const Eigen::VectorXd s = sub(t1.pred, idx) - sub(t0.pred, idx);
      const Eigen::VectorXd r = sub(d.measured, idx) - sub(t0.pred, idx);
      const double info = s.dot(ldlt.solve(s));
      const double u0 = info > 0 ? s.dot(ldlt.solve(r)) / info : 0.0;
      const double su = info > 0 ? 1 / std::sqrt(info) : 1.0;
      const double half = 3 * std::abs(u0) + 20 * su;
      double lo = e_.fitted().nominal + du * (u0 - half), hi = e_.fitted().nominal + du * (u0 + half);
      if (lo > hi) std::swap(lo, hi);
      lo = std::clamp(lo, e_.fitted().lower, e_.fitted().upper), hi = std::clamp(hi, e_.fitted().lower, e_.fitted().upper);
      if (!(hi > lo)) lo = e_.fitted().lower, hi = e_.fitted().upper;  // the estimate lies outside the physical range
      for (int k = 0; k <= 60; ++k) xs.push_back(lo + (hi - lo) * k / 60.0);
    } else {
      xs = values_;
      if (xs.empty()) return {e_.fitted().nominal, INFINITY};
    }
    std::vector<double> ls;
    for (double x : xs) ls.push_back(L(x));
    // Refinement in [x_{b-1}, x_{b+1}] by successive parabolic interpolation (safeguarded by
    // golden steps): where the prediction is near linear in p across a grid step, -2 ln L is
    // near quadratic and a step or two lands on the minimum.
    const auto refine = [&](std::size_t b) {
      double best = xs[b], lbest = ls[b];
      double lo = xs[b - 1], hi = xs[b + 1], flo = ls[b - 1], fhi = ls[b + 1];
      const double tol = 1e-4 * (hi - lo);
      for (int it = 0; it < 12; ++it) {
        const double dl = best - lo, dh = best - hi;
        const double den = dl * (lbest - fhi) - dh * (lbest - flo);
        double x = den != 0 ? best - 0.5 * (dl * dl * (lbest - fhi) - dh * dh * (lbest - flo)) / den : NAN;
        if (!(x > lo + tol && x < hi - tol)) x = best - lo > hi - best ? best - 0.382 * (best - lo) : best + 0.382 * (hi - best);
        if (std::abs(x - best) < tol) break;
        const double fx = L(x);
        if (fx < lbest) {
          if (x < best) hi = best, fhi = lbest;
          else lo = best, flo = lbest;
          best = x, lbest = fx;
        } else {
          if (x < best) lo = x, flo = fx;
          else hi = x, fhi = fx;
        }
      }
      return std::make_pair(best, lbest);
    };
    // The grid's interior local minima, best first: the three best are refined (a narrow valley
    // between grid points, such as a resonance's, can refine below a broader one that looked
    // better on the grid).
    std::vector<std::size_t> minima;
    for (std::size_t k = 1; k + 1 < xs.size(); ++k)
      if (ls[k] <= ls[k - 1] && ls[k] <= ls[k + 1]) minima.push_back(k);
    std::sort(minima.begin(), minima.end(), [&](std::size_t a, std::size_t b) { return ls[a] < ls[b]; });
    const std::size_t g = static_cast<std::size_t>(std::min_element(ls.begin(), ls.end()) - ls.begin());
    double best = xs[g], lbest = ls[g], sigma = INFINITY;
    std::size_t at = g;
    for (std::size_t m = 0; m < std::min<std::size_t>(3, minima.size()); ++m) {
      const auto [x, l] = refine(minima[m]);
      if (l < lbest || minima[m] == g) best = x, lbest = l, at = minima[m];
    }
    if (at > 0 && at + 1 < xs.size()) {  // the curvature at the minimum
      const double h = 0.25 * (xs[at + 1] - xs[at - 1]);
      const double curv = (L(best + h) - 2 * lbest + L(best - h)) / (h * h);  // d2(-2 log L)/dp2
      if (curv > 0) sigma = std::sqrt(2 / curv);
    }
    return {best, sigma};
  }

  const Effect& e_;
  const Table& nominal_;
  const PlantConfig& plant_;
  const std::vector<RunRecord>& runs_;
  ResponseCache& cache_;
  const Absorbed& absorbed_;
  Table unit_;
  std::vector<Table> grid_;
  std::vector<double> values_;  // the grid's values the plant can take
  mutable std::map<double, Table> extra_;
  std::vector<double> nominal_values_;
  mutable std::map<std::vector<double>, Table> tables_;
  mutable bool cov_never_definite_ = false;  // covariance_at's Hessian never positive definite
  mutable Eigen::MatrixXd last_info_;  // levenberg_marquardt's information matrix at its last point
  mutable std::map<std::vector<std::uint64_t>, std::pair<double, double>> fits_;  // fit_first's, by its inputs' bits
};

std::string fmt_peak(const RunRecord& run, const std::string& dir, const std::string& orient, double z) {
  std::ostringstream o;
  o.precision(3);
  o << run.id << " (" << run.frequency_Hz << " Hz, " << run.amplitude_g << " g along " << dir << ", static " << orient
    << ", z = " << z << ")";
  return o.str();
}

// chi^2 with n degrees of freedom as a normal deviate (Wilson-Hilferty).
double chi2_as_sigma(double chi2, int n) {
  const double v = 2.0 / (9.0 * n);
  return (std::cbrt(chi2 / n) - (1 - v)) / std::sqrt(v);
}

}  // namespace

TableMotion table_motion(const RunRecord& r) {
  TableMotion m;
  m.sine = r.vibration();
  if (r.motion && !r.motion->tones.empty()) {
    // The measured fundamental (transverse parts included); its harmonics are in run_input.
    for (const auto& [h, W] : r.motion->tones)
      if (h == 1)
        for (int i = 0; i < 3; ++i) m.sine.amplitude_g[i] = std::abs(W[i]), m.sine.phase_rad[i] = std::arg(W[i]);
  }
  m.commanded_amplitude_g = r.amplitude_g;
  m.static_gravity_g = r.orientation_g;
  return m;
}

vibration::SineVibration RunRecord::vibration() const {
  vibration::SineVibration v;
  for (int i = 0; i < 3; ++i) {
    v.amplitude_g[i] = amplitude_g * std::abs(direction[i]);
    v.phase_rad[i] = direction[i] < 0 ? std::numbers::pi : 0.0;
  }
  v.frequency_Hz = frequency_Hz;
  return v;
}

namespace {
// The fit to the plant's own settled readings (the "without" of taken_up_by_static_test; the
// same for every effect: diagnose computes it once).
Coefficients settled_fit(const PlantConfig& plant, const std::vector<Position>& positions, const std::vector<double>& weights,
                         const FixedSet& fixed) {
  std::vector<Reading> readings;
  const double K1 = plant.coefficients[plant::K1];
  // A position read more than once (a static test's repeats) is settled once: the same plant
  // at the same orientation settles to the same number.
  std::map<std::array<double, 3>, double> settled;
  for (std::size_t i = 0; i < positions.size(); ++i) {
    const Vec3& g = positions[i].nominal_g;
    const std::array<double, 3> at{g[0], g[1], g[2]};
    auto it = settled.find(at);
    if (it == settled.end()) it = settled.emplace(at, plant::settled_output_g(plant, g)).first;
    readings.push_back({static_cast<int>(i), K1 * it->second});
  }
  return least_squares(positions, readings, weights, fixed).estimate.value;
}

Coefficients taken_up_given_base(const Effect& e, const PlantConfig& plant, const std::vector<Position>& positions,
                                 const std::vector<double>& weights, const FixedSet& fixed, const Coefficients& b) {
  if (!e.fitted().linear) throw std::logic_error("diagnose: " + e.name + " acts at rest but is not linear");
  PlantConfig with = plant;
  TableMotion unused;
  e.apply(e.fitted().unit_value, with, unused);
  // Least squares is linear in the readings: the difference of the fits to the plant's
  // settled readings with and without the effect.
  const Coefficients m = settled_fit(with, positions, weights, fixed);
  Coefficients diff;
  for (int i = 0; i < plant::kNumCoefficients; ++i) diff[i] = (m[i] - b[i]) / (e.fitted().unit_value - e.fitted().nominal);
  return diff;
}
}  // namespace

Coefficients taken_up_by_static_test(const Effect& e, const PlantConfig& plant, const std::vector<Position>& positions,
                                     const std::vector<double>& weights, const FixedSet& fixed) {
  if (!e.fitted().linear) throw std::logic_error("diagnose: " + e.name + " acts at rest but is not linear");
  return taken_up_given_base(e, plant, positions, weights, fixed, settled_fit(plant, positions, weights, fixed));
}

namespace {
double predict_values(const PlantConfig& nominal, const RunRecord& r, const Effect* e, ParameterValues values);
}  // namespace

double predict_run_g(const PlantConfig& nominal, const RunRecord& r, const Effect* e, double p) {
  const std::vector<double> v = e ? e->values_at(p) : std::vector<double>{};
  return predict_values(nominal, r, e, v);
}

double predict_run_g(const PlantConfig& nominal, const RunRecord& r, const Effect& e, ParameterValues values) {
  return predict_values(nominal, r, &e, values);
}

namespace {
double predict_values(const PlantConfig& nominal, const RunRecord& r, const Effect* e, ParameterValues values) {
  PlantConfig cfg = nominal;
  TableMotion m = table_motion(r);
  apply_effect(e, values, r, cfg, m);
  const PlantConfig with_films = cfg;
  if (!r.random) cfg = rectification::amplitude_linearised(cfg, m.sine);
  std::map<double, rectification::LoopResponse> responses;
  std::optional<PlantConfig> loop_cfg;  // cfg with its servo designed once (ResponseCache)
  const rectification::ResponseAt h = [&](double f) {
    auto it = responses.find(f);
    if (it == responses.end()) {
      if (!loop_cfg) {
        loop_cfg = cfg;
        if (!loop_cfg->servo) loop_cfg->servo = plant::design_servo(cfg.dynamics);
      }
      it = responses.emplace(f, rectification::loop_response(*loop_cfg, f)).first;
    }
    return it->second;
  };
  if (r.random) {
    const rectification::RandomResponse rr = rectification::random_response(run_random(r), h, kRandomRunQuadrature);
    std::optional<vibration::SineVibration> sine;
    std::optional<rectification::LoopResponse> sine_h;
    if (r.sine_part) sine = measured_sine(r) ? m.sine : r.vibration(), sine_h = h(r.frequency_Hz);
    return rectification::random_rectification_at_frequency(cfg, r.orientation_g, rr, sine, sine_h).total_g();
  }
  return rectification::periodic_rectification(cfg, r.orientation_g, rectification::film_harmonic_balance(with_films, cfg, run_input(r, m), h), h)
      .total_g();
}
}  // namespace

namespace {
// cache: the tables and what the static test takes up, shared by the wrapper's passes over the
// same campaign (the runs' sigma may differ between them, nothing else).
Diagnosis diagnose_once(const Campaign& c, const DiagnoseSettings& s, ResponseCache& cache);
}  // namespace

std::vector<double> EffectFit::values() const {
  std::vector<double> v;
  for (const FittedParameter& q : parameters) v.push_back(q.value);
  if (v.empty()) v.push_back(value);
  return v;
}

const Nuisance* Diagnosis::nuisance(const std::string& name) const {
  for (const Nuisance& x : nuisances)
    if (x.name == name) return &x;
  return nullptr;
}

namespace {

// The level every nuisance is tested at: the one-sided tail of a normal deviate beyond 3,
// 1 - Phi(3) = 1.35e-3 (a clean campaign is flagged for drift with twice that, both signs,
// and for an understated sigma with it: 0.4 % in all, within the issue's 2 % false alarms
// with room for the gap's own test). The thresholds are this tail's quantiles of each
// statistic's distribution under "no nuisance", not values tuned on campaigns.
constexpr double kNuisanceTail = 1.3498980316300946e-3;

}  // namespace

// Bias drift: a line through the rest readings over the campaign's time (unweighted least
// squares; its scatter gives the readings' sigma), removed from every run with a time, the
// line's own variance added to the run's. The runs without time are left as they are.
Nuisance remove_drift(Campaign& c) {
  Nuisance nu;
  nu.name = "bias_drift", nu.unit = "ug/h";
  std::vector<const RunRecord*> rest;
  for (const RunRecord& r : c.runs)
    if (std::isfinite(r.time_h) && std::isfinite(r.rest_g)) rest.push_back(&r);
  if (rest.size() < 3) {
    nu.note = "not estimable: fewer than 3 runs with a time and a rest reading (runs.csv columns time_h, rest_ug)";
    return nu;
  }
  const double m = static_cast<double>(rest.size());
  double tm = 0, ym = 0;
  for (const RunRecord* r : rest) tm += r->time_h / m, ym += r->rest_g / m;
  double stt = 0, sty = 0;
  for (const RunRecord* r : rest) stt += std::pow(r->time_h - tm, 2), sty += (r->time_h - tm) * (r->rest_g - ym);
  if (!(stt > 0)) {
    nu.note = "not estimable: the rest readings are all at one time";
    return nu;
  }
  const double b = sty / stt, a = ym - b * tm;
  double rss = 0;
  for (const RunRecord* r : rest) rss += std::pow(r->rest_g - a - b * r->time_h, 2);
  const double s2 = rest.size() > 2 ? rss / (m - 2) : 0.0;
  nu.estimated = true, nu.applied = true;
  nu.value = b * 1e6, nu.sigma = std::sqrt(s2 / stt) * 1e6;
  // Without a drift, b / sigma_b is Student's t with m - 2 degrees of freedom (a line fit to m
  // readings with Gaussian noise of unknown sigma): significant beyond its two-sided quantile
  // at the 3-sigma level (3.05 for 168 readings; 4.28 for 10).
  double t_crit = INFINITY;
  if (rest.size() > 2) t_crit = boost::math::quantile(boost::math::students_t(m - 2), 1 - kNuisanceTail);
  nu.significant = s2 > 0 ? std::abs(b) > t_crit * std::sqrt(s2 / stt) : b != 0;
  for (RunRecord& r : c.runs) {
    if (!std::isfinite(r.time_h)) continue;
    r.measured_g -= a + b * r.time_h;
    r.sigma_g = std::sqrt(r.sigma_g * r.sigma_g + s2 * (1 / m + std::pow(r.time_h - tm, 2) / stt));
  }
  char buf[200];
  std::snprintf(buf, sizeof buf, "the rest readings' line over %d runs (%.3g h), removed; the readings scatter by %.3g ug",
                static_cast<int>(rest.size()), rest.back()->time_h - rest.front()->time_h, std::sqrt(s2) * 1e6);
  nu.note = buf;
  return nu;
}

namespace {

// Runs alike but for one step of frequency or of amplitude (same direction, orientation and
// the other): how alike their gaps z are, as the correlation of neighbours, and how many pairs.
std::pair<double, int> neighbour_correlation(const Campaign& c, const std::vector<double>& z) {
  const auto key = [](const Vec3& v) { return std::to_string(std::lround(v[0] * 1e3)) + "," + std::to_string(std::lround(v[1] * 1e3)) + "," + std::to_string(std::lround(v[2] * 1e3)); };
  std::map<std::string, std::vector<std::pair<double, int>>> by_f, by_a;
  for (std::size_t k = 0; k < c.runs.size(); ++k) {
    const RunRecord& r = c.runs[k];
    const std::string g = key(r.direction) + "|" + key(r.orientation_g);
    by_f[g + "|" + std::to_string(r.amplitude_g)].emplace_back(r.frequency_Hz, static_cast<int>(k));
    by_a[g + "|" + std::to_string(r.frequency_Hz)].emplace_back(r.amplitude_g, static_cast<int>(k));
  }
  double sxy = 0, sxx = 0, syy = 0;
  int pairs = 0;
  for (auto* groups : {&by_f, &by_a})
    for (auto& [g, v] : *groups) {
      std::sort(v.begin(), v.end());
      for (std::size_t i = 1; i < v.size(); ++i) {
        if (v[i].first == v[i - 1].first) continue;  // repeats: not neighbours
        const double x = z[static_cast<std::size_t>(v[i - 1].second)], y = z[static_cast<std::size_t>(v[i].second)];
        sxy += x * y, sxx += x * x, syy += y * y, ++pairs;
      }
    }
  return {sxx > 0 && syy > 0 ? sxy / std::sqrt(sxx * syy) : 0.0, pairs};
}

// Repeated runs (the same frequency, amplitude, direction and orientation): the pooled
// scatter over the stated sigma, and its degrees of freedom.
std::pair<double, int> repeat_scatter(const Campaign& c) {
  std::map<std::string, std::vector<const RunRecord*>> groups;
  for (const RunRecord& r : c.runs) {
    char b[200];
    std::snprintf(b, sizeof b, "%.9g|%.9g|%.4f,%.4f,%.4f|%.4f,%.4f,%.4f", r.frequency_Hz, r.amplitude_g, r.direction[0],
                  r.direction[1], r.direction[2], r.orientation_g[0], r.orientation_g[1], r.orientation_g[2]);
    groups[b].push_back(&r);
  }
  double chi2 = 0;
  int dof = 0;
  for (const auto& [k, g] : groups) {
    if (g.size() < 2) continue;
    double w = 0, m = 0;
    for (const RunRecord* r : g) w += 1 / (r->sigma_g * r->sigma_g), m += r->measured_g / (r->sigma_g * r->sigma_g);
    m /= w;
    for (const RunRecord* r : g) chi2 += std::pow((r->measured_g - m) / r->sigma_g, 2);
    dof += static_cast<int>(g.size()) - 1;
  }
  return {chi2, dof};
}

}  // namespace

Diagnosis diagnose(const Campaign& c0, const DiagnoseSettings& s) {
  Campaign c = c0;
  const Nuisance drift = remove_drift(c);
  ResponseCache cache;
  Diagnosis d = diagnose_once(c, s, cache);
  // The stated sigma: from repeated runs when there are enough (their scatter is the
  // measurement's alone), else from the gaps no effect explains (the nominal's adjusted gaps
  // when unexplained, the chosen effect's held-out ones when explained).
  Nuisance scale;
  scale.name = "sigma_scale", scale.unit = "1", scale.value = 1;
  const int n = static_cast<int>(c.runs.size());
  std::vector<double> z(static_cast<std::size_t>(n));
  double z2 = 0;
  for (int k = 0; k < n; ++k) {
    const RunDiagnosis& rd = d.runs[static_cast<std::size_t>(k)];
    const double sig = std::hypot(c.runs[static_cast<std::size_t>(k)].sigma_g, s.model_accuracy * rd.predicted_g);  // as rd.z's
    z[static_cast<std::size_t>(k)] = d.explained ? rd.heldout_after_g / sig : rd.z;
    z2 += z[static_cast<std::size_t>(k)] * z[static_cast<std::size_t>(k)];
  }
  const auto [rep_chi2, rep_dof] = repeat_scatter(c);
  const auto [rho, pairs] = neighbour_correlation(c, z);
  const double rho_sigma = rho * std::sqrt(std::max(pairs, 1));
  // (The adjusted gaps have the coefficients' errors taken out under the static test's prior,
  // not fitted freely: n degrees of freedom, a little fewer in truth, so k a little low.)
  const int dof = n;
  const bool from_repeats = rep_dof >= 5;
  const double k2 = from_repeats ? rep_chi2 / rep_dof : z2 / dof;
  const int kdof = from_repeats ? rep_dof : dof;
  scale.estimated = true;
  scale.value = std::sqrt(std::max(k2, 0.0));
  scale.sigma = scale.value / std::sqrt(2.0 * kdof);
  {
    const std::string from = from_repeats ? std::string("from ").append(std::to_string(rep_dof)).append(" degrees of freedom of repeated runs")
                             : d.explained ? std::string("from the gaps the chosen effect leaves (held out)")
                                           : std::string("from the gaps no effect explains");
    char buf[240];
    std::snprintf(buf, sizeof buf, "%s; neighbouring runs' gaps correlate by %.2f (%.1f sigma over %d pairs)", from.c_str(), rho,
                  rho_sigma, pairs);
    scale.note = buf;
  }
  // Overdispersion beyond chance: with the stated sigma right, the repeats' pooled chi^2 is
  // chi^2 with rep_dof degrees of freedom exactly (Gaussian noise); the gaps' sum of z^2 is at
  // most chi^2 with n (the coefficients' errors taken out under their prior use up a little:
  // the test errs on the side of not flagging). Beyond its quantile at kNuisanceTail: 1.13 x
  // the stated sigma for 168 runs, 2.2 x for 5 degrees of freedom of repeats.
  const double chi2 = from_repeats ? rep_chi2 : z2;
  const double chi2_crit = boost::math::quantile(boost::math::chi_squared(kdof), 1 - kNuisanceTail);
  const bool excess = chi2 > chi2_crit;
  // It is scatter when measured by repeats, or when no effect explains the gaps and their
  // neighbours are not alike (structure is physics). Whatever the gap's verdict: an
  // overdispersion below the gap's own 5-sigma test is still reported.
  const bool scatter = from_repeats || (!d.explained && rho_sigma < s.structure_sigma);
  // A physical gap is not scatter: scaled from the gaps alone (no repeats), the scaling is not
  // applied when, judged with the corrected sigma, one library effect's held-out evidence still
  // exceeds the targeted test's level (significance^2 = 25). With the right sigma, 30 clean
  // campaigns gave a best evidence of at most 7.0 (docs/diagnose.md step 3), so an excess that
  // is scatter leaves none above 25 once corrected; a squeeze film's weakly structured gap does.
  // Then the gap is judged with the stated sigma, and only repeats can measure the scatter.
  if (excess && scatter) {
    Campaign scaled = c;
    for (RunRecord& r : scaled.runs) r.sigma_g *= scale.value;
    Diagnosis ds = diagnose_once(scaled, s, cache);
    const double level = s.significance_sigma * s.significance_sigma;
    if (!from_repeats && !ds.effects.empty() && ds.effects.front().not_ranked.empty() && ds.effects.front().evidence > level) {
      char buf[240];
      std::snprintf(buf, sizeof buf,
                    "; not applied: with the corrected sigma %s's held-out evidence %.1f still exceeds %.0f (a physical gap, "
                    "not scatter; repeated runs would measure the scatter)",
                    ds.effects.front().name.c_str(), ds.effects.front().evidence, level);
      scale.note += buf;
    } else {
      d = std::move(ds);
      scale.applied = true, scale.significant = true;
      char buf[80];
      std::snprintf(buf, sizeof buf, " (sigma understated x%.2f; judged with the corrected sigma)", scale.value);
      d.verdict += buf;
    }
  } else if (excess) {
    scale.note += d.explained ? "; not applied: the chosen effect explains the gap (only repeated runs would tell scatter apart)"
                              : "; not applied: the gaps are alike between neighbouring runs (structure, not scatter)";
  }
  if (drift.significant) {
    char buf[120];
    std::snprintf(buf, sizeof buf, " (bias drift %.3g +- %.2g ug/h removed)", drift.value, drift.sigma);
    d.verdict += buf;
  }
  d.nuisances = {drift, scale};
  return d;
}

namespace {

// 1. What diagnose and blind's family size start from: the identification from the static
// readings, weighted by their sigma, with its first-order covariance, and the runs' data (sigma2
// the runs' own variance: the model accuracy is added at the nominal prediction).
struct Identified {
  std::vector<Position> positions;
  std::vector<double> weights;
  Propagation uncertainty;
  PlantConfig plant;  // the identified coefficients, the manifest's dynamics
  Data data;
};

Identified identify(const Campaign& c) {
  if (c.statics.empty()) throw std::invalid_argument("diagnose: the campaign has no static readings");
  if (c.runs.empty()) throw std::invalid_argument("diagnose: the campaign has no usable shaker runs");
  Identified id;
  std::vector<Reading> readings;
  ReadingBudget budget;
  for (std::size_t i = 0; i < c.statics.size(); ++i) {
    id.positions.push_back(vector_position(c.statics[i].orientation_g.normalized()));
    readings.push_back({static_cast<int>(i), c.statics[i].output});
    const double var = std::max(c.statics[i].sigma_output * c.statics[i].sigma_output, 1e-30);
    id.weights.push_back(1 / var);
    budget.variance.push_back(var);
    budget.bias.push_back(0.0);
  }
  const LeastSquaresResult ls = least_squares(id.positions, readings, id.weights, c.fixed);
  if (!ls.identifiability.full_rank()) {
    std::string msg = "the static readings do not determine the free coefficients (rank " +
                      std::to_string(ls.identifiability.rank) + " of " + std::to_string(ls.identifiability.parameters) + ")";
    for (const auto& w : ls.identifiability.confounded) msg += "; " + w;
    throw std::invalid_argument(msg + ": hold more coefficients in the manifest's [identification] fixed, or add positions");
  }
  const Estimator est = [&](const std::vector<Reading>& r) { return least_squares(id.positions, r, id.weights, c.fixed).estimate; };
  id.uncertainty = propagate_first_order(est, readings, budget);
  id.plant.coefficients = ls.estimate.value;
  id.plant.dynamics = c.dynamics;
  const int n = static_cast<int>(c.runs.size());
  Data& data = id.data;
  data.measured.resize(n), data.sigma2.resize(n);
  for (int k = 0; k < n; ++k) {
    data.measured(k) = c.runs[static_cast<std::size_t>(k)].measured_g;
    data.sigma2(k) = std::pow(c.runs[static_cast<std::size_t>(k)].sigma_g, 2);
  }
  data.Sigma.resize(plant::kNumCoefficients, plant::kNumCoefficients);
  for (int i = 0; i < plant::kNumCoefficients; ++i)
    for (int j = 0; j < plant::kNumCoefficients; ++j) data.Sigma(i, j) = id.uncertainty.covariance[i][j];
  return id;
}

// The held-out folds: leave one amplitude out, so every frequency and direction stays in
// training (a resonance cannot be located from the other frequencies) and the held-out runs
// test the effect's scaling with amplitude, which tells most effects apart; with one amplitude,
// leave one frequency out; with neither, no cross-validation (in-sample).
struct Folds {
  std::string description;
  std::vector<double> key;                   // each run's fold
  std::map<double, std::vector<int>> test;   // each fold's held-out runs
  std::vector<int> train(double k) const {  // the other folds' runs (every run when none is left)
    std::vector<int> t;
    for (std::size_t j = 0; j < key.size(); ++j)
      if (key[j] != k) t.push_back(static_cast<int>(j));
    if (t.empty())
      for (std::size_t j = 0; j < key.size(); ++j) t.push_back(static_cast<int>(j));
    return t;
  }
};

Folds folds_of(const std::vector<RunRecord>& runs) {
  std::set<double> amplitudes, frequencies;
  for (const auto& run : runs) amplitudes.insert(run.amplitude_g), frequencies.insert(run.frequency_Hz);
  const bool by_amplitude = amplitudes.size() >= 2, by_frequency = !by_amplitude && frequencies.size() >= 2;
  Folds f;
  f.description = by_amplitude ? "leave one amplitude out" : by_frequency ? "leave one frequency out" : "none (in-sample: one amplitude, one frequency)";
  for (std::size_t k = 0; k < runs.size(); ++k) {
    f.key.push_back(by_amplitude ? runs[k].amplitude_g : by_frequency ? runs[k].frequency_Hz : 0.0);
    f.test[f.key.back()].push_back(static_cast<int>(k));
  }
  return f;
}

Diagnosis diagnose_once(const Campaign& c, const DiagnoseSettings& s, ResponseCache& cache) {
  Diagnosis d;
  // Reference channels: when every sine run's motion is measured, the table-motion effects
  // have nothing left to explain (docs/data-format.md, "Reference channels").
  {
    int sine_runs = 0, measured_sine_runs = 0;
    for (const RunRecord& r : c.runs) {
      if (motion_used(r)) ++d.runs_with_measured_motion;
      if (!r.random) ++sine_runs, measured_sine_runs += motion_used(r) ? 1 : 0;
    }
    if (sine_runs > 0 && measured_sine_runs == sine_runs)
      for (const Effect& e : effect_library())
        if (e.acts_on == ActsOn::table_motion) d.measured_effects.push_back(e.name);
  }
  const Identified id = identify(c);
  const std::vector<Position>& positions = id.positions;
  const std::vector<double>& weights = id.weights;
  d.identified = id.plant.coefficients;
  d.identified_uncertainty = id.uncertainty;
  const PlantConfig& plant = id.plant;
  const int n = static_cast<int>(c.runs.size());
  Data data = id.data;

  // What the static test takes up of each effect that acts at rest: the identification of the
  // change the effect (at its unit value) makes to the readings, at the campaign's own
  // positions and weights (least squares is linear in the readings: the difference of two fits).
  // (The plant's own fit is the same for every effect; all of it is kept in the cache for the
  // wrapper's second pass, whose static test is the same.)
  Absorbed absorbed;
  cache.bind(plant);
  std::optional<Coefficients> base_fit;
  for (const Effect& e : effect_library()) {
    if (!e.acts_at_rest) continue;
    auto it = cache.absorbed_.find(e.name);
    if (it == cache.absorbed_.end()) {
      if (!base_fit) base_fit = settled_fit(plant, positions, weights, c.fixed);
      it = cache.absorbed_.emplace(e.name, taken_up_given_base(e, plant, positions, weights, c.fixed, *base_fit)).first;
    }
    absorbed[e.name] = it->second;
  }

  // 2. The nominal simulation: gap, significance, where.
  const Table nominal = tabulate(plant, c.runs, nullptr, 0, cache, absorbed);
  for (int k = 0; k < n; ++k) data.sigma2(k) += std::pow(s.model_accuracy * nominal.pred(k), 2);
  std::vector<int> all(static_cast<std::size_t>(n));
  for (int k = 0; k < n; ++k) all[static_cast<std::size_t>(k)] = k;
  const Eigen::VectorXd r = data.measured - nominal.pred;
  d.chi2_nominal = factored(data, nominal.G, all).chi2(r);
  const double chi2_sigma = chi2_as_sigma(d.chi2_nominal, n);
  d.runs.resize(static_cast<std::size_t>(n));
  // Where: each run's gap that the static test's coefficient errors cannot take up (r - G dc*,
  // dc* from all runs and the static prior), in units of the run's own sigma (measurement and
  // simulation accuracy). The raw gap is dominated by the coefficient errors at several g
  // and would point everywhere.
  const Eigen::VectorXd adj = adjusted_residual(data, nominal.pred, nominal.G, all, all);
  const auto vec_name = [](const Vec3& v) {
    char b[64];
    std::snprintf(b, sizeof b, "[%.2g, %.2g, %.2g]", v[0], v[1], v[2]);
    return std::string(b);
  };
  std::set<std::string> dirs;
  double f_lo = INFINITY, f_hi = 0, a_lo = INFINITY, a_hi = 0;
  // ln |adj| against ln A within each (direction, frequency, orientation), and against ln f
  // within each (direction, amplitude, orientation): one intercept per group.
  std::map<std::string, std::vector<std::pair<double, double>>> over_amplitude, over_frequency;
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
    const std::string dir = vec_name(run.direction), orient = vec_name(run.orientation_g);
    z2_by_direction[dir].first += rd.z * rd.z, ++z2_by_direction[dir].second;
    if (std::abs(rd.z) > d.max_abs_z) {
      d.max_abs_z = std::abs(rd.z);
      d.peak = fmt_peak(run, dir, orient, rd.z);
    }
    if (std::abs(rd.z) >= s.significance_sigma) {
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
  // Odd or even in the static a_IA: runs alike but for the sign of a_IA, where either is
  // significant; the share of the pairs' gap power in (z1 - z2) / 2.
  {
    double odd = 0, even = 0;
    for (int k = 0; k < n; ++k)
      for (int j = k + 1; j < n; ++j) {
        const RunRecord &a = c.runs[static_cast<std::size_t>(k)], &b = c.runs[static_cast<std::size_t>(j)];
        const Vec3 mirrored(-a.orientation_g[0], a.orientation_g[1], a.orientation_g[2]);
        if (a.frequency_Hz != b.frequency_Hz || a.amplitude_g != b.amplitude_g || (a.direction - b.direction).norm() > 1e-6 ||
            (mirrored - b.orientation_g).norm() > 1e-3 || std::abs(a.orientation_g[0]) < 0.1)
          continue;
        const double za = d.runs[static_cast<std::size_t>(k)].z, zb = d.runs[static_cast<std::size_t>(j)].z;
        if (std::max(std::abs(za), std::abs(zb)) < s.significance_sigma) continue;
        odd += std::pow((za - zb) / 2, 2), even += std::pow((za + zb) / 2, 2);
      }
    d.odd_in_a_IA_fraction = odd + even > 0 ? odd / (odd + even) : NAN;
  }
  d.gap_significant = d.significant_runs > 0 || chi2_sigma >= s.significance_sigma;
  {
    // The slope of ln |gap| within groups, pooled.
    const auto pooled_slope = [](const std::map<std::string, std::vector<std::pair<double, double>>>& groups) {
      double sxy = 0, sxx = 0;
      for (const auto& [key, pts] : groups) {
        if (pts.size() < 2) continue;
        double mx = 0, my = 0;
        for (auto [x, y] : pts) mx += x, my += y;
        mx /= static_cast<double>(pts.size()), my /= static_cast<double>(pts.size());
        for (auto [x, y] : pts) sxy += (x - mx) * (y - my), sxx += (x - mx) * (x - mx);
      }
      return sxx > 0 ? sxy / sxx : 0.0;
    };
    d.amplitude_power = pooled_slope(over_amplitude);
    d.frequency_power = pooled_slope(over_frequency);
    std::ostringstream w;
    w.precision(3);
    w << "chi^2 " << d.chi2_nominal << " for " << n << " runs (" << chi2_sigma << " sigma); ";
    if (d.significant_runs > 0) {
      w << d.significant_runs << " run(s) with a gap beyond " << s.significance_sigma
        << " sigma that the coefficients cannot take up: " << f_lo << "-" << f_hi << " Hz, " << a_lo << "-" << a_hi
        << " g, direction(s)";
      for (const auto& x : dirs) w << " " << x;
      w << "; largest at " << d.peak << "; |gap| ~ amplitude^" << d.amplitude_power << ", ~ frequency^"
        << d.frequency_power << " (pooled within groups); rms z by direction:";
      for (const auto& [dir, z] : d.rms_z_by_direction) w << " " << dir << " " << z;
      if (std::isfinite(d.odd_in_a_IA_fraction))
        w << "; share of the gap odd in the static a_IA: " << d.odd_in_a_IA_fraction;
    } else {
      w << "no single run beyond " << s.significance_sigma << " sigma";
    }
    d.where = w.str();
  }

  // 3. Each effect: fits on training runs and the evidence on the held-out ones (folds_of: by
  // amplitude, else by frequency, else in-sample; said in d.folds).
  const Folds fold_set = folds_of(c.runs);
  d.folds = fold_set.description;
  const std::map<double, std::vector<int>>& folds = fold_set.test;
  const auto train_of = [&](double key) { return fold_set.train(key); };
  struct Scored {
    EffectFit fit;
    Eigen::VectorXd heldout;  // held-out adjusted residual per run
    EffectFitter::Multi all;  // the fit on all runs (its sigma with the hypothesis' accuracy)
  };
  std::vector<Scored> scored;
  Eigen::VectorXd heldout_nominal = Eigen::VectorXd::Zero(n);
  for (const auto& [key, test] : folds) {
    const Eigen::VectorXd a = adjusted_residual(data, nominal.pred, nominal.G, train_of(key), test);
    for (std::size_t i = 0; i < test.size(); ++i) heldout_nominal(test[i]) = a(static_cast<Eigen::Index>(i));
  }
  // -2 ln p(test | train) = -2 ln L(all) + 2 ln L(train): the held-out runs given what the
  // training runs say about the coefficients (the same conditioning as the shrinkage's).
  const auto conditional_on = [&](const Data& dd, const Eigen::VectorXd& pred, const Eigen::MatrixXd& G,
                                  const std::vector<int>& train) {
    const Likelihood l_all = likelihood(dd, pred, G, all), l_train = likelihood(dd, pred, G, train);
    return Likelihood{l_all.m2logl - l_train.m2logl, l_all.chi2 - l_train.chi2};
  };
  const auto conditional = [&](const Table& t, const std::vector<int>& train) {
    return conditional_on(data, t.pred, t.G, train);
  };
  // Scores a candidate on each fold: -2 ln p(held-out | training) and the held-out chi^2,
  // with the coefficients and the candidate's parameters uncertain: the parameters, fitted on
  // the training runs, enter like the coefficients, with their slopes S = d pred / d p as
  // columns of G and their fitted variances beside Sigma. So an effect whose parameter the
  // training runs pin only loosely (k6 from 1 and 2 g, extrapolated to 4 g) is judged with
  // that looseness. (The training runs then count twice for the parameters, which makes the
  // judgement a little strict.) fit_on(runs) fits the candidate on `runs`.
  struct Fitted {
    Table t;
    Eigen::MatrixXd slopes;    // n x k; k = 0 when a parameter ended on a bound
    Eigen::MatrixXd cov;       // k x k: the fitted parameters' covariance
  };
  // The nominal's held-out -2 ln L per fold (the same for every candidate).
  std::map<double, Likelihood> nominal_heldout;
  const auto score = [&](const std::function<Fitted(const std::vector<int>&)>& fit_on, Scored& sc) {
    sc.heldout = Eigen::VectorXd::Zero(n);
    for (const auto& [key, test] : folds) {
      const std::vector<int> train = train_of(key);
      const Fitted f = fit_on(train);
      Likelihood with;
      if (train.size() == all.size()) {
        with = likelihood(data, f.t.pred, f.t.G, all);
      } else {
        const Eigen::Index k = f.cov.rows(), m = plant::kNumCoefficients;
        Data da = data;
        da.Sigma = Eigen::MatrixXd::Zero(m + k, m + k);
        da.Sigma.topLeftCorner(m, m) = data.Sigma;
        da.Sigma.bottomRightCorner(k, k) = f.cov;
        Eigen::MatrixXd Ga(n, m + k);
        Ga << f.t.G, f.slopes;
        with = conditional_on(da, f.t.pred, Ga, train);
      }
      auto known = nominal_heldout.find(key);
      if (known == nominal_heldout.end())
        known = nominal_heldout
                    .emplace(key, train.size() == all.size() ? likelihood(data, nominal.pred, nominal.G, all) : conditional(nominal, train))
                    .first;
      const Likelihood without = known->second;
      sc.fit.evidence += without.m2logl - with.m2logl;
      sc.fit.heldout_chi2 += with.chi2;
      const Eigen::VectorXd a = adjusted_residual(data, f.t.pred, f.t.G, train, test);
      for (std::size_t i = 0; i < test.size(); ++i) sc.heldout(test[i]) = a(static_cast<Eigen::Index>(i));
    }
  };
  // A fitted effect with its slope (none at a bound).
  const auto fitted_at = [&](const EffectFitter& fitter, double p, double sp) {
    Fitted f{fitter.at(p), Eigen::MatrixXd(n, 0), Eigen::MatrixXd(0, 0)};
    if (std::isfinite(sp) && sp > 0) {
      f.slopes = fitter.slope(p, sp);
      f.cov = Eigen::MatrixXd::Constant(1, 1, sp * sp);
    }
    return f;
  };
  // Every parameter the runs pin (EffectFitter::fit_all); the one-parameter fit when the
  // further ones are held (then as before), else the fitted parameters' slopes and covariance.
  const auto fitted_multi = [&](const EffectFitter& fitter, const EffectFitter::Multi& mf) {
    if (mf.cov.size() == 0) {
      if (mf.values.size() > 1 && mf.status.size() > 1 &&
          std::any_of(mf.status.begin() + 1, mf.status.end(), [](const std::string& x) { return x != "held"; })) {
        // A discrete parameter chosen, the first fitted at it: its slope at that value.
        Fitted f{fitter.at(mf.values), Eigen::MatrixXd(n, 0), Eigen::MatrixXd(0, 0)};
        const double sp = mf.sigma.front();
        if (std::isfinite(sp) && sp > 0) {
          std::vector<double> up = mf.values, down = mf.values;
          up.front() += sp, down.front() -= sp;
          try {
            f.slopes = (fitter.at(up).pred - fitter.at(down).pred) / (2 * sp);
            f.cov = Eigen::MatrixXd::Constant(1, 1, sp * sp);
          } catch (const std::invalid_argument&) {
            f.slopes = Eigen::MatrixXd(n, 0);
          }
        }
        return f;
      }
      return fitted_at(fitter, mf.values.front(), mf.sigma.front());
    }
    return Fitted{fitter.at(mf.values), mf.slopes, mf.cov};
  };
  const auto fitted_one = [&](const EffectFitter& fitter, const Data& dd, const std::vector<int>& runs) {
    return fitted_multi(fitter, fitter.fit_all(dd, runs));
  };
  std::map<std::string, std::unique_ptr<EffectFitter>> fitters;
  for (const Effect& e : effect_library()) {
    if (std::find(d.measured_effects.begin(), d.measured_effects.end(), e.name) != d.measured_effects.end()) continue;
    const EffectFitter& fitter = *(fitters[e.name] = std::make_unique<EffectFitter>(e, nominal, plant, c.runs, cache, absorbed));
    Scored sc;
    sc.fit.name = e.name, sc.fit.parameter = e.fitted().name, sc.fit.unit = e.fitted().unit;
    score([&](const std::vector<int>& runs) { return fitted_one(fitter, data, runs); }, sc);
    EffectFitter::Multi mf = fitter.fit_all(data, all);
    fitter.add_model_error(data, all, mf);
    const double p = mf.values.front(), sp = mf.sigma.front();
    sc.fit.value = p, sc.fit.sigma = sp;
    sc.fit.at_bound = !std::isfinite(sp);
    for (std::size_t j = 0; j < e.parameters.size(); ++j) {
      const EffectParameter& q = e.parameters[j];
      FittedParameter fp{q.name, q.unit, mf.values[j], mf.sigma[j], mf.status[j], q.lower, q.upper};
      fp.sign_identifiable = q.sign_identifiable;
      if (j == 0 && !q.linear && !q.grid.empty()) fp.lower = q.grid.front(), fp.upper = q.grid.back();
      if (j == 0) fp.at_bound = sc.fit.at_bound || fp.value <= fp.lower || fp.value >= fp.upper;
      else if (fp.status == "fitted" && !q.periodic) fp.at_bound = fp.value <= q.lower || fp.value >= q.upper;
      sc.fit.parameters.push_back(fp);
    }
    sc.all = std::move(mf);
    scored.push_back(std::move(sc));
  }
  // An effect whose held-out evidence or chi^2 is not a finite number (a fold's -2 ln L not
  // finite) is no candidate: listed after the ranked ones with why, never chosen.
  for (Scored& sc : scored)
    if (!std::isfinite(sc.fit.evidence) || !std::isfinite(sc.fit.heldout_chi2))
      sc.fit.not_ranked = "its held-out evidence or chi^2 is not a finite number";
  const auto ranked_end = std::stable_partition(scored.begin(), scored.end(), [](const Scored& a) { return a.fit.not_ranked.empty(); });
  std::sort(scored.begin(), ranked_end, [](const Scored& a, const Scored& b) { return a.fit.evidence > b.fit.evidence; });
  for (const auto& sc : scored) d.effects.push_back(sc.fit);

  // 4. The verdict and the held-out shrinkage of the chosen effect(s). The held-out gap rms
  // need not shrink for "explained": the adjusted residuals leave out the runs' correlations
  // and can grow while chi^2 falls (docs/diagnose.md).
  const auto explains = [&](const Scored& sc, double rms_after) {
    return sc.fit.not_ranked.empty() && sc.fit.evidence > s.significance_sigma * s.significance_sigma &&
           (chi2_as_sigma(sc.fit.heldout_chi2, n) < s.significance_sigma ||
            rms_after <= (1 - s.explained_shrinkage) * d.rms_before_g);
  };
  const auto rms = [&](const Eigen::VectorXd& v) { return std::sqrt(v.squaredNorm() / n); };
  const Scored* best = &scored.front();
  // The targeted test: one effect's held-out evidence (the chi^2 it removes on runs it was
  // not fitted to) beyond significance^2 is a gap, also where the omnibus chi^2 and the runs'
  // z miss it because most of its shape trades with the coefficients' errors (a squeeze film,
  // ~ amplitude^4 like k4). 30 clean campaigns (blind's random truths, seeds 5000-5029) gave
  // at most 7.
  if (!d.gap_significant && best->fit.not_ranked.empty() && best->fit.evidence > s.significance_sigma * s.significance_sigma) {
    d.gap_significant = true;
    std::ostringstream w;
    w.precision(3);
    w << "; " << best->fit.name << " lowers -2 ln L of the held-out runs by " << best->fit.evidence << " (beyond "
      << s.significance_sigma * s.significance_sigma << ")";
    d.where += w.str();
  }
  double ss_b = 0, zs_b = 0;
  for (int k = 0; k < n; ++k) {
    ss_b += heldout_nominal(k) * heldout_nominal(k), zs_b += heldout_nominal(k) * heldout_nominal(k) / data.sigma2(k);
    d.runs[static_cast<std::size_t>(k)].heldout_before_g = heldout_nominal(k);
  }
  d.rms_before_g = std::sqrt(ss_b / n), d.rms_before_sigma = std::sqrt(zs_b / n);
  std::vector<std::pair<const Effect*, std::vector<double>>> chosen = {{find_effect(best->fit.name), best->fit.values()}};
  // Two effects at once, when no one effect explains a significant gap: the best effect A with
  // a second B, additive to first order (T = T_A(pA) + T_B(pB) - T_0). The candidates for B
  // are ranked by how much they lower -2 ln L of what A leaves, on the training runs of each
  // fold (so the held-out runs do not choose them); the best and the next are fitted together
  // with A by alternating one-parameter fits, each on the data less the other's part, and
  // scored on the held-out runs like a single effect. A pair is chosen only when its evidence
  // beats A's by significance_sigma^2 and it explains the gap.
  Scored pair_best;
  if (d.gap_significant && best->fit.not_ranked.empty() && !explains(*best, rms(best->heldout)) && s.try_pairs) {
    // (The two parameters' variances: each conditional on the other, their correlation left out.)
    const auto fit_pair = [&](const EffectFitter& A, const EffectFitter& B, double pB, const std::vector<int>& idx) {
      double pA = A.fit(data, idx).first;  // (pB: B's nominal, the start)
      Fitted fa, fb;
      for (int round = 0; round < 3; ++round) {
        Data db = data;
        db.measured -= A.at(pA).pred - nominal.pred;
        const auto [pb, sb] = B.fit(db, idx);
        pB = pb;
        Data da = data;
        da.measured -= B.at(pB).pred - nominal.pred;
        const auto [pa, sa] = A.fit(da, idx);
        pA = pa;
        if (round == 2) fa = fitted_at(A, pA, sa), fb = fitted_at(B, pB, sb);
      }
      Fitted f{{fa.t.pred + fb.t.pred - nominal.pred, fa.t.G + fb.t.G - nominal.G}, Eigen::MatrixXd(n, fa.slopes.cols() + fb.slopes.cols()),
               Eigen::MatrixXd::Zero(fa.cov.rows() + fb.cov.rows(), fa.cov.rows() + fb.cov.rows())};
      f.slopes << fa.slopes, fb.slopes;
      f.cov.topLeftCorner(fa.cov.rows(), fa.cov.rows()) = fa.cov;
      f.cov.bottomRightCorner(fb.cov.rows(), fb.cov.rows()) = fb.cov;
      return std::make_tuple(pA, pB, f);
    };
    const Effect& ea = *find_effect(best->fit.name);
    const EffectFitter& A = *fitters.at(ea.name);
    // The seconds ranked on the runs `idx` alone (each fold's training runs when scored): each
    // other effect fitted to what A (fitted on idx) leaves, by the drop of -2 ln L.
    std::map<std::vector<int>, std::vector<const Effect*>> ranked;
    const auto seconds = [&](const std::vector<int>& idx) -> const std::vector<const Effect*>& {
      auto it = ranked.find(idx);
      if (it != ranked.end()) return it->second;
      Data rest = data;
      rest.measured -= A.at(A.fit(data, idx).first).pred - nominal.pred;
      const double l_rest = likelihood(rest, nominal.pred, nominal.G, idx).m2logl;
      std::vector<std::pair<double, const Effect*>> drop;
      for (const Effect& eb : effect_library()) {
        if (eb.name == ea.name || !fitters.count(eb.name)) continue;
        const EffectFitter& B = *fitters.at(eb.name);
        const Table tb = B.at(B.fit(rest, idx).first);
        const double fall = l_rest - likelihood(rest, tb.pred, tb.G, idx).m2logl;
        drop.emplace_back(std::isfinite(fall) ? fall : -INFINITY, &eb);  // (not finite: last)
      }
      std::stable_sort(drop.begin(), drop.end(), [](const auto& x, const auto& y) { return x.first > y.first; });
      std::vector<const Effect*> v;
      for (const auto& x : drop) v.push_back(x.second);
      return ranked.emplace(idx, v).first->second;
    };
    PairFit chosen_pair;
    for (std::size_t j = 0; j < std::min<std::size_t>(2, effect_library().size() - 1); ++j) {
      // Candidate j: A with the j-th best second, that second chosen on each fold's training runs.
      Scored sc;
      score([&](const std::vector<int>& train) {
        const Effect& eb = *seconds(train)[j];
        return std::get<2>(fit_pair(A, *fitters.at(eb.name), eb.fitted().nominal, train));
      }, sc);
      const Effect& eb = *seconds(all)[j];
      sc.fit.name = ea.name + " + " + eb.name;
      const auto [pa, pb, t] = fit_pair(A, *fitters.at(eb.name), eb.fitted().nominal, all);
      const PairFit pf{ea.name, eb.name, pa, pb, sc.fit.evidence, sc.fit.heldout_chi2};
      d.pairs.push_back(pf);
      // (A pair whose evidence or chi^2 is not a finite number is listed, last, never chosen.)
      const bool finite = std::isfinite(sc.fit.evidence) && std::isfinite(sc.fit.heldout_chi2);
      if (finite && (pair_best.fit.name.empty() || sc.fit.evidence > pair_best.fit.evidence)) pair_best = sc, chosen_pair = pf;
    }
    const auto pair_key = [](const PairFit& p) { return std::isfinite(p.evidence) && std::isfinite(p.heldout_chi2) ? p.evidence : -INFINITY; };
    std::stable_sort(d.pairs.begin(), d.pairs.end(), [&](const PairFit& a, const PairFit& b) { return pair_key(a) > pair_key(b); });
    // A pair is the more flexible model: it must also remove at least half of the held-out gap
    // rms (a pair whose parameters the training runs leave loose can pass chi^2 without
    // predicting anything).
    if (!pair_best.fit.name.empty() &&
        pair_best.fit.evidence > best->fit.evidence + s.significance_sigma * s.significance_sigma &&
        explains(pair_best, rms(pair_best.heldout)) && rms(pair_best.heldout) <= 0.5 * d.rms_before_g) {
      best = &pair_best;
      chosen = {{find_effect(chosen_pair.a), find_effect(chosen_pair.a)->values_at(chosen_pair.pa)},
                {find_effect(chosen_pair.b), find_effect(chosen_pair.b)->values_at(chosen_pair.pb)}};
    }
  }
  double ss_a = 0, zs_a = 0;
  for (int k = 0; k < n; ++k) {
    ss_a += best->heldout(k) * best->heldout(k), zs_a += best->heldout(k) * best->heldout(k) / data.sigma2(k);
    d.runs[static_cast<std::size_t>(k)].heldout_after_g = best->heldout(k);
  }
  d.rms_after_g = std::sqrt(ss_a / n), d.rms_after_sigma = std::sqrt(zs_a / n);
  d.chosen = best->fit.name;
  if (!best->fit.not_ranked.empty()) {  // no effect ranked: nothing chosen, nothing removed
    d.chosen.clear();
    d.rms_after_g = d.rms_before_g, d.rms_after_sigma = d.rms_before_sigma;
    for (RunDiagnosis& rd : d.runs) rd.heldout_after_g = rd.heldout_before_g;
  }
  if (!d.gap_significant) {
    d.verdict = "no significant gap";
  } else if (explains(*best, d.rms_after_g)) {
    d.explained = true;
    d.verdict = "explained by " + best->fit.name;
  } else {
    d.verdict = "not explained by any known effect";
  }
  // Ambiguity: another single effect that also explains the gap with held-out evidence within
  // ambiguity_evidence of the chosen one's (2 ln of their Bayes factor on the held-out runs).
  if (d.explained && chosen.size() == 1) {
    std::vector<std::string> tied = {best->fit.name};
    for (const Scored& sc : scored)
      if (&sc != best && best->fit.evidence - sc.fit.evidence < s.ambiguity_evidence && explains(sc, rms(sc.heldout)))
        tied.push_back(sc.fit.name);
    if (tied.size() > 1) {
      d.ambiguous_with = tied;
      d.verdict = "ambiguous between " + tied[0];
      for (std::size_t i = 1; i < tied.size(); ++i) d.verdict += (i + 1 == tied.size() ? " and " : ", ") + tied[i];
    }
  }
  // The reported effects' held parameters in their fitted parameters' sigma (add_held_spread):
  // the top effect's (the one a verdict names or that stands first) and the ambiguous ones'.
  for (EffectFit& f : d.effects) {
    if (&f != &d.effects.front() && std::find(d.ambiguous_with.begin(), d.ambiguous_with.end(), f.name) == d.ambiguous_with.end())
      continue;
    const auto sc = std::find_if(scored.begin(), scored.end(), [&](const Scored& x) { return x.fit.name == f.name; });
    if (sc == scored.end() || sc->all.values.empty()) continue;
    EffectFitter::Multi mf = sc->all;
    fitters.at(f.name)->add_held_spread(data, all, mf);
    f.sigma = mf.sigma.front();
    for (std::size_t j = 0; j < f.parameters.size(); ++j) f.parameters[j].sigma = mf.sigma[j];
  }
  // Advice on the next runs: for an ambiguous or unexplained gap, the runs (direction,
  // frequency, amplitude, static orientation) where the candidates' predictions differ most,
  // in a run's sigma (the campaign's median, with the model accuracy). The candidates: the
  // ambiguous ones, else the three best by evidence, each at its fitted value; predicted from
  // the identified coefficients (what the static test took up of an effect acting at rest is
  // not given back here: a small part of such an effect's prediction).
  if (s.advise_next_runs && d.gap_significant && (!d.ambiguous_with.empty() || !d.explained)) {
    std::vector<std::pair<const Effect*, std::vector<double>>> cand;
    if (!d.ambiguous_with.empty()) {
      for (const auto& name : d.ambiguous_with)
        for (const EffectFit& f : d.effects)
          if (f.name == name) cand.emplace_back(find_effect(name), f.values());
    } else {
      for (std::size_t i = 0; i < d.effects.size() && cand.size() < 3; ++i)
        if (d.effects[i].not_ranked.empty()) cand.emplace_back(find_effect(d.effects[i].name), d.effects[i].values());
    }
    std::vector<double> sig;
    for (const RunRecord& run : c.runs) sig.push_back(run.sigma_g);
    std::nth_element(sig.begin(), sig.begin() + static_cast<std::ptrdiff_t>(sig.size() / 2), sig.end());
    const double sigma_run = sig[sig.size() / 2];
    double amax = 0;
    for (const RunRecord& run : c.runs) amax = std::max(amax, run.amplitude_g);
    std::vector<NextRun> options;
    const std::vector<Vec3> next_dirs = {Vec3(1, 0, 0), Vec3(0, 1, 0), Vec3(0, 0, 1), Vec3(1, 1, 0).normalized(),
                                    Vec3(1, 0, 1).normalized(), Vec3(0, 1, 1).normalized()};
    const std::vector<Vec3> orients = {Vec3(1, 0, 1).normalized(), Vec3(-1, 0, 1).normalized(), Vec3(1, 0, 0), Vec3(0, 1, 0)};
    for (const Vec3& dir : next_dirs)
      for (const Vec3& o : orients)
        for (double a : {amax / 4, amax / 2, amax})
          for (double f : {10.0, 30.0, 100.0, 300.0, 1000.0, 2000.0}) {
            RunRecord run;
            run.frequency_Hz = f, run.amplitude_g = a, run.direction = dir, run.orientation_g = o;
            try {
              const double p0 = predict_run_g(plant, run, nullptr, 0);
              const double sg = std::hypot(sigma_run, s.model_accuracy * p0);
              std::vector<double> pr;
              for (const auto& [e, v] : cand) pr.push_back(predict_run_g(plant, run, *e, v));
              NextRun nr{f, a, dir, o, INFINITY, ""};
              for (std::size_t i = 0; i < pr.size(); ++i)
                for (std::size_t j = i + 1; j < pr.size(); ++j) {
                  const double sep = std::abs(pr[i] - pr[j]) / sg;
                  if (sep < nr.separation_sigma) nr.separation_sigma = sep, nr.between = cand[i].first->name + " vs " + cand[j].first->name;
                }
              if (std::isfinite(nr.separation_sigma)) options.push_back(nr);
            } catch (const std::exception&) {  // a candidate's plant that cannot run there: not advised
            }
          }
    std::sort(options.begin(), options.end(), [](const NextRun& x, const NextRun& y) { return x.separation_sigma > y.separation_sigma; });
    // The best three, each a different direction or orientation where possible (else the next best).
    for (const NextRun& nr : options) {
      if (d.next_runs.size() == 3) break;
      const bool alike = std::any_of(d.next_runs.begin(), d.next_runs.end(), [&](const NextRun& x) {
        return (x.direction - nr.direction).norm() < 1e-9 && (x.orientation_g - nr.orientation_g).norm() < 1e-9;
      });
      if (!alike) d.next_runs.push_back(nr);
    }
    for (const NextRun& nr : options) {
      if (d.next_runs.size() == 3) break;
      if (std::none_of(d.next_runs.begin(), d.next_runs.end(), [&](const NextRun& x) { return &x == &nr || (x.frequency_Hz == nr.frequency_Hz && x.amplitude_g == nr.amplitude_g && (x.direction - nr.direction).norm() < 1e-9 && (x.orientation_g - nr.orientation_g).norm() < 1e-9); }))
        d.next_runs.push_back(nr);
    }
  }

  // 5. Confirmation on the ODE plant: the runs with the largest gaps re-simulated with the
  // coefficients corrected by all runs (under the chosen effect) and the effect added, and
  // without it.
  if (s.resimulate_runs > 0 && d.explained) {
    // The chosen effect(s) applied to a plant and a table motion; less what the static test
    // took up of those that act at rest.
    const auto apply_chosen = [&](PlantConfig& cfg, TableMotion& v, bool give_back) {
      for (const auto& [e, values] : chosen) {
        e->apply(values, cfg, v);
        if (give_back && e->acts_at_rest)
          for (int i = 0; i < plant::kNumCoefficients; ++i)
            cfg.coefficients[i] -= (values.front() - e->fitted().nominal) * absorbed.at(e->name)[i];
      }
    };
    Table t = tabulate(plant, c.runs, chosen[0].first, chosen[0].second, cache, absorbed);
    for (std::size_t q = 1; q < chosen.size(); ++q) {
      const Table u = tabulate(plant, c.runs, chosen[q].first, chosen[q].second, cache, absorbed);
      t.pred += u.pred - nominal.pred, t.G += u.G - nominal.G;
    }
    const Eigen::VectorXd dc = factored(data, t.G, all).conditional_mean(data.measured - t.pred);
    PlantConfig corrected = plant;
    for (int i = 0; i < plant::kNumCoefficients; ++i) corrected.coefficients[i] += dc(i);
    std::vector<int> order = all;
    // Random runs are not re-simulated here (the ODE measures them statistically, seconds each).
    // Nor are runs with measured motion (the ODE takes the commanded sine and the effects).
    std::erase_if(order, [&](int k) {
      return c.runs[static_cast<std::size_t>(k)].random.has_value() || c.runs[static_cast<std::size_t>(k)].motion.has_value();
    });
    std::sort(order.begin(), order.end(), [&](int a, int b) { return std::abs(r(a)) > std::abs(r(b)); });
    order.resize(std::min<std::size_t>(order.size(), static_cast<std::size_t>(s.resimulate_runs)));
    double sb = 0, sa = 0;
    int done = 0;
    for (int k : order) {
      const RunRecord& run = c.runs[static_cast<std::size_t>(k)];
      const vibration::SineVibration commanded = run.vibration();
      PlantConfig with = corrected;
      TableMotion table = table_motion(run);
      apply_chosen(with, table, true);
      try {
        const double ode_with = rectification::shake_sine(with, run.orientation_g, commanded, {}, {}, table.excitation().get()).measured_g;
        const double ode_without = rectification::shake_sine(corrected, run.orientation_g, commanded).measured_g;
        sb += std::pow(run.measured_g - ode_without, 2), sa += std::pow(run.measured_g - ode_with, 2);
        ++done;
      } catch (const std::exception& x) {  // a solver failure: said, and the other runs still count
        d.resimulation_failures.push_back(run.id + ": " + x.what());
      }
    }
    d.resimulated_runs = done;
    if (done > 0) {
      d.resimulated_rms_before_g = std::sqrt(sb / done);
      d.resimulated_rms_after_g = std::sqrt(sa / done);
    }
  }
  return d;
}

}  // namespace

}  // namespace vrelab::validation

// ---------------------------------------------------------------------------------------------
// Blind's family size and its shrinkage's drift line (validation/diagnosis/blind.cpp): the
// nominal model only, never an effect hypothesis.
namespace vrelab::validation {
namespace {

// A campaign as diagnose sees it before any hypothesis: the nominal simulation's gap
// r = measured - predicted and the covariance V its runs are judged by.
struct NominalView {
  Eigen::VectorXd r;
  FactoredCovariance V;
};

// The nominal simulation of a campaign as diagnose sees it before any hypothesis: the drift line
// removed (each run's sigma scaled by sigma_scale), identified from its static readings,
// tabulated, V's model accuracy at the nominal prediction.
struct Nominal {
  Data data;
  Table t;
};

Nominal nominal_of(const Campaign& c0, const DiagnoseSettings& s, double sigma_scale) {
  Campaign c = c0;
  remove_drift(c);
  for (RunRecord& r : c.runs) r.sigma_g *= sigma_scale;
  Identified id = identify(c);
  ResponseCache cache;
  Nominal nm{std::move(id.data), tabulate(id.plant, c.runs, nullptr, 0, cache, Absorbed{})};
  for (Eigen::Index k = 0; k < nm.t.pred.size(); ++k) nm.data.sigma2(k) += std::pow(s.model_accuracy * nm.t.pred(k), 2);
  return nm;
}

// The gap r = measured - predicted and the covariance V its runs are judged by, the stated
// sigma taken as it is (no sigma_scale: a family's size is judged with the runs' stated sigma).
NominalView nominal_view(const Campaign& c, const DiagnoseSettings& s) {
  const Nominal nm = nominal_of(c, s, 1);
  std::vector<int> all(static_cast<std::size_t>(nm.t.pred.size()));
  for (std::size_t k = 0; k < all.size(); ++k) all[k] = static_cast<int>(k);
  return {nm.data.measured - nm.t.pred, factored(nm.data, nm.t.G, all)};
}

}  // namespace

// Why sqrt(g^T V^-1 g) >= 5 is the issue's "a gap >= 5 sigma": with Gaussian errors of
// covariance V, the most powerful test of "no gap" against "the gap g" (known shape and size,
// Neyman-Pearson) is the statistic g^T V^-1 y / sqrt(g^T V^-1 g), distributed N(0, 1) without
// the gap and N(sqrt(g^T V^-1 g), 1) with it: sqrt(g^T V^-1 g) is the gap's separation from
// none in sigma of the best test there is, with the runs' correlations through the static
// test's coefficients counted (a gap the coefficients can take up is no gap to any test).
// The diagnosis' targeted test asks an effect's held-out evidence, the fall of -2 ln L it
// brings, for more than significance_sigma^2 = 25; for a one-parameter effect of the true
// shape that fall is (g^T V^-1 y)^2 / g^T V^-1 g, expected g^T V^-1 g + 1: a gap at 5 is the
// one the diagnosis' own test finds about half the time, no yardstick asks for more. The
// largest |g_k| / sigma_k of any one run (the old size) counts neither the take-up nor the
// runs' joint power: a squeeze film 55 sigma in one run whose shape trades with k2/k3 is a few
// sigma here; an effect below 5 sigma in every run but present in all is more.
double nominal_gap_significance(const Campaign& with, const Campaign& without, const DiagnoseSettings& s) {
  if (with.runs.size() != without.runs.size())
    throw std::invalid_argument("nominal_gap_significance: the campaigns have different runs");
  for (std::size_t k = 0; k < with.runs.size(); ++k) {
    const RunRecord &a = with.runs[k], &b = without.runs[k];
    if (a.frequency_Hz != b.frequency_Hz || a.amplitude_g != b.amplitude_g || a.direction != b.direction ||
        a.orientation_g != b.orientation_g || a.sigma_g != b.sigma_g)
      throw std::invalid_argument("nominal_gap_significance: run " + a.id + " differs between the campaigns");
  }
  const NominalView w = nominal_view(with, s), o = nominal_view(without, s);
  const Eigen::VectorXd g = w.r - o.r;
  const double q = w.V.chi2(g);
  // (A NaN would be size 0: the campaign out of its scored family without a word.)
  if (!w.V.ok() || !std::isfinite(q))
    throw std::invalid_argument("nominal_gap_significance: the gap's chi^2 is not a number (a run's variance not positive, a coefficient's variance negative, or a slope or prediction not finite)");
  return std::sqrt(std::max(0.0, q));
}

std::vector<double> heldout_nominal_gap_g(const Campaign& c, const DiagnoseSettings& s, double sigma_scale) {
  const Nominal nm = nominal_of(c, s, sigma_scale);
  const Folds folds = folds_of(c.runs);
  std::vector<double> h(c.runs.size());
  for (const auto& [key, test] : folds.test) {
    const Eigen::VectorXd a = adjusted_residual(nm.data, nm.t.pred, nm.t.G, folds.train(key), test);
    for (std::size_t i = 0; i < test.size(); ++i) h[static_cast<std::size_t>(test[i])] = a(static_cast<Eigen::Index>(i));
  }
  return h;
}

std::vector<double> drift_line_removed_g(const Campaign& c0) {
  Campaign c = c0;
  remove_drift(c);
  std::vector<double> line(c.runs.size());
  for (std::size_t k = 0; k < c.runs.size(); ++k) line[k] = c0.runs[k].measured_g - c.runs[k].measured_g;
  return line;
}

}  // namespace vrelab::validation
