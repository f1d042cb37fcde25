// rectification::LoopResponder solves (j w I - A) x = B on the states the current and the angle
// depend on only, by its own elimination. Checked here against the whole linearised plant
// solved independently (Eigen's full-pivot LU of every state, the anti-alias filter and the
// quadrature included, in the plant's state scales), 0.01 Hz to 20 kHz, on the plants the
// diagnosis builds: the default loop, one without integrator, servo dynamics moved, modes on
// each axis (masked axes' states inert), two modes at once. Both are backward-stable solves
// of systems whose scaled condition is ~1e2..1e6 here, so they agree to ~1e-16 x condition;
// 1e-9 of the responses' scales is far above that (4e-15 seen) and far below anything a
// prediction could show; a state left out of the reduced system errs by O(1).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <complex>
#include <memory>
#include <numbers>
#include <string>
#include <vector>

#include <Eigen/Dense>

#include "plant/accelerometer.hpp"
#include "plant/effects/effects.hpp"
#include "rectification/prediction/frequency.hpp"
#include "support/instrument.hpp"

namespace test_loop_responder {

using namespace vrelab;
using namespace vrelab::plant;

namespace {

// The current and the angle per g on each axis from every state of the linear plant.
struct FullSolve {
  std::array<std::complex<double>, 3> current, angle;
  double angle_scale = 1;  // rad per g
};
FullSolve full_solve(const PlantConfig& cfg, double f_Hz) {
  PlantConfig lin_cfg = cfg;
  for (int c : {k1_asym, k2, k3, k4, k_IP, k_IO, k_PO, k_PP, k_OO}) lin_cfg.coefficients[c] = 0.0;
  const Accelerometer plant(lin_cfg, Vec3(1, 0, 0));
  const Accelerometer::Linear lin = plant.linearise();
  const int n = plant.size();
  const std::vector<double> scale = plant.state_scale();
  Eigen::VectorXd s(n);
  for (int k = 0; k < n; ++k) s[k] = scale[static_cast<std::size_t>(k)];
  const Eigen::MatrixXcd a = (s.cwiseInverse().asDiagonal() * lin.A * s.asDiagonal()).cast<std::complex<double>>();
  const Eigen::MatrixXcd b = (s.cwiseInverse().asDiagonal() * lin.B).cast<std::complex<double>>();
  const std::complex<double> jw(0, 2 * std::numbers::pi * f_Hz);
  const Eigen::MatrixXcd m = jw * Eigen::MatrixXcd::Identity(n, n) - a;
  const Eigen::MatrixXcd y = m.fullPivLu().solve(b);
  const Servo& sv = plant.servo();
  const double k = sv.lead_pole_rad_per_s / sv.lead_zero_rad_per_s;
  FullSolve out;
  out.angle_scale = s[Accelerometer::kTheta];
  for (int j = 0; j < 3; ++j) {
    const auto sj = static_cast<std::size_t>(j);
    const std::complex<double> theta = s[Accelerometer::kTheta] * y(Accelerometer::kTheta, j);
    out.angle[sj] = theta;
    out.current[sj] = k * sv.gain_g_per_rad * theta + (1 - k) * s[Accelerometer::kLead] * y(Accelerometer::kLead, j) +
                      sv.integrator_rad_per_s * s[Accelerometer::kIntegral] * y(Accelerometer::kIntegral, j);
  }
  return out;
}

}  // namespace

TEST(LoopResponder, TheReducedSolveIsTheWholePlantsFrom10mHzTo20kHz) {
  const PlantConfig plain = test::paper_like_linear_plant();
  const double tol = 1e-9;
  std::vector<std::pair<std::string, PlantConfig>> plants;
  plants.emplace_back("default loop", plain);
  PlantConfig no_pi = plain;
  no_pi.dynamics.integrator = false;
  plants.emplace_back("no integrator", no_pi);
  PlantConfig moved = plain;
  moved.dynamics.loop_bandwidth_Hz *= 0.6, moved.dynamics.phase_margin_deg -= 10, moved.dynamics.pendulum_frequency_Hz *= 0.8;
  plants.emplace_back("servo dynamics moved", moved);
  const Vec3 axes[] = {Vec3(1, 0, 0), Vec3(0, 1, 0), Vec3(0, 0, 1), Vec3(1, 1, 1)};
  for (const Vec3& ax : axes) {
    PlantConfig mode = plain;
    mode.effects.push_back(std::make_shared<MechanicalMode>(2500.0, 0.01, ax));
    plants.emplace_back("mode 2.5 kHz on (" + std::to_string(ax[0]) + "," + std::to_string(ax[1]) + "," + std::to_string(ax[2]) + ")", mode);
  }
  PlantConfig two = plain;
  two.effects.push_back(std::make_shared<MechanicalMode>(620.0, 0.05, Vec3(1, 0, 0)));
  two.effects.push_back(std::make_shared<MechanicalMode>(4800.0, 0.2, Vec3(0, 1, 1)));
  plants.emplace_back("two modes", two);
  int compared = 0;
  double worst = 0;
  for (const auto& [name, cfg] : plants) {
    const rectification::LoopResponder responder(cfg);
    for (double lf = std::log(0.01); lf <= std::log(20000.0); lf += 0.37) {
      const double f = std::exp(lf);
      const rectification::LoopResponse r = responder(f);
      const FullSolve ref = full_solve(cfg, f);
      for (std::size_t j = 0; j < 3; ++j) {
        // Against the responses' own scales: 1 g per g for the current (the loop's gain in
        // band), the plant's typical angle per g (Accelerometer::state_scale) for the angle. A
        // backward-stable solve errs by ~eps x condition of these; the angle's smallest values
        // (at 10 mHz with the integrator, ~1e-8 of its scale) are differences in both solves.
        EXPECT_LE(std::abs(r.current[j] - ref.current[j]), tol) << name << " current axis " << j << " at " << f << " Hz";
        EXPECT_LE(std::abs(r.angle_rad[j] - ref.angle[j]), tol * ref.angle_scale) << name << " angle axis " << j << " at " << f << " Hz";
        worst = std::max({worst, std::abs(r.current[j] - ref.current[j]), std::abs(r.angle_rad[j] - ref.angle[j]) / ref.angle_scale});
        ++compared;
      }
    }
    // The DC gain (|current| per g on IA at 0.01 Hz): 1 with the integrator, L0 / (1 + L0) without.
    const FullSolve dc = full_solve(cfg, 0.01);
    EXPECT_NEAR(responder(1.0).dc_gain, std::abs(dc.current[0]), 1e-12) << name;
  }
  EXPECT_EQ(compared, 8 * 40 * 3);  // plants, frequencies, axes
  char text[32];
  std::snprintf(text, sizeof text, "%.3g", worst);
  RecordProperty("worst_difference_of_scale", text);
}

}  // namespace test_loop_responder
