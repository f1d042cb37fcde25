#pragma once
// plant/effects/squeeze_film_damping.hpp -- the gas film's damping rises as the gap closes.
#include "plant/effects/effect.hpp"

namespace vrelab::plant {

// Squeeze-film damping: the gas film between the pendulum and the case stiffens in damping
// as the gap closes, c(theta) = c0 / (1 - (theta / theta_gap)^2)^(3/2) (1/h^3 law, the gap
// closing on either side), c0 = 2 zeta w_p the nominal damping (1/s) and theta_gap the angle
// at which the pendulum would touch (rad). The extra torque -(c(theta) - c0) theta' is
// c0 theta' times a function of theta: over a period the derivative of a periodic function,
// mean zero, so it does not rectify by itself; it changes the loop's response with the
// angle amplitude. Beyond 0.95 theta_gap the film is held at its value there.
class SqueezeFilmDamping final : public Effect {
 public:
  // c0_per_s = 2 zeta w_p, angle_gain = b (rad/s^2 per g) of the plant it goes into.
  SqueezeFilmDamping(double gap_angle_rad, double c0_per_s, double angle_gain_rad_per_s2_per_g);
  std::string name() const override { return "squeeze_film_damping"; }
  double extra_input_g(double theta_rad, double omega_rad_per_s, double s1_g, const Vec3& a_g) const override;
  // The describing function: the damping that dissipates as much per period as the film
  // does for theta = Theta sin(wt), relative to c0: 2 <f(Theta sin phi) cos^2 phi>_phi,
  // f = c / c0 (1 + 3 x^2 / 8 + O(x^4), x = Theta / theta_gap).
  double damping_factor(double theta_amplitude_rad) const;
  // Under random motion (statistical linearisation): the damping c_eq that dissipates as much
  // as the film, E[c(theta) theta'^2] / E[theta'^2], relative to c0, for
  // theta = Theta sin(phi) + G, theta' = W cos(phi) + G' (phi uniform; G, G' zero-mean
  // Gaussian, independent of phi and of each other, as a stationary process and its rate are
  // at one instant): E[f(Theta sin phi + G) (W^2 cos^2 phi + s'^2)] / (W^2 / 2 + s'^2).
  // G = 0 gives damping_factor(Theta) (by another quadrature); Theta = 0 gives E[f(G)].
  double damping_factor_on_random(double theta_amplitude_rad, double rate_amplitude_rad_per_s, double sigma_rad,
                                  double sigma_rate_rad_per_s) const;
  double extra_damping_on_random_per_s(double theta_amplitude_rad, double rate_amplitude_rad_per_s, double sigma_rad,
                                       double sigma_rate_rad_per_s, double plant_angle_gain_rad_per_s2_per_g) const override {
    return c0_per_s(plant_angle_gain_rad_per_s2_per_g) *
           (damping_factor_on_random(theta_amplitude_rad, rate_amplitude_rad_per_s, sigma_rad, sigma_rate_rad_per_s) - 1);
  }
  double gap_angle_rad() const { return gap_rad_; }
  // Its own c0 and b as constructed (what makes two films the same film).
  double c0_own_per_s() const { return c0_; }
  double angle_gain_own_rad_per_s2_per_g() const { return b_; }
  // Its name, then the bytes of its gap, c0 and b as constructed.
  std::optional<std::string> cache_key() const override;
  // The film's nominal damping as the plant feels it, 1/s: c0 times b(plant) / b(film).
  double c0_per_s(double plant_angle_gain_rad_per_s2_per_g) const { return c0_ * plant_angle_gain_rad_per_s2_per_g / b_; }
  bool amplitude_dependent_damping() const override { return true; }
  // c0 (damping_factor - 1), as the plant feels it.
  double extra_damping_per_s(double theta_amplitude_rad, double plant_angle_gain_rad_per_s2_per_g) const override {
    return c0_per_s(plant_angle_gain_rad_per_s2_per_g) * (damping_factor(theta_amplitude_rad) - 1);
  }

 private:
  double gap_rad_, c0_, b_;
};

}  // namespace vrelab::plant
