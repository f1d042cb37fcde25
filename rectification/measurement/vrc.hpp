#pragma once
// rectification/measurement/vrc.hpp -- the vibration rectification coefficient (VRC) that
// datasheets quote.
//
// Takes: a vibration error e (g) and the input's rms (g).
// Gives: VRC = e / (input rms)^2, in ug/g^2 (1e6 e / rms^2).
// The input rms is the rms of the magnitude of the dynamic input acceleration vector,
// sqrt(E|x(t)|^2) = sqrt(sum_i rms_i^2) over the three sensor axes (gravity excluded): a sine
// of peak w_i per axis has rms sqrt(sum_i w_i^2 / 2), a Gaussian of per-axis rms s_i has
// sqrt(sum_i s_i^2), sine on random adds the two squares. The VRC is a constant of the
// instrument only where the error grows as rms^2 (k2, k3 a_IA, the cross terms, k4 a_IA^2, the
// pickoff and geometry effects); the k4 w^4 part grows as rms^4 and the k1' asymmetry as
// rms^1 (less its static part), so with those the VRC depends on the level (docs/prediction.md).
#include <cmath>
#include <limits>

#include "vibration/profile.hpp"

namespace vrelab::rectification {

// NaN when the rms is not positive (no vibration: no coefficient).
inline double vrc_ug_per_g2(double error_g, double input_rms_g) {
  if (!(input_rms_g > 0)) return std::numeric_limits<double>::quiet_NaN();
  return 1e6 * error_g / (input_rms_g * input_rms_g);
}
inline double input_rms_g(const vibration::SineVibration& v) { return v.amplitude_g.norm() / std::sqrt(2.0); }
inline double input_rms_g(const vibration::RandomVibration& v) { return v.rms_g.norm(); }
inline double input_rms_g(const vibration::SineVibration& sine, const vibration::RandomVibration& random) {
  return std::hypot(input_rms_g(sine), input_rms_g(random));
}

}  // namespace vrelab::rectification
