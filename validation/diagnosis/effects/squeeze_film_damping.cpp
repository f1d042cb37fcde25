// The gas film's damping rises as the pendulum nears the case (plant::SqueezeFilmDamping).
#include <memory>
#include <numbers>

#include "plant/effects/squeeze_film_damping.hpp"
#include "validation/diagnosis/effects/common.hpp"

namespace vrelab::validation {

Effect effect_squeeze_film_damping() {
  Effect e;
  e.name = "squeeze_film_damping";
  e.rank = 13;
  e.acts_on = ActsOn::instrument;
  e.changes_dynamics = true;
  e.hypothesis_accuracy = 0.02;  // the harmonic balance against the ODE near contact
  e.physics = "the gas film's damping rises as the pendulum nears the case, c0 / (1 - (theta / theta_gap)^2)^(3/2); "
              "the parameter is 1 / theta_gap (0: no film nonlinearity). It does not rectify by itself (its torque "
              "is c0 theta' times a function of theta, mean zero over a period) but the damping grows with the "
              "angle amplitude, which changes the loop's response and so the loop-placed terms' rectification: "
              "~ amplitude^4, near the pendulum's and the loop's resonances";
  EffectParameter p("inverse_gap_angle", "1/rad");
  p.example = 700;
  p.nominal = 0;
  p.grid = {0};
  for (double x : effects::geometric(30, 3000, 16)) p.grid.push_back(x);
  e.parameters = {p};
  // The film on the nominal plant: c0 its nominal damping 2 zeta w_p, the gap 1 / parameter.
  e.hypothesis = [](ParameterValues v, plant::PlantConfig& c, TableMotion&) {
    if (!(v[0] > 0)) return;
    const plant::Dynamics& d = c.dynamics;
    const double c0_per_s = 2 * d.pendulum_damping_ratio * 2 * std::numbers::pi * d.pendulum_frequency_Hz;
    c.effects.push_back(std::make_shared<plant::SqueezeFilmDamping>(1 / v[0], c0_per_s, d.angle_gain_rad_per_s2_per_g));
  };
  // The instrument's film, on its own dynamics (written out: the truth does not share the
  // hypothesis' code).
  e.truth = [](ParameterValues v, VirtualLab& lab) {
    if (!(v[0] > 0)) return;
    const plant::Dynamics& d = lab.instrument.dynamics;
    const double c0_per_s = 2 * d.pendulum_damping_ratio * 2 * std::numbers::pi * d.pendulum_frequency_Hz;
    lab.instrument.effects.push_back(
        std::make_shared<plant::SqueezeFilmDamping>(1 / v[0], c0_per_s, d.angle_gain_rad_per_s2_per_g));
  };
  // The gap 1.0-1.2 mrad: the pendulum swings up to 1.01 mrad at 4 g (130 Hz; 0.998 mrad in
  // the 100 Hz runs), so these films are near contact; at 1.3 mrad and more the film's gap
  // trades with the coefficients' errors (docs/diagnose.md).
  e.draw = [](std::mt19937_64& rng) {
    effects::random_sign(rng);
    return std::vector<double>{1 / effects::log_uniform(rng, 1.0e-3, 1.2e-3)};
  };
  e.check = [name = e.name](ParameterValues v, std::string* why) {
    if (v[0] >= 0) return true;
    if (why) *why = name + " is 1 / the gap angle in 1/rad (0: none), >= 0, got " + std::to_string(v[0]);
    return false;
  };
  return e;
}

}  // namespace vrelab::validation
