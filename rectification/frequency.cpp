#include "rectification/frequency.hpp"

#include <cmath>
#include <numbers>
#include <stdexcept>

#include <Eigen/Dense>

namespace vrelab::rectification {

using plant::Accelerometer;
using namespace plant;

LoopResponse loop_response(const PlantConfig& config, double frequency_Hz) {
  if (!(frequency_Hz > 0)) throw std::invalid_argument("frequency_Hz must be positive");
  // The linear plant: the same dynamics, K1 and the linear cross terms, no nonlinear part.
  PlantConfig lin_cfg = config;
  for (int c : {k1_asym, k2, k3, k4, k_IP, k_IO, k_PO, k_PP, k_OO}) lin_cfg.coefficients[c] = 0.0;
  lin_cfg.torquer_c2_per_g = lin_cfg.torquer_c3_per_g2 = 0.0;
  lin_cfg.effects.clear();
  LoopResponse out;
  const double w_rad = 2 * std::numbers::pi * frequency_Hz;
  for (const auto& e : config.effects)
    if (const auto* mode = dynamic_cast<const MechanicalMode*>(e.get())) {
      lin_cfg.effects.push_back(e);  // linear: keep
      for (int j = 0; j < 3; ++j) out.mechanical[static_cast<std::size_t>(j)] *= mode->transmissibility(j, w_rad);
    }
  // Linear: the response does not depend on the static orientation (IA up is as good as any).
  const Accelerometer plant(lin_cfg, Vec3(1, 0, 0));
  const Accelerometer::Linear lin = plant.linearise();
  const int n = plant.size();
  const double w = 2 * std::numbers::pi * frequency_Hz;
  const Eigen::MatrixXcd m = std::complex<double>(0, w) * Eigen::MatrixXcd::Identity(n, n) - lin.A.cast<std::complex<double>>();
  const Eigen::MatrixXcd x = m.fullPivLu().solve(lin.B.cast<std::complex<double>>());  // n x 3: per unit input axis
  // The rebalance current of the linear plant: i = k G theta + (1 - k) q + w_i r, with
  // k = lead pole / lead zero (plant/accelerometer.cpp, the servo's realisation).
  const plant::Servo& sv = plant.servo();
  const double lead_ratio = sv.lead_pole_rad_per_s / sv.lead_zero_rad_per_s;
  out.frequency_Hz = frequency_Hz;
  for (int j = 0; j < 3; ++j) {
    out.current[j] = lead_ratio * sv.gain_g_per_rad * x(Accelerometer::kTheta, j) + (1 - lead_ratio) * x(Accelerometer::kLead, j) +
                     sv.integrator_rad_per_s * x(Accelerometer::kIntegral, j);
    out.angle_rad[j] = x(Accelerometer::kTheta, j);
  }
  // DC gain of the loop from a disturbance entering before it (an input term, a torque) to
  // the current: exactly 1 with the integrator, L0 / (1 + L0) without (L0 = b G / w_p^2).
  // Evaluated at 0.01 Hz: within O((f / f_c)^2) ~ 1e-9 of DC, and clear of the pivot
  // threshold that the quadrature and inert states (zero poles) would hit at f = 0.
  const Eigen::MatrixXcd m_dc = std::complex<double>(0, 2 * std::numbers::pi * 0.01) * Eigen::MatrixXcd::Identity(n, n) - lin.A.cast<std::complex<double>>();
  const Eigen::VectorXcd x_dc = m_dc.fullPivLu().solve(lin.B.col(IA).cast<std::complex<double>>());
  out.dc_gain = std::abs(lead_ratio * sv.gain_g_per_rad * x_dc[Accelerometer::kTheta] +
                         (1 - lead_ratio) * x_dc[Accelerometer::kLead] + sv.integrator_rad_per_s * x_dc[Accelerometer::kIntegral]);
  return out;
}

FrequencyPrediction sine_rectification_at_frequency(const PlantConfig& config, const Vec3& a, const vibration::SineVibration& v,
                                                    std::optional<double> range_g) {
  vibration::validate(v);
  return sine_rectification_at_frequency(config, a, v, range_g, loop_response(config, v.frequency_Hz));
}

FrequencyPrediction sine_rectification_at_frequency(const PlantConfig& config, const Vec3& a, const vibration::SineVibration& v,
                                                    std::optional<double> range_g, const LoopResponse& h) {
  if (std::abs(h.frequency_Hz - v.frequency_Hz) > 1e-9 * v.frequency_Hz)
    throw std::invalid_argument("sine_rectification_at_frequency: the loop response is for another frequency");
  double p2 = 0.0;
  bool geometry = false;
  for (const auto& e : config.effects) {
    if (const auto* p = dynamic_cast<const PickoffNonlinearity*>(e.get())) p2 += p->p2_per_rad();
    if (dynamic_cast<const PendulumGeometry*>(e.get())) geometry = true;
  }
  Eigen::Vector3cd W, F;  // the case's vibration, and what the pendulum's base feels
  vibration::SineVibration felt = v;
  for (int i = 0; i < 3; ++i) {
    W[i] = v.amplitude_g[i] * std::exp(std::complex<double>(0, v.phase_rad[i]));
    F[i] = h.mechanical[static_cast<std::size_t>(i)] * W[i];
    felt.amplitude_g[i] = std::abs(F[i]);
    felt.phase_rad[i] = std::arg(F[i]);
  }
  const std::complex<double> current = h.current[0] * W[0] + h.current[1] * W[1] + h.current[2] * W[2];
  const double dc_gain = h.dc_gain;
  FrequencyPrediction out;
  out.current_amplitude_g = current;
  out.angle_amplitude_rad = h.angle_rad[0] * W[0] + h.angle_rad[1] * W[1] + h.angle_rad[2] * W[2];

  // Terms of (1): each through the place where it acts.
  const double amp_i = std::abs(current);
  vibration::SineVibration through_loop = felt;
  through_loop.amplitude_g[IA] = amp_i;
  for (int c = k0; c < kNumCoefficients; ++c) {
    if (c == k0 || c == delta_OA || c == delta_PA || config.coefficients[c] == 0) continue;
    Coefficients only;
    only[K1] = 1;
    only[c] = config.coefficients[c];
    const bool ia_term = c <= k4;
    const bool filtered = ia_term && config.location[c] != Location::input;
    const Eq3Terms t = sine_rectification(only, a, filtered ? through_loop : felt);
    // What rectifies before the loop (input, torquer) reaches the output with the loop's DC gain.
    const double gain = config.location[c] == Location::output ? 1.0 : dc_gain;
    for (int k = 0; k < kNumTerms; ++k) out.terms.g[k] += gain * t.g[k];
  }
  if (range_g) out.terms.g[t_clipping] = clipping_sine(a[IA], amp_i, *range_g);
  // Effects beyond (1), from the averaged torque balance.
  const Dynamics& d = config.dynamics;
  const double wp = 2 * std::numbers::pi * d.pendulum_frequency_Hz;
  const std::complex<double> theta = out.angle_amplitude_rad;
  out.pickoff_g = wp * wp / d.angle_gain_rad_per_s2_per_g * p2 * std::norm(theta) / 2;
  if (geometry)
    out.pendulum_geometry_g = dc_gain * (-0.5 * std::real(F[PA] * std::conj(theta)) - a[IA] * std::norm(theta) / 4);
  // A readout polynomial: the period average of R over the output's oscillation, by the
  // trapezoidal rule on 32 points (exact for a trigonometric polynomial of degree < 32).
  // U: the output's oscillation, the current plus the output-placed cross terms' linear part
  // (their gradient at the static orientation, on what the pendulum's base feels).
  Coefficients cross_out;
  cross_out[K1] = 1;
  for (int c = delta_OA; c < kNumCoefficients; ++c)
    if (config.location[c] == Location::output) cross_out[c] = config.coefficients[c];
  const Vec3 slope = plant::output_gradient(cross_out, a) - Vec3::UnitX();
  std::complex<double> U = current + slope[IA] * F[IA] + slope[PA] * F[PA] + slope[OA] * F[OA];
  const double u0 = plant::output_g(config.coefficients, a);
  for (const auto& e : config.effects) {
    if (!dynamic_cast<const OutputPolynomial*>(e.get())) continue;
    constexpr int kN = 32;
    double mean = 0;
    for (int k = 0; k < kN; ++k) mean += e->readout(u0 + std::real(U * std::polar(1.0, 2 * std::numbers::pi * k / kN)));
    out.readout_g += mean / kN - e->readout(u0);
  }
  out.loop_dc_gain = dc_gain;
  return out;
}

}  // namespace vrelab::rectification
