#pragma once
// rectification/frequency.hpp -- eq. (3) at a vibration frequency: what the paper left open.
//
// Takes: a plant (plant/accelerometer.hpp), the static orientation (g), a sine vibration
//        (g peak, per-axis phase, frequency in Hz).
// Gives: the vibration error per term (g) to first order in the nonlinearities, each term
//        seen through the plant's linear dynamics at that frequency (docs/frequency.md):
//  - terms at the input (mechanical) and the cross terms: the vibration itself (eq. (3));
//  - IA terms in the loop or at the output: eq. (3) with the IA amplitude replaced by the
//    amplitude |I| of the rebalance current, I = sum_j H_ij(jw) W_j (W_j = w_j e^{j phi_j});
//    the averaged torque balance makes both places rectify alike;
//  - pickoff nonlinearity p2: (w_p^2 / b) p2 |Theta|^2 / 2, Theta = sum_j G_j(jw) W_j the
//    pendulum angle (<theta> = -p2 <theta^2> and the hinge stiffness turns it into torque);
//  - pendulum geometry: -Re(W_PA conj(Theta)) / 2 - a_IA |Theta|^2 / 4 (vibropendulous);
//  - clipping at [range]: of the current's amplitude |I|;
//  - a polynomial on the readout R(u) (plant::OutputPolynomial): <R(u0 + Re(U e^{jwt}))> -
//    R(u0), u0 the static output of (1), U = I + the output-placed cross terms' linear part.
// H and G come from the linearisation of the plant with every nonlinear part removed. What
// rectifies before the loop (input terms, the torquer, the pendulum geometry) reaches the
// output with the loop's DC gain: 1 with the integrator, L0/(1 + L0) without (L0 = b G/w_p^2).
// The pickoff formula assumes the integrator (<u> = 0).
// Behind a mechanical mode, the input-placed terms, the cross terms and the pendulum geometry
// see the vibration through the mode's transmissibility (what the pendulum's base feels).
#include <array>
#include <complex>

#include "plant/accelerometer.hpp"
#include "rectification/eq3.hpp"
#include "vibration/profile.hpp"

namespace vrelab::rectification {

struct FrequencyPrediction {
  Eq3Terms terms;                         // the terms of (1), at this frequency
  double pickoff_g = 0.0;                 // effect: pickoff nonlinearity
  double pendulum_geometry_g = 0.0;       // effect: vibropendulous coupling
  double readout_g = 0.0;                 // effect: a polynomial on the readout
  std::complex<double> current_amplitude_g;  // I
  std::complex<double> angle_amplitude_rad;  // Theta
  double loop_dc_gain = 1.0;  // from a disturbance before the loop to the output; 1 with the integrator
  double total_g() const { return terms.total_g() + pickoff_g + pendulum_geometry_g + readout_g; }
};

FrequencyPrediction sine_rectification_at_frequency(const plant::PlantConfig& plant, const Vec3& a_static_g,
                                                    const vibration::SineVibration& v,
                                                    std::optional<double> range_limit_g = std::nullopt);

// The linear plant's response at one frequency (what the prediction filters through):
// the rebalance current and the pendulum angle per g of vibration on each sensor axis, and
// the loop's DC gain. It depends on the dynamics and the linear effects (a mechanical mode)
// only, not on the coefficients, the orientation or the amplitude: compute it once per
// (plant dynamics, frequency) and reuse it.
struct LoopResponse {
  double frequency_Hz = 0;
  std::array<std::complex<double>, 3> current{}, angle_rad{};
  // What the pendulum's base feels per g of case vibration on each axis: the mechanical
  // modes' transmissibility (1 without a mode).
  std::array<std::complex<double>, 3> mechanical{1.0, 1.0, 1.0};
  double dc_gain = 1;
};
LoopResponse loop_response(const plant::PlantConfig& plant, double frequency_Hz);
// The same prediction with the response given (its frequency must be v's).
FrequencyPrediction sine_rectification_at_frequency(const plant::PlantConfig& plant, const Vec3& a_static_g,
                                                    const vibration::SineVibration& v, std::optional<double> range_limit_g,
                                                    const LoopResponse& response);

}  // namespace vrelab::rectification
