#pragma once
// plant/accelerometer.hpp -- a pendulous force-rebalance accelerometer as an ODE system.
//
// Takes: model (1) coefficients with the place where each term acts, the loop dynamics,
//        effects beyond model (1), the static orientation (gravity in sensor axes, g) and
//        the dynamic input a(t) (g, sensor axes).
// Gives: an OdeSystem (plant/ode_solver.hpp) whose normalised output U/K1 (g) reproduces
//        model (1) exactly in static equilibrium, its equilibrium and linearisation, and
//        the output at any state. docs/plant.md has the equations and the defaults.
//
// Signal path (normalised: accelerations and the torquer current in g of rebalance):
//   a_case = a_static + a(t) --[effects: mechanical]--> a
//   s1 = a_IA + F_input(a_IA) + C_input(a)                      mechanical input terms
//   theta'' = -2 zeta w_p theta' - w_p^2 theta + b (s1 - tau(i) + effects' extra input)
//   u = G * pickoff(theta);  y = lead(u);  i = y + w_i * integral(y)   (PI + phase lead)
//   tau(i) = m_in(m_il^-1(i))                                   torquer with the loop terms
//   U/K1 = R(i + F_output(m_il^-1(i)) + C_output(a))            readout (R: the effects'
//                                                               readout hooks; identity without)
// where F_X(z) = sum over the IA terms (k0, k1_asym, k2, k3, k4) placed at X of k f(z),
// C_X the cross terms (delta_*, k_IP..k_OO) placed at X, m_in(z) = z + F_input(z) and
// m_il(z) = z + F_input(z) + F_loop(z). With the integrator theta = 0 at rest, so
// tau(i) = s1 and U/K1 = model (1) exactly (cross terms at the input: to second order).
// The pendulum geometry (a_IA cos theta - a_PA sin theta: vibropendulous coupling) is the
// effect PendulumGeometry, so that a plant without effects is linear where (1) is.
#include <array>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "plant/effects/effects.hpp"
#include "plant/model1.hpp"
#include "plant/ode_solver.hpp"

namespace vrelab::plant {

enum class Location { input, loop, output };
std::string_view location_name(Location l);
// Allowed places: k0..k4 anywhere; delta_* and the cross terms at the input or the output.
bool location_allowed(int coefficient, Location l);

struct Dynamics {
  double pendulum_frequency_Hz = 50.0;           // open-loop sqrt(k_h / J) / 2 pi
  double pendulum_damping_ratio = 0.3;           // c / (2 sqrt(k_h J))
  double angle_gain_rad_per_s2_per_g = 1000.0;   // b = P g / J
  double loop_bandwidth_Hz = 500.0;              // open-loop crossover frequency
  double phase_margin_deg = 50.0;                // set by the phase-lead network
  bool integrator = true;                        // PI servo (exact static model (1))
  double integrator_zero_ratio = 0.1;            // integrator zero / crossover
  double antialias_Hz = 0.0;                     // readout 2nd-order Butterworth; 0 = off
  bool IsValid(std::string* error) const;
};

// The servo that Dynamics implies (phase lead at the crossover, gain for |L| = 1 there).
struct Servo {
  double gain_g_per_rad;  // G
  double lead_zero_rad_per_s, lead_pole_rad_per_s;
  double integrator_rad_per_s;  // 0 without integrator
};
Servo design_servo(const Dynamics& d);

struct PlantConfig {
  Coefficients coefficients;
  std::array<Location, kNumCoefficients> location = default_locations();
  Dynamics dynamics;
  std::vector<std::shared_ptr<const Effect>> effects;
  // A servo given explicitly (physical parameters) instead of designed from `dynamics`.
  std::optional<Servo> servo;
  // A torquer polynomial in g of rebalance, tau(i) += c2 i^2 + c3 i^3 (physical plants;
  // the plant's static curve is then its inverse, not a finite model (1)).
  double torquer_c2_per_g = 0.0, torquer_c3_per_g2 = 0.0;
  static std::array<Location, kNumCoefficients> default_locations();
};

class Accelerometer final : public OdeSystem {
 public:
  // Core states: theta, theta', lead state, PI integral, output quadrature Q, two
  // anti-alias states; then the effects' states in order.
  static constexpr int kTheta = 0, kOmega = 1, kLead = 2, kIntegral = 3, kQuadrature = 4, kAA1 = 5, kAA2 = 6;
  static constexpr int kCoreStates = 7;

  using Input = std::function<Vec3(double t_s)>;  // dynamic part of the input, g
  Accelerometer(PlantConfig config, const Vec3& a_static_g, Input input = {});

  int size() const override { return n_; }
  void rhs(double t, const double* x, double* dx) const override;
  // The Jacobian d(rhs)/dx: analytic for the loop, model (1)'s IA terms through m_il^-1, the
  // torquer polynomial and the anti-alias filter; with effects, the chain rule through their
  // hooks, each hook's own derivative by a central difference of that hook alone (the
  // mechanical input with its states, pickoff, current, readout, extra input; the cross
  // terms' dependence on the felt acceleration likewise). Cheap: no right-hand side is
  // evaluated, only the hooks.
  bool has_jacobian() const override { return true; }
  void jacobian(double t, const double* x, double* j) const override;

  // Normalised output U/K1 (g) at state x and time t (after the anti-alias filter if on).
  double output_g(double t, const double* x) const;
  // rhs and output_g in one evaluation, at the dynamic input given (g, sensor axes) instead
  // of the Input function: dx = rhs, returns the output (the discretised random path of
  // rectification/simulation/discretised.hpp evaluates the plant once per sample this way).
  double rhs_output(const Vec3& dynamic_input_g, const double* x, double* dx) const;
  // dQ/dt = output_g - quadrature_reference_g: Q integrates the output minus a reference.
  void set_quadrature_reference(double g) { q_ref_ = g; }

  // Equilibrium under the static orientation alone (Newton on the right-hand side).
  std::vector<double> equilibrium() const;
  // Linearisation at the equilibrium: dx/dt = A dx + B da (da: dynamic input, g), and the
  // output row C with U/K1 = C dx. The quadrature state is kept (its row is C).
  struct Linear {
    Eigen::MatrixXd A, B;
    Eigen::RowVectorXd C;
  };
  Linear linearise() const;
  // Typical magnitude of each state per g of input (finite-difference steps, tolerances).
  std::vector<double> state_scale() const;
  // Slowest closed-loop time constant of `lin` (the quadrature's zero pole excluded);
  // throws std::invalid_argument if a pole has Re >= 0.
  double slowest_time_constant_s(const Linear& lin) const;

  const PlantConfig& config() const { return config_; }
  const Servo& servo() const { return servo_; }
  const Vec3& static_g() const { return a_static_; }

 private:
  // rhs; returns the output. fast_z: solve_z's fast variant (rhs_output only).
  double evaluate(const Vec3& a_case, const double* x, double* dx, bool fast_z = false) const;
  void jacobian_with_effects(double t, const double* x, double* j) const;
  double solve_z(double i) const;  // m_il^-1
  // m_il^-1 from the inverse's second-order series i - F(i) + F'(i) F(i), stopped when the next
  // Newton step is bounded below the rounding (|F''| dz^2): the same root to the last ulp or
  // two, one Newton step instead of three for model (1)'s small terms. Not used where the plant
  // is linearised by difference quotients (an ulp there is amplified; docs/performance.md).
  double solve_z_fast(double i) const;
  double f_ia(Location l, double z) const;
  double f_ia_slope(Location l, double z) const;
  double cross(Location l, const Vec3& a) const;
  double readout(double i, const Vec3& a) const;

  PlantConfig config_;
  Vec3 a_static_;
  Input input_;
  Servo servo_;
  double lead_ratio_ = 1.0;  // servo_.lead_pole_rad_per_s / servo_.lead_zero_rad_per_s
  int n_;
  std::vector<int> effect_offset_;
  double q_ref_ = 0.0;
  bool has_in_ia_ = false, has_loop_ = false, has_out_ia_ = false;
  std::array<bool, 3> has_cross_{};  // a cross term with a non-zero coefficient at each Location
  // The IA terms solve_z's Newton iteration sums: non-zero, at the input or in the loop.
  struct NewtonTerm {
    int c = 0;
    double k = 0;
    bool input = false;
  };
  std::array<NewtonTerm, 5> newton_terms_{};
  int n_newton_terms_ = 0;
  bool newton_smooth_ = true;
  bool has_torquer_poly_ = false;  // a torquer polynomial c2, c3  // no k1_asym among them (|z| has no curvature bound at 0)
};

// The plant run statically: from rest with every state zero (the instrument switched on in
// orientation a_g), integrated for 30 slowest time constants (transient e^-30 ~ 1e-13),
// returns U/K1 in g. Solver failures throw SolverError.
double settled_output_g(const PlantConfig& config, const Vec3& a_g, double relative_tolerance = 1e-12);
// Its limit without the ODE: the equilibrium (Accelerometer::equilibrium, Newton to 1e-15 of
// the state scales) read at the output, U/K1 in g.
double rest_output_g(const PlantConfig& config, const Vec3& a_g);

}  // namespace vrelab::plant
