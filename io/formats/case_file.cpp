#include "io/formats/case_file.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <limits>
#include <numbers>
#include <set>
#include <span>
#include <sstream>

#include <fmt/format.h>
#include <toml++/toml.h>

#include "io/formats/case_file_internal.hpp"
#include "io/formats/lab_data.hpp"
#include "io/formats/paths.hpp"
#include "plant/physical.hpp"

namespace vrelab::io::internal {

std::size_t edit_distance(std::string_view a, std::string_view b) {
  std::vector<std::size_t> prev(b.size() + 1), cur(b.size() + 1);
  for (std::size_t j = 0; j <= b.size(); ++j) prev[j] = j;
  for (std::size_t i = 1; i <= a.size(); ++i) {
    cur[0] = i;
    for (std::size_t j = 1; j <= b.size(); ++j)
      cur[j] = std::min({prev[j] + 1, cur[j - 1] + 1, prev[j - 1] + (a[i - 1] == b[j - 1] ? 0 : 1)});
    std::swap(prev, cur);
  }
  return prev[b.size()];
}

// Physical ranges of model (1)'s coefficients. K1 in (0, 1e6] output units per g (mA/g, V/g:
// navigation instruments are ~1); every other coefficient within 1 in its unit (1 g of bias,
// 1/g, 1/g^2, 1 rad: orders beyond any accelerometer, whose values are <= 1e-2). Beyond these
// the results overflow (K1 = 1e308 would give inf with exit 0) or mean nothing.
constexpr double kMaxK1 = 1e6, kMaxCoefficient = 1.0;
void check_coefficient(const Table& t, int i, double x) {
  const std::string_view name = plant::coefficient_name(i);
  if (i == plant::K1 && !(x > 0 && x <= kMaxK1))
    t.fail(t.raw().get(name), name, fmt::format("must lie in (0, {:g}] output units per g, got {:g}", kMaxK1, x));
  if (i != plant::K1 && !(std::abs(x) <= kMaxCoefficient))
    t.fail(t.raw().get(name), name,
           fmt::format("must lie in [-{0:g}, {0:g}] in its unit (beyond any accelerometer), got {1:g}", kMaxCoefficient, x));
}

// Vibration amplitudes: at most 1000 g (shakers reach ~100 g); beyond, eq. (3)'s k3 a^3 and the
// plant's states leave any meaning (and overflow near 1e100 g).
constexpr double kMaxAmplitude_g = 1e3;
void check_amplitude(const Table& t, std::string_view key, double a) {
  if (!(a <= kMaxAmplitude_g))
    t.fail(t.raw().get(key), key, fmt::format("amplitudes must be at most {:g} g, got {:g} g", kMaxAmplitude_g, a));
}

namespace {

constexpr double kArcsec = std::numbers::pi / (180.0 * 3600.0);

nlohmann::json to_json(const toml::node& n) {
  if (auto t = n.as_table()) {
    nlohmann::json j = nlohmann::json::object();
    for (auto&& [k, v] : *t) j[std::string(k.str())] = to_json(v);
    return j;
  }
  if (auto a = n.as_array()) {
    nlohmann::json j = nlohmann::json::array();
    for (auto&& v : *a) j.push_back(to_json(v));
    return j;
  }
  if (auto v = n.as_integer()) return v->get();
  if (auto v = n.as_floating_point()) {
    const double x = v->get();
    return std::isfinite(x) ? nlohmann::json(x) : nlohmann::json(std::to_string(x));
  }
  if (auto v = n.as_boolean()) return v->get();
  if (auto v = n.as_string()) return v->get();
  // Dates and times: recorded by their type only (vrelab uses none).
  return std::string("<date/time>");
}

// A static orientation is gravity in sensor axes, in units of the local g: |a| = 1 g, within
// validation::kGravityNormTolerance_g (reproduce.hpp says why).
constexpr double kGravityNormTolerance = validation::kGravityNormTolerance_g;
void check_gravity(const Table& t, const toml::node* n, std::string_view key, const Vec3& a) {
  if (!(std::abs(a.norm() - 1) <= kGravityNormTolerance))
    t.fail(n, key,
           fmt::format("a static orientation is gravity in sensor axes [IA, PA, OA], |a| = 1 g (within {:g}); got |a| = {:.6g} g",
                       kGravityNormTolerance, a.norm()));
}

std::vector<Vec3> vec3_list(Table& t, std::string_view key, bool unit) {
  std::vector<Vec3> out;
  const toml::node* n = t.get(key, false);
  if (!n) return out;
  const toml::array* a = n->as_array();
  if (!a || a->empty()) t.fail(n, key, "expected a non-empty array of [IA, PA, OA] vectors");
  for (auto&& x : *a) {
    Vec3 v = t.vec3_of(&x, key);
    if (unit) {
      if (!(v.norm() > 0)) t.fail(&x, key, "a direction must not be zero");
      v.normalize();
    } else {
      check_gravity(t, &x, key, v);  // every unnormalised list is of orientations_g
    }
    out.push_back(v);
  }
  return out;
}

std::vector<double> number_list(Table& t, std::string_view key) {
  std::vector<double> out;
  const toml::node* n = t.get(key, false);
  if (!n) return out;
  const toml::array* a = n->as_array();
  if (!a || a->empty()) t.fail(n, key, "expected a non-empty array of numbers");
  for (auto&& x : *a) out.push_back(t.number_of(&x, key));
  return out;
}

void read_dividing_head(Table t, Case& c) {
  DividingHead h;
  const int modes = t.has("positions_per_series") + t.has("positions") + t.has("orientations_g");
  if (modes != 1)
    t.fail(nullptr, "positions_per_series",
           "give exactly one of positions_per_series, positions or orientations_g");
  if (t.has("positions_per_series")) {
    const auto n = t.integer("positions_per_series", true, 8, 1, 3600);
    std::vector<int> series{1, 2, 3};
    if (const toml::node* s = t.get("series", false)) {
      series.clear();
      const toml::array* a = s->as_array();
      if (!a || a->empty()) t.fail(s, "series", "expected a non-empty array of series numbers (1, 2, 3)");
      for (auto&& x : *a) {
        const auto v = x.value<std::int64_t>();
        if (!v || *v < 1 || *v > 3) t.fail(&x, "series", "series numbers are 1, 2 or 3");
        series.push_back(static_cast<int>(*v));
      }
    }
    h.positions = validation::equally_spaced_positions(static_cast<int>(n), series);
    h.description = std::to_string(series.size()) + " series x " + std::to_string(n) + " positions";
  } else if (const toml::node* p = t.get("positions", false)) {
    const toml::array* a = p->as_array();
    if (!a) t.fail(p, "positions", "expected an array of tables {series = 1, angle_deg = 45.0}");
    if (a->empty()) t.fail(p, "positions", "the position set is empty");
    for (auto&& x : *a) {
      const toml::table* e = x.as_table();
      if (!e) t.fail(&x, "positions", "each position is a table {series = 1, angle_deg = 45.0}");
      const toml::node* s = e->get("series");
      const toml::node* ang = e->get("angle_deg");
      if (!s || !s->is_integer() || s->as_integer()->get() < 1 || s->as_integer()->get() > 3)
        t.fail(&x, "positions", "each position needs series = 1, 2 or 3");
      if (!ang || !ang->is_number() || !std::isfinite(ang->value<double>().value()))
        t.fail(&x, "positions", "each position needs a finite angle_deg");
      for (auto&& [k, v] : *e)
        if (k.str() != "series" && k.str() != "angle_deg")
          t.fail(&v, "positions", "unknown key '" + std::string(k.str()) + "' in a position");
      h.positions.push_back(validation::series_position_deg(static_cast<int>(s->as_integer()->get()),
                                                            ang->value<double>().value()));
    }
    h.description = std::to_string(h.positions.size()) + " listed positions";
  } else {
    const toml::node* o = t.get("orientations_g", true);
    const toml::array* a = o->as_array();
    if (!a) t.fail(o, "orientations_g", "expected an array of [a_IA, a_PA, a_OA] vectors");
    if (a->empty()) t.fail(o, "orientations_g", "the position set is empty");
    for (auto&& x : *a) {
      const Vec3 v = t.vec3_of(&x, "orientations_g");
      if (std::abs(v.norm() - 1) > 1e-6)
        t.fail(&x, "orientations_g", "each orientation is gravity in sensor axes and must have norm 1 g, got " +
                                         std::to_string(v.norm()));
      h.positions.push_back(validation::vector_position(v));
    }
    h.description = std::to_string(h.positions.size()) + " listed orientations";
  }
  h.errors.initial_error_rad = t.opt_vec3("initial_error_arcsec").value_or(Vec3::Zero()) * kArcsec;
  h.errors.angle_sigma_rad = t.non_negative("angle_sigma_arcsec", 0.0) * kArcsec;
  h.errors.noise_sigma_g = t.non_negative("noise_sigma_ug", 0.0) * 1e-6;
  h.errors.repeats = static_cast<int>(t.integer("repeats", false, 1, 1, 100000));
  const std::string source = t.string("source", "model");
  if (source != "model" && source != "ode")
    t.fail(t.raw().get("source"), "source", "must be \"model\" (model (1)) or \"ode\" (the ODE plant), got \"" + source + "\"");
  h.from_ode = source == "ode";
  t.check_unknown({"positions_per_series", "series", "positions", "orientations_g", "initial_error_arcsec",
                   "angle_sigma_arcsec", "noise_sigma_ug", "repeats", "source"});
  c.dividing_head = std::move(h);
}

void read_identification(Table t, Case& c) {
  if (auto f = t.subtable("fixed", false)) {
    for (auto&& [k, v] : f->raw()) {
      const auto idx = plant::coefficient_from_name(k.str());
      if (!idx) {
        std::vector<std::string_view> names;
        for (int i = 0; i < plant::kNumCoefficients; ++i) names.push_back(plant::coefficient_name(i));
        f->check_unknown(names);
      }
      c.fixed[*idx] = f->number(k.str());
      check_coefficient(*f, *idx, *c.fixed[*idx]);
    }
  }
  t.check_unknown({"fixed"});
}

void read_sweep(Table t, Case& c) {
  rectification::SweepGrid g;
  g.frequencies_Hz = number_list(t, "frequencies_Hz");
  if (g.frequencies_Hz.empty()) {
    const double f1 = t.number("frequency_from_Hz"), f2 = t.number("frequency_to_Hz");
    const auto n = t.integer("frequency_points", true, 0, 1, 100000);
    const std::string spacing = t.string("frequency_spacing", "log");
    if (spacing != "log" && spacing != "linear")
      t.fail(t.raw().get("frequency_spacing"), "frequency_spacing", "must be \"log\" or \"linear\"");
    if (!(f1 > 0) || !(f2 > f1)) t.fail(t.raw().get("frequency_to_Hz"), "frequency_to_Hz", "need 0 < from < to");
    g.frequencies_Hz = rectification::spaced(f1, f2, static_cast<int>(n), spacing == "log");
  }
  for (double f : g.frequencies_Hz)
    if (!(f > 0)) t.fail(t.raw().get("frequencies_Hz"), "frequencies_Hz", "frequencies must be positive");
  g.amplitudes_g = number_list(t, "amplitudes_g");
  if (g.amplitudes_g.empty()) t.fail(nullptr, "amplitudes_g", "missing (required)");
  for (double a : g.amplitudes_g)
    if (!(a >= 0)) t.fail(t.raw().get("amplitudes_g"), "amplitudes_g", "amplitudes must not be negative");
  for (double a : g.amplitudes_g) check_amplitude(t, "amplitudes_g", a);
  g.directions = vec3_list(t, "directions", true);
  if (g.directions.empty()) t.fail(nullptr, "directions", "missing (required)");
  g.orientations_g = vec3_list(t, "orientations_g", false);
  if (g.orientations_g.empty()) {
    if (!c.orientation_g) t.fail(nullptr, "orientations_g", "missing, and the case has no [orientation] a_g");
    g.orientations_g.push_back(*c.orientation_g);
  }
  c.sweep_threads = static_cast<int>(t.integer("threads", false, 0, 0, 1024));
  if (c.shake.readout.active())
    for (double f : g.frequencies_Hz)
      if (f >= c.shake.readout.sample_rate_Hz / 2)
        t.fail(t.raw().get(t.has("frequencies_Hz") ? "frequencies_Hz" : "frequency_to_Hz"), "frequencies_Hz",
               "frequency " + std::to_string(f) + " Hz is at or above the Nyquist frequency of [readout] sample_rate_Hz");
  t.check_unknown({"frequencies_Hz", "frequency_from_Hz", "frequency_to_Hz", "frequency_points", "frequency_spacing",
                   "amplitudes_g", "directions", "orientations_g", "threads"});
  c.sweep = g;
}

void read_frequency_study(Table t, Case& c) {
  rectification::FrequencyStudySettings f;
  rectification::FrequencyGrid grid;
  t.read_described(f, grid);
  if (std::string why; !grid.IsValid(&why)) t.fail_sentence(why);
  if (t.has("direction")) {
    if (!(f.direction.norm() > 0)) t.fail(t.raw().get("direction"), "direction", "must not be zero");
    f.direction.normalize();
  }
  grid.apply(f);
  c.frequency_study = f;
}

// [reproduce] through its description (ReproduceSettings, its lists as written through
// ReproduceLists), then what needs the other tables: the sampling of [readout], and the static
// test, the seed and the measurement.
void read_reproduce(Table t, Case& c) {
  validation::ReproduceSettings r;
  validation::ReproduceLists lists;
  for (std::string_view key : {"frequency_Hz", "amplitudes_g", "directions", "orientations_g"}) t.get(key, true);
  auto conf = t.subtable("confirmation", true);
  for (std::string_view key : {"amplitude_g", "record_s"}) conf->get(key, true);
  t.read_described(r, lists);
  if (std::string why; !lists.IsValid(&why)) t.fail_sentence(why);
  lists.apply(r);
  // Each run is sampled with at least 10 samples per period (shake.hpp).
  if (c.shake.readout.active()) {
    if (10 * r.frequency_Hz > c.shake.readout.sample_rate_Hz)
      t.fail(t.raw().get("frequency_Hz"), "frequency_Hz",
             fmt::format("{:g} Hz needs at least 10 samples per period: [readout] sample_rate_Hz >= {:g}", r.frequency_Hz,
                         10 * r.frequency_Hz));
    for (double f : r.departure_frequencies_Hz)
      if (10 * f > c.shake.readout.sample_rate_Hz)
        t.fail(t.raw().get("departure_frequencies_Hz"), "departure_frequencies_Hz",
               fmt::format("{:g} Hz needs at least 10 samples per period: [readout] sample_rate_Hz >= {:g}", f, 10 * f));
  }
  // The fields set_by the tables read before this one.
  if (c.dividing_head) r.positions = c.dividing_head->positions, r.errors = c.dividing_head->errors;
  r.fixed = c.fixed;
  r.seed = c.seed;
  r.shake = c.shake;
  c.reproduce = r;
}

// [[campaign.random_runs]]: per table a PSD file (relative to the case file; the lab data
// format's, docs/data-format.md), its coupling, an optional rms to scale it to (g, the motion's
// magnitude), the static orientations (default: the design's; one run each) and an optional
// sine on it (sine_frequency_Hz, sine_amplitude_g, sine_direction: all three or none).
void read_random_runs(Table& t, validation::CampaignDesign& d) {
  const toml::node* n = t.get("random_runs", false);
  if (!n) return;
  const toml::array* a = n->as_array();
  if (!a || a->empty()) t.fail(n, "random_runs", "expected an array of tables [[campaign.random_runs]]");
  int index = 0;
  for (auto&& x : *a) {
    ++index;
    const toml::table* e = x.as_table();
    if (!e) t.fail(&x, "random_runs", "expected a table");
    Table rt(*e, "campaign.random_runs[" + std::to_string(index) + "]", t.file());
    const std::string file = rt.string("psd", "");
    if (file.empty()) rt.fail(nullptr, "psd", "missing (required): the PSD file (frequency_Hz, psd_IA_g2_per_Hz, ...)");
    const std::string coupling = rt.string("coupling", "common");
    if (coupling != "common" && coupling != "independent") rt.fail(rt.raw().get("coupling"), "coupling", "must be common or independent");
    const std::filesystem::path path = std::filesystem::path(t.file()).parent_path() / file;
    if (!std::filesystem::is_regular_file(path))
      rt.fail(rt.raw().get("psd"), "psd", "no PSD file " + path.string() + " (the path is relative to the case file)");
    validation::RandomRunDesign r;
    r.profile = read_psd_file(path.string(), coupling);
    if (const auto rms = rt.opt_number("rms_g")) {
      if (!(*rms > 0)) rt.fail(rt.raw().get("rms_g"), "rms_g", "must be positive");
      check_amplitude(rt, "rms_g", *rms);
      double now2 = 0;
      for (const auto& p : r.profile.psd)
        if (p) now2 += std::pow(vibration::rms_g(*p), 2);
      vibration::scale_levels(r.profile, *rms * *rms / now2);
    }
    const int sine_keys = rt.has("sine_frequency_Hz") + rt.has("sine_amplitude_g") + rt.has("sine_direction");
    if (sine_keys != 0 && sine_keys != 3)
      rt.fail(nullptr, "sine_frequency_Hz", "a sine on random needs sine_frequency_Hz, sine_amplitude_g and sine_direction");
    if (sine_keys == 3) {
      r.sine_part = true;
      r.frequency_Hz = rt.number("sine_frequency_Hz");
      r.amplitude_g = rt.number("sine_amplitude_g");
      if (!(r.frequency_Hz > 0)) rt.fail(rt.raw().get("sine_frequency_Hz"), "sine_frequency_Hz", "must be positive");
      if (!(r.amplitude_g > 0)) rt.fail(rt.raw().get("sine_amplitude_g"), "sine_amplitude_g", "must be positive");
      check_amplitude(rt, "sine_amplitude_g", r.amplitude_g);
      const auto dir = rt.opt_vec3("sine_direction");
      if (!(dir->norm() > 0)) rt.fail(rt.raw().get("sine_direction"), "sine_direction", "must not be zero");
      r.direction = dir->normalized();
    }
    std::vector<Vec3> orientations = vec3_list(rt, "orientations_g", false);
    if (orientations.empty()) orientations = d.orientations_g;
    rt.check_unknown({"psd", "coupling", "rms_g", "orientations_g", "sine_frequency_Hz", "sine_amplitude_g", "sine_direction"});
    for (const Vec3& o : orientations) {
      r.orientation_g = o;
      d.random_runs.push_back(r);
    }
  }
}

void read_campaign(Table t, Case& c) {
  CampaignSpec s;
  s.name = t.string("name", s.name);
  if (const toml::node* n = t.get("hidden", false)) {
    const toml::array* a = n->as_array();
    if (!a) t.fail(n, "hidden", "expected an array of tables { name = \"...\", parameter = ... }");
    for (auto&& x : *a) {
      const toml::table* e = x.as_table();
      if (!e) t.fail(&x, "hidden", "expected a table { name = \"...\", parameter = ... }");
      Table et(*e, "campaign.hidden", t.file());
      validation::HiddenEffect h;
      h.name = et.string("name", "");
      if (!validation::find_effect(h.name)) {
        std::string names;
        for (const auto& m : validation::effect_registry()) names += " " + m.name;
        t.fail(&x, "hidden", "unknown effect '" + h.name + "'; known:" + names);
      }
      const toml::node* p = e->get("parameter");
      if (!p || !p->is_number()) t.fail(&x, "hidden", "each hidden effect needs a numeric parameter");
      h.parameter = p->value<double>().value();
      std::string why;  // the registry's check of the effect's values
      if (!validation::find_effect(h.name)->is_valid(h.values(*validation::find_effect(h.name)), &why)) t.fail(&x, "hidden", why);
      s.hidden.push_back(h);
    }
  }
  validation::CampaignDesign& d = s.design;
  if (auto f = number_list(t, "frequencies_Hz"); !f.empty()) d.frequencies_Hz = f;
  if (auto a = number_list(t, "amplitudes_g"); !a.empty()) d.amplitudes_g = a;
  if (auto v = vec3_list(t, "directions", true); !v.empty()) d.directions = v;
  if (auto v = vec3_list(t, "orientations_g", false); !v.empty()) d.orientations_g = v;
  for (double f : d.frequencies_Hz)
    if (!(f > 0)) t.fail(t.raw().get("frequencies_Hz"), "frequencies_Hz", "frequencies must be positive");
  for (double a : d.amplitudes_g)
    if (!(a > 0)) t.fail(t.raw().get("amplitudes_g"), "amplitudes_g", "amplitudes must be positive");
  for (double a : d.amplitudes_g) check_amplitude(t, "amplitudes_g", a);
  d.run_sigma_g = t.non_negative("run_sigma_ug", d.run_sigma_g * 1e6) * 1e-6;
  if (!(d.run_sigma_g > 0)) t.fail(t.raw().get("run_sigma_ug"), "run_sigma_ug", "must be positive");
  d.positions_per_series = static_cast<int>(t.integer("positions_per_series", false, d.positions_per_series, 8, 360));
  if (const toml::node* n = t.get("raw_series", false)) {
    if (!n->is_boolean()) t.fail(n, "raw_series", "expected true or false");
    s.raw_series = n->as_boolean()->get();
  }
  d.raw_noise_sigma_g = t.non_negative("raw_noise_sigma_ug", d.raw_noise_sigma_g * 1e6) * 1e-6;
  d.raw_record_s = t.non_negative("raw_record_s", d.raw_record_s);
  const double rate = t.non_negative("raw_sample_rate_Hz", 2000.0);
  if (s.raw_series) {
    if (!(rate > 0)) t.fail(t.raw().get("raw_sample_rate_Hz"), "raw_sample_rate_Hz", "must be positive");
    if (!(d.raw_record_s > 0)) t.fail(t.raw().get("raw_record_s"), "raw_record_s", "must be positive");
    d.raw_sample_rate_Hz = rate;
  }
  d.random_record_s = t.non_negative("random_record_s", d.random_record_s);
  if (!(d.random_record_s > 0) || d.random_record_s > 3600)
    t.fail(t.raw().get("random_record_s"), "random_record_s", "must lie in (0, 3600] s");
  read_random_runs(t, d);
  if (s.raw_series && !d.random_runs.empty())
    t.fail(t.raw().get("random_runs"), "random_runs", "raw records of random runs are not made: leave raw_series out");
  t.check_unknown({"name", "hidden", "frequencies_Hz", "amplitudes_g", "directions", "orientations_g", "run_sigma_ug",
                   "positions_per_series", "raw_series", "raw_sample_rate_Hz", "raw_noise_sigma_ug", "raw_record_s",
                   "random_runs", "random_record_s"});
  c.campaign = s;
}

}  // namespace
}  // namespace vrelab::io::internal

namespace vrelab::io {

Case read_case(const std::string& path) {
  using namespace internal;  // Table and the tables' readers (case_file_internal.hpp)
  require_readable_file(path, "the case file");
  toml::table root;
  try {
    root = toml::parse_file(path);
  } catch (const toml::parse_error& e) {
    throw FormatError({.file = path, .line = static_cast<long>(e.source().begin.line)}, std::string(e.description()));
  }
  Case c;
  c.path = path;
  c.content = to_json(root);
  Table top(root, "", path);
  if (auto g = top.opt_number("g_m_per_s2")) {
    if (*g < 9.7 || *g > 9.9)
      top.fail(root.get("g_m_per_s2"), "g_m_per_s2", "a site's gravity lies between 9.7 and 9.9 m/s^2");
    c.g_m_per_s2 = *g;
  }
  if (auto t = top.subtable("instrument", false)) {
    c.instrument = t->string("name", c.instrument);
    c.output_unit_given = t->has("output_unit");
    c.output_unit = t->string("output_unit", c.output_unit);
    t->check_unknown({"name", "output_unit"});
  }
  if (auto t = top.subtable("coefficients", false)) read_coefficients(*t, c);
  if (auto t = top.subtable("orientation", false)) {
    c.orientation_g = t->vec3("a_g");
    check_gravity(*t, t->raw().get("a_g"), "a_g", *c.orientation_g);
    t->check_unknown({"a_g"});
  }
  if (auto t = top.subtable("vibration", false)) read_vibration(*t, c);
  if (auto t = top.subtable("range", false)) {
    const double r = t->number("limit_g");
    if (r <= 0) t->fail(t->raw().get("limit_g"), "limit_g", "must be positive");
    c.range_limit_g = r;
    t->check_unknown({"limit_g"});
  }
  if (auto t = top.subtable("dividing_head", false)) read_dividing_head(*t, c);
  if (auto t = top.subtable("identification", false)) read_identification(*t, c);
  if (auto t = top.subtable("run", false)) {
    c.seed = static_cast<std::uint64_t>(t->integer("seed", false, 1, 0, std::numeric_limits<std::int64_t>::max()));
    t->check_unknown({"seed"});
  }
  if (auto t = top.subtable("plant", false)) read_plant(*t, c);
  else if (c.coefficients) c.plant.coefficients = *c.coefficients;
  if (auto t = top.subtable("readout", false)) read_readout(*t, c);
  if (auto t = top.subtable("shake", false)) read_shake(*t, c);
  c.shake.readout.seed = c.seed;
  if (auto t = top.subtable("sweep", false)) read_sweep(*t, c);
  if (auto t = top.subtable("shaker", false)) {
    read_shaker(*t, c);
    c.shaker.line = t->line(&t->raw());
  }
  if (auto t = top.subtable("frequency_study", false)) read_frequency_study(*t, c);
  if (auto t = top.subtable("reproduce", false)) read_reproduce(*t, c);
  if (auto t = top.subtable("campaign", false)) read_campaign(*t, c);
  top.check_unknown({"g_m_per_s2", "instrument", "coefficients", "orientation", "vibration", "range",
                     "dividing_head", "identification", "run", "plant", "readout", "shake", "sweep", "shaker",
                     "frequency_study", "reproduce", "campaign"});
  return c;
}

void require(const Case& c, bool present, const std::string& table, const std::string& command) {
  if (!present) throw FormatError({.file = c.path}, command + " needs a [" + table + "] table");
}

}  // namespace vrelab::io
