// A second mechanical mode along IA (plant::MechanicalMode).
#include <memory>

#include "plant/effects/mechanical_mode.hpp"
#include "validation/diagnosis/effects/common.hpp"

namespace vrelab::validation {

namespace {
constexpr double kDampingRatio = 0.05;  // the library's mode: one parameter, its frequency
}  // namespace

Effect effect_mechanical_mode() {
  Effect e;
  e.name = "mechanical_mode";
  e.rank = 7;
  e.acts_on = ActsOn::instrument;
  e.changes_dynamics = true;
  e.physics = "a second mechanical mode (flexure or mount, along IA, damping 0.05) amplifies the IA vibration "
              "that reaches the pendulum near its frequency: a resonance in the gap over frequency, along IA";
  EffectParameter p("frequency_Hz", "Hz");
  p.example = 700;
  p.nominal = 0;  // 0: no mode
  p.grid = effects::geometric(100, 5000, 41);
  e.parameters = {p};
  e.hypothesis = [](ParameterValues v, plant::PlantConfig& c, TableMotion&) {
    if (v[0] > 0) c.effects.push_back(std::make_shared<plant::MechanicalMode>(v[0], kDampingRatio, Vec3(1, 0, 0)));
  };
  e.truth = [](ParameterValues v, VirtualLab& lab) {
    if (v[0] > 0) lab.instrument.effects.push_back(std::make_shared<plant::MechanicalMode>(v[0], kDampingRatio, Vec3::UnitX()));
  };
  e.draw = [](std::mt19937_64& rng) {
    effects::random_sign(rng);
    return std::vector<double>{effects::log_uniform(rng, 300, 1200)};
  };
  e.check = [name = e.name](ParameterValues v, std::string* why) {
    if (v[0] >= 0) return true;
    if (why) *why = name + " is the mode's frequency in Hz (0: none), >= 0, got " + std::to_string(v[0]);
    return false;
  };
  return e;
}

}  // namespace vrelab::validation
