// The input axis turns with the pendulum: the vibropendulous coupling (plant::PendulumGeometry).
#include <memory>

#include "plant/effects/pendulum_geometry.hpp"
#include "validation/diagnosis/effects/common.hpp"

namespace vrelab::validation {

Effect effect_pendulum_geometry() {
  Effect e;
  e.name = "pendulum_geometry";
  e.rank = 2;
  e.acts_on = ActsOn::instrument;
  e.physics = "vibropendulous coupling: the input axis turns with the pendulum, so vibration along IA and PA in "
              "phase rectifies as -<a_PA theta>; with a static a_IA also -a_IA <theta^2> / 4, which alone looks like "
              "the pickoff nonlinearity";
  EffectParameter p("fraction", "1");  // a hypothesis: 1 = present; the fit says how much of it the data show
  p.example = 1;
  p.lower = -0.5, p.upper = 1.5;
  p.linear = true, p.unit_value = 1;
  e.parameters = {p};
  e.hypothesis = [](ParameterValues v, plant::PlantConfig& c, TableMotion&) {
    if (v[0] != 0) c.effects.push_back(std::make_shared<plant::PendulumGeometry>());
  };
  e.truth = [](ParameterValues v, VirtualLab& lab) {
    if (v[0] == 1) lab.instrument.effects.push_back(std::make_shared<plant::PendulumGeometry>());
  };
  e.draw = [](std::mt19937_64& rng) {
    effects::random_sign(rng);
    return std::vector<double>{1};
  };
  e.check = [name = e.name](ParameterValues v, std::string* why) { return effects::present_or_not(name, v, why); };
  return e;
}

}  // namespace vrelab::validation
