#pragma once
// rectification/prediction/second_order.hpp -- a pickoff nonlinearity beyond first order: its
// current through the loop's nonlinearity (a product of two first-order responses) and its own
// term's correction, which the first-order prediction (frequency.hpp, random.hpp) leaves out.
//
// Takes: the plant (its dynamics, IA terms and pickoff nonlinearity p2, 1/rad), the
//        first-order angle theta_1 (rad) and torquer current z_1 (g) of a periodic motion, or
//        the random profile (g^2/Hz) and the loop's responses.
// Gives: FrequencyPrediction::second_order_g (g): exact for periodic motion (a harmonic
//        balance), to second order in the pickoff's error for Gaussian motion.
//
// The servo nulls the measured angle p = theta + p2 theta^2, not the angle: the pickoff's
// error e = p2 theta^2 enters the loop as a measurement error and makes a torquer current
//     z_2 = T_ze * e,  T_ze(jw) = C / (1 + P C) = H_zF(jw) (w_p^2 - w^2 + 2 j zeta w_p w) / b,
// H_zF the current per g of force at the pendulum (a LoopResponse's current over its mode
// transmissibility along IA), P = b / (w_p^2 - w^2 + 2 j zeta w_p w) the bare pendulum; the
// angle moves by G_e * e, G_e = -H_zF. Its mean is the first-order pickoff term
// (w_p^2 / b) p2 <theta_1^2>; its oscillation (2 g rms under 5.7 g rms of NAVMAT-shaped motion
// with p2 = 40 /rad behind a 620 Hz mode) is rectified by the IA terms f acting on the torque
// z (in the loop or at the output: plant/accelerometer.cpp). A term in the loop also pushes
// the pendulum by its own oscillation f(z), which moves the angle the pickoff squares.
//   - Periodic motion (PeriodicPickoffBalance): both nonlinear places solved together on the
//     period.
//   - Gaussian motion (z_1, theta_1 jointly Gaussian; s^2 = E[z_1^2]; c(tau) =
//     E[z_1(t) theta_1(t - tau)], rho(tau) = E[theta_1(t) theta_1(t - tau)]; L the impulse
//     response of T_ze, g that of G_e), by Isserlis' theorem, for each IA basis function f:
//       <f'(a + Z) z_2> = p2 J E[f'(a + Z)(Z^2 - s^2)] / s^4,  J = int L(tau) c(tau)^2 dtau
//                         (k1': -u phi(u) s^2 with u = a / s; k2: 0; k3: 6 s^4; k4: 24 a s^4);
//       <f''(a + Z) z_2^2> / 2: k2 E[z_2^2], k3 3 a E[z_2^2], k4 6 ((a^2 + s^2) E[z_2^2] + 8 p2^2 K),
//         E[z_2^2] = 2 p2^2 int int L L rho^2, K = int int L(t1) L(t2) c(t1) c(t2) rho(t1 - t2);
//       delta E[f'(a + Z)] for the current's mean shift delta;
//       in the loop, 2 p2 (w_p^2 / b) E[f'(a + Z)] E[theta_1 (H_thetaF * z_1)] (Stein's lemma);
//     the pickoff's own: <theta^2> gains <theta>^2 + E[theta_2^2 + 2 theta_1 theta_3] +
//     4 p2 <theta> int s_theta G_e (theta_2 = g * e, theta_3 = g * (2 p2 theta_1 theta_2), the
//     loop's gain moved by the pickoff's slope at the mean angle). Relative error O((p2
//     sigma_theta)^2 ) of the second-order part. The integrals are convolutions of the
//     cross-spectra on a uniform grid (FFTW). k1''s f'' term (a delta function) is left out.
// Not included: sine on random (FrequencyPrediction::second_order_left_out); the pickoff's
// current in the readout or the pendulum geometry; input-placed terms (first order).
#include <array>
#include <complex>
#include <memory>
#include <vector>

#include <Eigen/Dense>

#include "plant/accelerometer.hpp"
#include "rectification/prediction/frequency.hpp"
#include "vibration/random.hpp"

namespace vrelab::rectification {

// The plant's pickoff nonlinearity p2 (1/rad, the sum over its effects); 0 without one.
double pickoff_p2_per_rad(const plant::PlantConfig& plant);

// T_ze at r.frequency_Hz: the torquer current (g) per rad of pickoff error, from the loop's
// response r of the plant whose dynamics are d. (The angle's, G = -H_zF, is -T_ze P.)
std::complex<double> pickoff_error_current(const plant::Dynamics& d, const LoopResponse& r);

// Gaussian motion's pickoff beyond first order: its own term's correction
// (g); how its current moves the means of the IA basis functions k1'..k4 (|x|/2, x^2, x^3,
// x^4 at their indices; the rest 0); and, per unit of such a term placed in the loop (its
// torque on the pendulum), how much that term's oscillation moves the pickoff term (g).
struct PickoffSecondOrder {
  double pickoff_g = 0;
  double expansion = 0;  // p2 sigma_theta: the pickoff's error relative to the angle
  std::array<double, plant::kNumCoefficients> shift{}, loop_shift{};
  // pickoff_g plus, over the IA terms placed in the loop (gain dc_gain) or at the output (1),
  // gain c_k shift[k], plus c_k loop_shift[k] for those in the loop.
  double g(const plant::Coefficients& c, const std::array<plant::Location, plant::kNumCoefficients>& location, double dc_gain) const;
  // Its error: the orders left out, expansion^2 |g|, and k4's part whole (against the ODE the
  // p2 k4 part is not linear in k4 at 15 g rms of current: docs/frequency.md).
  double error_g(const plant::Coefficients& c, const std::array<plant::Location, plant::kNumCoefficients>& location,
                 double dc_gain) const;
};

// Periodic motion: the loop's harmonic balance with its two nonlinear places, the pickoff
// (e = p2 theta^2, through G_e = -H_zF and T_ze) and the IA terms in the loop (the torque z
// solves z + f_loop(z) = i, the pendulum pushed by f_loop(z), through H_thetaF and H_zF), on
// kM points of the period, harmonics up to Q = 4 h_max of e and f (the DC through the loop's
// DC gain), by fixed-point iteration from the first-order angle and current; the output is
// <i> + <f_out(z)>. operator() gives the vibration error beyond the first-order prediction's
// (FrequencyPrediction's pickoff_g and IA terms, recomputed on the same points): exact but for
// the truncation, in p2 and in the coefficients alike (in-phase input-placed terms stay first
// order). Throws std::invalid_argument where the iteration does not settle.
struct PeriodicTone {
  int h;
  std::complex<double> current_g, angle_rad;
};
class PeriodicPickoffBalance {
 public:
  // tones: the first-order current and angle per harmonic h of frequency_Hz (phasors,
  // Im(X e^{j h w t})); a_IA_g the mean IA acceleration the loop holds; pickoff_g and dc_gain
  // the first-order prediction's.
  PeriodicPickoffBalance(const plant::PlantConfig& plant, double a_IA_g, double pickoff_g, double dc_gain, double frequency_Hz,
                         const std::vector<PeriodicTone>& tones, const ResponseAt& response);
  double operator()(const plant::Coefficients& c) const;  // g

 private:
  std::array<plant::Location, plant::kNumCoefficients> location_;
  double p2_, a_, pickoff_g_, dc_gain_, stiffness_, frequency_Hz_;
  int Q_, M_;
  // Per harmonic q = 0..Q: T_ze, G_e, H_thetaF, H_zF (DC: the loop's DC gains).
  std::vector<std::complex<double>> T_, G_, Hth_, Hz_;
  std::shared_ptr<const std::vector<std::complex<double>>> ph_;  // e^{j q phi_k}, k-major (shared)
  std::vector<double> theta1_, z1_;      // first order on the points
  std::vector<double> theta0_, i0_;      // the balance without IA terms: where each call starts
  // Iterates theta, the current i and the torque z to the balance with the IA terms `loop`.
  void solve(const plant::Coefficients& loop, std::vector<double>& theta, std::vector<double>& i, std::vector<double>& z) const;
};

// Gaussian motion: the integrals above on a uniform grid of `points` frequencies up to the
// band's top (their sums up to twice it), from the profile (turned by `turn`, as
// random_response) and the loop's response. Per p2 (J) and p2^2 (the rest); g the current's
// unit, rad the angle's.
//   J: int L c^2, g^3 (E[z_1^2 z_2] = 2 p2 J);
//   z2_var: E[z_2^2] / p2^2; K = int int L L c c rho (cov(Z^2, z_2^2) = 8 p2^2 K);
//   current_z3: 2 E[z_1 z_3] / p2^2 (z_3 = T * (2 p2 theta_1 theta_2)); K2 = int Q_zt(F) G(-F)
//     Y(-F) dF (E[Z^3 z_3] = 3 s^2 E[Z z_3] + 12 p2^2 K2); current_slope: int s_zt(f) T(-f) df
//     (z_1 moved by the pickoff's slope at the mean angle: 2 E[z_1 dz_1] = 4 p2 <theta> of it);
//   angle_var: E[theta_2^2 + 2 theta_1 theta_3] / p2^2 (the angle's own second order: theta_2
//     = G * e, theta_3 = G * (2 p2 theta_1 theta_2));
//   loop_slope: int s_theta(f) G(-f) df (two-sided): the loop's gain for theta_1 moved by the
//     mean angle (the pickoff's slope 1 + 2 p2 <theta>);
//   angle_force: E[theta_1 (H_thetaF * z_1)], the angle a torque like the current makes,
//     correlated with the angle (a term in the loop torques the pendulum by E[f'] z_1);
//   current_var, angle_var_first: E[z_1^2], E[theta_1^2] on the grid (a check of it).
struct GaussianPickoffMoments {
  double J = 0, z2_var = 0, K = 0, angle_var = 0, loop_slope = 0, angle_force = 0;
  double current_z3 = 0, current_slope = 0, K2 = 0;
  double current_var = 0, angle_var_first = 0;
};
GaussianPickoffMoments gaussian_pickoff_moments(const plant::PlantConfig& plant, const vibration::RandomProfile& p,
                                                const ResponseAt& response, const Eigen::Matrix3d& turn = Eigen::Matrix3d::Identity(),
                                                int points = 4096);
// The second order of Gaussian motion: current_var_g2 and angle_var_rad2 the first-order
// E[z_1^2] and E[theta_1^2] (RandomResponse), Z ~ N(0, current_var) about a_IA_g.
PickoffSecondOrder gaussian_second_order(const GaussianPickoffMoments& m, const plant::Dynamics& d, double p2, double current_var_g2,
                                         double angle_var_rad2, double a_IA_g);

}  // namespace vrelab::rectification
