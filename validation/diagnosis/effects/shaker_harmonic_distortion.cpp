// The table's motion carries a 2nd harmonic (vibration::HarmonicDistortion): ratio and phase.
#include "validation/diagnosis/effects/common.hpp"

namespace vrelab::validation {

Effect effect_shaker_harmonic_distortion() {
  return effects::shaker_harmonic(
      2, "shaker_harmonic_distortion", 14,
      "the table's motion carries a 2nd harmonic, ratio h of the fundamental and phase phi on every axis, as "
      "w (sin t + h sin(2t + phi)): the quadratic terms see (1 + h^2) w^2 / 2, the cubic and quartic ones "
      "cross products of the two tones (<a^3> = -(3/4) h sin(phi) w^3), each tone through the loop at its own "
      "frequency; along every direction the instrument is nonlinear in");
}

}  // namespace vrelab::validation
