#include "plant/physical.hpp"

#include <cmath>
#include <numbers>
#include <stdexcept>

namespace vrelab::plant {

bool PhysicalParameters::IsValid(std::string* error) const {
  auto fail = [&](const std::string& m) {
    if (error) *error = m;
    return false;
  };
  auto positive = [](double x) { return std::isfinite(x) && x > 0; };
  if (!positive(inertia_kg_m2)) return fail("inertia_kg_m2 must be positive");
  if (!positive(damping_N_m_s_per_rad)) return fail("damping_N_m_s_per_rad must be positive");
  if (!positive(hinge_stiffness_N_m_per_rad)) return fail("hinge_stiffness_N_m_per_rad must be positive");
  if (!positive(pendulosity_kg_m)) return fail("pendulosity_kg_m must be positive");
  if (!positive(pickoff_V_per_rad)) return fail("pickoff_V_per_rad must be positive");
  if (!positive(servo_gain_A_per_V)) return fail("servo_gain_A_per_V must be positive");
  if (!positive(lead_zero_Hz)) return fail("lead_zero_Hz must be positive");
  if (!positive(lead_pole_Hz)) return fail("lead_pole_Hz must be positive");
  if (!(integrator_Hz >= 0) || !std::isfinite(integrator_Hz)) return fail("integrator_Hz must not be negative");
  if (!positive(torquer_N_m_per_A)) return fail("torquer_N_m_per_A must be positive");
  if (!std::isfinite(torquer_n2_per_A)) return fail("torquer_n2_per_A must be finite");
  if (!std::isfinite(torquer_n3_per_A2)) return fail("torquer_n3_per_A2 must be finite");
  if (!std::isfinite(bias_torque_N_m)) return fail("bias_torque_N_m must be finite");
  if (!positive(load_ohm)) return fail("load_ohm must be positive");
  if (!(antialias_Hz >= 0) || !std::isfinite(antialias_Hz)) return fail("antialias_Hz must not be negative");
  return true;
}

PlantConfig plant_from_physical(const PhysicalParameters& p, double g) {
  std::string why;
  if (!p.IsValid(&why)) throw std::invalid_argument(why);
  constexpr double two_pi = 2 * std::numbers::pi;
  const double amps_per_g = p.pendulosity_kg_m * g / p.torquer_N_m_per_A;  // 1 g of rebalance
  PlantConfig c;
  Dynamics& d = c.dynamics;
  d.pendulum_frequency_Hz = std::sqrt(p.hinge_stiffness_N_m_per_rad / p.inertia_kg_m2) / two_pi;
  d.pendulum_damping_ratio = p.damping_N_m_s_per_rad / (2 * std::sqrt(p.hinge_stiffness_N_m_per_rad * p.inertia_kg_m2));
  d.angle_gain_rad_per_s2_per_g = p.pendulosity_kg_m * g / p.inertia_kg_m2;
  d.integrator = p.integrator_Hz > 0;
  d.antialias_Hz = p.antialias_Hz;
  Servo s;
  s.gain_g_per_rad = p.servo_gain_A_per_V * p.pickoff_V_per_rad / amps_per_g;
  s.lead_zero_rad_per_s = two_pi * p.lead_zero_Hz;
  s.lead_pole_rad_per_s = two_pi * p.lead_pole_Hz;
  s.integrator_rad_per_s = two_pi * p.integrator_Hz;
  c.servo = s;
  c.coefficients[K1] = p.load_ohm * amps_per_g;
  c.coefficients[k0] = p.bias_torque_N_m / (p.pendulosity_kg_m * g);
  c.location[k0] = Location::input;
  c.torquer_c2_per_g = p.torquer_n2_per_A * amps_per_g;
  c.torquer_c3_per_g2 = p.torquer_n3_per_A2 * amps_per_g * amps_per_g;
  return c;
}

Coefficients implied_coefficients(const PhysicalParameters& p, double g) {
  const PlantConfig c = plant_from_physical(p, g);
  const double c2 = c.torquer_c2_per_g, c3 = c.torquer_c3_per_g2;
  // i = tau^-1(s): s = i + c2 i^2 + c3 i^3 inverted as a series in s.
  Coefficients k;
  k[K1] = c.coefficients[K1];
  k[k0] = c.coefficients[k0];  // exact only without torquer nonlinearity (k0 passes tau^-1 too)
  k[k2] = -c2;
  k[k3] = 2 * c2 * c2 - c3;
  k[k4] = 5 * c2 * c3 - 5 * c2 * c2 * c2;
  return k;
}

}  // namespace vrelab::plant
