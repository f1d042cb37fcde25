// An input-axis term k5 a^5 beyond model (1), on the readout (plant::OutputPolynomial).
#include "validation/diagnosis/effects/common.hpp"

namespace vrelab::validation {

Effect effect_higher_order_k5() {
  return effects::higher_order_term(
      5, 9,
      "an input-axis term k5 a^5 beyond the identified k4: in 1 g the static test folds it into K1 "
      "and k3 (and leaves its cos 5 phi part as misfit); under vibration it rectifies "
      "5 a0^3 |I|^2 + (15/8) a0 |I|^4 beyond what k3 predicts, as amplitude^4 at a static a_IA",
      1e-8, 3e-8, 5e-8, 5e-7);
}

}  // namespace vrelab::validation
