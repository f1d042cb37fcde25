// The pickoff reads theta + p2 theta^2 (plant::PickoffNonlinearity).
#include <memory>

#include "plant/effects/pickoff_nonlinearity.hpp"
#include "validation/diagnosis/effects/common.hpp"

namespace vrelab::validation {

Effect effect_pickoff_nonlinearity() {
  Effect e;
  e.name = "pickoff_nonlinearity";
  e.rank = 1;
  e.acts_on = ActsOn::instrument;
  e.physics = "the pickoff reads theta + p2 theta^2: under vibration <theta> = -p2 <theta^2>, an output shift "
              "growing with the pendulum's angle amplitude (quadratic in amplitude, rising towards the pendulum's "
              "and the loop's resonances)";
  EffectParameter p("p2", "1/rad");
  p.example = 20;
  p.linear = true, p.unit_value = 10;
  e.parameters = {p};
  e.hypothesis = [](ParameterValues v, plant::PlantConfig& c, TableMotion&) {
    if (v[0] != 0) c.effects.push_back(std::make_shared<plant::PickoffNonlinearity>(v[0]));
  };
  e.truth = [](ParameterValues v, VirtualLab& lab) {
    if (v[0] != 0) lab.instrument.effects.push_back(std::make_shared<plant::PickoffNonlinearity>(v[0]));
  };
  e.draw = [](std::mt19937_64& rng) {
    const double s = effects::random_sign(rng);
    return std::vector<double>{s * effects::log_uniform(rng, 5, 50)};
  };
  return e;
}

}  // namespace vrelab::validation
