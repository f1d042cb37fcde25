// An input-axis term k6 a^6 beyond model (1), on the readout (plant::OutputPolynomial).
#include "validation/diagnosis/effects/common.hpp"

namespace vrelab::validation {

Effect effect_higher_order_k6() {
  return effects::higher_order_term(
      6, 10,
      "an input-axis term k6 a^6 beyond the identified k4: folded into k0, k2, k4 by the static "
      "test; under vibration it rectifies (5/16) |I|^6 + ..., as amplitude^6, along IA",
      1e-9, 3e-9, 1e-8, 6e-8);
}

}  // namespace vrelab::validation
