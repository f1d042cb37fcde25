// Outside the library: the table's motion carries a 3rd harmonic (vibration::HarmonicDistortion).
#include "validation/diagnosis/effects/common.hpp"

namespace vrelab::validation {

Effect effect_shaker_third_harmonic() {
  Effect e;
  e.name = "shaker_third_harmonic";
  e.rank = 102;
  e.in_library = false;
  e.acts_on = ActsOn::table_motion;
  e.physics = "the table's motion carries a 3rd harmonic, ratio h of the fundamental and phase phi on every axis, as "
              "w (sin t + h sin(3t + phi)): the odd terms see cross products of the two tones (outside the diagnosis' "
              "library, whose distortion is the 2nd harmonic)";
  EffectParameter p("third_harmonic_ratio", "1");
  p.example = 0.2;
  p.nominal = 0;
  e.parameters = {p, effects::harmonic_phase("third_harmonic_phase_rad")};
  e.truth = [](ParameterValues v, VirtualLab& lab) {
    lab.harmonics.push_back(vibration::Harmonic{.order = 3, .ratio = v[0], .phase_rad = v[1]});
  };
  e.draw = [](std::mt19937_64& rng) {
    effects::random_sign(rng);
    return std::vector<double>{effects::log_uniform(rng, 0.1, 0.3)};
  };
  e.draw_form = [](std::mt19937_64& rng) {
    return std::vector<double>{std::uniform_real_distribution<double>(-std::numbers::pi, std::numbers::pi)(rng)};
  };
  e.check = [name = e.name](ParameterValues v, std::string* why) { return effects::harmonic_ratio(name, v, why); };
  return e;
}

}  // namespace vrelab::validation
