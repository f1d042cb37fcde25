#include <cmath>
#include <numbers>
#include <stdexcept>
#include <string>

#include <fmt/format.h>
#include <toml++/toml.h>

#include "io/formats/case_file_internal.hpp"
#include "io/formats/ranges.hpp"
#include "vibration/psd.hpp"

// The [vibration] and [shaker] tables of a case file (docs/case-files.md).
namespace vrelab::io::internal {
namespace {

constexpr double kDeg = std::numbers::pi / 180.0;

// Sine part: amplitude_g per axis, phase_deg, frequency_Hz (required for sine on random).
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
  // The lab data's physical ranges (io/formats/ranges.hpp), on the levels as resolved from slopes.
  const vibration::ResolvedPsd r = vibration::resolve(table);
  for (std::size_t k = 0; k < r.frequency_Hz.size(); ++k) {
    std::string out = range_problem(kFrequencyRange, r.frequency_Hz[k]);
    if (out.empty()) out = range_problem(kPsdLevelRange, r.psd_g2_per_Hz[k]);
    if (!out.empty()) t.fail(a->get(k), std::string(key) + " row " + std::to_string(k + 1), out);
  }
  if (const double rms = vibration::rms_g(table); !(rms <= kPsdMaxRms_g))
    t.fail(n, key, fmt::format("the table's rms is {:g} g, over the {:g} g a shaker's motion stays within", rms, kPsdMaxRms_g));
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

int axis_index(Table& t, std::string_view key, const std::string& name) {
  if (name == "IA") return IA;
  if (name == "PA") return PA;
  if (name == "OA") return OA;
  t.fail(t.raw().get(key), key, "axes are \"IA\", \"PA\" or \"OA\", got \"" + name + "\"");
}

}  // namespace

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

}  // namespace vrelab::io::internal
