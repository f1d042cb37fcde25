#include "validation/diagnosis/effect.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <stdexcept>

#include "validation/diagnosis/effects/common.hpp"
#include "vibration/excitation.hpp"

namespace vrelab::validation {

std::shared_ptr<const vibration::Excitation> TableMotion::excitation() const {
  auto tone = std::make_shared<vibration::SineExcitation>(sine);
  std::shared_ptr<const vibration::Excitation> motion = tone;
  if (!harmonics.empty()) motion = std::make_shared<vibration::HarmonicDistortion>(tone, harmonics);
  if (rocking_rad_per_g != 0) {
    // Gravity and the table's motion turn with the fixture; the lever arm adds a tangential
    // acceleration along PA (~ f^2) and a centripetal one along -IA (~ f^2 alpha^2).
    vibration::RockingSpec rs;
    rs.axis = Vec3::UnitZ();
    rs.amplitude_rad = std::abs(rocking_rad_per_g) * commanded_amplitude_g;
    rs.phase_rad = rocking_rad_per_g < 0 ? std::numbers::pi : 0.0;
    rs.static_gravity_g = static_gravity_g;
    rs.lever_arm_m = Vec3(kRockingLeverArm_m, 0, 0);
    rs.g_m_per_s2 = 9.80665;
    motion = std::make_shared<vibration::Rocking>(motion, tone, rs);
  }
  return motion;
}

plant::PlantConfig VirtualLab::run_plant() const {
  plant::PlantConfig p = instrument;
  p.effects.insert(p.effects.end(), run_acquisition.begin(), run_acquisition.end());
  return p;
}

std::shared_ptr<const vibration::Excitation> VirtualLab::excitation() const {
  auto tone = std::make_shared<vibration::SineExcitation>(table);
  std::shared_ptr<const vibration::Excitation> motion = tone;
  if (!harmonics.empty()) motion = std::make_shared<vibration::HarmonicDistortion>(tone, harmonics);
  if (rocking) motion = std::make_shared<vibration::Rocking>(motion, tone, *rocking);
  return motion;
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
  if (!hypothesis) throw std::logic_error(name + " is not in the diagnosis' library: it has no hypothesis");
  std::vector<double> values;
  for (const EffectParameter& q : parameters) values.push_back(q.nominal);
  values.front() = p;
  hypothesis(values, plant, motion);
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

}  // namespace vrelab::validation
