// The servo's phase margin differs from nominal.
#include <algorithm>

#include "validation/diagnosis/effects/common.hpp"

namespace vrelab::validation {

Effect effect_servo_phase_margin() {
  Effect e;
  e.name = "servo_phase_margin";
  e.rank = 6;
  e.acts_on = ActsOn::instrument;
  e.changes_dynamics = true;
  e.physics = "the servo's phase margin differs from nominal (lead network, torquer or pickoff phase): the "
              "closed loop's peaking at the crossover, and with it the rectification of the loop-placed terms "
              "there, grows as the margin falls; no effect at low frequency or far above the crossover";
  EffectParameter p("phase_margin_change_deg", "deg");
  p.example = -15;
  p.nominal = 0;
  for (int k = -8; k <= 8; ++k) p.grid.push_back(4.0 * k);  // -32 .. +32 deg (the plant takes 10 .. 85)
  e.parameters = {p};
  e.hypothesis = [](ParameterValues v, plant::PlantConfig& c, TableMotion&) {
    c.dynamics.phase_margin_deg = std::clamp(c.dynamics.phase_margin_deg + v[0], 10.0, 85.0);
  };
  // The instrument's servo is designed for the changed margin (the plant refuses one it cannot build).
  e.truth = [](ParameterValues v, VirtualLab& lab) { lab.instrument.dynamics.phase_margin_deg += v[0]; };
  e.draw = [](std::mt19937_64& rng) {
    const double s = effects::random_sign(rng);
    return std::vector<double>{s * effects::log_uniform(rng, 4, 20)};
  };
  return e;
}

}  // namespace vrelab::validation
