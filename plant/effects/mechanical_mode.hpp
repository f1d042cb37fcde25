#pragma once
// plant/effects/mechanical_mode.hpp -- a second mechanical mode between the case and the pendulum.
#include <complex>

#include "plant/effects/effect.hpp"

namespace vrelab::plant {

// A second mechanical mode (flexure or mount resonance) between the case and the pendulum
// along the chosen axes: base-excited oscillator, transmissibility
// (w^2 + 2 z w s) / (s^2 + 2 z w s + w^2), static gain 1. Linear: the prediction keeps it in
// the linearised plant.
class MechanicalMode final : public Effect {
 public:
  MechanicalMode(double frequency_Hz, double damping_ratio, const Vec3& axes_mask);
  std::string name() const override { return "mechanical_mode"; }
  int num_states() const override { return 6; }  // relative displacement and velocity per axis
  double state_scale(int k) const override;
  void rest_state(const Vec3& a_static_g, double* s) const override;
  Vec3 input(const Vec3& a_g, const double* s, double* ds) const override;
  bool kept_in_linearisation() const override { return true; }
  // Its transmissibility on axis i at angular frequency w (1 on an axis it does not act on).
  std::complex<double> transmissibility(int axis, double w_rad_per_s) const override;

 private:
  double w_, z_;
  Vec3 mask_;
};

}  // namespace vrelab::plant
