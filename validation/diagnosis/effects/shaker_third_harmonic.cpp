// The table's motion carries a 3rd harmonic (vibration::HarmonicDistortion): ratio and phase.
#include "validation/diagnosis/effects/common.hpp"

namespace vrelab::validation {

Effect effect_shaker_third_harmonic() {
  return effects::shaker_harmonic(
      3, "shaker_third_harmonic", 16,
      "the table's motion carries a 3rd harmonic, ratio h of the fundamental and phase phi on every axis, as "
      "w (sin t + h sin(3t + phi)): the odd terms see cross products of the two tones, each tone through the loop at "
      "its own frequency; the 2nd harmonic's companion (a shaker's distortion has both, and with its phase free "
      "the 2nd harmonic alone would take up a 3rd's gap)");
}

}  // namespace vrelab::validation
