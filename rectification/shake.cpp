#include "rectification/shake.hpp"

#include <algorithm>
#include <cmath>
#include <complex>
#include <numbers>
#include <stdexcept>

#include <Eigen/Dense>
#include <Eigen/Eigenvalues>

namespace vrelab::rectification {
namespace {
constexpr double kPi = std::numbers::pi;
using plant::Accelerometer;
}  // namespace

bool ShakeSettings::IsValid(std::string* error) const {
  auto fail = [&](const std::string& m) {
    if (error) *error = m;
    return false;
  };
  if (!(relative_tolerance > 0 && relative_tolerance < 1e-3)) return fail("relative_tolerance must lie in (0, 1e-3)");
  if (!(settle_decay > 0 && settle_decay < 1)) return fail("settle_decay must lie in (0, 1)");
  if (blocks < 2) return fail("blocks must be at least 2");
  if (!(min_measure_s >= 0)) return fail("min_measure_s must not be negative");
  return true;
}

SineShakeResult shake_sine(const plant::PlantConfig& config, const Vec3& a_static, const vibration::SineVibration& v,
                           const ShakeSettings& s) {
  std::string why;
  if (!s.IsValid(&why)) throw std::invalid_argument(why);
  vibration::validate(v);
  if (!(v.frequency_Hz > 0)) throw std::invalid_argument("frequency_Hz must be positive for a shaker run");
  const double w = 2 * kPi * v.frequency_Hz;
  const double period = 1 / v.frequency_Hz;

  // The plant at rest: baseline, equilibrium, linearisation.
  const Accelerometer rest(config, a_static);
  const std::vector<double> x_eq = rest.equilibrium();
  SineShakeResult r;
  r.baseline_g = rest.output_g(0, x_eq.data());
  const Accelerometer::Linear lin = rest.linearise();
  const int n = rest.size();

  // Slowest closed-loop time constant (the quadrature state's zero eigenvalue excluded).
  std::vector<int> keep;
  for (int k = 0; k < n; ++k)
    if (k != Accelerometer::kQuadrature && !((k == Accelerometer::kAA1 || k == Accelerometer::kAA2) && config.dynamics.antialias_Hz <= 0))
      keep.push_back(k);
  Eigen::MatrixXd a_red(keep.size(), keep.size());
  for (std::size_t i = 0; i < keep.size(); ++i)
    for (std::size_t j = 0; j < keep.size(); ++j) a_red(static_cast<Eigen::Index>(i), static_cast<Eigen::Index>(j)) = lin.A(keep[i], keep[j]);
  const Eigen::VectorXcd eig = Eigen::EigenSolver<Eigen::MatrixXd>(a_red, false).eigenvalues();
  double slowest = std::numeric_limits<double>::infinity();
  for (Eigen::Index i = 0; i < eig.size(); ++i) slowest = std::min(slowest, -eig[i].real());
  if (!(slowest > 0)) throw std::invalid_argument("the closed loop is not stable (a pole with Re >= 0)");
  r.slowest_time_constant_s = 1 / slowest;

  // Linear periodic steady state: x = x_eq + Im(X e^{jwt}), X = (jwI - A)^-1 B W.
  Eigen::Vector3cd wc;
  for (int i = 0; i < 3; ++i) wc[i] = v.amplitude_g[i] * std::exp(std::complex<double>(0, v.phase_rad[i]));
  const Eigen::MatrixXcd m = std::complex<double>(0, w) * Eigen::MatrixXcd::Identity(n, n) - lin.A.cast<std::complex<double>>();
  const Eigen::VectorXcd phasor = m.fullPivLu().solve(lin.B.cast<std::complex<double>>() * wc);

  Accelerometer shaken(config, a_static, [v, w](double t) {
    Vec3 a;
    for (int i = 0; i < 3; ++i) a[i] = v.amplitude_g[i] * std::sin(w * t + v.phase_rad[i]);
    return a;
  });
  shaken.set_quadrature_reference(r.baseline_g);
  std::vector<double> x0(x_eq);
  plant::SolverSettings solver;
  solver.relative_tolerance = s.relative_tolerance;
  const std::vector<double> scale = rest.state_scale();
  const double amplitude = std::max(v.amplitude_g.cwiseAbs().maxCoeff(), 1e-12);
  for (int k = 0; k < n; ++k) {
    const std::size_t kk = static_cast<std::size_t>(k);
    x0[kk] += phasor[k].imag();
    const double typical = std::max({std::abs(phasor[k]), std::abs(x_eq[kk]), 1e-6 * amplitude * scale[kk]});
    solver.absolute_tolerance.push_back(s.relative_tolerance * typical);
  }
  solver.max_step_s = period / 8;

  // Settling: whole periods covering ln(1/decay) slowest time constants.
  const int settle_periods = static_cast<int>(std::ceil(std::log(1 / s.settle_decay) * r.slowest_time_constant_s / period));
  r.settle_s = settle_periods * period;
  const int per_block = std::max(1, static_cast<int>(std::ceil(s.min_measure_s / (s.blocks * period))));
  r.periods = per_block * s.blocks;

  plant::OdeSolver ode(shaken, 0.0, x0, solver);
  double q_prev = ode.advance(r.settle_s)[Accelerometer::kQuadrature];
  const double q_start = q_prev;
  const double block_s = per_block * period;
  std::vector<double> block_mean;
  for (int b = 1; b <= s.blocks; ++b) {
    const double q = ode.advance(r.settle_s + b * block_s)[Accelerometer::kQuadrature];
    block_mean.push_back((q - q_prev) / block_s);
    q_prev = q;
  }
  r.measured_g = (q_prev - q_start) / (r.periods * period);
  double ss = 0;
  for (double b : block_mean) ss += (b - r.measured_g) * (b - r.measured_g);
  const double batch_sigma = std::sqrt(ss / (s.blocks - 1) / s.blocks);
  // Floor: the quadrature's own tolerance over the measured span.
  const double floor = s.relative_tolerance * std::abs(phasor[Accelerometer::kQuadrature]) / (r.periods * period);
  r.sigma_g = std::max(batch_sigma, floor);
  r.steps = ode.steps();
  r.rhs_evaluations = ode.rhs_evaluations();
  return r;
}

}  // namespace vrelab::rectification
