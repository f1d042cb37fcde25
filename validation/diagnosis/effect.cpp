#include "validation/diagnosis/effect.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <memory>
#include <numbers>
#include <stdexcept>
#include <string>
#include <utility>

#include "plant/effects/output_polynomial.hpp"
#include "rectification/simulation/shaker_motion.hpp"
#include "validation/diagnosis/effects/common.hpp"
#include "vibration/excitation.hpp"

namespace vrelab::validation {

namespace {

// A sine run's motion through the one builder of a shaker run's motion.
std::shared_ptr<const vibration::Excitation> sine_motion(const vibration::SineVibration& sine,
                                                         const rectification::ShakerImperfections& shaker,
                                                         const Vec3& static_gravity_g, double g_m_per_s2) {
  rectification::VibrationRequest request;
  request.type = rectification::VibrationKind::sine;
  request.sine = sine;
  return rectification::shaker_motion(request, shaker, static_gravity_g, g_m_per_s2, 0).motion;
}

}  // namespace

std::shared_ptr<const vibration::Excitation> TableMotion::excitation() const {
  rectification::ShakerImperfections shaker;
  shaker.harmonics = harmonics;
  if (rocking_rad_per_g != 0) {
    // Gravity and the table's motion turn with the fixture; the lever arm adds a tangential
    // acceleration along PA (~ f^2) and a centripetal one along -IA (~ f^2 alpha^2).
    vibration::RockingSpec rs;
    rs.axis = Vec3::Unit(rocking_axis);
    rs.amplitude_rad = std::abs(rocking_rad_per_g) * commanded_amplitude_g;
    rs.phase_rad = rocking_rad_per_g < 0 ? std::numbers::pi : 0.0;
    rs.lever_arm_m = kRockingLeverArm_m * Vec3::Unit((rocking_axis + 1) % 3);
    shaker.rocking = rs;
  }
  return sine_motion(sine, shaker, static_gravity_g, 9.80665);
}

plant::PlantConfig VirtualLab::run_plant() const {
  plant::PlantConfig p = instrument;
  p.effects.insert(p.effects.end(), run_acquisition.begin(), run_acquisition.end());
  return p;
}

std::shared_ptr<const vibration::Excitation> VirtualLab::excitation() const {
  rectification::ShakerImperfections shaker;
  shaker.harmonics = harmonics;
  shaker.rocking = rocking;
  return sine_motion(table, shaker, rocking ? rocking->static_gravity_g : static_gravity_g,
                     rocking ? rocking->g_m_per_s2 : 9.80665);
}

const char* to_string(ActsOn a) {
  switch (a) {
    case ActsOn::instrument: return "instrument";
    case ActsOn::table_motion: return "table motion";
    case ActsOn::data_acquisition: return "data acquisition";
  }
  return "?";
}

void Effect::apply(double p, plant::PlantConfig& plant, TableMotion& motion) const {
  apply(values_at(p), plant, motion);
}

void Effect::apply(ParameterValues values, plant::PlantConfig& plant, TableMotion& motion) const {
  if (!hypothesis) throw std::logic_error(name + " is not in the diagnosis' library: it has no hypothesis");
  hypothesis(values, plant, motion);
}

std::vector<double> Effect::values_at(double p) const {
  std::vector<double> values;
  for (const EffectParameter& q : parameters) values.push_back(q.nominal);
  values.front() = p;
  return values;
}

bool Effect::is_valid(ParameterValues values, std::string* why) const {
  if (values.size() != parameters.size()) {
    if (why) *why = name + " takes " + std::to_string(parameters.size()) + " parameter(s), got " + std::to_string(values.size());
    return false;
  }
  for (std::size_t i = 0; i < values.size(); ++i)
    if (!std::isfinite(values[i])) {
      if (why) *why = name + ": " + parameters[i].name + " must be finite";
      return false;
    }
  return !check || check(values, why);
}

namespace {

std::vector<Effect> make_registry() {
  std::vector<Effect> all = registered_effects();
  std::stable_sort(all.begin(), all.end(), [](const Effect& a, const Effect& b) { return a.rank < b.rank; });
  for (Effect& e : all)
    for (EffectParameter& p : e.parameters)
      if (p.linear && !std::isfinite(p.lower)) {
        const double span = 100 * std::abs(p.unit_value - p.nominal);
        p.lower = p.nominal - span, p.upper = p.nominal + span;
      }
  return all;
}

}  // namespace

const std::vector<Effect>& effect_registry() {
  static const std::vector<Effect> all = make_registry();
  return all;
}

const std::vector<Effect>& effect_library() {
  static const std::vector<Effect> lib = [] {
    std::vector<Effect> v;
    for (const Effect& e : effect_registry())
      if (e.in_library) v.push_back(e);
    return v;
  }();
  return lib;
}

const Effect* find_effect(const std::string& name) {
  for (const Effect& e : effect_library())  // the library's first: callers hold pointers into it
    if (e.name == name) return &e;
  for (const Effect& e : effect_registry())
    if (e.name == name) return &e;
  return nullptr;
}

namespace effects {

Effect higher_order_term(int n, int rank, std::string physics, double unit_value, double example, double lo, double hi) {
  // (Appending to a named string: GCC 12 warns falsely (-Wrestrict) on "literal" + to_string.)
  const std::string order = std::to_string(n);
  Effect e;
  e.name = std::string("higher_order_k").append(order);
  e.rank = rank;
  e.acts_on = ActsOn::instrument;
  e.acts_at_rest = true;
  e.physics = std::move(physics);
  EffectParameter p(std::string("k").append(order), std::string("1/g^").append(std::to_string(n - 1)));
  p.example = example;
  p.linear = true, p.unit_value = unit_value;
  e.parameters = {p};
  e.hypothesis = [n, name = e.name](ParameterValues v, plant::PlantConfig& c, TableMotion&) {
    if (v[0] == 0) return;
    std::array<double, 7> poly{};
    poly[static_cast<std::size_t>(n)] = v[0];
    c.effects.push_back(std::make_shared<plant::OutputPolynomial>(name, poly));
  };
  // The instrument's own term: the static test and the runs both read it (written out: the
  // truth does not share the hypothesis' code).
  e.truth = [n, name = e.name](ParameterValues v, VirtualLab& lab) {
    if (v[0] == 0) return;
    std::array<double, 7> c{};
    c[static_cast<std::size_t>(n)] = v[0];
    lab.instrument.effects.push_back(std::make_shared<plant::OutputPolynomial>(name, c));
  };
  e.draw = [lo, hi](std::mt19937_64& rng) {
    const double s = random_sign(rng);
    return std::vector<double>{s * log_uniform(rng, lo, hi)};
  };
  return e;
}

Effect shaker_harmonic(int order, std::string name, int rank, std::string physics) {
  static const char* const kOrdinal[] = {"", "", "second", "third", "fourth", "fifth"};
  if (order < 2 || order > 5)
    throw std::invalid_argument(std::string("shaker_harmonic: order 2 to 5, got ").append(std::to_string(order)));
  const std::string ordinal = kOrdinal[order];
  Effect e;
  e.name = std::move(name);
  e.rank = rank;
  e.acts_on = ActsOn::table_motion;
  e.physics = std::move(physics);
  EffectParameter p(ordinal + "_harmonic_ratio", "1");
  p.example = 0.2;
  p.nominal = 0;
  p.grid = {0};
  for (double h : geometric(0.01, 0.5, 22)) p.grid.push_back(h);
  e.parameters = {p, harmonic_phase(ordinal + "_harmonic_phase_rad")};
  e.hypothesis = [order](ParameterValues v, plant::PlantConfig&, TableMotion& m) {
    if (v[0] > 0) m.harmonics.push_back({order, v[0], v[1]});
  };
  e.truth = [order](ParameterValues v, VirtualLab& lab) {
    if (v[0] > 0) lab.harmonics.push_back(vibration::Harmonic{.order = order, .ratio = v[0], .phase_rad = v[1]});
  };
  e.draw = [](std::mt19937_64& rng) {
    random_sign(rng);
    return std::vector<double>{log_uniform(rng, 0.1, 0.3)};
  };
  e.draw_form = [](std::mt19937_64& rng) {
    return std::vector<double>{std::uniform_real_distribution<double>(-std::numbers::pi, std::numbers::pi)(rng)};
  };
  e.check = [name = e.name](ParameterValues v, std::string* why) { return harmonic_ratio(name, v, why); };
  return e;
}

}  // namespace effects

}  // namespace vrelab::validation
