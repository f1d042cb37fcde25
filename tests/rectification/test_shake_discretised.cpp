// Random runs stepped once per sample (rectification/simulation/discretised.hpp) against
// CVODE on the same realisation: the linear loop exact for the excitation's spline, the
// nonlinear correction far inside the statistical sigma, the fallback for non-smooth effects.
#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <vector>

#include "plant/accelerometer.hpp"
#include "plant/effects/effects.hpp"
#include "rectification/simulation/discretised.hpp"
#include "rectification/simulation/shake.hpp"
#include "support/instrument.hpp"
#include "support/vibrations.hpp"
#include "vibration/sampled.hpp"

namespace test_shake_discretised {

using namespace vrelab;
using namespace vrelab::plant;

namespace {

// cases/shake-random-gevs.toml's instrument: every model (1) term, IA terms in the loop.
PlantConfig gevs_plant() {
  PlantConfig cfg;
  const std::pair<int, double> c[] = {{K1, 1.25},        {k0, 1.5e-3},     {k1_asym, 2.0e-5}, {k2, 1.5e-5},
                                      {k3, 1.0e-6},      {k4, 2.0e-7},     {delta_OA, 1e-4},  {delta_PA, -5e-5},
                                      {k_IP, 8e-6},      {k_IO, -5e-6},    {k_PO, 3e-6},      {k_PP, 4e-6}};
  for (auto [i, v] : c) cfg.coefficients[i] = v;
  return cfg;
}

const Vec3 kTilted(0.5, 0.8660254037844386, 0.0);

rectification::ShakeResult run(const PlantConfig& cfg, const vibration::Excitation& ex, double measure_s, double rate,
                               bool exponential, double rtol, const rectification::SampleSink& sink = {}) {
  rectification::ShakeSettings s;
  s.relative_tolerance = rtol;
  s.blocks = 16;
  s.readout.sample_rate_Hz = rate;
  s.exponential_integrator = exponential;
  return rectification::shake_excitation(cfg, kTilted, ex, measure_s, s, sink);
}

}  // namespace

TEST(ExponentialIntegrator, InputIsTheExcitationsSplineAtEveryGridPoint) {
  // Knots at 16 kHz, grid at 20 kHz (4/5 of a knot interval per step): the input the plant
  // sees is RandomExcitation's own quintic spline, rebuilt from its samples with the same
  // prefilter (truncation ~3e-18 of the signal) and evaluated in monomial form rather than
  // the factorised one: equal to the rounding, 1e-10 g of peaks near 60 g (measured 5e-11).
  const vibration::RandomExcitation ex(test::gevs_on_ia(), 16000, 7);
  const PlantConfig cfg = gevs_plant();
  const Accelerometer rest(cfg, kTilted);
  const Accelerometer::Linear lin = rest.linearise();
  const std::vector<double> x_eq = rest.equilibrium();
  rectification::DiscretisedRandomPlant d(rest, lin, x_eq, ex, 20000);
  double worst = 0;
  for (int m = 0; m < 30000; ++m) {
    if (m > 0) d.advance();
    worst = std::max(worst, (d.input_g() - ex.acceleration_g(d.time_s())).cwiseAbs().maxCoeff());
  }
  EXPECT_LT(worst, 1e-10);
}

TEST(ExponentialIntegrator, LinearPlantOutputEqualsCvodeSampleBySample) {
  // A linear plant (K1 only): the discretisation is exact for the spline input, so the
  // output sample by sample differs from CVODE at rtol 1e-12 by CVODE's error only (the
  // output is ~14 g rms, peaks near 60 g; CVODE at rtol 1e-10 is 4.3e-7 g away, at 1e-12
  // 8.5e-9 g: it converges on the discretisation).
  const vibration::RandomExcitation ex(test::gevs_on_ia(), 16000, 3);
  const PlantConfig cfg = test::paper_like_linear_plant();
  std::vector<double> a, b;
  const auto ra = run(cfg, ex, 0.1, 20000, true, 1e-10, [&](double t, const Vec3&, double u) {
    if (t >= 0) a.push_back(u);
  });
  const auto rb = run(cfg, ex, 0.1, 20000, false, 1e-12, [&](double t, const Vec3&, double u) {
    if (t >= 0) b.push_back(u);
  });
  EXPECT_EQ(ra.path, "exponential integrator");
  EXPECT_EQ(rb.path, "CVODE: exponential_integrator off");
  ASSERT_EQ(a.size(), b.size());
  double worst = 0, size = 0;
  for (std::size_t i = 0; i < a.size(); ++i) {
    worst = std::max(worst, std::abs(a[i] - b[i]));
    size = std::max(size, std::abs(b[i]));
  }
  EXPECT_GT(size, 10.0);
  EXPECT_LT(worst / cfg.coefficients[K1], 3e-8);  // measured 8.5e-9
  EXPECT_LT(std::abs(ra.measured_g), 1e-9);  // output minus its own linearisation: nothing
}

TEST(ExponentialIntegratorCampaign, GevsRectificationAgreesWithCvodeFarInsideItsSigma) {
  // The shipped GEVS instrument, 1 s, 14 g rms: the rectification is ~22 mg, its statistical
  // sigma ~1.3 mg. Against CVODE at rtol 1e-8 (itself within ~1e-9 g of rtol 1e-10) the
  // exponential integrator is within 5e-8 g sampled at 20 kHz and 9e-8 g continuous (the
  // block edges between grid points by Hermite interpolation), measured; the bounds leave a
  // factor 5 and are 4e-4 sigma. CVODE at the case's own rtol 1e-4 is 1e-5 g off.
  const vibration::RandomExcitation ex(test::gevs_on_ia(), 16000, 1);
  const PlantConfig cfg = gevs_plant();
  for (double rate : {20000.0, 0.0}) {
    const auto e = run(cfg, ex, 1.0, rate, true, 1e-4);
    const auto c = run(cfg, ex, 1.0, rate, false, 1e-8);
    EXPECT_EQ(e.path, "exponential integrator");
    EXPECT_GT(e.measured_g, 0.015);
    EXPECT_NEAR(e.sigma_g, c.sigma_g, 0.01 * c.sigma_g);
    EXPECT_NEAR(e.measured_g, c.measured_g, 5e-7) << rate << " Hz";
    EXPECT_LT(std::abs(e.measured_g - c.measured_g), 1e-3 * c.sigma_g);
  }
}

TEST(ExponentialIntegrator, SmoothEffectsWithStatesAgreeWithCvode) {
  // Pendulum geometry (vibropendulous: GEVS on IA and PA, common phases) and a mechanical
  // mode at 3 kHz (6 more states: the general kernel): measured 4e-8 g apart on a ~19 mg
  // answer whose sigma is 1.7 mg; bound 1e-4 sigma.
  vibration::RandomProfile p = test::gevs_on_ia();
  p.psd[PA] = p.psd[IA];
  const vibration::RandomExcitation ex(p, 16000, 5);
  PlantConfig cfg = gevs_plant();
  cfg.effects.push_back(std::make_shared<PendulumGeometry>());
  cfg.effects.push_back(std::make_shared<MechanicalMode>(3000.0, 0.05, Vec3(1, 1, 0)));
  const auto e = run(cfg, ex, 0.5, 20000, true, 1e-4);
  const auto c = run(cfg, ex, 0.5, 20000, false, 1e-8);
  EXPECT_EQ(e.path, "exponential integrator");
  EXPECT_LT(std::abs(e.measured_g - c.measured_g), 1e-4 * c.sigma_g) << e.measured_g << " " << c.measured_g;
}

TEST(ExponentialIntegrator, NonSmoothEffectsAndSlowReadoutsRunCvodeAndSaySo) {
  const vibration::RandomExcitation ex(test::gevs_on_ia(), 16000, 2);
  PlantConfig cfg = gevs_plant();
  EXPECT_EQ(run(cfg, ex, 0.05, 5000, true, 1e-4).path, "CVODE: the output is sampled below the excitation's sample rate");
  EXPECT_EQ(run(cfg, ex, 0.05, 17000 * std::sqrt(2.0), true, 1e-4).path,
            "CVODE: the output's sample rate is not a small rational multiple of the excitation's");
  PlantConfig pickoff = cfg;
  pickoff.effects.push_back(std::make_shared<PickoffNonlinearity>(20.0));
  EXPECT_EQ(run(pickoff, ex, 0.05, 20000, true, 1e-4).path.rfind("CVODE: pickoff_nonlinearity is not verified", 0), 0u);
  cfg.effects.push_back(std::make_shared<CurrentSaturation>(30.0));
  const auto r = run(cfg, ex, 0.05, 20000, true, 1e-4);
  EXPECT_EQ(r.path.rfind("CVODE: current_saturation is not smooth", 0), 0u) << r.path;
}

}  // namespace test_shake_discretised
