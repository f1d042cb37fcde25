// The servo loop's crossover differs from nominal.
#include "validation/diagnosis/effects/common.hpp"

namespace vrelab::validation {

Effect effect_servo_dynamics() {
  Effect e;
  e.name = "servo_dynamics";
  e.rank = 5;
  e.acts_on = ActsOn::instrument;
  e.changes_dynamics = true;
  e.physics = "the servo loop's crossover differs from nominal: the rebalance current's resonance, and with it "
              "the loop-placed terms' rectification, moves in frequency; no effect at low frequency";
  EffectParameter p("bandwidth_ratio", "1");
  p.example = 0.7;
  p.nominal = 1;
  p.grid = effects::geometric(0.5, 2.0, 41);
  e.parameters = {p};
  e.hypothesis = [](ParameterValues v, plant::PlantConfig& c, TableMotion&) { c.dynamics.loop_bandwidth_Hz *= v[0]; };
  e.truth = [](ParameterValues v, VirtualLab& lab) { lab.instrument.dynamics.loop_bandwidth_Hz *= v[0]; };
  e.draw = [](std::mt19937_64& rng) {
    effects::random_sign(rng);
    return std::vector<double>{effects::coin(rng) ? effects::log_uniform(rng, 0.6, 0.85) : effects::log_uniform(rng, 1.15, 1.6)};
  };
  e.check = [name = e.name](ParameterValues v, std::string* why) {
    if (v[0] > 0) return true;
    if (why) *why = name + " is a ratio of loop bandwidths, > 0, got " + std::to_string(v[0]);
    return false;
  };
  return e;
}

}  // namespace vrelab::validation
