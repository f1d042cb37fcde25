#pragma once
// plant/physical.hpp -- the accelerometer from physical parameters (SI).
//
// Takes: the pendulum (inertia, gas damping, hinge stiffness, pendulosity), the pickoff
//        gain, the servo (gain, phase-lead zero and pole, integrator zero), the torquer (gain,
//        quadratic and cubic nonlinearity, bias torque) and the load resistor; the site's g.
// Gives: the same normalised plant (accelerometer.hpp) with explicit servo, and the model (1)
//        coefficients it implies statically. Mapping (docs/plant.md):
//   b = P g / J,  w_p = sqrt(k_h / J),  zeta = c / (2 sqrt(k_h J)),
//   1 g of rebalance = P g / K_t amperes,  G = K_t K_s K_po / (P g)  [g/rad],
//   K1 = R_L P g / K_t  [V/g],  torquer T = K_t i (1 + n2 i + n3 i^2) ->
//   tau(i_g) = i_g + c2 i_g^2 + c3 i_g^3 with c2 = n2 P g / K_t, c3 = n3 (P g / K_t)^2,
//   bias torque T_b -> k0 = T_b / (P g) at the input.
// Statically the output is tau^-1(a_IA + k0): model (1) with k2 = -c2, k3 = 2 c2^2 - c3,
// k4 = 5 c2 c3 - 5 c2^3 and higher orders that (1) lacks (series inversion).
#include <string>

#include "plant/accelerometer.hpp"

namespace vrelab::plant {

struct PhysicalParameters {
  double inertia_kg_m2 = 5e-8;
  double damping_N_m_s_per_rad = 9.4e-6;
  double hinge_stiffness_N_m_per_rad = 4.93e-3;
  double pendulosity_kg_m = 5e-6;
  double pickoff_V_per_rad = 1000.0;
  double servo_gain_A_per_V = 3.8e-3;
  double lead_zero_Hz = 153.0;
  double lead_pole_Hz = 1635.0;
  double integrator_Hz = 50.0;  // 0: no integrator
  double torquer_N_m_per_A = 0.0392;
  double torquer_n2_per_A = 0.0;
  double torquer_n3_per_A2 = 0.0;
  double bias_torque_N_m = 0.0;
  double load_ohm = 1000.0;
  double antialias_Hz = 0.0;
  bool IsValid(std::string* error) const;
};

// Throws std::invalid_argument naming the parameter when !p.IsValid().
PlantConfig plant_from_physical(const PhysicalParameters& p, double g_m_per_s2);
// The model (1) coefficients the plant shows statically (to third order in the torquer's
// nonlinearity); the cross terms are zero.
Coefficients implied_coefficients(const PhysicalParameters& p, double g_m_per_s2);

}  // namespace vrelab::plant
