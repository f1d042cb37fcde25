// An input-axis term k5 a^5 beyond model (1), on the readout (plant::OutputPolynomial).
#include <array>
#include <memory>

#include "plant/effects/output_polynomial.hpp"
#include "validation/diagnosis/effects/common.hpp"

namespace vrelab::validation {

Effect effect_higher_order_k5() {
  Effect e;
  e.name = "higher_order_k5";
  e.rank = 9;
  e.acts_on = ActsOn::instrument;
  e.acts_at_rest = true;
  e.physics = "an input-axis term k5 a^5 beyond the identified k4: in 1 g the static test folds it into K1 "
              "and k3 (and leaves its cos 5 phi part as misfit); under vibration it rectifies "
              "5 a0^3 |I|^2 + (15/8) a0 |I|^4 beyond what k3 predicts, as amplitude^4 at a static a_IA";
  EffectParameter p("k5", "1/g^4");
  p.example = 3e-8;
  p.linear = true, p.unit_value = 1e-8;
  e.parameters = {p};
  const auto term = [](double k) {
    std::array<double, 7> poly{};
    poly[5] = k;
    return std::make_shared<plant::OutputPolynomial>("higher_order_k5", poly);
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
    return std::vector<double>{s * effects::log_uniform(rng, 5e-8, 5e-7)};
  };
  return e;
}

}  // namespace vrelab::validation
