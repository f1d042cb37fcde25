// The table's motion carries a 2nd harmonic (vibration::HarmonicDistortion): ratio and phase.
#include "validation/diagnosis/effects/common.hpp"

namespace vrelab::validation {

Effect effect_shaker_harmonic_distortion() {
  Effect e;
  e.name = "shaker_harmonic_distortion";
  e.rank = 14;
  e.acts_on = ActsOn::table_motion;
  e.physics = "the table's motion carries a 2nd harmonic, ratio h of the fundamental and phase phi on every axis, as "
              "w (sin t + h sin(2t + phi)): the quadratic terms see (1 + h^2) w^2 / 2, the cubic and quartic ones "
              "cross products of the two tones (<a^3> = -(3/4) h sin(phi) w^3), each tone through the loop at its own "
              "frequency; along every direction the instrument is nonlinear in";
  EffectParameter p("second_harmonic_ratio", "1");
  p.example = 0.2;
  p.nominal = 0;
  p.grid = {0};
  for (double h : effects::geometric(0.01, 0.5, 22)) p.grid.push_back(h);
  e.parameters = {p, effects::harmonic_phase("second_harmonic_phase_rad")};
  e.hypothesis = [](ParameterValues v, plant::PlantConfig&, TableMotion& m) {
    if (v[0] > 0) m.harmonics.push_back({2, v[0], v[1]});
  };
  e.truth = [](ParameterValues v, VirtualLab& lab) {
    if (v[0] > 0) lab.harmonics.push_back(vibration::Harmonic{.order = 2, .ratio = v[0], .phase_rad = v[1]});
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
