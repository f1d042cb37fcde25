// The virtual lab's out-of-library truth modules (plant/effects/vibration_heating.hpp,
// velocity_cubic_damping.hpp): each changes the ODE's output, by what its physics says where
// that is known in closed form, and blind draws them.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <memory>
#include <numbers>

#include "plant/effects/velocity_cubic_damping.hpp"
#include "plant/effects/vibration_heating.hpp"
#include "rectification/simulation/shake.hpp"
#include "support/instrument.hpp"
#include "support/vibrations.hpp"
#include "validation/diagnosis/blind.hpp"
#include "validation/diagnosis/effect.hpp"

namespace vrelab::test_out_of_library {
namespace {

using plant::PlantConfig;

using test::sine;

// Vibration heating on the linear instrument, 4 g along PA with a_IA = 0.71 g: the IA input
// a_IA (1 + kappa (P - 1)) with <P> = 1 + A^2 / 2 (gravity has no PA part, so |a|^2 has no
// ripple at f; the 2f ripple meets a constant a_IA: mean zero), so the output moves by
// kappa a_IA A^2 / 2 = 11.31 ug for kappa = 2e-6 /g^2, through the loop's DC gain (1 - 8e-10),
// at any frequency. Tolerance 0.2 % + 1e-10 g: the solver's (1e-10 relative) and the loop's
// DC gain are far below it; a factor 1/2 or a missing a_IA would miss by 50 % or 41 %.
TEST(OutOfLibrary, VibrationHeatingShiftsTheOutputByKappaTimesAIaTimesThePower) {
  const PlantConfig linear = test::paper_like_linear_plant();
  PlantConfig warm = linear;
  constexpr double kappa = 2e-6, A = 4;
  warm.effects.push_back(std::make_shared<plant::VibrationHeating>(kappa, 0.05));
  const Vec3 g = Vec3(1, 0, 1).normalized();
  const double expected = kappa * g[0] * A * A / 2;
  for (double f : {10.0, 400.0}) {
    const double with = rectification::shake_sine(warm, g, sine(Vec3(0, A, 0), f)).measured_g;
    const double without = rectification::shake_sine(linear, g, sine(Vec3(0, A, 0), f)).measured_g;
    EXPECT_NEAR(with - without, expected, 2e-3 * expected + 1e-10) << f << " Hz";
  }
  // Odd in the static a_IA: the other orientation of the default design flips it.
  const Vec3 g2 = Vec3(-1, 0, 1).normalized();
  const double flipped = rectification::shake_sine(warm, g2, sine(Vec3(0, A, 0), 100)).measured_g -
                         rectification::shake_sine(linear, g2, sine(Vec3(0, A, 0), 100)).measured_g;
  EXPECT_NEAR(flipped, -expected, 2e-3 * expected + 1e-10);
  // Along IA, |a|^2 = 1 + 2 a_IA A sin(wt) + A^2 sin^2(wt): the ripple at f passes the thermal
  // low-pass as H = 1 / (1 + j w tau) and multiplies a_IA's own A sin(wt), adding
  // kappa a_IA A^2 Re H = kappa a_IA A^2 / (1 + (w tau)^2) (the 2f ripple times the f motion has
  // mean zero): 18 % more than along PA at 10 Hz, 3e-4 at 400 Hz. Same tolerance as above.
  for (double f : {10.0, 400.0}) {
    const double wt = 2 * std::numbers::pi * f * 0.05;
    const double along_ia = kappa * g[0] * A * A * (0.5 + 1 / (1 + wt * wt));
    const double with = rectification::shake_sine(warm, g, sine(Vec3(A, 0, 0), f)).measured_g;
    const double without = rectification::shake_sine(linear, g, sine(Vec3(A, 0, 0), f)).measured_g;
    EXPECT_NEAR(with - without, along_ia, 2e-3 * along_ia + 1e-10) << f << " Hz along IA";
  }
  // In 1 g at rest it is nothing: the static test cannot see it (P = |a|^2 = 1).
  PlantConfig warm_paper = test::paper_like_plant();
  warm_paper.effects.push_back(std::make_shared<plant::VibrationHeating>(kappa, 0.05));
  for (const Vec3& a : {g, g2, Vec3(0, 1, 0), Vec3(0.6, 0.8, 0)})
    EXPECT_NEAR(plant::settled_output_g(warm_paper, a), plant::settled_output_g(test::paper_like_plant(), a), 1e-13);
}

// The rate-dependent damping's torque is -c0 omega^3 / omega_ref^2: odd in omega, so on a
// linear instrument a sinusoidal swing does not rectify (bound 1e-9 g: the solver's noise is
// ~1e-12 g at these outputs); on the paper-like instrument it changes the loop's response and
// the loop-placed terms' rectification: 4 g along IA at 130 Hz (the pendulum at ~1 mrad, a
// rate of 0.8 rad/s) with the damping doubling at 0.5 rad/s moves the output by more than
// 1.5 ug (5 sigma of a run in the default design): blind's draws (0.3-1 rad/s) are seen.
TEST(OutOfLibrary, VelocityCubicDampingActsThroughTheLoopOnly) {
  PlantConfig linear = test::paper_like_linear_plant();
  const plant::Dynamics& d = linear.dynamics;
  const double c0 = 2 * d.pendulum_damping_ratio * 2 * std::numbers::pi * d.pendulum_frequency_Hz;
  const auto module = std::make_shared<plant::VelocityCubicDamping>(0.5, c0, d.angle_gain_rad_per_s2_per_g);
  linear.effects.push_back(module);
  const Vec3 g = Vec3(1, 0, 1).normalized();
  EXPECT_NEAR(rectification::shake_sine(linear, g, sine(Vec3(4, 0, 0), 130)).measured_g, 0.0, 1e-9);
  PlantConfig paper = test::paper_like_plant(), damped = paper;
  damped.effects.push_back(module);
  const double change = rectification::shake_sine(damped, g, sine(Vec3(4, 0, 0), 130)).measured_g -
                        rectification::shake_sine(paper, g, sine(Vec3(4, 0, 0), 130)).measured_g;
  EXPECT_GT(std::abs(change), 1.5e-6) << change;
  EXPECT_THROW(plant::VelocityCubicDamping(0, c0, 1), std::invalid_argument);
  EXPECT_THROW(plant::VibrationHeating(1e-6, 0), std::invalid_argument);
}

// blind hides every out-of-library effect of the registry: each has a truth and a draw, no
// hypothesis, and the draw is valid.
TEST(OutOfLibrary, TheRegistryHoldsSeveralAndEachIsDrawable) {
  int n = 0;
  std::mt19937_64 rng(6001);
  for (const validation::Effect& e : validation::effect_registry()) {
    if (e.in_library) continue;
    ++n;
    ASSERT_TRUE(e.truth && e.draw) << e.name;
    EXPECT_FALSE(e.hypothesis) << e.name;
    for (int k = 0; k < 10; ++k) EXPECT_TRUE(e.is_valid(e.values_at(e.draw(rng).front()))) << e.name;
  }
  EXPECT_GE(n, 4);
}

}  // namespace
}  // namespace vrelab::test_out_of_library
