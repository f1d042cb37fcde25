// The squeeze film's fast prediction (docs/performance.md, "Diagnosis"): tables of
// sines and phasors computed once, one pow per distinct |sin| in the describing function.
// These pin the fast paths against an independent computation:
//  - damping_factor against the direct 128-point sum (a sin, a cos and a pow per point): the
//    claim is the same floating-point operations on the same numbers, so the tolerance is 0;
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
#include <cstring>
#include <functional>
#include <limits>
#include <memory>
#include <numbers>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "plant/accelerometer.hpp"
#include "plant/effects/mechanical_mode.hpp"
#include "plant/effects/squeeze_film_damping.hpp"
#include "rectification/prediction/frequency.hpp"

namespace test_film_speed_paths {

using namespace vrelab;
using namespace vrelab::plant;

namespace {

// The describing function by the direct sum, without the tables: a sin, a cos and a pow per
// point (the reference).
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
namespace {

struct FilmKeyInputs {
  PlantConfig config;
  vibration::SineVibration v;
  rectification::PeriodicInput in;
  std::string key() const { return rectification::film_balance_key(config, v, in); }
};

std::shared_ptr<const Effect> film(double gap_rad, double c0_per_s, double b) {
  return std::make_shared<SqueezeFilmDamping>(gap_rad, c0_per_s, b);
}

// A plant with a film, another effect, an explicit servo and a torquer polynomial, and a
// motion with a mean, two table tones and a loop tone: every part the key encodes is present.
FilmKeyInputs film_key_inputs(const std::shared_ptr<const Effect>& other) {
  FilmKeyInputs k;
  PlantConfig& p = k.config;
  for (int c = 0; c < kNumCoefficients; ++c) p.coefficients[c] = 1e-6 * (c + 1);
  p.coefficients[K1] = 1.0;
  p.servo = design_servo(p.dynamics);
  p.torquer_c2_per_g = 1e-5, p.torquer_c3_per_g2 = -2e-6;
  const double c0 = 2 * p.dynamics.pendulum_damping_ratio * 2 * std::numbers::pi * p.dynamics.pendulum_frequency_Hz;
  p.effects = {film(1.1e-3, c0, p.dynamics.angle_gain_rad_per_s2_per_g), other};
  k.v.amplitude_g = Vec3(4.0, 0.5, 0.25);
  k.v.phase_rad = Vec3(0.0, 0.3, -0.2);
  k.v.frequency_Hz = 130.0;
  k.in = rectification::periodic_input(k.v);
  k.in.mean_g = Vec3(0.1, -0.2, 0.3);
  k.in.tones.push_back({3, Eigen::Vector3cd(std::complex<double>(0.1, 0.2), std::complex<double>(-0.3, 0.4), 0.5)});
  k.in.loop.push_back({3, std::complex<double>(1e-3, -2e-3), std::complex<double>(3e-6, 4e-6)});
  return k;
}

// The next double up: the smallest change of a field (its key must change all the same).
void bump(double& x) { x = std::nextafter(x, std::numeric_limits<double>::infinity()); }

}  // namespace

TEST(FilmSpeedPaths, FilmBalanceKeyIsEqualExactlyForTheSamePlantAndMotion) {
  const auto plant_with = [](double gap_rad) {
    PlantConfig p;
    p.coefficients[K1] = 1.0;
    const double c0 = 2 * p.dynamics.pendulum_damping_ratio * 2 * std::numbers::pi * p.dynamics.pendulum_frequency_Hz;
    p.effects.push_back(film(gap_rad, c0, p.dynamics.angle_gain_rad_per_s2_per_g));
    return p;
  };
  vibration::SineVibration v;
  v.amplitude_g = Vec3(4.0, 0, 0);
  v.frequency_Hz = 130.0;
  const rectification::PeriodicInput in = rectification::periodic_input(v);
  const PlantConfig a = plant_with(1.1e-3), b = plant_with(1.1e-3);
  const std::string ka = rectification::film_balance_key(a, v, in);
  ASSERT_FALSE(ka.empty());
  EXPECT_EQ(ka, rectification::film_balance_key(b, v, in));  // two films made alike
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

  // Each input the key encodes changed alone, by the least it can change (one double up, an
  // enum to another value, an item more or less): the key differs from the base's. The same
  // change made to two copies made alike gives equal keys (the key says nothing else).
  const auto other = std::make_shared<MechanicalMode>(1800.0, 0.04, Vec3(1, 1, 0));
  const auto other_afresh = std::make_shared<MechanicalMode>(1800.0, 0.04, Vec3(1, 1, 0));
  const std::string base = film_key_inputs(other).key();
  ASSERT_FALSE(base.empty());
  ASSERT_EQ(base, film_key_inputs(other).key());
  std::vector<std::pair<std::string, std::function<void(FilmKeyInputs&)>>> changes;
  for (int c = 0; c < kNumCoefficients; ++c) {
    changes.emplace_back(std::string("coefficient ").append(std::to_string(c)),
                         [c](FilmKeyInputs& k) { bump(k.config.coefficients.v[static_cast<std::size_t>(c)]); });
    changes.emplace_back(std::string("location ").append(std::to_string(c)), [c](FilmKeyInputs& k) {
      Location& l = k.config.location[static_cast<std::size_t>(c)];
      l = static_cast<Location>((static_cast<int>(l) + 1) % 3);
    });
  }
  const std::vector<std::pair<std::string, double Dynamics::*>> dynamics = {
      {"pendulum_frequency_Hz", &Dynamics::pendulum_frequency_Hz},
      {"pendulum_damping_ratio", &Dynamics::pendulum_damping_ratio},
      {"angle_gain_rad_per_s2_per_g", &Dynamics::angle_gain_rad_per_s2_per_g},
      {"loop_bandwidth_Hz", &Dynamics::loop_bandwidth_Hz},
      {"phase_margin_deg", &Dynamics::phase_margin_deg},
      {"integrator_zero_ratio", &Dynamics::integrator_zero_ratio},
      {"antialias_Hz", &Dynamics::antialias_Hz}};
  for (const auto& [name, field] : dynamics) {
    const auto f = field;  // clang 14 captures no structured binding
    changes.emplace_back(name, [f](FilmKeyInputs& k) { bump(k.config.dynamics.*f); });
  }
  changes.emplace_back("integrator", [](FilmKeyInputs& k) { k.config.dynamics.integrator = !k.config.dynamics.integrator; });
  changes.emplace_back("no servo", [](FilmKeyInputs& k) { k.config.servo.reset(); });
  changes.emplace_back("servo gain", [](FilmKeyInputs& k) { bump(k.config.servo->gain_g_per_rad); });
  changes.emplace_back("servo lead zero", [](FilmKeyInputs& k) { bump(k.config.servo->lead_zero_rad_per_s); });
  changes.emplace_back("servo lead pole", [](FilmKeyInputs& k) { bump(k.config.servo->lead_pole_rad_per_s); });
  changes.emplace_back("servo integrator", [](FilmKeyInputs& k) { bump(k.config.servo->integrator_rad_per_s); });
  changes.emplace_back("torquer c2", [](FilmKeyInputs& k) { bump(k.config.torquer_c2_per_g); });
  changes.emplace_back("torquer c3", [](FilmKeyInputs& k) { bump(k.config.torquer_c3_per_g2); });
  const auto film_changed = [](int which) {
    return [which](FilmKeyInputs& k) {
      const auto& f = dynamic_cast<const SqueezeFilmDamping&>(*k.config.effects[0]);
      double x[3] = {f.gap_angle_rad(), f.c0_own_per_s(), f.angle_gain_own_rad_per_s2_per_g()};
      bump(x[which]);
      k.config.effects[0] = film(x[0], x[1], x[2]);
    };
  };
  changes.emplace_back("film gap", film_changed(0));
  changes.emplace_back("film c0", film_changed(1));
  changes.emplace_back("film angle gain", film_changed(2));
  changes.emplace_back("other effect made afresh", [&other_afresh](FilmKeyInputs& k) { k.config.effects[1] = other_afresh; });
  changes.emplace_back("other effect removed", [](FilmKeyInputs& k) { k.config.effects.pop_back(); });
  changes.emplace_back("effects swapped", [](FilmKeyInputs& k) { std::swap(k.config.effects[0], k.config.effects[1]); });
  for (int i = 0; i < 3; ++i) {
    const std::string axis = std::string(" ").append(std::to_string(i));
    changes.emplace_back(std::string("amplitude").append(axis), [i](FilmKeyInputs& k) { bump(k.v.amplitude_g[i]); });
    changes.emplace_back(std::string("phase").append(axis), [i](FilmKeyInputs& k) { bump(k.v.phase_rad[i]); });
    changes.emplace_back(std::string("mean").append(axis), [i](FilmKeyInputs& k) { bump(k.in.mean_g[i]); });
    for (std::size_t t = 0; t < 2; ++t) {
      const std::string tone = std::string(" of tone ").append(std::to_string(t));
      changes.emplace_back(std::string("real W").append(axis).append(tone), [i, t](FilmKeyInputs& k) { k.in.tones[t].second[i] += std::complex<double>(1e-9, 0); });
      changes.emplace_back(std::string("imag W").append(axis).append(tone), [i, t](FilmKeyInputs& k) { k.in.tones[t].second[i] += std::complex<double>(0, 1e-9); });
    }
  }
  changes.emplace_back("vibration frequency", [](FilmKeyInputs& k) { bump(k.v.frequency_Hz); });
  changes.emplace_back("input frequency", [](FilmKeyInputs& k) { bump(k.in.frequency_Hz); });
  changes.emplace_back("tone harmonic", [](FilmKeyInputs& k) { k.in.tones[1].first = 5; });
  changes.emplace_back("tone removed", [](FilmKeyInputs& k) { k.in.tones.pop_back(); });
  changes.emplace_back("tone added", [](FilmKeyInputs& k) { k.in.tones.push_back({7, Eigen::Vector3cd::Zero()}); });
  changes.emplace_back("loop harmonic", [](FilmKeyInputs& k) { k.in.loop[0].h = 5; });
  changes.emplace_back("loop current real", [](FilmKeyInputs& k) { k.in.loop[0].current_g += std::complex<double>(1e-12, 0); });
  changes.emplace_back("loop current imag", [](FilmKeyInputs& k) { k.in.loop[0].current_g += std::complex<double>(0, 1e-12); });
  changes.emplace_back("loop angle real", [](FilmKeyInputs& k) { k.in.loop[0].angle_rad += std::complex<double>(1e-15, 0); });
  changes.emplace_back("loop angle imag", [](FilmKeyInputs& k) { k.in.loop[0].angle_rad += std::complex<double>(0, 1e-15); });
  changes.emplace_back("loop tone removed", [](FilmKeyInputs& k) { k.in.loop.clear(); });
  changes.emplace_back("loop tone added", [](FilmKeyInputs& k) { k.in.loop.push_back({9, 0.0, 0.0}); });
  for (const auto& [name, change] : changes) {
    FilmKeyInputs k1 = film_key_inputs(other), k2 = film_key_inputs(other);
    change(k1), change(k2);
    const std::string changed = k1.key();
    EXPECT_NE(changed, base) << name;
    EXPECT_EQ(changed, k2.key()) << name;
  }
}

// Parts of variable length next to each other: 9 table tones (52 bytes each: h and three
// complex amplitudes) and no loop tone, against no table tone and 13 loop tones (36 bytes
// each: h, current, angle) made of the same 468 bytes. Without the parts' counts the keys
// would be these same bytes after the same prefix: equal.
TEST(FilmSpeedPaths, FilmBalanceKeyTellsPartsOfVariableLengthApart) {
  PlantConfig p;
  p.coefficients[K1] = 1.0;
  p.effects.push_back(film(1.1e-3, 2 * 0.3 * 2 * std::numbers::pi * 50.0, 1000.0));
  vibration::SineVibration v;
  v.amplitude_g = Vec3(4.0, 0, 0);
  v.frequency_Hz = 130.0;
  rectification::PeriodicInput tones, loop;
  tones.frequency_Hz = loop.frequency_Hz = 130.0;
  std::string bytes;
  const auto append = [&bytes](const auto& x) { bytes.append(reinterpret_cast<const char*>(&x), sizeof x); };
  for (int h = 1; h <= 9; ++h) {
    Eigen::Vector3cd W;
    for (int i = 0; i < 3; ++i) W[i] = std::complex<double>(0.25 * h + i, -0.5 * i);
    tones.tones.push_back({h, W});
    append(h);
    for (int i = 0; i < 3; ++i) append(W[i].real()), append(W[i].imag());
  }
  ASSERT_EQ(bytes.size(), 9u * 52u);
  std::string loop_bytes;
  for (std::size_t at = 0; at < bytes.size();) {
    rectification::PeriodicInput::LoopTone l;
    double x[4];
    std::memcpy(&l.h, bytes.data() + at, sizeof l.h);
    at += sizeof l.h;
    std::memcpy(x, bytes.data() + at, sizeof x);
    at += sizeof x;
    l.current_g = {x[0], x[1]}, l.angle_rad = {x[2], x[3]};
    loop.loop.push_back(l);
    loop_bytes.append(reinterpret_cast<const char*>(&l.h), sizeof l.h);
    for (double y : {l.current_g.real(), l.current_g.imag(), l.angle_rad.real(), l.angle_rad.imag()}) loop_bytes.append(reinterpret_cast<const char*>(&y), sizeof y);
  }
  ASSERT_EQ(loop.loop.size(), 13u);
  ASSERT_EQ(loop_bytes, bytes);  // the two inputs' variable parts: the same bytes in a row
  const std::string kt = rectification::film_balance_key(p, v, tones), kl = rectification::film_balance_key(p, v, loop);
  EXPECT_EQ(kt.size(), kl.size());
  EXPECT_NE(kt, kl);
}

}  // namespace test_film_speed_paths
