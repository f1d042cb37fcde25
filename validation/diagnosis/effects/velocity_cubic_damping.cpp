// Outside the library: the gas damping grows with the pendulum's rate (plant::VelocityCubicDamping).
#include <memory>
#include <numbers>

#include "plant/effects/velocity_cubic_damping.hpp"
#include "validation/diagnosis/effects/common.hpp"

namespace vrelab::validation {

Effect effect_velocity_cubic_damping() {
  Effect e;
  e.name = "velocity_cubic_damping";
  e.rank = 102;
  e.in_library = false;
  e.acts_on = ActsOn::instrument;
  e.changes_dynamics = true;
  e.physics = "the gas damping of the proof mass grows with its angular rate (turbulent or rarefied flow), "
              "c0 (1 + (omega / omega_ref)^2): it raises the damping with the rate amplitude w Theta, not with the "
              "angle as the squeeze film does, and so changes the loop's response and the loop-placed terms' "
              "rectification (outside the diagnosis' library)";
  EffectParameter p("omega_ref_rad_per_s", "rad/s");
  p.example = 0.5;
  p.nominal = INFINITY;  // no rate dependence
  e.parameters = {p};
  e.truth = [](ParameterValues v, VirtualLab& lab) {
    if (!std::isfinite(v[0])) return;
    const plant::Dynamics& d = lab.instrument.dynamics;
    const double c0 = 2 * d.pendulum_damping_ratio * 2 * std::numbers::pi * d.pendulum_frequency_Hz;
    lab.instrument.effects.push_back(std::make_shared<plant::VelocityCubicDamping>(v[0], c0, d.angle_gain_rad_per_s2_per_g));
  };
  // The damping doubles at 0.3-1 rad/s: the pendulum swings at ~1 mrad near 100-200 Hz under
  // 4 g along IA, a rate of 0.6-1.3 rad/s (tests/validation/test_out_of_library.cpp measures the
  // gap this makes on the ODE).
  e.draw = [](std::mt19937_64& rng) {
    effects::random_sign(rng);
    return std::vector<double>{effects::log_uniform(rng, 0.3, 1.0)};
  };
  e.check = [name = e.name](ParameterValues v, std::string* why) {
    if (v[0] > 0) return true;
    if (why) *why = name + " is the rate at which the damping doubles, rad/s, > 0, got " + std::to_string(v[0]);
    return false;
  };
  return e;
}

}  // namespace vrelab::validation
