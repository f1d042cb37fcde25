#include "io/formats/case_file.hpp"

#include <algorithm>
#include <functional>
#include <map>
#include <memory>
#include <cctype>
#include <cmath>
#include <cstdint>
#include <limits>
#include <filesystem>
#include <numbers>
#include <set>
#include <span>
#include <sstream>

#include <fmt/format.h>
#include <toml++/toml.h>

#include "plant/physical.hpp"

namespace vrelab::io {
namespace {

constexpr double kArcsec = std::numbers::pi / (180.0 * 3600.0);
constexpr double kDeg = std::numbers::pi / 180.0;

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

// One TOML table with the keys it allows; every access marks the key as used.
class Table {
 public:
  Table(const toml::table& t, std::string name, const std::string& file)
      : t_(t), name_(std::move(name)), file_(file) {}

  bool has(std::string_view key) const { return t_.contains(key); }
  int line(const toml::node* n) const { return n ? static_cast<int>(n->source().begin.line) : 0; }

  // The key's place (the node's line, else the table's) and why it is wrong.
  [[noreturn]] void fail(const toml::node* n, std::string_view key, const std::string& what) const {
    throw FormatError({.file = file_, .line = line(n ? n : &t_), .table = name_, .key = std::string(key), .kind = KeyKind::toml_key},
                      what);
  }

  const toml::node* get(std::string_view key, bool required) {
    used_.insert(std::string(key));
    const toml::node* n = t_.get(key);
    if (!n && required) {
      // A required key missing is most often a typo of it (k_2 for k2, frequency_hz for
      // frequency_Hz): name the key the file has, on its line, with the match.
      for (auto&& [k, v] : t_) {
        const std::string have(k.str());
        if (used_.count(have)) continue;
        if (normalised(have) == normalised(key) || (key.size() > 3 && edit_distance(have, key) == 1))
          fail(&v, have, "unknown key (did you mean '" + std::string(key) + "'?); " + std::string(key) +
                             " is required");
      }
      fail(nullptr, key, "missing (required)");
    }
    return n;
  }
  // Lower case without '_' and '-': keys that differ only so are the same key mistyped.
  static std::string normalised(std::string_view k) {
    std::string out;
    for (char ch : k)
      if (ch != '_' && ch != '-') out += static_cast<char>(std::tolower(static_cast<unsigned char>(ch)));
    return out;
  }

  double number_of(const toml::node* n, std::string_view key) const {
    if (!n->is_number()) fail(n, key, std::string("expected a number, got ") + type_name(*n));
    const double x = n->value<double>().value();
    if (!std::isfinite(x)) fail(n, key, "must be a finite number, got " + std::to_string(x));
    return x;
  }
  double number(std::string_view key) { return number_of(get(key, true), key); }
  std::optional<double> opt_number(std::string_view key) {
    const toml::node* n = get(key, false);
    return n ? std::optional<double>(number_of(n, key)) : std::nullopt;
  }
  double non_negative(std::string_view key, double fallback) {
    const auto x = opt_number(key);
    if (x && *x < 0) fail(t_.get(key), key, "must not be negative, got " + std::to_string(*x));
    return x.value_or(fallback);
  }
  std::int64_t integer(std::string_view key, bool required, std::int64_t fallback, std::int64_t min,
                       std::int64_t max = std::numeric_limits<std::int32_t>::max()) {
    const toml::node* n = get(key, required);
    if (!n) return fallback;
    if (!n->is_integer()) fail(n, key, std::string("expected an integer, got ") + type_name(*n));
    const std::int64_t v = n->as_integer()->get();
    if (v < min) fail(n, key, "must be at least " + std::to_string(min) + ", got " + std::to_string(v));
    if (v > max) fail(n, key, "must be at most " + std::to_string(max) + ", got " + std::to_string(v));
    return v;
  }
  std::string string(std::string_view key, std::string fallback) {
    const toml::node* n = get(key, false);
    if (!n) return fallback;
    if (!n->is_string()) fail(n, key, std::string("expected a string, got ") + type_name(*n));
    return n->as_string()->get();
  }
  Vec3 vec3_of(const toml::node* n, std::string_view key) const {
    const toml::array* a = n->as_array();
    if (!a || a->size() != 3) fail(n, key, "expected an array of 3 numbers [IA, PA, OA]");
    Vec3 v;
    for (int i = 0; i < 3; ++i) v[i] = number_of(a->get(static_cast<std::size_t>(i)), key);
    return v;
  }
  Vec3 vec3(std::string_view key) { return vec3_of(get(key, true), key); }
  std::optional<Vec3> opt_vec3(std::string_view key) {
    const toml::node* n = get(key, false);
    return n ? std::optional<Vec3>(vec3_of(n, key)) : std::nullopt;
  }
  std::optional<Table> subtable(std::string_view key, bool required) {
    const toml::node* n = get(key, required);
    if (!n) return std::nullopt;
    if (!n->is_table()) fail(n, key, std::string("expected a table, got ") + type_name(*n));
    return Table(*n->as_table(), name_.empty() ? std::string(key) : name_ + "." + std::string(key), file_);
  }

  // Any key not read is a typo or a key of another version: say so, with the closest match.
  void check_unknown(const std::vector<std::string_view>& allowed) const {
    for (auto&& [k, v] : t_) {
      const std::string key(k.str());
      if (used_.count(key)) continue;
      std::string best;
      std::size_t best_d = 4;
      for (auto a : allowed) {
        const std::size_t d = edit_distance(key, a);
        if (d < best_d) best_d = d, best = std::string(a);
      }
      std::string msg = "unknown key";
      if (!best.empty()) msg += " (did you mean '" + best + "'?)";
      fail(&v, key, msg);
    }
  }

  const toml::table& raw() const { return t_; }
  const std::string& name() const { return name_; }
  const std::string& file() const { return file_; }

 private:
  static const char* type_name(const toml::node& n) {
    switch (n.type()) {
      case toml::node_type::string: return "a string";
      case toml::node_type::integer: return "an integer";
      case toml::node_type::floating_point: return "a number";
      case toml::node_type::boolean: return "a boolean";
      case toml::node_type::array: return "an array";
      case toml::node_type::table: return "a table";
      default: return "a date or time";
    }
  }
  const toml::table& t_;
  std::string name_;
  std::string file_;
  std::set<std::string> used_;
};

// Physical ranges of model (1)'s coefficients. K1 in (0, 1e6] output units per g (mA/g, V/g:
// navigation instruments are ~1); every other coefficient within 1 in its unit (1 g of bias,
// 1/g, 1/g^2, 1 rad: orders beyond any accelerometer, whose values are <= 1e-2). Beyond these
// the results overflow (K1 = 1e308 gave inf with exit 0) or mean nothing.
constexpr double kMaxK1 = 1e6, kMaxCoefficient = 1.0;
void check_coefficient(const Table& t, int i, double x) {
  const std::string_view name = plant::coefficient_name(i);
  if (i == plant::K1 && !(x > 0 && x <= kMaxK1))
    t.fail(t.raw().get(name), name, fmt::format("must lie in (0, {:g}] output units per g, got {:g}", kMaxK1, x));
  if (i != plant::K1 && !(std::abs(x) <= kMaxCoefficient))
    t.fail(t.raw().get(name), name,
           fmt::format("must lie in [-{0:g}, {0:g}] in its unit (beyond any accelerometer), got {1:g}", kMaxCoefficient, x));
}

void read_coefficients(Table t, Case& c) {
  plant::Coefficients k;
  std::vector<std::string_view> names;
  for (int i = 0; i < plant::kNumCoefficients; ++i) {
    names.push_back(plant::coefficient_name(i));
    k[i] = t.number(plant::coefficient_name(i));
    check_coefficient(t, i, k[i]);
  }
  t.check_unknown(names);
  c.coefficients = k;
}

// Vibration amplitudes: at most 1000 g (shakers reach ~100 g); beyond, eq. (3)'s k3 a^3 and the
// plant's states leave any meaning (and overflow near 1e100 g).
constexpr double kMaxAmplitude_g = 1e3;
void check_amplitude(const Table& t, std::string_view key, double a) {
  if (!(a <= kMaxAmplitude_g))
    t.fail(t.raw().get(key), key, fmt::format("amplitudes must be at most {:g} g, got {:g} g", kMaxAmplitude_g, a));
}

vibration::SineVibration read_sine_part(Table& t, bool frequency_required) {
  vibration::SineVibration v;
  v.amplitude_g = t.vec3("amplitude_g");
  v.phase_rad = t.opt_vec3("phase_deg").value_or(Vec3::Zero()) * kDeg;
  v.frequency_Hz = frequency_required ? t.number("frequency_Hz") : t.non_negative("frequency_Hz", 0.0);
  if (frequency_required && !(v.frequency_Hz > 0)) t.fail(t.raw().get("frequency_Hz"), "frequency_Hz", "must be positive");
  for (int i = 0; i < 3; ++i) check_amplitude(t, "amplitude_g", v.amplitude_g[i]);
  for (int i = 0; i < 3; ++i)
    if (v.amplitude_g[i] < 0)
      t.fail(t.raw().get("amplitude_g"), "amplitude_g",
             "amplitudes must not be negative (reverse an axis with phase_deg = 180)");
  return v;
}

// A PSD table: rows [frequency_Hz, g2_per_Hz] or {frequency_Hz = f, slope_dB_per_octave = s}.
vibration::PsdTable read_psd(Table& t, std::string_view key, const toml::node* n) {
  const toml::array* a = n->as_array();
  if (!a || a->size() < 2) t.fail(n, key, "expected at least two rows [frequency_Hz, g2_per_Hz]");
  vibration::PsdTable table;
  std::size_t row = 0;
  for (auto&& x : *a) {
    ++row;
    const std::string where = std::string(key) + " row " + std::to_string(row);
    if (const toml::array* r = x.as_array()) {
      if (r->size() != 2) t.fail(&x, where, "a row is [frequency_Hz, g2_per_Hz]");
      table.rows.push_back(vibration::PsdRow::level(t.number_of(r->get(0), where), t.number_of(r->get(1), where)));
    } else if (const toml::table* rt = x.as_table()) {
      const toml::node* f = rt->get("frequency_Hz");
      const toml::node* sl = rt->get("slope_dB_per_octave");
      if (!f || !sl || rt->size() != 2) t.fail(&x, where, "a slope row is {frequency_Hz = f, slope_dB_per_octave = s}");
      table.rows.push_back(vibration::PsdRow::slope(t.number_of(f, where), t.number_of(sl, where)));
    } else {
      t.fail(&x, where, "a row is [frequency_Hz, g2_per_Hz] or {frequency_Hz, slope_dB_per_octave}");
    }
  }
  try {
    vibration::validate(table);
  } catch (const std::invalid_argument& e) {
    t.fail(n, key, e.what());
  }
  return table;
}

// Random part: PSD tables per axis (psd_IA, psd_PA, psd_OA) or a Gaussian rms_g.
void read_random_part(Table& t, VibrationSpec& v, bool psd_required) {
  vibration::RandomProfile profile;
  bool any = false;
  const char* names[3] = {"psd_IA", "psd_PA", "psd_OA"};
  for (int i = 0; i < 3; ++i)
    if (const toml::node* n = t.get(names[i], false)) {
      profile.psd[static_cast<std::size_t>(i)] = read_psd(t, names[i], n);
      any = true;
    }
  const std::string coupling = t.string("coupling", "common");
  if (coupling != "common" && coupling != "independent")
    t.fail(t.raw().get("coupling"), "coupling", "must be \"common\" (one direction) or \"independent\"");
  profile.coupling = coupling == "common" ? vibration::AxisCoupling::common : vibration::AxisCoupling::independent;
  if (any) {
    if (t.has("rms_g")) t.fail(t.raw().get("rms_g"), "rms_g", "give PSD tables or rms_g, not both");
    v.psd = profile;
    v.gaussian = vibration::gaussian_equivalent(profile);
    v.duration_s = t.opt_number("duration_s").value_or(v.duration_s);
    if (!(v.duration_s > 0)) t.fail(t.raw().get("duration_s"), "duration_s", "must be positive");
    return;
  }
  if (psd_required) t.fail(nullptr, "psd_IA", "a shaken random profile needs PSD tables psd_IA / psd_PA / psd_OA");
  vibration::RandomVibration g;
  g.rms_g = t.vec3("rms_g");
  for (int i = 0; i < 3; ++i) check_amplitude(t, "rms_g", std::abs(g.rms_g[i]));
  if (const toml::node* n = t.get("correlation", false)) {
    const toml::array* rows = n->as_array();
    if (!rows || rows->size() != 3) t.fail(n, "correlation", "expected a 3 x 3 array of numbers");
    for (int i = 0; i < 3; ++i) g.correlation.row(i) = t.vec3_of(rows->get(static_cast<std::size_t>(i)), "correlation");
  }
  for (int i = 0; i < 3; ++i)
    if (g.rms_g[i] < 0) t.fail(t.raw().get("rms_g"), "rms_g", "rms values must not be negative");
  try {
    vibration::validate(g);
  } catch (const std::invalid_argument& e) {
    t.fail(t.raw().get("correlation"), "correlation", e.what());
  }
  v.gaussian = g;
}

void read_vibration(Table t, Case& c) {
  VibrationSpec v;
  v.line = t.line(&t.raw());
  const std::string type = t.string("type", "");
  const auto kind = rectification::parse_vibration_kind(type);
  if (!kind)
    t.fail(t.raw().get("type"), "type",
           "must be \"sine\", \"random\", \"sine_on_random\" or \"swept_sine\", got \"" + type + "\"");
  v.type = *kind;
  if (v.type == VibrationKind::sine) {
    v.sine = read_sine_part(t, false);
    t.check_unknown({"type", "amplitude_g", "phase_deg", "frequency_Hz"});
  } else if (v.type == VibrationKind::random) {
    read_random_part(t, v, false);
    t.check_unknown({"type", "rms_g", "correlation", "psd_IA", "psd_PA", "psd_OA", "coupling", "duration_s"});
  } else if (v.type == VibrationKind::sine_on_random) {
    v.sine = read_sine_part(t, true);
    read_random_part(t, v, false);
    t.check_unknown({"type", "amplitude_g", "phase_deg", "frequency_Hz", "rms_g", "correlation", "psd_IA", "psd_PA",
                     "psd_OA", "coupling", "duration_s"});
  } else {  // swept_sine
    vibration::SweptSine s;
    s.amplitude_g = t.vec3("amplitude_g");
    s.phase_rad = t.opt_vec3("phase_deg").value_or(Vec3::Zero()) * kDeg;
    s.start_frequency_Hz = t.number("start_frequency_Hz");
    s.end_frequency_Hz = t.number("end_frequency_Hz");
    const std::string law = t.string("law", "log");
    if (law != "log" && law != "linear") t.fail(t.raw().get("law"), "law", "must be \"log\" or \"linear\"");
    s.law = law == "log" ? vibration::SweepLaw::logarithmic : vibration::SweepLaw::linear;
    if (law == "log")
      s.rate_octaves_per_min = t.number("rate_octaves_per_min");
    else
      s.rate_Hz_per_s = t.number("rate_Hz_per_s");
    try {
      vibration::validate(s);
    } catch (const std::invalid_argument& e) {
      t.fail(nullptr, "swept_sine", e.what());
    }
    v.swept = s;
    v.sine.amplitude_g = s.amplitude_g;
    v.sine.phase_rad = s.phase_rad;
    v.duration_s = vibration::sweep_duration_s(s);
    t.check_unknown({"type", "amplitude_g", "phase_deg", "start_frequency_Hz", "end_frequency_Hz", "law",
                     "rate_octaves_per_min", "rate_Hz_per_s"});
  }
  c.vibration = v;
}

int axis_index(Table& t, std::string_view key, const std::string& name) {
  if (name == "IA") return IA;
  if (name == "PA") return PA;
  if (name == "OA") return OA;
  t.fail(t.raw().get(key), key, "axes are \"IA\", \"PA\" or \"OA\", got \"" + name + "\"");
}

void read_shaker(Table t, Case& c) {
  ShakerSpec& s = c.shaker;
  if (auto x = t.opt_number("stroke_limit_m")) s.limits.stroke_peak_to_peak_m = *x;
  if (auto x = t.opt_number("velocity_limit_m_per_s")) s.limits.velocity_peak_m_per_s = *x;
  if (!(s.limits.stroke_peak_to_peak_m > 0)) t.fail(t.raw().get("stroke_limit_m"), "stroke_limit_m", "must be positive");
  if (!(s.limits.velocity_peak_m_per_s > 0))
    t.fail(t.raw().get("velocity_limit_m_per_s"), "velocity_limit_m_per_s", "must be positive");
  if (auto x = t.subtable("transverse", false)) {
    vibration::TransverseSpec ts;
    ts.from_axis = axis_index(*x, "from_axis", x->string("from_axis", "IA"));
    ts.to_axis = axis_index(*x, "to_axis", x->string("to_axis", "PA"));
    ts.ratio = x->non_negative("ratio", 0.0);
    ts.phase_rad = x->opt_number("phase_deg").value_or(0.0) * kDeg;
    try {
      vibration::validate(ts);
    } catch (const std::invalid_argument& e) {
      x->fail(nullptr, "transverse", e.what());
    }
    x->check_unknown({"from_axis", "to_axis", "ratio", "phase_deg"});
    s.transverse = ts;
  }
  if (const toml::node* n = t.get("harmonics", false)) {
    const toml::array* a = n->as_array();
    if (!a) t.fail(n, "harmonics", "expected an array of {order = 2, ratio = 0.05, phase_deg = 0}");
    for (auto&& x : *a) {
      const toml::table* h = x.as_table();
      if (!h) t.fail(&x, "harmonics", "each harmonic is {order = 2, ratio = 0.05, phase_deg = 0}");
      Table ht(*h, "shaker.harmonics", t.file());
      vibration::Harmonic hm;
      const toml::node* order = h->get("order");
      if (!order || !order->is_integer()) t.fail(&x, "harmonics", "order must be an integer >= 2");
      hm.order = static_cast<int>(order->as_integer()->get());
      const toml::node* ratio = h->get("ratio");
      if (!ratio || !ratio->is_number()) t.fail(&x, "harmonics", "ratio must be a number");
      hm.ratio = ratio->value<double>().value();
      if (const toml::node* ph = h->get("phase_deg")) hm.phase_rad = ph->value<double>().value_or(0.0) * kDeg;
      for (auto&& [k, v] : *h)
        if (k.str() != "order" && k.str() != "ratio" && k.str() != "phase_deg")
          t.fail(&v, "harmonics", "unknown key '" + std::string(k.str()) + "' in a harmonic");
      s.harmonics.push_back(hm);
    }
    try {
      vibration::validate(s.harmonics);
    } catch (const std::invalid_argument& e) {
      t.fail(n, "harmonics", e.what());
    }
  }
  if (auto x = t.subtable("rocking", false)) {
    vibration::RockingSpec r;
    r.axis = x->opt_vec3("axis").value_or(Vec3::UnitZ());
    r.amplitude_rad = x->non_negative("amplitude_rad", 0.0);
    r.phase_rad = x->opt_number("phase_deg").value_or(0.0) * kDeg;
    if (auto arm = x->opt_vec3("lever_arm_m")) r.lever_arm_m = *arm;
    x->check_unknown({"axis", "amplitude_rad", "phase_deg", "lever_arm_m"});
    s.rocking = r;  // static gravity and g are filled in when the run is built
  }
  t.check_unknown({"stroke_limit_m", "velocity_limit_m_per_s", "transverse", "harmonics", "rocking"});
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

bool boolean(Table& t, std::string_view key, bool fallback) {
  const toml::node* n = t.get(key, false);
  if (!n) return fallback;
  if (!n->is_boolean()) t.fail(n, key, "expected true or false");
  return n->as_boolean()->get();
}

// The plant modules beyond model (1) a case can switch on: one entry per
// [plant.effects.<name>] table, with its own keys (a plant module's construction parameters,
// not the diagnosis' effect parameters of validation/diagnosis/effect.hpp, hence a reader of
// its own). Adding a plant module a case can use is a class in plant/effects/ and an entry here.
using EffectReader = std::function<std::shared_ptr<const plant::Effect>(Table&)>;
const std::map<std::string, EffectReader>& effect_readers() {
  static const std::map<std::string, EffectReader> readers{
      {"pickoff_nonlinearity",
       [](Table& t) {
         auto e = std::make_shared<plant::PickoffNonlinearity>(t.number("p2_per_rad"));
         t.check_unknown({"p2_per_rad"});
         return e;
       }},
      {"pendulum_geometry",
       [](Table& t) {
         t.check_unknown({});
         return std::make_shared<plant::PendulumGeometry>();
       }},
      {"current_saturation",
       [](Table& t) {
         const double limit = t.number("limit_g");
         if (!(limit > 0)) t.fail(t.raw().get("limit_g"), "limit_g", "must be positive");
         t.check_unknown({"limit_g"});
         return std::make_shared<plant::CurrentSaturation>(limit);
       }},
      {"mechanical_mode",
       [](Table& t) {
         const double f = t.number("frequency_Hz"), z = t.number("damping_ratio");
         if (!(f > 0)) t.fail(t.raw().get("frequency_Hz"), "frequency_Hz", "must be positive");
         if (!(z > 0)) t.fail(t.raw().get("damping_ratio"), "damping_ratio", "must be positive");
         const Vec3 axes = t.opt_vec3("axes").value_or(Vec3(1, 0, 0));
         t.check_unknown({"frequency_Hz", "damping_ratio", "axes"});
         return std::make_shared<plant::MechanicalMode>(f, z, axes);
       }},
  };
  return readers;
}

void read_effects(Table& t, Case& c) {
  if (auto eff = t.subtable("effects", false)) {
    std::vector<std::string_view> names;
    for (const auto& [name, reader] : effect_readers()) names.push_back(name);
    for (auto&& [k, v] : eff->raw()) {
      const auto it = effect_readers().find(std::string(k.str()));
      if (it == effect_readers().end()) eff->check_unknown(names);
      auto sub = eff->subtable(k.str(), true);
      try {
        c.plant.effects.push_back(it->second(*sub));
      } catch (const std::invalid_argument& e) {
        eff->fail(&v, k.str(), e.what());
      }
    }
  }
}

// The loop the [plant] keys set must be stable: checked here (the linearised loop's poles at
// rest), so the message names the file, the table and the keys that set the loop, not only
// "not stable" from deep inside a run.
void check_loop_stable(Table& t, const Case& c, const std::vector<std::string_view>& loop_keys) {
  try {
    const plant::Accelerometer rest(c.plant, c.orientation_g.value_or(Vec3::UnitX()));
    (void)rest.slowest_time_constant_s(rest.linearise());
  } catch (const std::invalid_argument& e) {
    std::string given;
    for (auto k : loop_keys)
      if (const toml::node* n = t.raw().get(k))
        given += fmt::format("{}{} = {}", given.empty() ? "" : ", ", k,
                             n->is_number() ? fmt::format("{:g}", n->value<double>().value()) : std::string("..."));
    std::string all;
    for (auto k : loop_keys) all += (all.empty() ? "" : ", ") + std::string(k);
    t.fail(nullptr, "", std::string(e.what()) + "; the loop is set by " + all +
                            (given.empty() ? " (all at their defaults" : " (given here: " + given) +
                            ") and any [plant.effects] table");
  }
}

// type = "physical": SI parameters (plant/physical.hpp); the model (1) coefficients follow.
void read_physical_plant(Table& t, Case& c) {
  if (c.coefficients)
    t.fail(t.raw().get("type"), "type",
           "a physical plant implies its coefficients: remove the [coefficients] table (or use \"from_coefficients\")");
  plant::PhysicalParameters p;
  struct Key {
    const char* name;
    double* value;
  };
  const Key keys[] = {{"inertia_kg_m2", &p.inertia_kg_m2},
                      {"damping_N_m_s_per_rad", &p.damping_N_m_s_per_rad},
                      {"hinge_stiffness_N_m_per_rad", &p.hinge_stiffness_N_m_per_rad},
                      {"pendulosity_kg_m", &p.pendulosity_kg_m},
                      {"pickoff_V_per_rad", &p.pickoff_V_per_rad},
                      {"servo_gain_A_per_V", &p.servo_gain_A_per_V},
                      {"lead_zero_Hz", &p.lead_zero_Hz},
                      {"lead_pole_Hz", &p.lead_pole_Hz},
                      {"integrator_Hz", &p.integrator_Hz},
                      {"torquer_N_m_per_A", &p.torquer_N_m_per_A},
                      {"torquer_n2_per_A", &p.torquer_n2_per_A},
                      {"torquer_n3_per_A2", &p.torquer_n3_per_A2},
                      {"bias_torque_N_m", &p.bias_torque_N_m},
                      {"load_ohm", &p.load_ohm},
                      {"antialias_Hz", &p.antialias_Hz}};
  std::vector<std::string_view> allowed{"type", "effects"};
  for (const Key& k : keys) {
    *k.value = t.opt_number(k.name).value_or(*k.value);
    allowed.push_back(k.name);
  }
  std::string why;
  if (!p.IsValid(&why)) {
    const std::string key = why.substr(0, why.find(' '));
    t.fail(t.raw().get(key), key, why.substr(why.find(' ') + 1));
  }
  c.plant = plant::plant_from_physical(p, c.g_m_per_s2);
  read_effects(t, c);
  check_loop_stable(t, c, {"inertia_kg_m2", "damping_N_m_s_per_rad", "hinge_stiffness_N_m_per_rad", "pendulosity_kg_m",
                           "pickoff_V_per_rad", "servo_gain_A_per_V", "lead_zero_Hz", "lead_pole_Hz", "integrator_Hz",
                           "torquer_N_m_per_A", "antialias_Hz"});
  t.check_unknown(allowed);
  c.coefficients = plant::implied_coefficients(p, c.g_m_per_s2);
  c.physical = p;
  if (!c.output_unit_given) c.output_unit = "V";  // the load resistor's voltage
}

void read_plant(Table t, Case& c) {
  const std::string type = t.string("type", "from_coefficients");
  if (type == "physical") return read_physical_plant(t, c);
  if (type != "from_coefficients")
    t.fail(t.raw().get("type"), "type", "must be \"from_coefficients\" or \"physical\", got \"" + type + "\"");
  if (!c.coefficients) t.fail(t.raw().get("type"), "type", "a [plant] is built from [coefficients], which is missing");
  plant::Dynamics& d = c.plant.dynamics;
  d.pendulum_frequency_Hz = t.opt_number("pendulum_frequency_Hz").value_or(d.pendulum_frequency_Hz);
  d.pendulum_damping_ratio = t.opt_number("pendulum_damping_ratio").value_or(d.pendulum_damping_ratio);
  d.angle_gain_rad_per_s2_per_g = t.opt_number("angle_gain_rad_per_s2_per_g").value_or(d.angle_gain_rad_per_s2_per_g);
  d.loop_bandwidth_Hz = t.opt_number("loop_bandwidth_Hz").value_or(d.loop_bandwidth_Hz);
  d.phase_margin_deg = t.opt_number("phase_margin_deg").value_or(d.phase_margin_deg);
  d.integrator = boolean(t, "integrator", d.integrator);
  d.integrator_zero_ratio = t.opt_number("integrator_zero_ratio").value_or(d.integrator_zero_ratio);
  d.antialias_Hz = t.non_negative("antialias_Hz", d.antialias_Hz);
  std::string why;
  if (!d.IsValid(&why)) {
    const std::string key = why.substr(0, why.find(' '));  // IsValid's message starts with the key
    t.fail(t.raw().get(key), key, why.substr(why.find(' ') + 1));
  }
  try {
    plant::design_servo(d);
  } catch (const std::invalid_argument& e) {
    t.fail(t.raw().get("phase_margin_deg"), "phase_margin_deg", e.what());
  }
  if (auto loc = t.subtable("location", false)) {
    for (auto&& [k, v] : loc->raw()) {
      const auto idx = plant::coefficient_from_name(k.str());
      if (idx && *idx == plant::K1) loc->fail(&v, k.str(), "K1 has no place to act (it is the scale factor)");
      if (!idx) {
        std::vector<std::string_view> names;
        for (int i = 1; i < plant::kNumCoefficients; ++i) names.push_back(plant::coefficient_name(i));
        loc->check_unknown(names);
      }
      const std::string where = loc->string(k.str(), "");
      const plant::Location l = where == "input" ? plant::Location::input
                                : where == "loop" ? plant::Location::loop
                                                  : plant::Location::output;
      if ((where != "input" && where != "loop" && where != "output") || !plant::location_allowed(*idx, l))
        loc->fail(&v, k.str(), std::string("must be ") + (*idx <= plant::k4 ? "\"input\", \"loop\" or \"output\""
                                                                            : "\"input\" or \"output\" (it needs a_PA or a_OA)") +
                                   ", got \"" + where + "\"");
      c.plant.location[*idx] = l;
    }
  }
  read_effects(t, c);
  c.plant.coefficients = *c.coefficients;
  check_loop_stable(t, c, {"pendulum_frequency_Hz", "pendulum_damping_ratio", "angle_gain_rad_per_s2_per_g",
                           "loop_bandwidth_Hz", "phase_margin_deg", "integrator_zero_ratio", "antialias_Hz",
                           "location"});
  t.check_unknown({"type", "pendulum_frequency_Hz", "pendulum_damping_ratio", "angle_gain_rad_per_s2_per_g",
                   "loop_bandwidth_Hz", "phase_margin_deg", "integrator", "integrator_zero_ratio", "antialias_Hz",
                   "location", "effects"});
}

void read_readout(Table t, Case& c) {
  rectification::Readout& r = c.shake.readout;
  r.sample_rate_Hz = t.number("sample_rate_Hz");
  if (!(r.sample_rate_Hz > 0)) t.fail(t.raw().get("sample_rate_Hz"), "sample_rate_Hz", "must be positive");
  r.noise_sigma_g = t.non_negative("noise_sigma_ug", 0.0) * 1e-6;
  r.quantisation_lsb_g = t.non_negative("quantisation_lsb_ug", 0.0) * 1e-6;
  t.check_unknown({"sample_rate_Hz", "noise_sigma_ug", "quantisation_lsb_ug"});
}

void read_shake(Table t, Case& c) {
  rectification::ShakeSettings& s = c.shake;
  s.relative_tolerance = t.opt_number("relative_tolerance").value_or(s.relative_tolerance);
  s.settle_decay = t.opt_number("settle_decay").value_or(s.settle_decay);
  s.blocks = static_cast<int>(t.integer("blocks", false, s.blocks, 2, 1000));
  s.min_measure_s = t.non_negative("min_measure_s", s.min_measure_s);
  std::string why;
  if (!s.IsValid(&why)) {
    const std::string key = why.substr(0, why.find(' '));  // IsValid's message starts with the key
    t.fail(t.raw().get(key), key, why.substr(why.find(' ') + 1));
  }
  t.check_unknown({"relative_tolerance", "settle_decay", "blocks", "min_measure_s"});
}

// A static orientation is gravity in sensor axes, in units of the local g: |a| = 1 g. Within
// 1e-3: a vector typed with four digits (0.7071) is off by ~1e-4, while a norm of 0 g (no
// gravity) or 10 g (a centrifuge, or m/s^2 typed for g) is not a static test on the earth.
constexpr double kGravityNormTolerance = 1e-3;
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
  const double from = t.opt_number("from_Hz").value_or(1.0), to = t.opt_number("to_Hz").value_or(5000.0);
  if (!(from > 0) || !(to > from)) t.fail(t.raw().get("to_Hz"), "to_Hz", "need 0 < from_Hz < to_Hz");
  const auto points = t.integer("points", false, 80, 2, 10000);
  const auto ode_points = t.integer("ode_points", false, 10, 0, 1000);
  f.frequencies_Hz = rectification::spaced(from, to, static_cast<int>(points), true);
  if (ode_points > 0) f.ode_frequencies_Hz = rectification::spaced(from, to, static_cast<int>(ode_points), true);
  f.amplitude_g = t.opt_number("amplitude_g").value_or(f.amplitude_g);
  if (!(f.amplitude_g > 0)) t.fail(t.raw().get("amplitude_g"), "amplitude_g", "must be positive");
  check_amplitude(t, "amplitude_g", f.amplitude_g);
  if (auto d = t.opt_vec3("direction")) {
    if (!(d->norm() > 0)) t.fail(t.raw().get("direction"), "direction", "must not be zero");
    f.direction = d->normalized();
  }
  f.pickoff_p2_per_rad = t.opt_number("pickoff_p2_per_rad").value_or(f.pickoff_p2_per_rad);
  t.check_unknown({"from_Hz", "to_Hz", "points", "ode_points", "amplitude_g", "direction", "pickoff_p2_per_rad"});
  c.frequency_study = f;
}

// Names for a list of vectors: given (one per vector) or the vectors written out.
std::vector<validation::NamedVector> named_vectors(Table& t, std::string_view key, std::string_view names_key,
                                                   bool unit) {
  const std::vector<Vec3> v = vec3_list(t, key, unit);
  if (v.empty()) t.fail(nullptr, key, "missing (required)");
  std::vector<std::string> names;
  if (const toml::node* n = t.get(names_key, false)) {
    const toml::array* a = n->as_array();
    if (!a || a->size() != v.size()) t.fail(n, names_key, "expected an array of " + std::to_string(v.size()) + " strings, one per entry of " + std::string(key));
    for (auto&& x : *a) {
      if (!x.is_string() || x.as_string()->get().empty()) t.fail(&x, names_key, "expected a non-empty string");
      names.push_back(x.as_string()->get());
    }
  }
  std::vector<validation::NamedVector> out;
  for (std::size_t i = 0; i < v.size(); ++i)
    out.push_back({names.empty() ? fmt::format("[{:.3g}, {:.3g}, {:.3g}]", v[i][0], v[i][1], v[i][2]) : names[i], v[i]});
  return out;
}

void read_reproduce(Table t, Case& c) {
  validation::ReproduceSettings r;
  r.frequency_Hz = t.number("frequency_Hz");
  if (!(r.frequency_Hz > 0)) t.fail(t.raw().get("frequency_Hz"), "frequency_Hz", "must be positive");
  r.amplitudes_g = number_list(t, "amplitudes_g");
  if (r.amplitudes_g.empty()) t.fail(nullptr, "amplitudes_g", "missing (required)");
  for (double a : r.amplitudes_g)
    if (!(a > 0)) t.fail(t.raw().get("amplitudes_g"), "amplitudes_g", "amplitudes must be positive");
  for (double a : r.amplitudes_g) check_amplitude(t, "amplitudes_g", a);
  r.directions = named_vectors(t, "directions", "direction_names", true);
  r.orientations = named_vectors(t, "orientations_g", "orientation_names", false);
  for (const auto& o : r.orientations)
    if (std::abs(o.v.norm() - 1) > 1e-3)
      t.fail(t.raw().get("orientations_g"), "orientations_g",
             fmt::format("a static orientation is gravity in sensor axes, |a| = 1 g; '{}' has |a| = {:.6g} g", o.name, o.v.norm()));
  r.departure_frequencies_Hz = number_list(t, "departure_frequencies_Hz");
  for (double f : r.departure_frequencies_Hz)
    if (!(f > 0)) t.fail(t.raw().get("departure_frequencies_Hz"), "departure_frequencies_Hz", "frequencies must be positive");
  r.invisible_shift_per_g = t.opt_number("invisible_shift_per_g").value_or(0.0);
  r.threads = static_cast<int>(t.integer("threads", false, 0, 0, 1024));
  auto conf = t.subtable("confirmation", true);
  const auto index = [&](std::string_view key, std::size_t n) {
    return static_cast<std::size_t>(conf->integer(key, false, 1, 1, static_cast<std::int64_t>(n)) - 1);
  };
  r.confirmation_orientation = r.orientations[index("orientation", r.orientations.size())];
  r.confirmation_direction = r.directions[index("direction", r.directions.size())];
  r.confirmation_amplitude_g = conf->number("amplitude_g");
  check_amplitude(*conf, "amplitude_g", r.confirmation_amplitude_g);
  if (!(r.confirmation_amplitude_g > 0)) conf->fail(conf->raw().get("amplitude_g"), "amplitude_g", "must be positive");
  r.confirmation_record_s = conf->number("record_s");
  if (!(r.confirmation_record_s > 0)) conf->fail(conf->raw().get("record_s"), "record_s", "must be positive");
  conf->check_unknown({"orientation", "direction", "amplitude_g", "record_s"});
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
  t.check_unknown({"frequency_Hz", "amplitudes_g", "directions", "direction_names", "orientations_g",
                   "orientation_names", "departure_frequencies_Hz", "invisible_shift_per_g", "threads",
                   "confirmation"});
  // The rest of the configuration from the tables read before this one.
  if (c.dividing_head) r.positions = c.dividing_head->positions, r.errors = c.dividing_head->errors;
  r.fixed = c.fixed;
  r.seed = c.seed;
  r.shake = c.shake;
  c.reproduce = r;
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
  t.check_unknown({"name", "hidden", "frequencies_Hz", "amplitudes_g", "directions", "orientations_g", "run_sigma_ug",
                   "positions_per_series", "raw_series", "raw_sample_rate_Hz", "raw_noise_sigma_ug", "raw_record_s"});
  c.campaign = s;
}

}  // namespace

Case read_case(const std::string& path) {
  if (std::filesystem::is_directory(path))
    throw FormatError({.file = path}, "cannot open the case file: is a directory (give the .toml file)");
  if (!std::filesystem::exists(path)) throw FormatError({.file = path}, "cannot open the case file (no such file)");
  if (!std::filesystem::is_regular_file(path)) throw FormatError({.file = path}, "cannot open the case file: not a regular file");
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
