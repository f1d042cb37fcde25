// The ODE plant: its static response is model (1); a linear plant does not rectify; at low
// frequency each term of (1), wherever it acts, rectifies as the corrected eq. (3); the loop
// has the designed crossover and phase margin; solver failures are reported, not crashed.
#include <gtest/gtest.h>

#include <cmath>
#include <complex>
#include <cstdio>
#include <numbers>
#include <random>

#include <Eigen/Dense>

#include "plant/accelerometer.hpp"
#include "plant/effects/effects.hpp"
#include "plant/physical.hpp"
#include "rectification/prediction/eq3.hpp"
#include "rectification/simulation/shake.hpp"
#include "support/constants.hpp"
#include "support/instrument.hpp"
#include "support/random_coefficients.hpp"
#include "validation/identification/dividing_head.hpp"

namespace test_plant {

using namespace vrelab;
using namespace vrelab::plant;
using vrelab::test::kPi;

namespace {

Location random_location(std::mt19937_64& rng, int c) {
  const int n = (c >= k0 && c <= k4) ? 3 : 2;
  const int pick = std::uniform_int_distribution<int>(0, n - 1)(rng);
  if (n == 2) return pick == 0 ? Location::input : Location::output;
  return pick == 0 ? Location::input : pick == 1 ? Location::loop : Location::output;
}

}  // namespace

TEST(PlantStatic, SettledOutputReproducesModel1InEveryPositionOfTheDividingHead) {
  // Navigation-grade magnitudes (1e-6 .. 1e-3), IA terms at random places; cross terms at
  // the output (at the input (1) holds only to second order, see accelerometer.hpp).
  // Tolerance 1e-9 relative to |U/K1| (floor 1e-3 g): the ODE settles for 30 time constants
  // (e^-30 ~ 1e-13) at a relative tolerance of 1e-12.
  std::mt19937_64 rng(41);
  const auto positions = validation::equally_spaced_positions(8);
  for (int n = 0; n < 4; ++n) {
    PlantConfig cfg;
    cfg.coefficients = test::random_coefficients(rng, 1e-6, 1e-3);
    for (int c = k0; c <= k4; ++c) cfg.location[c] = random_location(rng, c);
    if (n == 3) {  // the effects beyond (1) do not change the static response
      cfg.effects.push_back(std::make_shared<PickoffNonlinearity>(50.0));
      cfg.effects.push_back(std::make_shared<PendulumGeometry>());
      cfg.effects.push_back(std::make_shared<MechanicalMode>(2000.0, 0.05, Vec3(1, 1, 1)));
      cfg.effects.push_back(std::make_shared<CurrentSaturation>(30.0));
    }
    for (const auto& p : positions) {
      const double model = output_g(cfg.coefficients, p.nominal_g);
      EXPECT_NEAR(settled_output_g(cfg, p.nominal_g), model, 1e-9 * std::max(std::abs(model), 1e-3))
          << "draw " << n << " a = " << p.nominal_g.transpose();
    }
  }
}

// rest_output_g (the equilibrium by Newton, which the diagnosis' static take-up reads) against
// the ODE run from rest for 30 time constants at rtol 1e-12 (settled_output_g, what a simulated
// static test reads), on the plants the take-up builds: model (1) with its terms at random
// places and an output polynomial in u^5 and u^6 (higher_order_k5, k6), with and without the
// integrator and the anti-alias filter, at the 8 positions of a dividing head. The two are
// different computations of one number: they agree to the ODE's tolerance (rtol 1e-12 of a
// <= 1 g output, a few steps: 5e-12 g; seen 4.5e-13 g).
TEST(PlantStatic, RestOutputIsTheSettledOutput) {
  std::mt19937_64 rng(43);
  const auto positions = validation::equally_spaced_positions(8);
  double worst = 0;
  for (int n = 0; n < 4; ++n) {
    PlantConfig cfg = test::paper_like_linear_plant();
    const Coefficients c = test::random_coefficients(rng, 1e-6, 1e-3);
    for (int k = k0; k <= k4; ++k) cfg.coefficients[k] = c[k], cfg.location[k] = random_location(rng, k);
    std::array<double, 7> poly{};
    poly[5] = 4e-7, poly[6] = -3e-8;
    cfg.effects.push_back(std::make_shared<OutputPolynomial>("higher_order", poly));
    cfg.dynamics.integrator = n % 2 == 0;
    cfg.dynamics.antialias_Hz = n < 2 ? 0.0 : 2000.0;
    for (const auto& p : positions) {
      const double settled = settled_output_g(cfg, p.nominal_g), rest = rest_output_g(cfg, p.nominal_g);
      EXPECT_NEAR(rest, settled, 5e-12) << "draw " << n << " a = " << p.nominal_g.transpose();
      worst = std::max(worst, std::abs(rest - settled));
    }
  }
  char text[32];
  std::snprintf(text, sizeof text, "%.3g", worst);
  RecordProperty("worst_difference_g", text);
}

TEST(PlantStatic, CrossTermsAtTheInputHoldToSecondOrder) {
  PlantConfig cfg;
  cfg.coefficients[K1] = 1;
  cfg.coefficients[k2] = 1e-4;
  cfg.coefficients[delta_OA] = 1e-3;
  cfg.location[delta_OA] = Location::input;
  const Vec3 a(0.6, 0.8, 0);
  // The torquer's k2 acts on a_IA + delta_OA a_PA: the excess is k2 (2 a_IA delta a_PA + delta^2 a_PA^2).
  const double excess = 1e-4 * (2 * 0.6 * 1e-3 * 0.8 + 1e-6 * 0.64);
  EXPECT_NEAR(settled_output_g(cfg, a) - output_g(cfg.coefficients, a), excess, 1e-12);
}

TEST(PlantDynamics, LinearPlantDoesNotRectifyA20gSineAt1kHz) {
  PlantConfig cfg = test::paper_like_linear_plant();
  vibration::SineVibration v;
  v.amplitude_g = Vec3(20, 0, 0);
  v.frequency_Hz = 1000;
  const auto r = rectification::shake_sine(cfg, Vec3(0.5, std::sqrt(0.75), 0), v);
  EXPECT_LT(std::abs(r.measured_g), 1e-9);  // the numerical floor
  // Positive control: the same run with k2 = 10 ug/g^2 at the input, which sees the vibration
  // unfiltered, rectifies k2 A^2 / 2 = 1e-5 * 400 / 2 = 2 mg; 1 %: the loop's DC gain and the
  // pendulum's response to the 2 mg step are exact at the mean (what the issue bounds at 0.5 %).
  cfg.coefficients[k2] = 1e-5;
  cfg.location[k2] = Location::input;
  const auto control = rectification::shake_sine(cfg, Vec3(0.5, std::sqrt(0.75), 0), v);
  EXPECT_NEAR(control.measured_g, 2e-3, 0.01 * 2e-3);
}

TEST(PlantDynamics, EachTermAtEachPlaceRectifiesAsEq3AtOnePercentOfTheBandwidth) {
  // 5 Hz = 1 % of the 500 Hz crossover. Loop and output terms see |H(jw)|^2 of the closed
  // loop, 1 - O(1e-3) here; input terms see the vibration unfiltered. Bound 0.5 % (issue).
  const Vec3 a(0.5, std::sqrt(0.75), 0);  // a_IA = 0.5 g: k3 acts, and |a_IA| < |w_IA| for k1'
  for (int c = k1_asym; c <= k_OO; ++c) {
    if (c == delta_OA || c == delta_PA) continue;  // linear: no rectification
    for (Location l : {Location::input, Location::loop, Location::output}) {
      if (!location_allowed(c, l)) continue;
      PlantConfig cfg = test::paper_like_linear_plant();
      cfg.coefficients[c] = c == k1_asym ? 1e-3 : 2e-4;
      cfg.location[c] = l;
      vibration::SineVibration v;
      v.frequency_Hz = 5;
      v.amplitude_g = c <= k4 ? Vec3(3, 0, 0) : Vec3(2, 1.5, 1);
      v.phase_rad = Vec3(0, 0.4, -0.7);
      const double expected = rectification::sine_rectification(cfg.coefficients, a, v).total_g();
      const auto r = rectification::shake_sine(cfg, a, v);
      EXPECT_NEAR(r.measured_g / expected, 1.0, 5e-3) << coefficient_name(c) << " at " << location_name(l);
    }
  }
}

TEST(PlantDynamics, LoopHasTheDesignedCrossoverAndPhaseMargin) {
  // Independent of design_servo's arithmetic: the closed-loop response from the ODE's
  // finite-difference linearisation. With |L| = 1 and arg L = -180 + PM at the crossover,
  // T = L / (1 + L) has |T| = 1 / (2 sin(PM / 2)) there; and T -> 1 at low frequency.
  for (double pm : {40.0, 50.0, 60.0}) {
    PlantConfig cfg;
    cfg.coefficients[K1] = 1;
    cfg.dynamics.phase_margin_deg = pm;
    const Accelerometer plant(cfg, Vec3(0, 0, 1));
    const auto lin = plant.linearise();
    auto response = [&](double f) {
      const std::complex<double> jw(0, 2 * kPi * f);
      const Eigen::MatrixXcd m = jw * Eigen::MatrixXcd::Identity(plant.size(), plant.size()) - lin.A.cast<std::complex<double>>();
      const Eigen::VectorXcd x = m.fullPivLu().solve(lin.B.col(IA).cast<std::complex<double>>());
      return (lin.C.cast<std::complex<double>>() * x)(0);
    };
    EXPECT_NEAR(std::abs(response(cfg.dynamics.loop_bandwidth_Hz)), 1 / (2 * std::sin(pm * kPi / 360)), 1e-6) << pm;
    EXPECT_NEAR(std::abs(response(0.01)), 1.0, 1e-6);
  }
}

TEST(PlantSolver, FailureNamesTheCallAndTheSimulatedTime) {
  PlantConfig cfg;
  cfg.coefficients[K1] = 1;
  const Accelerometer plant(cfg, Vec3(1, 0, 0), [](double t) { return Vec3(std::sin(6000 * t), 0, 0); });
  SolverSettings s;
  s.max_steps = 20;
  for (double x : plant.state_scale()) s.absolute_tolerance.push_back(1e-12 * x);
  OdeSolver ode(plant, 0.0, std::vector<double>(static_cast<std::size_t>(plant.size()), 0.0), s);
  try {
    ode.advance(1.0);
    ADD_FAILURE() << "no failure";
  } catch (const SolverError& e) {
    EXPECT_EQ(e.call, "CVode");
    EXPECT_GT(e.t_s, 0.0);
    EXPECT_LT(e.t_s, 1.0);
    EXPECT_NE(std::string(e.what()).find("simulated time"), std::string::npos) << e.what();
  }
}

TEST(PlantSolver, AnExceptionInTheRightHandSideIsCarriedAcross) {
  PlantConfig cfg;
  cfg.coefficients[K1] = 1;
  const Accelerometer plant(cfg, Vec3(1, 0, 0), [](double t) -> Vec3 {
    if (t > 0.01) throw std::runtime_error("input failed");
    return Vec3::Zero();
  });
  SolverSettings s;
  for (double x : plant.state_scale()) s.absolute_tolerance.push_back(1e-12 * x);
  OdeSolver ode(plant, 0.0, plant.equilibrium(), s);
  EXPECT_THROW(ode.advance(1.0), std::runtime_error);
}

TEST(PlantPhysical, StaticOutputIsTheInverseOfTheTorquerCurve) {
  // The physical torquer tau(i) = i + c2 i^2 + c3 i^3 (in g) with a bias torque: at rest the
  // output is tau^-1(a_IA + k0), found here by bisection (independent of the plant's code),
  // and to third order it is model (1) with k2 = -c2, k3 = 2 c2^2 - c3, k4 = 5 c2 c3 - 5 c2^3.
  PhysicalParameters p;
  p.torquer_n2_per_A = 2.0;    // c2 = 2.5e-3 /g: large, to see the orders
  p.torquer_n3_per_A2 = 800.0;  // c3 = 1.25e-3 /g^2
  p.bias_torque_N_m = 5e-8;
  const double g = 9.81;
  const PlantConfig cfg = plant_from_physical(p, g);
  const double c2 = cfg.torquer_c2_per_g, c3 = cfg.torquer_c3_per_g2, k0_in = cfg.coefficients[k0];
  EXPECT_NEAR(c2, 2.0 * 5e-6 * g / 0.0392, 1e-15);
  // tau^-1(s) by bisection on [-3, 3] g (200 halvings: to the last bit).
  const auto inverse = [&](double s) {
    double lo = -3, hi = 3;
    for (int it = 0; it < 200; ++it) {
      const double m = 0.5 * (lo + hi);
      (m + c2 * m * m + c3 * m * m * m < s ? lo : hi) = m;
    }
    return 0.5 * (lo + hi);
  };
  for (double a_ia : {-1.0, -0.6, 0.0, 0.3, 1.0}) {
    const Vec3 a(a_ia, std::sqrt(1 - a_ia * a_ia), 0);
    const double exact = inverse(a_ia + k0_in);
    EXPECT_NEAR(settled_output_g(cfg, a), exact, 1e-9 * std::max(std::abs(exact), 1e-3)) << a_ia;
    // Series inversion to fourth order against the exact inverse.
    const Coefficients k = implied_coefficients(p, g);
    Coefficients no_bias = k;
    no_bias[k0] = 0;
    const double s = a_ia;  // without the bias, tau^-1(a) vs model (1)
    // The remainder is led by the fifth-order term of the series reversion,
    // (14 c2^4 - 21 c2^2 c3 + 3 c3^2) s^5 (~4.7e-6 at |s| = 1 here): bound it by 1.2 times that.
    const double c5 = 14 * c2 * c2 * c2 * c2 - 21 * c2 * c2 * c3 + 3 * c3 * c3;
    EXPECT_NEAR(output_g(no_bias, Vec3(s, 0, 0)), inverse(s), 1.2 * std::abs(c5 * std::pow(s, 5)) + 1e-12);
  }
  // Each implied coefficient on its own, read off the exact inverse (not through the series):
  // tau^-1(s) = s + k2 s^2 + k3 s^3 + k4 s^4 + k5 s^5 + k6 s^6 + ..., so with h = 0.05 and
  // 2h, the even part over s^2, G(h) = k2 + k4 h^2 + k6 h^4, and the odd part over s^3,
  // F(h) = k3 + k5 h^2 + ..., give by Richardson k2 = (4 G(h) - G(2h)) / 3 and
  // k3 = (4 F(h) - F(2h)) / 3 (errors 4 k6 h^4 = 3e-12, 4 k7 h^4 < 1e-12, against 2.5e-3 and
  // 1.2e-3). For k4, D(h) = (G(2h) - G(h)) / (3 h^2) = k4 + 5 k6 h^2 + 21 k8 h^4, where
  // k6 = -42 c2^5 + 84 c2^3 c3 - 28 c2 c3^2 = -1.1e-7 moves it by 9e-5 relative, so once more:
  // k4 = (4 D(h) - D(2h)) / 3 (error 28 k8 h^4 ~ 1e-12). The bisection's rounding, 3e-17 at
  // 0.2 g, over 3 h^2 is ~1e-12 in k4 = 1.56e-5. Bounds: 1e-6 relative: above those, and five
  // orders below the 30 % of k4 that the s^5 bound above lets through.
  const Coefficients k = implied_coefficients(p, g);
  const double h = 0.05;
  const auto even = [&](double x) { return (inverse(x) + inverse(-x)) / 2 / (x * x); };
  const auto odd = [&](double x) { return ((inverse(x) - inverse(-x)) / 2 - x) / (x * x * x); };
  const double k2_read = (4 * even(h) - even(2 * h)) / 3, k3_read = (4 * odd(h) - odd(2 * h)) / 3;
  const auto d4 = [&](double x) { return (even(2 * x) - even(x)) / (3 * x * x); };
  const double k4_read = (4 * d4(h) - d4(2 * h)) / 3;
  // By hand: k2 = -c2, k3 = 2 c2^2 - c3, k4 = 5 c2 c3 - 5 c2^3 (the series reversion).
  EXPECT_NEAR(k[k2], -c2, 1e-6 * std::abs(c2));
  EXPECT_NEAR(k[k3], 2 * c2 * c2 - c3, 1e-6 * std::abs(2 * c2 * c2 - c3));
  EXPECT_NEAR(k[k4], 5 * c2 * c3 - 5 * c2 * c2 * c2, 1e-6 * std::abs(5 * c2 * c3 - 5 * c2 * c2 * c2));
  EXPECT_NEAR(k2_read, k[k2], 1e-6 * std::abs(k[k2]));
  EXPECT_NEAR(k3_read, k[k3], 1e-6 * std::abs(k[k3]));
  EXPECT_NEAR(k4_read, k[k4], 1e-6 * std::abs(k[k4]));
}

TEST(PlantPhysical, MatchesTheFromCoefficientsPlantWithTheSameServoNearTheCrossover) {
  // Physical parameters chosen to reproduce the default designed servo exactly; a torquer
  // c2 then rectifies as a loop-located k2 = -c2 does, compared at 300 Hz where the loop
  // shapes the result. The torquers differ by 2 c2^2 i^3 (+ O(c2^3)), which rectifies like
  // k3 = 2 c2^2: relative to the k2 term, 6 c2 a_IA = 4.4e-5 here; allowed: twice that.
  PlantConfig ref = test::paper_like_linear_plant();
  const Servo sv = design_servo(ref.dynamics);
  PhysicalParameters p;
  const double g = 9.81, amps_per_g = p.pendulosity_kg_m * g / p.torquer_N_m_per_A;
  p.servo_gain_A_per_V = sv.gain_g_per_rad * amps_per_g / p.pickoff_V_per_rad;
  p.lead_zero_Hz = sv.lead_zero_rad_per_s / (2 * kPi);
  p.lead_pole_Hz = sv.lead_pole_rad_per_s / (2 * kPi);
  p.integrator_Hz = sv.integrator_rad_per_s / (2 * kPi);
  const double wp = 2 * kPi * ref.dynamics.pendulum_frequency_Hz;
  p.inertia_kg_m2 = p.pendulosity_kg_m * g / ref.dynamics.angle_gain_rad_per_s2_per_g;
  p.hinge_stiffness_N_m_per_rad = p.inertia_kg_m2 * wp * wp;
  p.damping_N_m_s_per_rad = 2 * ref.dynamics.pendulum_damping_ratio * std::sqrt(p.hinge_stiffness_N_m_per_rad * p.inertia_kg_m2);
  p.torquer_n2_per_A = 1.2e-2;
  const PlantConfig phys = plant_from_physical(p, g);
  ref.coefficients[k2] = -phys.torquer_c2_per_g;
  vibration::SineVibration v;
  v.amplitude_g = Vec3(5, 0, 0);
  v.frequency_Hz = 300;
  const Vec3 a(0.5, std::sqrt(0.75), 0);
  const double e_phys = rectification::shake_sine(phys, a, v).measured_g;
  const double e_ref = rectification::shake_sine(ref, a, v).measured_g;
  EXPECT_NEAR(e_phys / e_ref, 1.0, 2 * 6 * phys.torquer_c2_per_g * 0.5) << e_phys << " vs " << e_ref;
  EXPECT_GT(std::abs(e_phys / (ref.coefficients[k2] * 25 / 2) - 1), 0.1);  // the loop matters at 300 Hz
}

// Squeeze-film damping, c(theta) = c0 (1 - x^2)^(-3/2), x = theta / theta_gap: its describing
// function 2 <f(x sin phi) cos^2 phi> expands as 1 + 3 x^2 / 8 + 15 x^4 / 64 + O(x^6)
// (<sin^2 cos^2> = 1/8, <sin^4 cos^2> = 1/16); the next, 175 x^6 / 1024, is 1.7e-7 at
// x = 0.1: bound 5e-7 (an x^4 coefficient off by 10 % would miss it by 2.3e-6).
TEST(PlantEffects, SqueezeFilmDescribingFunctionIsItsSeries) {
  const SqueezeFilmDamping film(1e-3, 30.0, 1000.0);
  for (double x : {0.02, 0.05, 0.1}) EXPECT_NEAR(film.damping_factor(x * 1e-3), 1 + 3 * x * x / 8 + 15 * std::pow(x, 4) / 64, 5e-7) << x;
  EXPECT_DOUBLE_EQ(film.damping_factor(0), 1.0);
}

// The film's torque is c0 theta' times a function of theta: its mean over a period is zero,
// so on a linear instrument it does not rectify, however nonlinear the film: 4 g along IA at
// 200 Hz, where the angle swings to 0.97 mrad, with the gap at 1.1 mrad (the damping at the
// largest angle 9.5x nominal). Bound: 0.001 ug, against 0.5 ug that the same film moves the rectification
// of the paper-like instrument at 500 Hz (the film acts through the loop's response).
TEST(PlantEffects, SqueezeFilmDampingDoesNotRectifyByItself) {
  PlantConfig c = test::paper_like_linear_plant();
  const Dynamics& d = c.dynamics;
  const double c0 = 2 * d.pendulum_damping_ratio * 2 * std::numbers::pi * d.pendulum_frequency_Hz;
  c.effects.push_back(std::make_shared<SqueezeFilmDamping>(1.1e-3, c0, d.angle_gain_rad_per_s2_per_g));
  vibration::SineVibration v;
  v.amplitude_g = Vec3(4, 0, 0);
  const Vec3 a = Vec3(1, 0, 1).normalized();
  for (double f : {200.0, 500.0}) {
    v.frequency_Hz = f;
    EXPECT_NEAR(rectification::shake_sine(c, a, v).measured_g, 0.0, 1e-9) << f << " Hz";
  }
  PlantConfig nl = c, nominal = c;
  nl.coefficients = nominal.coefficients = test::paper_like_coefficients();
  nominal.effects.clear();
  v.frequency_Hz = 500;
  EXPECT_GT(std::abs(rectification::shake_sine(nl, a, v).measured_g - rectification::shake_sine(nominal, a, v).measured_g), 0.5e-6);
}

}  // namespace test_plant
