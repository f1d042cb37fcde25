#include "validation/diagnosis/internal/tabulate.hpp"

#include <cmath>
#include <cstdio>
#include <map>
#include <memory>
#include <numbers>
#include <optional>
#include <stdexcept>
#include <string>

#include "rectification/prediction/frequency.hpp"
#include "rectification/prediction/gradient.hpp"
#include "rectification/prediction/random.hpp"

namespace vrelab::validation {
namespace internal {
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
// The bytes of what periodic_input(m, f) depends on, for a motion that is not a pure sine (a
// pure sine's input is exact and cheap): the tone, its harmonics, the rocking and, only where
// the fixture rocks (it turns gravity), the static orientation.
std::string motion_key(const TableMotion& m, double frequency_Hz) {
  std::string key;
  const auto put = [&key](double x) { key.append(reinterpret_cast<const char*>(&x), sizeof x); };
  put(frequency_Hz), put(m.sine.frequency_Hz);
  for (int i = 0; i < 3; ++i) put(m.sine.amplitude_g[i]), put(m.sine.phase_rad[i]);
  put(static_cast<double>(m.harmonics.size()));
  for (const vibration::Harmonic& h : m.harmonics) put(h.order), put(h.ratio), put(h.phase_rad);
  put(m.rocking_rad_per_g);
  if (m.rocking_rad_per_g != 0) {
    put(m.rocking_axis), put(m.commanded_amplitude_g);
    for (int i = 0; i < 3; ++i) put(m.static_gravity_g[i]);
  }
  return key;
}

// (values: every parameter of e.) A run whose table motion was measured (reference channels)
// already holds what a table-motion effect does.
void apply_effect(const Effect* e, ParameterValues values, const RunRecord& r, PlantConfig& cfg, TableMotion& m) {
  if (!e || (motion_used(r) && e->acts_on == ActsOn::table_motion)) return;
  e->apply(values, cfg, m);  // a random part: only random_turn of what it does to the table's motion
}

Table tabulate_runs(const PlantConfig& nominal, const std::vector<RunRecord>& runs, const Effect* e,
                    const std::vector<double>& values, ResponseCache& cache, const Absorbed& absorbed);

}  // namespace

bool motion_used(const RunRecord& r) { return r.motion && r.motion->used(); }

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
  if (const std::shared_ptr<const Table> known = cache.table(key); known && known->pred.size() == static_cast<Eigen::Index>(runs.size()))
    return *known;
  auto t = std::make_shared<const Table>(tabulate_runs(nominal, runs, e, values, cache, absorbed));
  cache.store_table(key, t);
  return *t;
}

namespace {
bool has_film(const PlantConfig& cfg) {
  return std::any_of(cfg.effects.begin(), cfg.effects.end(), [](const auto& x) { return x->amplitude_dependent_damping(); });
}

// A squeeze film on a random or sine-on-random run: its statistical linearisation's damping
// ratio (rectification::random_linearised_damping) from the loop's responses without the film
// at its nominal damping and twice it; the run's responses are then damped_response of those.
struct RandomFilm {
  PlantConfig base, twice;  // without the films; the same with the damping doubled
  double zeta = 0;          // the linearised damping ratio
  double x() const { return zeta / base.dynamics.pendulum_damping_ratio - 1; }  // (damped_response's)
};
// The plants a film's linearisation reads (its damping ratio zeta set by the caller).
RandomFilm film_plants(const PlantConfig& with_films) {
  RandomFilm out;
  out.base = rectification::without_films(with_films);
  out.twice = out.base;
  out.twice.dynamics.pendulum_damping_ratio *= 2;
  return out;
}
std::optional<vibration::SineVibration> sine_part(const RunRecord& r, const TableMotion& m) {
  return r.sine_part ? std::optional(m.sine) : std::nullopt;
}

Table tabulate_runs(const PlantConfig& nominal, const std::vector<RunRecord>& runs, const Effect* e,
                    const std::vector<double>& values, ResponseCache& cache, const Absorbed& absorbed) {
  const double p = values.empty() ? 0.0 : values.front();
  const int n = static_cast<int>(runs.size());
  Table t{Eigen::VectorXd(n), Eigen::MatrixXd(n, plant::kNumCoefficients)};
  // A film's linearised plant, balance and loop responses per (plant, motion): runs that differ
  // only in orientation share them (the same function of the same numbers).
  struct OwnLoop {  // the linearised plant's own loop (its damping is the run's)
    std::unique_ptr<const rectification::LoopResponder> responder;  // (~9 kB: made only where needed)
    std::map<double, rectification::LoopResponse> responses;
  };
  struct FilmMemo {
    PlantConfig cfg;
    rectification::PeriodicInput input;
    std::shared_ptr<OwnLoop> own;
  };
  std::map<std::string, FilmMemo> film_memo;
  // A distorted or rocking table's period resolved into harmonics once per motion in the
  // table: runs that differ only in orientation shake alike (the same function of the same
  // numbers).
  std::map<std::string, rectification::PeriodicInput> input_memo;
  const auto motion_of = [&input_memo](const RunRecord& r, const TableMotion& m) {
    if (measured_sine(r) || m.pure_sine()) return run_input(r, m);
    const std::string key = motion_key(m, r.frequency_Hz);
    auto it = input_memo.find(key);
    if (it == input_memo.end()) it = input_memo.emplace(key, run_input(r, m)).first;
    return it->second;
  };
  for (int k = 0; k < n; ++k) {
    const RunRecord& r = runs[static_cast<std::size_t>(k)];
    PlantConfig cfg = nominal;
    TableMotion m = table_motion(r);
    apply_effect(e, values, r, cfg, m);
    const PlantConfig with_films = cfg;
    // A film's linearisation, balance and own loop once per (plant, motion) in the table
    // (film_memo).
    const rectification::PeriodicInput motion = r.random ? rectification::PeriodicInput{} : motion_of(r, m);
    const std::string film_key = r.random ? std::string() : rectification::film_balance_key(with_films, m.sine, motion);
    const auto memo = film_key.empty() ? film_memo.end() : film_memo.find(film_key);
    if (memo != film_memo.end()) cfg = memo->second.cfg;
    else if (!r.random) cfg = rectification::amplitude_linearised(cfg, m.sine);
    // A film on a random run: the loop without it at its damping and twice it, by keys of the
    // effect's further values alone (the same plants at every value of the film), so every
    // value and run shares their responses.
    std::optional<RandomFilm> film;
    const rectification::DampedRandomSpectrum* film_spectrum = nullptr;
    std::string film_key0, film_key2;
    if (r.random && has_film(with_films)) {
      film = film_plants(with_films);
      film_key0 = (e ? e->name : std::string()) + '\x01';
      for (std::size_t j = 1; j < values.size(); ++j) film_key0.append(reinterpret_cast<const char*>(&values[j]), sizeof(double));
      film_key2 = film_key0 + "twice";
      const auto at0 = [&](double f) { return cache.get(film->base, film_key0, f); };
      const auto at2 = [&](double f) { return cache.get(film->twice, film_key2, f); };
      film_spectrum = &cache.damped_random_spectrum(film_key0, run_random(r), m.random_turn, kRandomRunQuadrature, at0, at2);
      film->zeta = rectification::random_linearised_damping(with_films, *film_spectrum, sine_part(r, m), at0, at2);
      cfg = film->base;
      cfg.dynamics.pendulum_damping_ratio = film->zeta;
    }
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
    // responses are kept with its balance (film_memo), not in the cache.
    const bool own = !film && cfg.dynamics.pendulum_damping_ratio != with_films.dynamics.pendulum_damping_ratio && cfg.servo;
    const std::shared_ptr<OwnLoop> own_loop = memo != film_memo.end() ? memo->second.own : std::make_shared<OwnLoop>();
    const rectification::ResponseAt h = [&](double f) {
      if (film)
        return rectification::damped_response(cache.get(film->base, film_key0, f), cache.get(film->twice, film_key2, f),
                                              film->x());
      if (!own) return cache.get(cfg, key, f);
      auto it = own_loop->responses.find(f);
      if (it == own_loop->responses.end()) {
        if (!(f > 0)) throw std::invalid_argument("frequency_Hz must be positive");
        if (!own_loop->responder) own_loop->responder = std::make_unique<const rectification::LoopResponder>(cfg);
        it = own_loop->responses.emplace(f, (*own_loop->responder)(f)).first;
      }
      return it->second;
    };
    const rectification::PeriodicInput input = r.random                  ? rectification::PeriodicInput{}
                                               : memo != film_memo.end() ? memo->second.input
                                                                         : rectification::film_harmonic_balance(with_films, cfg, motion, h);
    if (!film_key.empty() && memo == film_memo.end()) film_memo.emplace(film_key, FilmMemo{cfg, input, own_loop});
    // A random or sine-on-random run: the random part's covariances through the loop, once;
    // the sine part as the table makes it (harmonics, rocking: motion_of).
    std::optional<rectification::RandomResponse> rr;
    std::optional<rectification::PeriodicInput> sine;
    if (r.random) {
      // (A film's are this run's and value's own; without a film a random run's plant is
      // cfg, whose responses h takes from the cache: !own.)
      rr = film ? rectification::random_response_at_damping(*film_spectrum, film->x())
                : cache.random_response(cfg, key, run_random(r), m.random_turn, kRandomRunQuadrature);
      if (r.sine_part) sine = motion_of(r, m);
      // A pickoff nonlinearity (its hypothesis): its second order's moments (second_order.hpp),
      // the same at every value of it (a film's loop is this run's own).
      else if (rectification::pickoff_p2_per_rad(cfg) != 0)
        rr->pickoff = film ? rectification::gaussian_pickoff_moments(cfg, run_random(r), h, m.random_turn)
                           : cache.pickoff_moments(cfg, key, run_random(r), m.random_turn, h);
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
    // What does not depend on the coefficients (the motion through the loop, the period's
    // averages, a random part's Gaussian moments) once for the gradient's 12 evaluations (the
    // same numbers).
    std::optional<rectification::PreparedPeriodicRectification> periodic;
    std::optional<rectification::PreparedRandomRectification> random;
    if (rr) random.emplace(cfg, r.orientation_g, *rr, sine, h);
    else periodic.emplace(cfg, r.orientation_g, input, h);
    const auto f = [&](const Coefficients& co) {
      Coefficients q;
      for (int i = 0; i < plant::kNumCoefficients; ++i) q[i] = co[i] + shift[i];
      return random ? (*random)(q).total_g() : (*periodic)(q).total_g();
    };
    const CoefArray g = rectification::prediction_gradient(f, nominal.coefficients);
    for (int i = 0; i < plant::kNumCoefficients; ++i) t.G(k, i) = g[i];
    t.pred(k) = f(nominal.coefficients);
  }
  return t;
}
}  // namespace

// At one value of the effect's first parameter, the others nominal.
Table tabulate(const PlantConfig& nominal, const std::vector<RunRecord>& runs, const Effect* e, double p,
               ResponseCache& cache, const Absorbed& absorbed) {
  return tabulate(nominal, runs, e, e ? e->values_at(p) : std::vector<double>{}, cache, absorbed);
}

}  // namespace internal

using plant::Coefficients;
using plant::PlantConfig;
using internal::apply_effect;
using internal::measured_sine;
using internal::run_input;
using internal::run_random;
using internal::has_film;
using internal::RandomFilm;
using internal::film_plants;
using internal::sine_part;
using internal::kRandomRunQuadrature;

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

void describe_random_motion(RunRecord& r) {
  if (!r.random) throw std::invalid_argument("describe_random_motion: run " + r.id + " has no random part");
  Vec3 rms = Vec3::Zero();
  double moment1 = 0;
  for (int i = 0; i < 3; ++i)
    if (const auto& t = r.random->psd[static_cast<std::size_t>(i)]) {
      rms[i] = vibration::rms_g(*t);
      moment1 += vibration::psd_moment(vibration::resolve(*t), 1);
    }
  r.frequency_Hz = moment1 / rms.squaredNorm(), r.amplitude_g = std::sqrt(2.0) * rms.norm(), r.direction = rms.normalized();
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
  // A film on a random run: as tabulate_runs, the responses without it at its damping and
  // twice it (each plant linearised once).
  std::optional<RandomFilm> film;
  std::optional<rectification::DampedRandomSpectrum> film_spectrum;
  std::optional<rectification::LoopResponder> at0, at2;
  std::map<double, std::pair<rectification::LoopResponse, rectification::LoopResponse>> film_responses;
  const auto film_at = [&](double f) -> const std::pair<rectification::LoopResponse, rectification::LoopResponse>& {
    auto it = film_responses.find(f);
    if (it == film_responses.end()) it = film_responses.emplace(f, std::make_pair((*at0)(f), (*at2)(f))).first;
    return it->second;
  };
  if (r.random && has_film(with_films)) {
    film = film_plants(with_films);
    at0.emplace(film->base), at2.emplace(film->twice);
    const rectification::ResponseAt h0 = [&](double f) { return film_at(f).first; };
    const rectification::ResponseAt h2 = [&](double f) { return film_at(f).second; };
    film_spectrum = rectification::damped_random_spectrum(run_random(r), h0, h2, kRandomRunQuadrature, m.random_turn);
    film->zeta = rectification::random_linearised_damping(with_films, *film_spectrum, sine_part(r, m), h0, h2);
    cfg = film->base;
    cfg.dynamics.pendulum_damping_ratio = film->zeta;
  }
  std::map<double, rectification::LoopResponse> responses;
  std::optional<PlantConfig> loop_cfg;  // cfg with its servo designed once (ResponseCache)
  const rectification::ResponseAt h = [&](double f) {
    if (film) {
      const auto& [r0, r2] = film_at(f);
      return rectification::damped_response(r0, r2, film->x());
    }
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
    rectification::RandomResponse rr = film ? rectification::random_response_at_damping(*film_spectrum, film->x())
                                            : rectification::random_response(run_random(r), h, kRandomRunQuadrature, m.random_turn);
    std::optional<rectification::PeriodicInput> sine;
    if (r.sine_part) sine = run_input(r, m);
    else rr = rectification::with_pickoff_moments(std::move(rr), cfg, run_random(r), h, m.random_turn);
    return rectification::random_rectification_at_frequency(cfg, r.orientation_g, rr, sine, h).total_g();
  }
  return rectification::periodic_rectification(cfg, r.orientation_g, rectification::film_harmonic_balance(with_films, cfg, run_input(r, m), h), h)
      .total_g();
}
}  // namespace

}  // namespace vrelab::validation
