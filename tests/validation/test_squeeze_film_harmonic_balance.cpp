// The squeeze film by harmonic balance (rectification::film_harmonic_balance) against the ODE
// with plant::SqueezeFilmDamping, on the strong run of test_effect_sweep.cpp (4 g along IA+PA,
// static a_IA +0.71 g, the paper-like instrument) where the pendulum's swing nearly closes the
// gap: 1 / theta_gap = 833 and 1000 /rad (the ends of what blind hides) and 3000 /rad (the fit
// grid's end, a gap a third of the swing without the film), at 96, 130 and 206 Hz (the swing's
// peak and either side of it). Compared: the change the film makes (with less without), so
// the first-order model's own error without a film is not charged to it.
//
// Tolerance: |HB - ODE| <= 2 % |ODE change| + 0.02 ug. The harmonic balance solves the
// film's nonlinear damping up to the 31st harmonic on 256 points a period (15 harmonics on
// 128 points would be 11 % off at 3000 /rad, 96 Hz, where the swing reaches the film's clamp
// at 0.95 theta_gap and its kink feeds high harmonics; 1 % with 31); what is left is the
// first-order model's treatment of the coefficients' terms on that
// motion, which test_effect_sweep.cpp bounds at 1 % for every other effect (<= 0.4 % seen),
// and the ODE's own quadrature (1e-9 relative). 2 %: twice the other effects' bound, for the
// rectification of a motion whose angle has harmonics of a few tens of % near contact.
// The floor 0.02 ug is test_effect_sweep.cpp's. The describing function (the harmonics left
// out) errs by up to 75 % here (96 Hz, 3000 /rad): the test checks the harmonic balance is
// at least 5 times closer there, so a balance that dropped the harmonics would fail.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <memory>
#include <numbers>

#include "plant/effects/mechanical_mode.hpp"
#include "plant/effects/squeeze_film_damping.hpp"
#include "rectification/prediction/frequency.hpp"
#include "rectification/simulation/shake.hpp"
#include "support/instrument.hpp"

namespace test_squeeze_film_harmonic_balance {

using namespace vrelab;

namespace {

struct Predictions {
  double describing_g, balance_g;
};

Predictions predict(const plant::PlantConfig& with_film, const Vec3& a, const vibration::SineVibration& v) {
  plant::PlantConfig lin = rectification::amplitude_linearised(with_film, v);
  if (!lin.servo) lin.servo = plant::design_servo(lin.dynamics);
  const rectification::ResponseAt h = [&lin](double f) { return rectification::loop_response(lin, f); };
  const rectification::PeriodicInput in = rectification::periodic_input(v);
  const double df = rectification::periodic_rectification(lin, a, in, h).total_g();
  const double hb = rectification::periodic_rectification(lin, a, rectification::film_harmonic_balance(with_film, lin, in, h), h).total_g();
  return {df, hb};
}

}  // namespace

TEST(SqueezeFilmHarmonicBalance, MatchesTheOdeNearContact) {
  const plant::PlantConfig base = test::paper_like_plant();
  const plant::Dynamics& d = base.dynamics;
  const double c0 = 2 * d.pendulum_damping_ratio * 2 * std::numbers::pi * d.pendulum_frequency_Hz;
  const Vec3 a = Vec3(1, 0, 1).normalized();
  double worst_df_at_3000 = 0, worst_hb_at_3000 = 0;
  for (double inverse_gap : {833.0, 1000.0, 3000.0}) {
    plant::PlantConfig film = base;
    film.effects.push_back(std::make_shared<plant::SqueezeFilmDamping>(1 / inverse_gap, c0, d.angle_gain_rad_per_s2_per_g));
    for (double f : {96.0, 130.0, 206.0}) {
      vibration::SineVibration v;
      v.frequency_Hz = f;
      const Vec3 dir = Vec3(1, 1, 0).normalized();
      for (int i = 0; i < 3; ++i) v.amplitude_g[i] = 4 * dir[i], v.phase_rad[i] = 0;
      const double ode = rectification::shake_sine(film, a, v).measured_g - rectification::shake_sine(base, a, v).measured_g;
      const Predictions with = predict(film, a, v);
      const Predictions without = predict(base, a, v);
      const double df = with.describing_g - without.describing_g, hb = with.balance_g - without.balance_g;
      std::printf("  1/gap %6.0f /rad, %5.0f Hz: ODE %9.4f ug, harmonic balance %9.4f ug (%.2f %%), describing function %9.4f ug (%.1f %%)\n",
                  inverse_gap, f, ode * 1e6, hb * 1e6, 100 * std::abs(hb - ode) / std::abs(ode), df * 1e6,
                  100 * std::abs(df - ode) / std::abs(ode));
      EXPECT_LE(std::abs(hb - ode), 0.02 * std::abs(ode) + 0.02e-6) << inverse_gap << " /rad at " << f << " Hz";
      if (inverse_gap == 3000.0) {
        worst_df_at_3000 = std::max(worst_df_at_3000, std::abs(df - ode) / std::abs(ode));
        worst_hb_at_3000 = std::max(worst_hb_at_3000, std::abs(hb - ode) / std::abs(ode));
      }
    }
  }
  EXPECT_GT(worst_df_at_3000, 5 * worst_hb_at_3000) << "the describing function is as good: the test cannot tell them apart";
}

// The film with a mechanical mode along IA (a pair hypothesis, or a lab's instrument with
// both): the film's torque acts at the pendulum, after the mode, so its harmonics go through
// the loop without the mode's transmissibility (1.09 at 96 Hz and 3.4 at 288 Hz for a mode
// at 340 Hz, damping 0.05: with it the balance's harmonics came out that much too large).
// The film's change with the mode present against the ODE's, the same 2 % + 0.02 ug.
// Teeth: at 206 Hz the change is more than 10 floors (0.2 ug; 44 ug seen), so the 2 % judges
// it there, and the harmonics matter: the describing function (the balance without them)
// misses the ODE by more than the tolerance (a third seen), so a balance that mishandled the
// harmonics (through the mode's transmissibility, 3.4 at 288 Hz) has room to fail. At 96 Hz
// the film's change is at the floor (0.01 ug): only the tolerance's floor is judged there.
TEST(SqueezeFilmHarmonicBalance, MatchesTheOdeWithAMechanicalModeAlongIa) {
  plant::PlantConfig base = test::paper_like_plant();
  base.effects.push_back(std::make_shared<plant::MechanicalMode>(340.0, 0.05, Vec3::UnitX()));
  const plant::Dynamics& d = base.dynamics;
  const double c0 = 2 * d.pendulum_damping_ratio * 2 * std::numbers::pi * d.pendulum_frequency_Hz;
  const Vec3 a = Vec3(1, 0, 1).normalized();
  plant::PlantConfig film = base;
  film.effects.push_back(std::make_shared<plant::SqueezeFilmDamping>(1 / 1000.0, c0, d.angle_gain_rad_per_s2_per_g));
  for (double f : {96.0, 206.0}) {
    vibration::SineVibration v;
    v.frequency_Hz = f;
    const Vec3 dir = Vec3(1, 1, 0).normalized();
    for (int i = 0; i < 3; ++i) v.amplitude_g[i] = 4 * dir[i], v.phase_rad[i] = 0;
    const double ode = rectification::shake_sine(film, a, v).measured_g - rectification::shake_sine(base, a, v).measured_g;
    const Predictions with = predict(film, a, v), without = predict(base, a, v);
    const double hb = with.balance_g - without.balance_g, df = with.describing_g - without.describing_g;
    std::printf("  mode at 340 Hz, 1/gap 1000 /rad, %5.0f Hz: ODE %9.4f ug, harmonic balance %9.4f ug (%.2f %%), "
                "describing function %9.4f ug (%.1f %%)\n",
                f, ode * 1e6, hb * 1e6, 100 * std::abs(hb - ode) / std::abs(ode), df * 1e6, 100 * std::abs(df - ode) / std::abs(ode));
    const double tolerance = 0.02 * std::abs(ode) + 0.02e-6;
    EXPECT_LE(std::abs(hb - ode), tolerance) << f << " Hz";
    if (f == 206.0) {
      EXPECT_GT(std::abs(ode), 10 * 0.02e-6) << f << " Hz: the film's change is at the floor";
      EXPECT_GT(std::abs(df - ode), tolerance) << "without the harmonics the prediction is as good: no teeth";
    }
  }
}

}  // namespace test_squeeze_film_harmonic_balance
