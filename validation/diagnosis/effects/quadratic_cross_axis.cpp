// k_PP a_PA^2: a term no static test in 1 g separates from k0, k2 and k_OO.
#include "validation/diagnosis/effects/common.hpp"

namespace vrelab::validation {

Effect effect_quadratic_cross_axis() {
  Effect e;
  e.name = "quadratic_cross_axis";
  e.rank = 3;
  e.acts_on = ActsOn::instrument;
  e.physics = "k_PP a_PA^2 (and the common part of k_PP, k_OO, k2 with k0): invisible to any static test in 1 g, "
              "so held at 0 by the identification; rectifies k_PP |w|^2 / 2 whatever the direction (its k2 part "
              "through the loop, like k2; flat in frequency along PA and OA)";
  EffectParameter p("k_PP", "1/g");
  p.example = 2e-6;
  p.linear = true, p.unit_value = 1e-6;
  e.parameters = {p};
  e.hypothesis = [](ParameterValues v, plant::PlantConfig& c, TableMotion&) {
    // The static test identified (k0 + p, k2 - p, 0, k_OO - p): give the part back.
    c.coefficients[plant::k0] -= v[0];
    for (int i : {plant::k2, plant::k_PP, plant::k_OO}) c.coefficients[i] += v[0];
  };
  // The instrument has the term; the static test takes up what it takes up.
  e.truth = [](ParameterValues v, VirtualLab& lab) { lab.instrument.coefficients[plant::k_PP] += v[0]; };
  e.draw = [](std::mt19937_64& rng) {
    const double s = effects::random_sign(rng);
    return std::vector<double>{s * effects::log_uniform(rng, 0.5e-6, 5e-6)};
  };
  return e;
}

}  // namespace vrelab::validation
