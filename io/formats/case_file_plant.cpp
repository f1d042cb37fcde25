#include <functional>
#include <map>
#include <memory>
#include <stdexcept>
#include <string>

#include <fmt/format.h>
#include <toml++/toml.h>

#include "io/formats/case_file_internal.hpp"
#include "plant/physical.hpp"

// The [coefficients], [plant] (with its effects), [readout] and [shake] tables of a case file
// (docs/case-files.md).
namespace vrelab::io::internal {
namespace {

// The boolean `key`, or `fallback` when the table has no such key.
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

}  // namespace

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
  t.get("sample_rate_Hz", true);  // required here (0, the struct's default, is "no readout")
  t.read_described(r);
  if (!(r.sample_rate_Hz > 0)) t.fail(t.raw().get("sample_rate_Hz"), "sample_rate_Hz", "must be positive");
}

void read_shake(Table t, Case& c) { t.read_described(c.shake); }

}  // namespace vrelab::io::internal
