#pragma once
// plant/effects/vibration_heating.hpp -- the sensor warms with the vibration's power and its
// pendulosity follows. Header-only (no build file to touch): the virtual lab's out-of-library
// truth module.
#include <cmath>
#include <stdexcept>

#include "plant/effects/effect.hpp"

namespace vrelab::plant {

// Vibration heating: the power the vibration dissipates in the sensor and its mount warms it
// with a thermal time constant tau, and the pendulosity (the input axis's scale) has a
// temperature coefficient. One state, the low-passed specific-force power P (g^2):
//     P' = (|a|^2 - P) / tau,   a_IA -> a_IA (1 + kappa (P - 1)),
// so in any 1 g static position P = 1 and nothing changes (the static test cannot see it),
// while under a sine of amplitude A the sensor settles warmer, P = 1 + A^2 / 2 (plus a ripple
// at 2f that tau smooths): the output shifts by kappa a_IA A^2 / 2, odd in the static a_IA,
// flat in frequency (at the input) along PA and OA (a PA or OA vibration changes the IA
// scale). Along IA, |a|^2 also has 2 a_IA A sin(wt), which tau passes as 1 / (1 + j w tau),
// and it correlates with the motion: kappa a_IA A^2 (1/2 + 1 / (1 + (w tau)^2)), 18 % more at
// 10 Hz, 1.3 % at 40 Hz. No term of model (1) nor a library effect is odd in a_IA under a PA
// or OA vibration. kappa in 1/g^2: 1e-6 is e.g. 100 ppm/K times 0.01 K/g^2.
class VibrationHeating final : public Effect {
 public:
  VibrationHeating(double kappa_per_g2, double tau_s) : kappa_(kappa_per_g2), tau_(tau_s) {
    if (!std::isfinite(kappa_)) throw std::invalid_argument("vibration heating kappa_per_g2 must be finite");
    if (!(tau_ > 0) || !std::isfinite(tau_)) throw std::invalid_argument("vibration heating tau_s must be positive");
  }
  std::string name() const override { return "vibration_heating"; }
  int num_states() const override { return 1; }
  double state_scale(int) const override { return 1.0; }
  void rest_state(const Vec3& a, double* s) const override { s[0] = a.squaredNorm(); }
  Vec3 input(const Vec3& a, const double* s, double* ds) const override {
    ds[0] = (a.squaredNorm() - s[0]) / tau_;
    Vec3 out = a;
    out[IA] *= 1 + kappa_ * (s[0] - 1);
    return out;
  }

 private:
  double kappa_, tau_;
};

}  // namespace vrelab::plant
