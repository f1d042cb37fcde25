// The virtual lab's out-of-library fixture joints (plant/effects/fixture_rattle.hpp): the ODE
// plant with the module against an independent integration of the joint alone, and the
// physics' limits (no rectification on a linear instrument, nothing below the threshold).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <memory>
#include <numbers>

#include "plant/effects/fixture_rattle.hpp"
#include "plant/effects/proof_mass_torsion.hpp"
#include "rectification/simulation/shake.hpp"
#include "support/instrument.hpp"
#include "support/vibrations.hpp"

namespace vrelab::test_out_of_library_joints {
namespace {

using plant::PlantConfig;

using test::sine;

double change_g(const PlantConfig& plain, const std::shared_ptr<const plant::Effect>& effect, const Vec3& gravity,
                const vibration::SineVibration& v) {
  PlantConfig with = plain;
  with.effects.push_back(effect);
  return rectification::shake_sine(with, gravity, v).measured_g - rectification::shake_sine(plain, gravity, v).measured_g;
}

// The joint alone, integrated by classical RK4 at a fixed step (an independent path: no
// CVODE, no plant): the table's specific force along n is f0 + A sin(w t); the sensor's is the
// joint's force over g. Returns <d_s^2> - <d_t^2> over the last `measure` periods after
// `settle` (d: the dynamic part), g^2, which k2 at the input turns into the rectification.
double rk4_power_change_g2(const plant::FixtureRattle& joint, double f0_g, double A_g, double f_Hz, int settle, int measure,
                           int steps_per_period) {
  const double w = 2 * std::numbers::pi * f_Hz, dt = 1 / (f_Hz * steps_per_period);
  const Vec3 n = Vec3::UnitX();
  double s[2];
  joint.rest_state(f0_g * n, s);
  const auto deriv = [&](double t, const double* y, double* dy) {
    const Vec3 a = (f0_g + A_g * std::sin(w * t)) * n;
    return joint.input(a, y, dy)[0];  // the sensor's specific force along n, g
  };
  double sum_s = 0, sum_t = 0, mean_s = 0;
  const long n_settle = static_cast<long>(settle) * steps_per_period, n_total = n_settle + static_cast<long>(measure) * steps_per_period;
  for (long k = 0; k < n_total; ++k) {
    const double t = k * dt;
    double k1[2], k2[2], k3[2], k4[2], y[2];
    const double fs = deriv(t, s, k1);
    if (k >= n_settle) {  // the rectangle rule on a periodic integrand: spectrally accurate
      const double d_s = fs - f0_g, d_t = A_g * std::sin(w * t);
      sum_s += d_s * d_s, sum_t += d_t * d_t, mean_s += d_s;
    }
    for (int i = 0; i < 2; ++i) y[i] = s[i] + dt / 2 * k1[i];
    deriv(t + dt / 2, y, k2);
    for (int i = 0; i < 2; ++i) y[i] = s[i] + dt / 2 * k2[i];
    deriv(t + dt / 2, y, k3);
    for (int i = 0; i < 2; ++i) y[i] = s[i] + dt * k3[i];
    deriv(t + dt, y, k4);
    for (int i = 0; i < 2; ++i) s[i] += dt / 6 * (k1[i] + 2 * k2[i] + 2 * k3[i] + k4[i]);
  }
  const double m = static_cast<double>(n_total - n_settle);
  EXPECT_NEAR(mean_s / m, 0.0, 1e-6 * A_g) << "the joint moves no mean specific force";
  return (sum_s - sum_t) / m;
}

// A preload of 2 g with 0.71 g of gravity along the joint: a 4 g sine along IA opens it at
// 400 Hz (4 > 2.71). With k2 at the input the output is <a + k2 a^2>, so the rattle moves it by
// k2 (<d_s^2> - <d_t^2>): the plant (CVODE, the whole loop, the periodic steady state) against
// the joint alone by RK4 at 40000 steps a period (5 per contact period: a clap's ~17 us
// resolved by ~14 steps). When written: 223.20 ug from the plant, 223.24 from RK4 (the power
// change 14.88 g^2 on the sine's 8); 20000 steps moved RK4's power by 0.02 % and its mean
// specific force to 4e-5 g (4e-8 at 40000: hence the 1e-6 A check of <x''> = 0). Tolerance
// 0.5 %: RK4's step and the loop's DC gain (1 - 8e-10) are well inside it; a wrong sign of the
// contact's damping, of gravity's share or a missing spike changes it by tens of %. The same joint on a linear instrument rectifies nothing (<x''> = 0: the joint
// carries the mean), bounded by 1e-9 g against a change of ~1e-4 g with k2.
TEST(OutOfLibraryJointsCampaign, FixtureRattleMatchesTheJointAloneAndRectifiesOnlyThroughTheInstrument) {
  const auto joint = std::make_shared<plant::FixtureRattle>(Vec3::UnitX(), 2.0);
  const Vec3 g = Vec3(1, 0, 1).normalized();
  constexpr double k2 = 1.5e-5, A = 4, f = 400;
  PlantConfig quad = test::paper_like_linear_plant();
  quad.coefficients[plant::k2] = k2;
  quad.location[plant::k2] = plant::Location::input;
  const double power = rk4_power_change_g2(*joint, g[0], A, f, 40, 4, 40000);
  const double expected = k2 * power;
  const double got = change_g(quad, joint, g, sine(Vec3(A, 0, 0), f));
  EXPECT_GT(std::abs(expected), 5e-6) << "the rattle is several sigma of a run (0.5 ug)";
  EXPECT_NEAR(got, expected, 0.005 * std::abs(expected)) << "power change " << power << " g^2";
  EXPECT_NEAR(change_g(test::paper_like_linear_plant(), joint, g, sine(Vec3(A, 0, 0), f)), 0.0, 1e-9);
}

// Below the threshold (2 g against a preload of 2 g plus 0.71 g of gravity) the joint stays
// shut and the sensor sees the table through the contact's 30 kHz compliance alone:
// <d_s^2> = <d_t^2> |T|^2, |T|^2 - 1 ~ 2 (f / f_c)^2 = 3.6e-4 at 400 Hz, so the change is at
// most k2 A^2 / 2 * 3.6e-4 = 1.1e-8 g (with margin 2x: 2.1e-8 g), against ~1e-4 g above the threshold.
// On the other static orientation (gravity's share -0.71 g) the same 2 g opens the joint
// (2 > 1.29): the threshold moves with the orientation.
TEST(OutOfLibraryJoints, FixtureRattleHasAThresholdThatMovesWithTheStaticOrientation) {
  const auto joint = std::make_shared<plant::FixtureRattle>(Vec3::UnitX(), 2.0);
  constexpr double k2 = 1.5e-5, A = 2, f = 400;
  PlantConfig quad = test::paper_like_linear_plant();
  quad.coefficients[plant::k2] = k2;
  quad.location[plant::k2] = plant::Location::input;
  const double bound = 2 * k2 * A * A / 2 * 2 * std::pow(f / 30000, 2);
  EXPECT_LT(std::abs(change_g(quad, joint, Vec3(1, 0, 1).normalized(), sine(Vec3(A, 0, 0), f))), bound);
  EXPECT_GT(std::abs(change_g(quad, joint, Vec3(-1, 0, 1).normalized(), sine(Vec3(A, 0, 0), f))), 50 * bound);
  EXPECT_THROW(plant::FixtureRattle(Vec3::Zero(), 2.0), std::invalid_argument);
  EXPECT_THROW(plant::FixtureRattle(Vec3::UnitX(), -1.0), std::invalid_argument);
}

// The proof mass's torsion on the linear instrument, 4 g along OA with a_OA0 = 0.71 g: the
// pendulum feels a_IA cos psi + a_OA sin psi, whose mean change from rest is
// kappa A^2 Re H / 2 (H = 1 / (1 - r^2 + 2 j zeta r), r = f / 600 Hz) from a_OA psi, less
// a_IA0 <psi_dyn^2> / 2 = a_IA0 kappa^2 A^2 |H|^2 / 4 from cos psi (1.1e-9 g at the mode, where
// Re H = 0 and |H| = 10), through the loop's DC gain (1 - 8e-10). The next terms are
// a_OA psi^3 / 6 ~ 1e-13 g. Tolerance 1e-3 relative + 1e-11 g: a wrong sign of the turn or of
// H's real part misses by 100 % or more. Checked at and across the mode (400, 600, 800 Hz:
// Re H = 1.77, 0, -1.25).
TEST(OutOfLibraryJoints, ProofMassTorsionRectifiesKappaTimesReHAlongOa) {
  constexpr double kappa = 2e-6, A = 4;
  const auto twist = std::make_shared<plant::ProofMassTorsion>(kappa);
  const Vec3 g = Vec3(1, 0, 1).normalized();
  for (double f : {400.0, 600.0, 800.0}) {
    const double r = f / 600;
    const double re_h = (1 - r * r) / ((1 - r * r) * (1 - r * r) + (2 * 0.05 * r) * (2 * 0.05 * r));
    const double h2 = 1 / ((1 - r * r) * (1 - r * r) + (2 * 0.05 * r) * (2 * 0.05 * r));
    const double expected = kappa * A * A / 2 * re_h - g[0] * kappa * kappa * A * A * h2 / 4;
    EXPECT_NEAR(change_g(test::paper_like_linear_plant(), twist, g, sine(Vec3(0, 0, A), f)), expected,
                1e-3 * std::abs(expected) + 1e-11)
        << f << " Hz";
  }
  EXPECT_THROW(plant::ProofMassTorsion(1e-6, 0), std::invalid_argument);
}

}  // namespace
}  // namespace vrelab::test_out_of_library_joints
