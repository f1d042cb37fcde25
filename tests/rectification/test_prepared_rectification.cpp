// The prepared predictions (rectification/prediction/frequency.hpp): what does not depend on the
// coefficients computed once, the terms for any coefficients. diagnose evaluates a run's
// prediction at 12 coefficient vectors on one prepared object (its gradient in the
// coefficients) and relies on each being the prediction of the plant with those coefficients,
// bit for bit (docs/performance.md, "Diagnosis"). The independent path: the one-shot functions on a
// plant that carries the second coefficients from the start, so a prepared part that read the
// coefficients it was built with would show here. Exact equality is the claim (the same
// floating-point operations), so the tolerance is 0.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <complex>
#include <memory>
#include <vector>

#include "plant/accelerometer.hpp"
#include "plant/effects/effects.hpp"
#include "rectification/prediction/frequency.hpp"
#include "support/instrument.hpp"

namespace test_prepared_rectification {

using namespace vrelab;
using namespace vrelab::plant;

namespace {

// A plant with every path of the prediction in use: nonlinear coefficients at the input, in
// the loop and at the output, a readout polynomial, the pickoff and the pendulum geometry, and
// a mechanical mode in the loop's linear part.
PlantConfig busy_plant(const Coefficients& c) {
  PlantConfig p = test::paper_like_plant();
  p.coefficients = c;
  p.location[k2] = Location::input;
  p.location[k_IP] = Location::output;
  p.location[delta_OA] = Location::output;
  p.effects.push_back(std::make_shared<OutputPolynomial>("readout", std::array<double, 7>{0, 0, 2e-5, 0, 0, 3e-6, 0}));
  p.effects.push_back(std::make_shared<PickoffNonlinearity>(20.0));
  p.effects.push_back(std::make_shared<PendulumGeometry>());
  p.effects.push_back(std::make_shared<MechanicalMode>(1800.0, 0.04, Vec3(1, 1, 0)));
  return p;
}

// The second coefficient vector: every nonlinear and cross coefficient changed (one of them
// to zero, which the terms skip), as the gradient's steps change them.
Coefficients other(Coefficients c) {
  for (int i = k1_asym; i < kNumCoefficients; ++i) c[i] = c[i] * 1.7 + 3e-6 * i;
  c[k3] = 0.0;
  c[delta_OA] = 2e-2;
  return c;
}

}  // namespace

TEST(PreparedRectification, APeriodicInputPreparedOnceIsThePredictionAtAnyCoefficients) {
  const Coefficients ca = test::paper_like_coefficients(), cb = other(ca);
  const PlantConfig pa = busy_plant(ca), pb = busy_plant(cb);
  const Vec3 a(0.5, std::sqrt(0.75), 0);
  rectification::PeriodicInput in;  // a distorted tone with a mean: the averaged path
  in.frequency_Hz = 130.0;
  in.mean_g = Vec3(0.01, -0.02, 0.005);
  in.tones.push_back({1, Eigen::Vector3cd(std::complex<double>(3, 0), std::complex<double>(0.5, 1), std::complex<double>(0, -0.2))});
  in.tones.push_back({2, Eigen::Vector3cd(std::complex<double>(0.2, 0.1), 0.0, std::complex<double>(0, 0.05))});
  in.tones.push_back({3, Eigen::Vector3cd(std::complex<double>(0, 0.05), std::complex<double>(0.01, 0), 0.0)});
  const rectification::ResponseAt response = [&](double f) { return rectification::loop_response(pa, f); };
  const rectification::PreparedPeriodicRectification prepared(pa, a, in, response);
  for (const Coefficients& c : {cb, ca}) {
    PlantConfig p = pa;
    p.coefficients = c;
    const rectification::FrequencyPrediction want = rectification::periodic_rectification(p, a, in, response);
    const rectification::FrequencyPrediction got = prepared(c);
    for (int k = 0; k < rectification::kNumTerms; ++k) EXPECT_EQ(got.terms.g[k], want.terms.g[k]) << "term " << k;
    EXPECT_EQ(got.readout_g, want.readout_g);
    EXPECT_EQ(got.pickoff_g, want.pickoff_g);
    EXPECT_EQ(got.pendulum_geometry_g, want.pendulum_geometry_g);
    EXPECT_EQ(got.input_mean_g, want.input_mean_g);
    EXPECT_EQ(got.total_g(), want.total_g());
    EXPECT_NE(want.readout_g, 0.0);  // the readout path is in use
  }
  // The plant built with the second coefficients from the start gives the same.
  EXPECT_EQ(prepared(cb).total_g(), rectification::periodic_rectification(pb, a, in, response).total_g());
}

TEST(PreparedRectification, ASineClosedFormPreparedOnceIsThePredictionAtAnyCoefficients) {
  const Coefficients ca = test::paper_like_coefficients(), cb = other(ca);
  const PlantConfig pa = busy_plant(ca), pb = busy_plant(cb);
  const Vec3 a(-0.3, 0.2, std::sqrt(0.87));
  for (double f : {20.0, 450.0, 2500.0}) {
    vibration::SineVibration v;
    v.amplitude_g = Vec3(4, 1, 0.5);
    v.phase_rad = Vec3(0, 0.7, -2.0);
    v.frequency_Hz = f;
    const rectification::LoopResponse h = rectification::loop_response(pa, f);
    const rectification::PreparedSineRectification prepared(pa, a, v, 12.0, h);
    const rectification::FrequencyPrediction want = rectification::sine_rectification_at_frequency(pb, a, v, 12.0, h);
    const rectification::FrequencyPrediction got = prepared(cb);
    for (int k = 0; k < rectification::kNumTerms; ++k) EXPECT_EQ(got.terms.g[k], want.terms.g[k]) << f << " Hz, term " << k;
    EXPECT_EQ(got.total_g(), want.total_g()) << f << " Hz";
    EXPECT_NE(want.readout_g, 0.0);
  }
}

// One linearisation for every frequency, asked in any order: each response is a fresh
// responder's (loop_response builds one per call), bit for bit. A property test: it fails when
// a response depends on what was asked before (state kept between calls); the responses' values
// are checked against the ODE elsewhere (test_frequency.cpp, test_random_at_frequency.cpp).
TEST(PreparedRectification, ALoopResponderLinearisedOnceGivesEachFrequencysResponse) {
  const PlantConfig p = busy_plant(test::paper_like_coefficients());
  const rectification::LoopResponder responder(p);
  for (double f : {2000.0, 1.0, 130.0, 1800.0, 37.5}) {
    const rectification::LoopResponse got = responder(f), want = rectification::loop_response(p, f);
    EXPECT_EQ(got.dc_gain, want.dc_gain) << f << " Hz";
    for (std::size_t j = 0; j < 3; ++j) {
      EXPECT_EQ(got.current[j], want.current[j]) << f << " Hz, axis " << j;
      EXPECT_EQ(got.angle_rad[j], want.angle_rad[j]) << f << " Hz, axis " << j;
      EXPECT_EQ(got.mechanical[j], want.mechanical[j]) << f << " Hz, axis " << j;
    }
  }
  EXPECT_THROW(responder(0.0), std::invalid_argument);
}

}  // namespace test_prepared_rectification
