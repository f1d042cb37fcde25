#pragma once
// plant/effects/velocity_cubic_damping.hpp -- the gas damping grows with the pendulum's rate.
// Header-only (no build file to touch): the virtual lab's out-of-library truth module.
#include <cmath>
#include <stdexcept>

#include "plant/effects/effect.hpp"

namespace vrelab::plant {

// Velocity-squared (turbulent or rarefied-flow) damping of the proof mass: the gas film's
// damping grows with the angular rate, c(omega) = c0 (1 + (omega / omega_ref)^2), so the extra
// torque is -c0 omega^3 / omega_ref^2 (c0 = 2 zeta w_p the nominal damping, 1/s; omega_ref the
// rate at which the damping doubles, rad/s). Odd in omega: it does not rectify by itself for a
// sinusoidal swing (<cos^3> = 0); it raises the damping with the rate amplitude (its
// describing function: c0 (1 + (3/4) (Omega / omega_ref)^2), Omega = w Theta), which changes
// the loop's response and so the loop-placed terms' rectification. Unlike the squeeze film
// (a function of the angle, steepest near contact), it follows w Theta: it grows with
// frequency at a given angle. Not in the diagnosis' library (validation/diagnosis/effects/
// velocity_cubic_damping.cpp); the frequency-domain prediction does not model it.
class VelocityCubicDamping final : public Effect {
 public:
  // c0_per_s = 2 zeta w_p, angle_gain = b (rad/s^2 per g) of the plant it goes into.
  VelocityCubicDamping(double omega_ref_rad_per_s, double c0_per_s, double angle_gain_rad_per_s2_per_g)
      : w_ref_(omega_ref_rad_per_s), c0_(c0_per_s), b_(angle_gain_rad_per_s2_per_g) {
    if (!(w_ref_ > 0) || !std::isfinite(w_ref_)) throw std::invalid_argument("velocity cubic damping omega_ref_rad_per_s must be positive");
    if (!(c0_ >= 0) || !std::isfinite(c0_)) throw std::invalid_argument("velocity cubic damping c0_per_s must be >= 0");
    if (!(b_ > 0) || !std::isfinite(b_)) throw std::invalid_argument("velocity cubic damping angle_gain must be positive");
  }
  std::string name() const override { return "velocity_cubic_damping"; }
  double extra_input_g(double, double omega, double, const Vec3&) const override {
    const double r = omega / w_ref_;
    return -c0_ * r * r * omega / b_;  // the plant multiplies by b
  }

 private:
  double w_ref_, c0_, b_;
};

}  // namespace vrelab::plant
