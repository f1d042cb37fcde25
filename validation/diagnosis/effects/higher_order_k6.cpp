// An input-axis term k6 a^6 beyond model (1), on the readout (plant::OutputPolynomial).
#include <array>
#include <memory>

#include "plant/effects/output_polynomial.hpp"
#include "validation/diagnosis/effects/common.hpp"

namespace vrelab::validation {

Effect effect_higher_order_k6() {
  Effect e;
  e.name = "higher_order_k6";
  e.rank = 10;
  e.acts_on = ActsOn::instrument;
  e.acts_at_rest = true;
  e.physics = "an input-axis term k6 a^6 beyond the identified k4: folded into k0, k2, k4 by the static "
              "test; under vibration it rectifies (5/16) |I|^6 + ..., as amplitude^6, along IA";
  EffectParameter p("k6", "1/g^5");
  p.example = 3e-9;
  p.linear = true, p.unit_value = 1e-9;
  e.parameters = {p};
  const auto term = [](double k) {
    std::array<double, 7> poly{};
    poly[6] = k;
    return std::make_shared<plant::OutputPolynomial>("higher_order_k6", poly);
  };
  e.hypothesis = [term](ParameterValues v, plant::PlantConfig& c, TableMotion&) {
    if (v[0] != 0) c.effects.push_back(term(v[0]));
  };
  // The instrument's own term: the static test and the runs both read it.
  e.truth = [term](ParameterValues v, VirtualLab& lab) {
    if (v[0] != 0) lab.instrument.effects.push_back(term(v[0]));
  };
  e.draw = [](std::mt19937_64& rng) {
    const double s = effects::random_sign(rng);
    return std::vector<double>{s * effects::log_uniform(rng, 1e-8, 6e-8)};
  };
  return e;
}

}  // namespace vrelab::validation
