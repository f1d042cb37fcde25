// Swept sine (vibration/sweep.hpp): sweep times by hand, the analytic phase against the
// numerical derivative and the numerical integral of the instantaneous frequency, phase
// continuity at the end of a pass and at turnarounds, and validation.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <stdexcept>
#include <string>

#include "support/constants.hpp"
#include "support/quadrature.hpp"
#include "vibration/sweep.hpp"

namespace test_vibration_sweep {

using namespace vrelab;
using namespace vrelab::vibration;
using vrelab::test::kPi;

namespace {

SweptSine log_sweep(double f1, double f2, double oct_per_min, SweepEnd end) {
  SweptSine s;
  s.amplitude_g = Vec3(2.0, 0.5, 0.0);
  s.phase_rad = Vec3(0.0, kPi, 0.0);
  s.start_frequency_Hz = f1;
  s.end_frequency_Hz = f2;
  s.law = SweepLaw::logarithmic;
  s.rate_octaves_per_min = oct_per_min;
  s.at_end = end;
  return s;
}

SweptSine linear_sweep(double f1, double f2, double hz_per_s, SweepEnd end) {
  SweptSine s = log_sweep(f1, f2, 1, end);
  s.law = SweepLaw::linear;
  s.rate_Hz_per_s = hz_per_s;
  return s;
}

}  // namespace

// By hand: 20 -> 2000 Hz is log2(100) = 6.643856 octaves; at 2 oct/min that is 3.321928 min
// = 199.3157 s; at 1 oct/min the frequency doubles each minute (40 Hz at 60 s, 80 Hz at
// 120 s). Linear 10 -> 510 Hz at 5 Hz/s: 100 s, 260 Hz at 50 s. Down sweeps take as long.
// Tolerances: 1e-4 s on the hand-rounded 199.3157; 1e-9 relative for exp/log chains.
TEST(SweptSine, TimeToSweepTheBandByHand) {
  EXPECT_NEAR(sweep_duration_s(log_sweep(20, 2000, 2, SweepEnd::hold)), 199.3157, 1e-4);
  EXPECT_NEAR(sweep_duration_s(log_sweep(2000, 20, 2, SweepEnd::hold)), 199.3157, 1e-4);
  const SweptSineExcitation up(log_sweep(20, 2000, 1, SweepEnd::hold));
  EXPECT_NEAR(up.carrier(60).frequency_Hz, 40, 40e-9);
  EXPECT_NEAR(up.carrier(120).frequency_Hz, 80, 80e-9);
  EXPECT_NEAR(up.carrier(398.6314).frequency_Hz, 2000, 2000 * 1e-6);  // 6.643856 min
  EXPECT_NEAR(up.carrier(1e4).frequency_Hz, 2000, 1e-9);              // hold
  const SweptSineExcitation down(log_sweep(2000, 20, 1, SweepEnd::hold));
  EXPECT_NEAR(down.carrier(60).frequency_Hz, 1000, 1000e-9);
  const SweptSine lin = linear_sweep(10, 510, 5, SweepEnd::reverse);
  EXPECT_NEAR(sweep_duration_s(lin), 100, 1e-12);
  const SweptSineExcitation l(lin);
  EXPECT_NEAR(l.carrier(50).frequency_Hz, 260, 1e-12);
  EXPECT_NEAR(l.carrier(150).frequency_Hz, 260, 1e-12);  // on the way back
  EXPECT_NEAR(l.carrier(200).frequency_Hz, 10, 1e-12);   // back at the start
  EXPECT_NEAR(l.carrier(250).frequency_Hz, 260, 1e-12);  // second pass
  EXPECT_EQ(up.max_frequency_Hz(), 2000);
  EXPECT_EQ(down.max_frequency_Hz(), 2000);
}

// theta'(t) = 2 pi f(t), numerically: central difference with h = 1e-4 s. Truncation
// h^2 theta'''/6: theta''' = 2 pi f'' <= 2 pi k^2 f ~ 1e-2 (log) and 0 (linear) -> 2e-11;
// rounding eps |theta| / h with |theta| <= 2 pi 2000 x 800 = 1e7: 2e-5 rad/s. Against
// 2 pi f >= 125 rad/s: 1e-6 relative covers both. Likewise f'(t) = rate_Hz_per_s.
TEST(SweptSine, PhaseDerivativeIsTheInstantaneousFrequency) {
  for (const SweptSine& s : {log_sweep(20, 2000, 2, SweepEnd::reverse), log_sweep(2000, 20, 3, SweepEnd::hold),
                             linear_sweep(10, 510, 5, SweepEnd::reverse), linear_sweep(510, 10, 5, SweepEnd::hold)}) {
    const SweptSineExcitation e(s);
    const double T = sweep_duration_s(s);
    for (double t : {-1.0, 0.5, 0.2 * T, 0.5 * T, 0.97 * T, 1.3 * T, 1.9 * T, 2.4 * T, 3.7 * T}) {
      const double h = 1e-4;
      const double numeric = (e.carrier(t + h).phase_rad - e.carrier(t - h).phase_rad) / (2 * h);
      const double w = 2 * kPi * e.carrier(t).frequency_Hz;
      EXPECT_NEAR(numeric, w, 1e-6 * w) << e.describe() << " t = " << t;
      const double rate = (e.carrier(t + h).frequency_Hz - e.carrier(t - h).frequency_Hz) / (2 * h);
      EXPECT_NEAR(rate, e.carrier(t).rate_Hz_per_s, 1e-6 * e.carrier(t).frequency_Hz) << e.describe() << " t = " << t;
    }
  }
}

// theta(t) = 2 pi integral_0^t f: Gauss-Legendre (64 pieces x 20 points; f is smooth on each
// leg, legs split at multiples of T) of the reported frequency against the closed form:
// 1e-10 relative (quadrature converged to ~1e-15; the closed form's expm1/exp rounding).
TEST(SweptSine, PhaseIsTheIntegralOfTheFrequency) {
  for (const SweptSine& s : {log_sweep(20, 2000, 2, SweepEnd::reverse), linear_sweep(10, 510, 5, SweepEnd::reverse),
                             log_sweep(100, 50, 1, SweepEnd::hold)}) {
    const SweptSineExcitation e(s);
    const double T = sweep_duration_s(s);
    auto f = [&](double t) { return e.carrier(t).frequency_Hz; };
    for (double t : {0.37 * T, T, 1.61 * T, 2.0 * T, 2.8 * T}) {
      double integral = 0;
      for (double a = 0; a < t; a += T) integral += vrelab::test::integrate_smooth(f, a, std::min(a + T, t), 64);
      EXPECT_NEAR(e.carrier(t).phase_rad, 2 * kPi * integral, 1e-10 * 2 * kPi * integral) << e.describe() << " " << t;
    }
  }
}

// Continuity: across the end of a pass, the turnarounds and t = 0, theta(t + d) - theta(t - d)
// = 2 pi f 2d + O(d^2 f'), d = 1e-7 s: within 1e-8 rad of 4 pi f d (f' d^2 <= 1e-12; rounding
// of theta ~ 2e6 rad is 5e-10 rad per value). A jump of even 1e-6 rad fails. The signal on
// each axis carries its own phase: PA was given 180 deg, so it is -A_PA/A_IA times IA (to
// 1e-9 g: theta + pi is rounded to ulp(theta) ~ 1e-10 rad).
TEST(SweptSine, PhaseIsContinuousAtEndsAndTurnarounds) {
  for (const SweptSine& s : {log_sweep(20, 2000, 2, SweepEnd::reverse), linear_sweep(10, 510, 5, SweepEnd::hold)}) {
    const SweptSineExcitation e(s);
    const double T = sweep_duration_s(s);
    for (double t : {0.0, T, 2 * T, 3 * T}) {
      const double d = 1e-7;
      const double jump = e.carrier(t + d).phase_rad - e.carrier(t - d).phase_rad;
      EXPECT_NEAR(jump, 4 * kPi * e.carrier(t).frequency_Hz * d, 1e-8) << e.describe() << " t = " << t;
    }
    for (double t : {0.1, 0.4 * T, 1.2 * T}) {
      const Vec3 a = e.acceleration_g(t);
      EXPECT_NEAR(a[IA], 2.0 * std::sin(e.carrier(t).phase_rad), 1e-12);
      EXPECT_NEAR(a[PA], -0.25 * a[IA], 1e-9);
      EXPECT_EQ(a[OA], 0.0);
    }
  }
}

TEST(SweptSine, ValidationNamesTheField) {
  auto message = [](const SweptSine& s) -> std::string {
    try {
      validate(s);
    } catch (const std::invalid_argument& e) {
      return e.what();
    }
    return "(no exception)";
  };
  SweptSine s = log_sweep(20, 2000, 1, SweepEnd::hold);
  EXPECT_EQ(message(s), "(no exception)");
  s.rate_octaves_per_min = 0;
  EXPECT_NE(message(s).find("rate_octaves_per_min"), std::string::npos);
  s = linear_sweep(20, 2000, 0, SweepEnd::hold);
  EXPECT_NE(message(s).find("rate_Hz_per_s"), std::string::npos);
  s = log_sweep(0, 2000, 1, SweepEnd::hold);
  EXPECT_NE(message(s).find("start_frequency_Hz"), std::string::npos);
  s = log_sweep(20, 20, 1, SweepEnd::hold);
  EXPECT_NE(message(s).find("end_frequency_Hz"), std::string::npos);
  s = log_sweep(20, 2000, 1, SweepEnd::hold);
  s.amplitude_g[OA] = -1;
  EXPECT_NE(message(s).find("amplitude_g[OA]"), std::string::npos);
  EXPECT_THROW(SweptSineExcitation{s}, std::invalid_argument);
}

}  // namespace test_vibration_sweep
