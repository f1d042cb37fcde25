// Outside the library: the sensor warms with the vibration's power and its scale follows
// (plant::VibrationHeating).
#include <memory>

#include "plant/effects/vibration_heating.hpp"
#include "validation/diagnosis/effects/common.hpp"

namespace vrelab::validation {

namespace {
constexpr double kThermalTimeConstant_s = 0.05;  // the hinge's: short, so that each run settles warm
}  // namespace

Effect effect_vibration_heating() {
  Effect e;
  e.name = "vibration_heating";
  e.rank = 103;
  e.in_library = false;
  e.acts_on = ActsOn::instrument;
  e.physics = "the vibration's power warms the sensor (time constant 50 ms) and the input axis's scale has a "
              "temperature coefficient: a_IA (1 + kappa (<|a|^2> - 1)), nothing in a 1 g static test; under a sine "
              "kappa a_IA A^2 / 2, odd in the static a_IA, flat in frequency along PA and OA (along IA more at low "
              "frequency: the power's ripple at f, kappa a_IA A^2 / (1 + (w tau)^2) further) (outside the diagnosis' "
              "library)";
  EffectParameter p("kappa_per_g2", "1/g^2");
  p.example = 2e-6;
  p.nominal = 0;
  e.parameters = {p};
  e.truth = [](ParameterValues v, VirtualLab& lab) {
    if (v[0] != 0) lab.instrument.effects.push_back(std::make_shared<plant::VibrationHeating>(v[0], kThermalTimeConstant_s));
  };
  // 0.3-2 ppm/g^2 either sign: 1.7-11 ug at 4 g with a_IA = 0.71 g (kappa a_IA A^2 / 2), i.e.
  // 6-38 sigma of a run in the default design.
  e.draw = [](std::mt19937_64& rng) {
    const double s = effects::random_sign(rng);
    return std::vector<double>{s * effects::log_uniform(rng, 0.3e-6, 2e-6)};
  };
  return e;
}

}  // namespace vrelab::validation
