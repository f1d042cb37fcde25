#pragma once
// plant/effects/effects.hpp -- effects beyond model (1), each a switchable module on the plant.
//
// An Effect hooks into the signal path of the accelerometer (accelerometer.hpp) at fixed
// places: the mechanical input (the acceleration the pendulum feels), the pickoff, the
// torquer current, and the pendulum's torque balance; it may own states. Adding an effect is
// a new class here and a line in the case reader. Each hook's default is the identity, so
// an effect overrides only where it acts. Only OutputPolynomial changes the static response
// inside the range (the static identification absorbs part of it); the others vanish at rest.
#include <array>
#include <complex>
#include <memory>
#include <string>

#include "plant/model1.hpp"

namespace vrelab::plant {

class Effect {
 public:
  virtual ~Effect() = default;
  virtual std::string name() const = 0;
  virtual int num_states() const { return 0; }
  // Typical magnitude of state k per g of input (sets finite-difference steps, tolerances).
  virtual double state_scale(int /*k*/) const { return 1.0; }
  // A guess of the states at rest under a static case acceleration (refined by Newton).
  virtual void rest_state(const Vec3& /*a_static_g*/, double* /*s*/) const {}
  // Mechanical path: the acceleration (g) the pendulum feels for a case acceleration a_g;
  // writes the derivatives of the effect's own states.
  virtual Vec3 input(const Vec3& a_g, const double* /*s*/, double* /*ds*/) const { return a_g; }
  virtual double pickoff(double theta_rad) const { return theta_rad; }
  virtual double current(double i_g) const { return i_g; }
  // The readout: the normalised output U/K1 (g) as read, before the anti-alias filter.
  virtual double readout(double u_g) const { return u_g; }
  // Extra unbalanced input on the pendulum, in g (the plant multiplies by b = P g / J):
  // s1 is the input-axis drive, a_g the acceleration the pendulum feels.
  virtual double extra_input_g(double /*theta_rad*/, double /*omega_rad_per_s*/, double /*s1_g*/,
                               const Vec3& /*a_g*/) const {
    return 0.0;
  }
};

// Pendulum geometry: the input axis turns with the pendulum, so the drive is
// a_IA cos(theta) - a_PA sin(theta) instead of a_IA. The a_PA sin(theta) part is the
// vibropendulous coupling: under vibration along IA and PA it rectifies as
// -<a_PA theta>, zero statically (theta = 0 at rest with the integrator).
class PendulumGeometry final : public Effect {
 public:
  std::string name() const override { return "pendulum_geometry"; }
  double extra_input_g(double theta, double, double s1, const Vec3& a) const override;
};

// Pickoff nonlinearity: the pickoff reads theta + p2 theta^2 (p2 in 1/rad). With the
// integrator the loop nulls the reading, so theta settles at 0 statically; under vibration
// <theta> = -p2 <theta^2> and the hinge stiffness turns it into an output shift.
class PickoffNonlinearity final : public Effect {
 public:
  explicit PickoffNonlinearity(double p2_per_rad);
  std::string name() const override { return "pickoff_nonlinearity"; }
  double pickoff(double theta) const override { return theta + p2_ * theta * theta; }
  double p2_per_rad() const { return p2_; }

 private:
  double p2_;
};

// Current saturation: the torquer current (in g of rebalance) clips at +-limit_g.
class CurrentSaturation final : public Effect {
 public:
  explicit CurrentSaturation(double limit_g);
  std::string name() const override { return "current_saturation"; }
  double current(double i) const override;

 private:
  double limit_g_;
};

// A polynomial on the readout: U/K1 = u -> u + sum_n c_n u^n, n = 2..6 (u in g, c_n in
// 1/g^(n-1)). One mechanism for two effects of validation/diagnosis/diagnose.hpp's library: the
// instrument's terms of higher order than model (1) identifies (k5 u^5, k6 u^6: they act at
// rest too, and in the loop they would rectify alike, the averaged torque balance making
// loop and output equivalent), and the nonlinearity of the data acquisition that records
// the shaker runs (q2 u^2; a lab reads its static test with another instrument).
class OutputPolynomial final : public Effect {
 public:
  OutputPolynomial(std::string name, const std::array<double, 7>& c);  // c[n] multiplies u^n; c[0], c[1] must be 0
  std::string name() const override { return name_; }
  double readout(double u) const override;
  const std::array<double, 7>& coefficients() const { return c_; }

 private:
  std::string name_;
  std::array<double, 7> c_;
};

// The data acquisition's range: the readout clips at +-full_scale_g (in g of input). A DAQ
// set too close to a run's peak output clips one side more than the other when the sensor
// has a static a_IA, and the mean shifts (validation/diagnosis/campaign.hpp's effect outside the
// diagnosis's library: a lab sees it in the raw record).
class ReadoutClipping final : public Effect {
 public:
  explicit ReadoutClipping(double full_scale_g);
  std::string name() const override { return "readout_clipping"; }
  double readout(double u) const override;

 private:
  double full_scale_g_;
};

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
  double gap_angle_rad() const { return gap_rad_; }
  // The film's nominal damping as the plant feels it, 1/s: c0 times b(plant) / b(film).
  double c0_per_s(double plant_angle_gain_rad_per_s2_per_g) const { return c0_ * plant_angle_gain_rad_per_s2_per_g / b_; }

 private:
  double gap_rad_, c0_, b_;
};

// A second mechanical mode (flexure or mount resonance) between the case and the pendulum
// along the chosen axes: base-excited oscillator, transmissibility
// (w^2 + 2 z w s) / (s^2 + 2 z w s + w^2), static gain 1.
class MechanicalMode final : public Effect {
 public:
  MechanicalMode(double frequency_Hz, double damping_ratio, const Vec3& axes_mask);
  std::string name() const override { return "mechanical_mode"; }
  int num_states() const override { return 6; }  // relative displacement and velocity per axis
  double state_scale(int k) const override;
  void rest_state(const Vec3& a_static_g, double* s) const override;
  Vec3 input(const Vec3& a_g, const double* s, double* ds) const override;
  // Its transmissibility on axis i at angular frequency w (1 on an axis it does not act on).
  std::complex<double> transmissibility(int axis, double w_rad_per_s) const;

 private:
  double w_, z_;
  Vec3 mask_;
};

}  // namespace vrelab::plant
