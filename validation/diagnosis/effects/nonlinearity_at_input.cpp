// The input-axis nonlinearity acts on the mechanical input, not in the torquer.
#include "validation/diagnosis/effects/common.hpp"

namespace vrelab::validation {

Effect effect_nonlinearity_at_input() {
  Effect e;
  e.name = "nonlinearity_at_input";
  e.rank = 4;
  e.acts_on = ActsOn::instrument;
  e.physics = "the input-axis nonlinearity (k1', k2, k3, k4) acts on the mechanical input, not in the torquer: it "
              "sees the vibration itself, not the rebalance current, so it stays flat with frequency where the "
              "loop-placed one peaks near the crossover and falls above it";
  EffectParameter p("fraction", "1");
  p.example = 1;
  p.lower = -0.5, p.upper = 1.5;  // a hypothesis: 0 (in the loop) or 1 (at the input)
  p.linear = true, p.unit_value = 1;
  e.parameters = {p};
  e.hypothesis = [](ParameterValues v, plant::PlantConfig& c, TableMotion&) {
    if (v[0] >= 0.5)
      for (int i : {plant::k1_asym, plant::k2, plant::k3, plant::k4}) c.location[i] = plant::Location::input;
  };
  e.truth = [](ParameterValues v, VirtualLab& lab) {
    if (v[0] != 1) return;
    for (int i : {plant::k1_asym, plant::k2, plant::k3, plant::k4}) lab.instrument.location[i] = plant::Location::input;
  };
  e.draw = [](std::mt19937_64& rng) {
    effects::random_sign(rng);
    return std::vector<double>{1};
  };
  e.check = [name = e.name](ParameterValues v, std::string* why) { return effects::present_or_not(name, v, why); };
  return e;
}

}  // namespace vrelab::validation
