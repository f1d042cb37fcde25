// The squeeze film's prediction made faster (docs/diagnose.md "Speed", session 8): tables of
// sines and phasors computed once, one pow per distinct |sin| in the describing function.
// These pin the fast paths against an independent computation:
//  - damping_factor against the direct 128-point sum as it was written before (a sin, a cos
//    and a pow per point): the claim is the same floating-point operations on the same
//    numbers, so the tolerance is 0;
//  - the periodic rectification of current harmonics up to h = 31 inside the loop (the film's
//    harmonics: 187 points, the phasor tables of 67-187 points) against the closed form of a
//    cubic's mean, <u^3> = -(3/4) Im(B conj(A)^2) for u = Im(A e^{j15 phi}) + Im(B e^{j30 phi})
//    (+ a tone at h = 31, which makes no product with them that averages to nonzero). The
//    trapezoid on 187 points is exact for trigonometric polynomials of degree < 187 (u^3 has
//    degree 93), so only rounding is left: 1e-13 relative (~40 ulp over 187 x 3 terms).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <complex>
#include <memory>
#include <numbers>
#include <stdexcept>
#include <string>

#include "plant/accelerometer.hpp"
#include "plant/effects/mechanical_mode.hpp"
#include "plant/effects/squeeze_film_damping.hpp"
#include "rectification/prediction/frequency.hpp"

using namespace vrelab;
using namespace vrelab::plant;

namespace {

// The describing function as the film computed it before the tables (the reference).
double direct_damping_factor(double theta_amplitude, double gap) {
  constexpr int kN = 128;
  double sum = 0;
  for (int k = 0; k < kN; ++k) {
    const double phi = 2 * std::numbers::pi * k / kN;
    const double x = std::min(std::abs(theta_amplitude * std::sin(phi)) / gap, 0.95);
    sum += std::cos(phi) * std::cos(phi) / std::pow(1 - x * x, 1.5);
  }
  return 2 * sum / kN;
}

}  // namespace

TEST(FilmSpeedPaths, DampingFactorIsTheDirectSumBitForBit) {
  const double gap = 1.1e-3;
  const SqueezeFilmDamping film(gap, 40.0, 3.0e4);
  // From no film effect through near contact to beyond 0.95 of the gap (held), both signs.
  for (double r : {0.0, 1e-6, 0.05, 0.3, 0.7, 0.9, 0.949, 0.95, 0.97, 1.2, 3.0}) {
    for (double sign : {1.0, -1.0}) {
      const double theta = sign * r * gap;
      EXPECT_EQ(film.damping_factor(theta), direct_damping_factor(theta, gap)) << "theta = " << theta;
    }
  }
}

TEST(FilmSpeedPaths, LoopHarmonicsUpTo31AverageAsTheCubicsClosedForm) {
  PlantConfig p;
  for (int c = 0; c < kNumCoefficients; ++c) p.coefficients[c] = 0.0;
  p.coefficients[K1] = 1.0;
  const double k3_per_g2 = 2e-3;
  p.coefficients[k3] = k3_per_g2;
  p.location[k3] = Location::loop;  // averaged over the current's oscillation
  rectification::PeriodicInput in;
  in.frequency_Hz = 100.0;
  const std::complex<double> A(0.8, -1.7), B(-0.6, 0.9), C31(0.3, 0.2);  // g
  in.loop = {{15, A, 0.0}, {30, B, 0.0}, {31, C31, 0.0}};
  // No table tones: the loop's response is never asked for (the DC gain stays 1).
  const rectification::ResponseAt no_response = [](double) -> rectification::LoopResponse {
    throw std::logic_error("no table tone: no response expected");
  };
  const Vec3 a_static(0, 0, 1);  // IA horizontal: the current oscillates about a_IA = 0
  const double got = rectification::periodic_rectification(p, a_static, in, no_response).total_g();
  const double expected = k3_per_g2 * -0.75 * std::imag(B * std::conj(A) * std::conj(A));
  EXPECT_NEAR(got, expected, 1e-13 * std::abs(expected)) << got << " vs " << expected;
  // The same with the h = 31 tone's phase turned: it makes no average with the others.
  in.loop[2].current_g = C31 * std::polar(1.0, 1.0);
  EXPECT_NEAR(rectification::periodic_rectification(p, a_static, in, no_response).total_g(), expected,
              1e-13 * std::abs(expected));
}

// diagnose reuses a film run's linearisation and balance for runs whose film_balance_key is
// equal (the same plant and motion: runs that differ only in orientation). The key must tell
// films apart by their parameters (a film is made afresh per run), and anything else it cannot
// compare by identity; equal keys must give equal results (computed here without reuse).
TEST(FilmSpeedPaths, FilmBalanceKeyIsEqualExactlyForTheSamePlantAndMotion) {
  const auto plant_with = [](double gap_rad) {
    PlantConfig p;
    p.coefficients[K1] = 1.0;
    const double c0 = 2 * p.dynamics.pendulum_damping_ratio * 2 * std::numbers::pi * p.dynamics.pendulum_frequency_Hz;
    p.effects.push_back(std::make_shared<SqueezeFilmDamping>(gap_rad, c0, p.dynamics.angle_gain_rad_per_s2_per_g));
    return p;
  };
  vibration::SineVibration v;
  v.amplitude_g = Vec3(4.0, 0, 0);
  v.frequency_Hz = 130.0;
  const rectification::PeriodicInput in = rectification::periodic_input(v);
  const PlantConfig a = plant_with(1.1e-3), b = plant_with(1.1e-3), c = plant_with(1.2e-3);
  const std::string ka = rectification::film_balance_key(a, v, in);
  ASSERT_FALSE(ka.empty());
  EXPECT_EQ(ka, rectification::film_balance_key(b, v, in));  // two films made alike
  EXPECT_NE(ka, rectification::film_balance_key(c, v, in));  // another gap
  vibration::SineVibration v2 = v;
  v2.amplitude_g[0] = 4.0 * (1 + 1e-15);
  EXPECT_NE(ka, rectification::film_balance_key(a, v2, rectification::periodic_input(v2)));  // another motion
  PlantConfig d = a, e = a;
  d.effects.push_back(std::make_shared<MechanicalMode>(1800.0, 0.04, Vec3(1, 1, 0)));
  e.effects.push_back(std::make_shared<MechanicalMode>(1800.0, 0.04, Vec3(1, 1, 0)));
  EXPECT_NE(rectification::film_balance_key(d, v, in), rectification::film_balance_key(e, v, in));  // by identity
  EXPECT_TRUE(rectification::film_balance_key(PlantConfig{}, v, in).empty());  // no film
  // Equal keys: the linearisation and the balance computed afresh are the same numbers.
  const PlantConfig la = rectification::amplitude_linearised(a, v), lb = rectification::amplitude_linearised(b, v);
  EXPECT_EQ(la.dynamics.pendulum_damping_ratio, lb.dynamics.pendulum_damping_ratio);
  const rectification::ResponseAt ha = [&la](double f) { return rectification::loop_response(la, f); };
  const rectification::ResponseAt hb = [&lb](double f) { return rectification::loop_response(lb, f); };
  const rectification::PeriodicInput ba = rectification::film_harmonic_balance(a, la, in, ha);
  const rectification::PeriodicInput bb = rectification::film_harmonic_balance(b, lb, in, hb);
  ASSERT_EQ(ba.loop.size(), bb.loop.size());
  for (std::size_t i = 0; i < ba.loop.size(); ++i) {
    EXPECT_EQ(ba.loop[i].current_g, bb.loop[i].current_g) << i;
    EXPECT_EQ(ba.loop[i].angle_rad, bb.loop[i].angle_rad) << i;
  }
}
