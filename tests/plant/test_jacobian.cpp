// The plant's analytic Jacobian (Accelerometer::jacobian) against difference quotients of its
// right-hand side, and CVODE's answers with it against CVODE's own difference quotients.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <memory>
#include <random>
#include <vector>

#include <Eigen/Dense>

#include "plant/accelerometer.hpp"
#include "plant/effects/effects.hpp"
#include "plant/effects/fixture_rattle.hpp"
#include "plant/effects/proof_mass_torsion.hpp"
#include "plant/effects/velocity_cubic_damping.hpp"
#include "plant/effects/vibration_heating.hpp"
#include "rectification/simulation/shake.hpp"
#include "vibration/profile.hpp"

namespace test_jacobian {

using namespace vrelab;
using namespace vrelab::plant;

namespace {

// Central difference quotient of the right-hand side, column by column.
Eigen::MatrixXd difference_jacobian(const Accelerometer& p, const std::vector<double>& x0) {
  const int n = p.size();
  const std::vector<double> scale = p.state_scale();
  Eigen::MatrixXd j(n, n);
  std::vector<double> x = x0, fp(static_cast<std::size_t>(n)), fm(fp);
  for (int c = 0; c < n; ++c) {
    const std::size_t k = static_cast<std::size_t>(c);
    const double h = 1e-6 * scale[k];
    x[k] = x0[k] + h;
    p.rhs(0, x.data(), fp.data());
    x[k] = x0[k] - h;
    p.rhs(0, x.data(), fm.data());
    x[k] = x0[k];
    for (int r = 0; r < n; ++r) j(r, c) = (fp[static_cast<std::size_t>(r)] - fm[static_cast<std::size_t>(r)]) / (2 * h);
  }
  return j;
}

}  // namespace

TEST(AnalyticJacobian, EqualsCentralDifferencesAtRandomStates) {
  // Random plants (IA terms k0, k2, k3, k4 up to 1e-3, 1e-4 /g, 1e-5 /g^2, 1e-7 /g^3 at random
  // places, cross terms, the torquer polynomial, anti-alias filter and integrator on or off)
  // at random states of ~10 g-sized motion (m_il stays monotone there). The central quotient's truncation error is ~h^2 f''' / 6 ~ 1e-12 of
  // the entry (h = 1e-6 of each state's scale) and its rounding ~eps / 1e-6 ~ 1e-10 of the
  // row's size: the entries agree to 1e-7 of the row's largest entry (a wrong derivative of
  // any term, e.g. F' for k2 = 1e-4 at 30 g, is 6e-3 of it).
  std::mt19937_64 rng(6101);
  std::uniform_real_distribution<double> u(-1, 1);
  for (int trial = 0; trial < 40; ++trial) {
    PlantConfig cfg;
    cfg.coefficients[K1] = 1.25;
    for (int c : {k0, k2, k3, k4}) {
      cfg.coefficients[c] = u(rng) * (c == k0 ? 1e-3 : c == k2 ? 1e-4 : c == k3 ? 1e-5 : 1e-7);
      const int pick = static_cast<int>(rng() % 3);
      cfg.location[c] = pick == 0 ? Location::input : pick == 1 ? Location::loop : Location::output;
    }
    cfg.coefficients[k_IP] = 1e-4 * u(rng);
    cfg.coefficients[delta_PA] = 1e-4 * u(rng);
    cfg.dynamics.integrator = trial % 3 != 0;
    cfg.dynamics.antialias_Hz = trial % 2 == 0 ? 2000.0 : 0.0;
    if (trial % 4 == 1) cfg.torquer_c2_per_g = 1e-4, cfg.torquer_c3_per_g2 = -1e-6;
    const Accelerometer p(cfg, Vec3(0.5 * u(rng), 0.8, 0.3 * u(rng)), [](double t) { return Vec3(3 * std::sin(400 * t), 2, 0); });
    ASSERT_TRUE(p.has_jacobian());
    const std::vector<double> scale = p.state_scale();
    std::vector<double> x = p.equilibrium();
    for (std::size_t k = 0; k < x.size(); ++k) x[k] += 10 * u(rng) * scale[k];
    Eigen::MatrixXd analytic(p.size(), p.size());
    p.jacobian(0, x.data(), analytic.data());
    const Eigen::MatrixXd quotient = difference_jacobian(p, x);
    for (int r = 0; r < p.size(); ++r) {
      const double size = std::max(quotient.row(r).cwiseAbs().maxCoeff(), 1e-300);
      for (int c = 0; c < p.size(); ++c)
        EXPECT_NEAR(analytic(r, c), quotient(r, c), 1e-7 * size) << "trial " << trial << " row " << r << " col " << c;
    }
  }
}

TEST(AnalyticJacobian, WithEveryEffectModuleEqualsCentralDifferencesAtRandomStates) {
  // Every module of plant/effects at once (the mechanical ones with states in series: mode,
  // torsion, heating, rattle; pickoff, current, readout hooks; the extra inputs of geometry,
  // squeeze film and cubic damping), model (1) terms, anti-alias filter on or off, at random
  // states of ~3 g-sized motion. The plant's Jacobian chains each hook's own central
  // difference; the reference is the central quotient of the whole right-hand side at two
  // steps, h = 1e-6 and 1e-4 of each state's scale, and an entry must agree with one of them
  // to 1e-6 of itself plus that quotient's rounding error, 100 eps (|f+| + |f-|) / (2 h) of
  // the row's values. Entry by entry, not per row: the rattle's contact puts ~1e12 into the
  // pendulum's row, beside the geometry's d/dtheta of ~1e3. One step does not serve every
  // entry: at 1e-6 the output rows' quotients in the mode's states lose ~1e-5 of themselves
  // to the rounding of the ~1 g output (the 1e-4 quotient agrees with the chain to 1e-8
  // there), and at 1e-4 the contact (a softplus over a short length) has a truncation error.
  // A chain-rule error (a missing term, e.g. the geometry's or the squeeze film's d/dtheta,
  // the mode's coupling into the pendulum) fails at both steps.
  // The saturation and clipping limits sit far from the states (a difference across a kink
  // is not a derivative); at these states they are the identity, which the chain must keep.
  std::mt19937_64 rng(6202);
  std::uniform_real_distribution<double> u(-1, 1);
  for (int trial = 0; trial < 12; ++trial) {
    PlantConfig cfg;
    cfg.coefficients[K1] = 1.25;
    cfg.coefficients[k0] = 1e-3 * u(rng);
    cfg.coefficients[k2] = 1e-4 * u(rng);
    cfg.coefficients[k3] = 1e-5 * u(rng);
    cfg.location[k3] = trial % 2 == 0 ? Location::input : Location::output;
    cfg.coefficients[k_IP] = 1e-4 * u(rng);
    cfg.coefficients[delta_PA] = 1e-4 * u(rng);
    cfg.location[delta_PA] = Location::input;
    cfg.dynamics.antialias_Hz = trial % 2 == 0 ? 2000.0 : 0.0;
    const double b = cfg.dynamics.angle_gain_rad_per_s2_per_g, c0 = 2 * 0.3 * 2 * 3.141592653589793 * 50;
    cfg.effects = {std::make_shared<MechanicalMode>(900.0, 0.05, Vec3(1, 1, 0)),
                   std::make_shared<ProofMassTorsion>(2e-4 * u(rng)),
                   std::make_shared<VibrationHeating>(1e-6, 0.5),
                   std::make_shared<FixtureRattle>(Vec3(1, 0.2, 0), 2.0),
                   std::make_shared<PendulumGeometry>(),
                   std::make_shared<PickoffNonlinearity>(20.0 * u(rng)),
                   std::make_shared<CurrentSaturation>(1e3),
                   std::make_shared<SqueezeFilmDamping>(5e-3, c0, b),
                   std::make_shared<VelocityCubicDamping>(0.5, c0, b),
                   std::make_shared<OutputPolynomial>("output_polynomial", std::array<double, 7>{0, 0, 1e-4 * u(rng), 1e-6, 0, 0, 0}),
                   std::make_shared<ReadoutClipping>(1e3)};
    const Accelerometer p(cfg, Vec3(0.5 * u(rng), 0.8, 0.3 * u(rng)), [](double t) { return Vec3(3 * std::sin(400 * t), 2, 1); });
    ASSERT_TRUE(p.has_jacobian());
    const std::vector<double> scale = p.state_scale();
    std::vector<double> x = p.equilibrium();
    for (std::size_t k = 0; k < x.size(); ++k) x[k] += 3 * u(rng) * scale[k];
    Eigen::MatrixXd analytic(p.size(), p.size());
    p.jacobian(0.001, x.data(), analytic.data());
    const auto quotient_at = [&](double rel, Eigen::MatrixXd* rounding) {
      // difference_jacobian at t = 0.001 (the input moves the mechanical states' rows).
      const int n = p.size();
      Eigen::MatrixXd j(n, n);
      rounding->resize(n, n);
      std::vector<double> xx = x, fp(static_cast<std::size_t>(n)), fm(fp);
      for (int c = 0; c < n; ++c) {
        const std::size_t k = static_cast<std::size_t>(c);
        const double h = rel * scale[k];
        xx[k] = x[k] + h;
        p.rhs(0.001, xx.data(), fp.data());
        xx[k] = x[k] - h;
        p.rhs(0.001, xx.data(), fm.data());
        xx[k] = x[k];
        for (int r = 0; r < n; ++r) {
          const double up = fp[static_cast<std::size_t>(r)], down = fm[static_cast<std::size_t>(r)];
          j(r, c) = (up - down) / (2 * h);
          (*rounding)(r, c) = 100 * 2.2e-16 * (std::abs(up) + std::abs(down)) / (2 * h);
        }
      }
      return j;
    };
    Eigen::MatrixXd rf, rc;
    const Eigen::MatrixXd fine = quotient_at(1e-6, &rf), coarse = quotient_at(1e-4, &rc);
    double worst = 0;
    for (int r = 0; r < p.size(); ++r)
      for (int c = 0; c < p.size(); ++c) {
        const double a = analytic(r, c);
        const double off_fine = std::abs(a - fine(r, c)) / (1e-6 * std::abs(a) + rf(r, c) + 1e-300);
        const double off_coarse = std::abs(a - coarse(r, c)) / (1e-6 * std::abs(a) + rc(r, c) + 1e-300);
        const double off = std::min(off_fine, off_coarse);  // <= 1: within the tolerance
        EXPECT_LE(off, 1.0) << "trial " << trial << " row " << r << " col " << c << ": " << a << " against "
                            << fine(r, c) << " and " << coarse(r, c);
        worst = std::max(worst, off);
      }
    // The effects' states and couplings are there (the test checks something).
    EXPECT_GT(p.size(), Accelerometer::kCoreStates + 6) << trial;
    EXPECT_NE(analytic(Accelerometer::kOmega, Accelerometer::kCoreStates), 0.0) << trial;  // the mode moves the pendulum
    if (trial == 0) std::printf("every effect: worst |analytic - quotient| / tolerance %.2e\n", worst);
  }
}

TEST(AnalyticJacobian, TransientShakeEqualsCvodesDifferenceQuotientsWithin1e9g) {
  // The transient path (settle 16 time constants, 4 periods, rtol 1e-10) with the analytic
  // Jacobian and with CVODE's difference quotients: the Jacobian only steers Newton's
  // iteration, so the answers differ by the solver's tolerance-level error, far below 1e-9 g
  // (the accuracy) on 5 g with k2 = 15 ug/g^2 in the loop (answers ~2e-4 g).
  PlantConfig cfg;
  cfg.coefficients[K1] = 1.25;
  cfg.coefficients[k0] = 1.5e-3;
  cfg.coefficients[k2] = 1.5e-5;
  for (double f : {20.0, 120.0, 1500.0}) {
    vibration::SineVibration v;
    v.amplitude_g = Vec3(5, 0, 0);
    v.frequency_Hz = f;
    rectification::ShakeSettings s;
    s.periodic_steady_state = false;
    s.analytic_jacobian = true;
    const auto a = rectification::shake_sine(cfg, Vec3(0.5, std::sqrt(0.75), 0), v, s);
    s.analytic_jacobian = false;
    const auto q = rectification::shake_sine(cfg, Vec3(0.5, std::sqrt(0.75), 0), v, s);
    EXPECT_NEAR(a.measured_g, q.measured_g, 1e-9) << f << " Hz";
    EXPECT_GT(std::abs(q.measured_g), 1e-5) << f << " Hz";
    std::printf("%g Hz: analytic %.12e g (%ld rhs), difference quotients %.12e g (%ld rhs)\n", f, a.measured_g,
                a.rhs_evaluations, q.measured_g, q.rhs_evaluations);
  }
}

}  // namespace test_jacobian
