// Composite excitations and shaker imperfections (vibration/decorators.hpp), each against
// an expectation derived by hand: sine-on-random, transverse motion (exact phase shift on a
// tone, phasor form, time-shift form), harmonic distortion (values and Fourier content),
// rocking (rotated gravity, its Bessel-function rectification, and the lever-arm kinematics
// against finite differences of the rotating position).
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <memory>
#include <numbers>
#include <stdexcept>
#include <string>

#include "support/constants.hpp"
#include "support/quadrature.hpp"
#include "support/vibrations.hpp"
#include "vibration/decorators.hpp"
#include "vibration/demand.hpp"
#include "vibration/sampled.hpp"

namespace test_vibration_decorators {

using namespace vrelab;
using namespace vrelab::vibration;
using vrelab::test::gevs_on_ia;
using vrelab::test::kG;
using vrelab::test::kPi;

namespace {

std::shared_ptr<const SineExcitation> sine(Vec3 amp, Vec3 phase, double f) {
  return std::make_shared<const SineExcitation>(SineVibration{amp, phase, f});
}

// Mean over one period [0, 1/f] of component `axis`, by 32 x 20-point Gauss-Legendre
// (smooth periodic integrand: converged to rounding).
double period_mean(const Excitation& e, double f, int axis) {
  return vrelab::test::integrate_smooth([&](double t) { return e.acceleration_g(t)[axis]; }, 0, 1 / f, 32) * f;
}

}  // namespace

// Sine on random: the sum is the parts at every instant (rounding only); its mean square
// over 16 s is the sine's A^2/2 plus the random's, within 1 % (the random's own record-to-
// record spread is ~0.2 % and the sine-random cross term ~A sqrt(G / T) / (A^2/2 + rms^2)
// ~ 0.2 %), which is what combine() of the two demands reports.
TEST(SumExcitation, SineOnRandomAddsAndPowersAdd) {
  auto s = sine(Vec3(5, 0, 0), Vec3::Zero(), 300);
  auto r = std::make_shared<const RandomExcitation>(gevs_on_ia(), 5120, 8, 8192);
  const SumExcitation sum({s, r});
  for (double t : {0.0, 0.01234, 1.5, 7.77})
    EXPECT_NEAR((sum.acceleration_g(t) - s->acceleration_g(t) - r->acceleration_g(t)).norm(), 0, 1e-14);
  EXPECT_EQ(sum.max_frequency_Hz(), 2000);
  double ms = 0;
  const int n = 16 * 5120;
  for (int i = 0; i < n; ++i) ms += std::pow(sum.acceleration_g((i + 0.5) / 5120)[IA], 2) / n;
  const ShakerDemand d =
      combine(shaker_demand(SineVibration{Vec3(5, 0, 0), Vec3::Zero(), 300}, kG), shaker_demand(gevs_on_ia(), kG));
  EXPECT_NEAR(std::sqrt(ms), d.acceleration_rms_g[IA], 0.01 * d.acceleration_rms_g[IA]);
  EXPECT_NEAR(d.acceleration_rms_g[IA], std::sqrt(12.5 + std::pow(rms_g(*gevs_on_ia().psd[IA]), 2)), 1e-12);
  EXPECT_THROW(SumExcitation({}), std::invalid_argument);
  EXPECT_THROW(SumExcitation({s, nullptr}), std::invalid_argument);
}

// Transverse motion 10 % at +30 deg from IA onto PA. Exact on a tone: a_PA = 0.1 x 2 g x
// sin(w t + 0.2 + pi/6) by hand; the phasor form with_transverse() gives the same signal;
// the time-shift form on the tone seen as a general Excitation with f_ref = f is exact too.
// Agreement to 1e-12 g (rounding of sines of arguments ~ 1e3 rad). In phase, on a random
// signal: a_PA = 0.1 a_IA exactly.
TEST(TransverseMotion, ExactForSinePhasorAndTimeShiftForms) {
  const double f = 150, w = 2 * kPi * f;
  auto tone = sine(Vec3(2, 0, 0.5), Vec3(0.2, 0, 0), f);
  const TransverseSpec spec{IA, PA, 0.1, kPi / 6};
  const TransverseMotion exact(tone, spec);
  const SineExcitation phasor(with_transverse(tone->sine(), spec));
  const TransverseMotion shifted(std::shared_ptr<const Excitation>(tone), spec, f);
  for (double t : {0.0, 0.0013, 0.25, 1.001}) {
    const Vec3 a = exact.acceleration_g(t);
    EXPECT_NEAR(a[PA], 0.2 * std::sin(w * t + 0.2 + kPi / 6), 1e-12);
    EXPECT_NEAR(a[IA], 2 * std::sin(w * t + 0.2), 1e-12);
    EXPECT_NEAR(a[OA], 0.5 * std::sin(w * t), 1e-12);
    EXPECT_NEAR((phasor.acceleration_g(t) - a).norm(), 0, 1e-12);
    EXPECT_NEAR((shifted.acceleration_g(t) - a).norm(), 0, 1e-12);
  }
  // Adding onto an axis that already moves: phasor sum, e.g. PA already 0.2 g at pi/6 + 0.2
  // doubles to 0.4 g at the same phase.
  const SineVibration twice = with_transverse(phasor.sine(), spec);
  EXPECT_NEAR(twice.amplitude_g[PA], 0.4, 1e-15);
  EXPECT_NEAR(twice.phase_rad[PA], 0.2 + kPi / 6, 1e-15);

  auto random = std::make_shared<const RandomExcitation>(gevs_on_ia(), 5120, 1, 4096);
  const TransverseMotion inphase(random, TransverseSpec{IA, OA, 0.07, 0.0}, 0.0);
  for (double t : {0.1, 0.2345, 3.0}) EXPECT_EQ(inphase.acceleration_g(t)[OA], 0.07 * random->acceleration_g(t)[IA]);
  EXPECT_THROW(TransverseMotion(random, spec, 0.0), std::invalid_argument);  // a phase needs f_ref
  EXPECT_THROW(TransverseMotion(tone, TransverseSpec{IA, IA, 0.1, 0}), std::invalid_argument);
  EXPECT_THROW(TransverseMotion(tone, TransverseSpec{IA, 3, 0.1, 0}), std::invalid_argument);
}

// Harmonic distortion: 10 % second harmonic at +0.5 rad and 5 % third at -1 rad. By hand at
// t = 0: IA (phase 0) = 2 (0.1 sin 0.5 + 0.05 sin(-1)); OA (phase pi/2) = 1 (1 + 0.1 sin(pi +
// 0.5) + 0.05 sin(3 pi/2 - 1)) = 1 - 0.1 sin 0.5 - 0.05 cos 1. The Fourier coefficients over
// a period (quadrature) recover 0.2 g at 2f and 0.1 g at 3f on IA, and the mean square
// matches shaker_demand's rms, A^2 (1 + 0.1^2 + 0.05^2) / 2 (1e-12: converged quadrature).
TEST(HarmonicDistortion, HandValuesFourierContentAndRms) {
  const double f = 100;
  auto tone = sine(Vec3(2, 0, 1), Vec3(0, 0, kPi / 2), f);
  const std::vector<Harmonic> hs = {{2, 0.1, 0.5}, {3, 0.05, -1.0}};
  const HarmonicDistortion d(tone, hs);
  EXPECT_NEAR(d.acceleration_g(0)[IA], 2 * (0.1 * std::sin(0.5) + 0.05 * std::sin(-1.0)), 1e-15);
  EXPECT_NEAR(d.acceleration_g(0)[OA], 1 - 0.1 * std::sin(0.5) - 0.05 * std::cos(1.0), 1e-15);
  EXPECT_EQ(d.acceleration_g(0.0123)[PA], 0.0);
  EXPECT_NEAR(d.total_harmonic_distortion(), std::sqrt(0.01 + 0.0025), 1e-15);
  EXPECT_EQ(d.max_frequency_Hz(), 300);
  for (int h = 1; h <= 4; ++h) {
    auto coef = [&](auto trig) {
      return 2 * f *
             vrelab::test::integrate_smooth(
                 [&](double t) { return d.acceleration_g(t)[IA] * trig(2 * kPi * h * f * t); }, 0, 1 / f, 32);
    };
    const double amp =
        std::hypot(coef([](double x) { return std::sin(x); }), coef([](double x) { return std::cos(x); }));
    const double expected = h == 1 ? 2 : h == 2 ? 0.2 : h == 3 ? 0.1 : 0;
    EXPECT_NEAR(amp, expected, 1e-12) << "harmonic " << h;
  }
  const double ms =
      vrelab::test::integrate_smooth([&](double t) { return std::pow(d.acceleration_g(t)[IA], 2); }, 0, 1 / f, 32) * f;
  const ShakerDemand dem = shaker_demand(tone->sine(), hs, kG);
  EXPECT_NEAR(std::sqrt(ms), dem.acceleration_rms_g[IA], 1e-12);
  EXPECT_NEAR(dem.acceleration_rms_g[IA], 2 * std::sqrt((1 + 0.01 + 0.0025) / 2), 1e-15);
  EXPECT_THROW(HarmonicDistortion(tone, {{1, 0.1, 0}}), std::invalid_argument);
  EXPECT_THROW(HarmonicDistortion(tone, {{2, -0.1, 0}}), std::invalid_argument);
}

// Rocking about OA by alpha = 0.01 sin(w t + 0.3), gravity +1 g on IA, shaker 5 g on IA.
// By hand, the rocked sensor axes are x_s = (cos a, sin a, 0), y_s = (-sin a, cos a, 0) in
// the laboratory, so the laboratory vector (1 + a_IA, 0, 0) reads ((1 + a_IA) cos a,
// -(1 + a_IA) sin a, 0); minus the static (1, 0, 0). Averages over a period (with cos(a0 sin)
// = J0 + 2 J2 cos 2y + ..., sin(a0 sin y) = 2 J1 sin y + ...): IA rectifies by J0(a0) - 1
// (-2.5e-5 g), PA by -A J1(a0) cos(0.3) (cross-axis, -2.4e-2 g). Quadrature to 1e-13 g.
TEST(Rocking, RotatedGravityAndBesselRectification) {
  const double f = 100, w = 2 * kPi * f, a0 = 0.01, A = 5;
  auto tone = sine(Vec3(A, 0, 0), Vec3::Zero(), f);
  RockingSpec spec;
  spec.axis = Vec3(0, 0, 2);  // normalised by the decorator
  spec.amplitude_rad = a0;
  spec.phase_rad = 0.3;
  spec.static_gravity_g = Vec3(1, 0, 0);
  const Rocking r(tone, spec);
  for (double t : {0.0, 0.00137, 0.0042, 0.5}) {
    const double al = a0 * std::sin(w * t + 0.3), v = 1 + A * std::sin(w * t);
    const Vec3 a = r.acceleration_g(t);
    EXPECT_NEAR(a[IA], v * std::cos(al) - 1, 1e-14);
    EXPECT_NEAR(a[PA], -v * std::sin(al), 1e-14);
    EXPECT_NEAR(a[OA], 0, 1e-15);
    EXPECT_NEAR(r.angle_rad(t), al, 1e-17);
  }
  EXPECT_NEAR(period_mean(r, f, IA), std::cyl_bessel_j(0.0, a0) - 1, 1e-13);
  EXPECT_NEAR(period_mean(r, f, PA), -A * std::cyl_bessel_j(1.0, a0) * std::cos(0.3), 1e-13);
  EXPECT_NEAR(r.mean_g()[IA], std::cyl_bessel_j(0.0, a0) - 1, 1e-13);  // the same means, as the decorator states them
  EXPECT_NEAR(r.mean_g()[PA], -A * std::cyl_bessel_j(1.0, a0) * std::cos(0.3), 1e-13);
  EXPECT_EQ(SumExcitation({tone, std::make_shared<Rocking>(tone, spec)}).mean_g(), r.mean_g());
  EXPECT_EQ(tone->mean_g(), Vec3::Zero());
  // Only gravity rotated: IA = a_IA + cos a - 1, PA = -sin a (no cross-axis term from a_IA).
  spec.rotate_shaker_motion = false;
  const Rocking g_only(tone, spec);
  EXPECT_NEAR(period_mean(g_only, f, PA), 0, 1e-13);
  EXPECT_NEAR(g_only.acceleration_g(0.00137)[IA],
              A * std::sin(w * 0.00137) + std::cos(a0 * std::sin(w * 0.00137 + 0.3)) - 1, 1e-14);
  EXPECT_EQ(r.max_frequency_Hz(), 200);
}

// Lever arm: a point at r (sensor axes) on a table rocking about a general axis e through
// the origin moves along p(t) = R(alpha(t)) r in the laboratory; the sensor feels
// R^T p''(t). p'' by central second differences of the rotated position (Eigen AngleAxis,
// not the decorator's formula), h = 3e-6 s: truncation h^2 p''''/12 ~ 6e-6 m/s^2, rounding
// eps |r| / h^2 ~ 1e-6 m/s^2: 2e-5 m/s^2 = 2e-6 g. The tone is silent and gravity 0, so the
// decorator's output is the kinematic term alone (~2 g tangential, centripetal ~3e-3 g
// with a mean of -alpha0^2 w^2 |r_perp| / 2, which the finite differences also see).
TEST(Rocking, LeverArmKinematicsAgainstFiniteDifferences) {
  const double f = 100, w = 2 * kPi * f, a0 = 1e-3;
  auto silent = sine(Vec3::Zero(), Vec3::Zero(), f);
  RockingSpec spec;
  spec.axis = Vec3(1, 2, -0.5).normalized();
  spec.amplitude_rad = a0;
  spec.phase_rad = -0.7;
  spec.lever_arm_m = Vec3(0.03, -0.04, 0.02);
  spec.g_m_per_s2 = kG;
  const Rocking r(silent, spec);
  auto position = [&](double t) -> Vec3 {
    const double al = a0 * std::sin(w * t - 0.7);
    return Eigen::AngleAxisd(al, spec.axis) * *spec.lever_arm_m;
  };
  for (double t : {0.0, 0.0011, 0.0027, 0.0063}) {
    const double h = 3e-6, al = a0 * std::sin(w * t - 0.7);
    const Vec3 acc = (position(t + h) - 2 * position(t) + position(t - h)) / (h * h);
    const Vec3 body = Eigen::AngleAxisd(al, spec.axis).toRotationMatrix().transpose() * acc / kG;
    EXPECT_NEAR((r.acceleration_g(t) - body).norm(), 0, 2e-6) << t;
    EXPECT_GT(r.acceleration_g(t).norm(), 1e-2);
  }
  const Vec3 rp = *spec.lever_arm_m - spec.axis * spec.axis.dot(*spec.lever_arm_m);
  const Vec3 mean(period_mean(r, f, IA), period_mean(r, f, PA), period_mean(r, f, OA));
  EXPECT_NEAR((mean + a0 * a0 * w * w / 2 * rp / kG).norm(), 0, 1e-12);
  spec.g_m_per_s2 = 0;
  EXPECT_THROW(Rocking(silent, spec), std::invalid_argument);
}

}  // namespace test_vibration_decorators
