// The table's motion carries a 3rd harmonic (vibration::HarmonicDistortion): ratio and phase.
#include "validation/diagnosis/effects/common.hpp"

namespace vrelab::validation {

Effect effect_shaker_third_harmonic() {
  Effect e;
  e.name = "shaker_third_harmonic";
  e.rank = 16;
  e.acts_on = ActsOn::table_motion;
  e.physics = "the table's motion carries a 3rd harmonic, ratio h of the fundamental and phase phi on every axis, as "
              "w (sin t + h sin(3t + phi)): the odd terms see cross products of the two tones, each tone through the loop at "
              "its own frequency; the 2nd harmonic's companion (a shaker's distortion has both, and with its phase free "
              "the 2nd harmonic alone would take up a 3rd's gap)";
  EffectParameter p("third_harmonic_ratio", "1");
  p.example = 0.2;
  p.nominal = 0;
  p.grid = {0};
  for (double h : effects::geometric(0.01, 0.5, 22)) p.grid.push_back(h);
  e.parameters = {p, effects::harmonic_phase("third_harmonic_phase_rad")};
  e.hypothesis = [](ParameterValues v, plant::PlantConfig&, TableMotion& m) {
    if (v[0] > 0) m.harmonics.push_back({3, v[0], v[1]});
  };
  e.truth = [](ParameterValues v, VirtualLab& lab) {
    if (v[0] > 0) lab.harmonics.push_back(vibration::Harmonic{.order = 3, .ratio = v[0], .phase_rad = v[1]});
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
