#pragma once
// plant/effects/effect.hpp -- the interface of an effect beyond model (1): a switchable module
// on the plant (plant/accelerometer.hpp), one class per file in this folder.
//
// Time-domain hooks (the ODE plant): an Effect hooks into the signal path at fixed places: the
// mechanical input (the acceleration the pendulum feels), the pickoff, the torquer current,
// the readout and the pendulum's torque balance; it may own states. Each hook's default is
// the identity, so an effect overrides only where it acts.
// Frequency-domain hooks (rectification/prediction/frequency.hpp): what the first-order
// prediction needs to know of the effect, so that it never asks for a concrete class. Each
// default says "not this kind".
// Only OutputPolynomial changes the static response inside the range (the static
// identification absorbs part of it); the others vanish at rest.
#include <complex>
#include <optional>
#include <string>

#include "plant/model1.hpp"

namespace vrelab::plant {

class Effect {
 public:
  virtual ~Effect() = default;
  virtual std::string name() const = 0;

  // --- The ODE plant.
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

  // --- The frequency-domain prediction.
  // A linear effect the linearisation keeps (a mechanical mode); the others are removed from
  // the linear plant the prediction filters through.
  virtual bool kept_in_linearisation() const { return false; }
  // What the pendulum's base feels per g of case vibration on `axis` at w (kept effects; 1 else).
  virtual std::complex<double> transmissibility(int /*axis*/, double /*w_rad_per_s*/) const { return 1.0; }
  // The pickoff's quadratic coefficient p2 (1/rad): <theta> = -p2 <theta^2> rectifies.
  virtual double pickoff_p2_per_rad() const { return 0.0; }
  // The vibropendulous geometry (the input axis turns with the pendulum).
  virtual bool vibropendulous() const { return false; }
  // The readout is averaged over the output's oscillation in the prediction (a polynomial on
  // the readout); a readout that is not (clipping) is left to the ODE.
  virtual bool readout_averaged_in_prediction() const { return false; }
  // An amplitude-dependent damping, replaced in the prediction by its describing function
  // (rectification::amplitude_linearised).
  virtual bool amplitude_dependent_damping() const { return false; }
  // The describing function's damping beyond the nominal, 1/s, at angle amplitude
  // theta_amplitude_rad in a plant of angle gain b (rad/s^2 per g).
  virtual double extra_damping_per_s(double /*theta_amplitude_rad*/, double /*plant_angle_gain_rad_per_s2_per_g*/) const {
    return 0.0;
  }
  // The statistical linearisation's damping beyond the nominal, 1/s, for an angle
  // theta = Theta sin(phi) + G, phi uniform and G zero-mean Gaussian independent of it
  // (random and sine-on-random motion, rectification::random_linearised): the sine's angle and
  // rate amplitudes, G's and its rate's standard deviations.
  virtual double extra_damping_on_random_per_s(double /*theta_amplitude_rad*/, double /*rate_amplitude_rad_per_s*/,
                                               double /*sigma_rad*/, double /*sigma_rate_rad_per_s*/,
                                               double /*plant_angle_gain_rad_per_s2_per_g*/) const {
    return 0.0;
  }
  // The bytes that say which effect this is, its class and parameters, for the prediction's
  // cache of a run's balance (rectification::film_balance_key): two effects with the same key
  // act alike. nullopt: no such key, and the cache tells the effect by its address.
  virtual std::optional<std::string> cache_key() const { return std::nullopt; }
};

}  // namespace vrelab::plant
