// mounting_misalignment on a random run: its hypothesis turns the random part's motion
// (TableMotion::random_turn, S' = R S R^T) as it turns a sine's, and the prediction of the
// turned run is what the ODE measures on the same motion made another way: the profile along
// the turned direction u = R e_IA built by hand (tables u_i^2 G, common phases), through the
// virtual shaker. The instrument rectifies only through its cross-axis terms (k_IP, k_IO,
// k_PO), so the unturned run along IA rectifies nothing and the turned one
// sigma^2 (k_IP u_IA u_PA + k_IO u_IA u_OA + k_PO u_PA u_OA) through the loop: ~14 ug here,
// against an ODE sigma of ~0.3 ug (a 20 s record of a 480 Hz band), so the check has teeth.
// Tolerance: 3 sigma of the ODE plus 1 % (the frequency-dependent prediction's own error for
// a Gaussian input through the loop: docs/frequency.md). 0.1 s in Release, 12 s under the
// sanitizers (the ODE at -O0): label campaign; the hypothesis check beside it stays fast.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <cstdio>

#include "rectification/simulation/shake.hpp"
#include "support/instrument.hpp"
#include "support/vibrations.hpp"
#include "validation/diagnosis/diagnose.hpp"
#include "validation/diagnosis/effect.hpp"
#include "vibration/random.hpp"
#include "vibration/sampled.hpp"

namespace test_misalignment_random {

using namespace vrelab;
using namespace vrelab::validation;

namespace {

plant::PlantConfig cross_terms_only() {
  plant::PlantConfig p = test::paper_like_linear_plant();
  const plant::Coefficients c = test::paper_like_coefficients();
  for (int i : {plant::k_IP, plant::k_IO, plant::k_PO}) p.coefficients[i] = c[i];
  return p;
}

}  // namespace

TEST(MisalignmentRandom, TheHypothesisTurnsTheRandomPartAndLeavesItAtZero) {
  const Effect& e = *find_effect("mounting_misalignment");
  TableMotion m;
  plant::PlantConfig cfg;
  const std::vector<double> none{0.0, 0.0}, turn{0.1, -0.05};
  e.apply(none, cfg, m);
  EXPECT_TRUE(m.random_turn.isIdentity(0.0));
  e.apply(turn, cfg, m);
  const Eigen::Matrix3d expected =
      (Eigen::AngleAxisd(-0.05, Vec3::UnitY()) * Eigen::AngleAxisd(0.1, Vec3::UnitZ())).toRotationMatrix();
  EXPECT_LT((m.random_turn - expected).cwiseAbs().maxCoeff(), 1e-15);
}

TEST(MisalignmentRandomCampaign, ARandomRunsTurnIsWhatTheOdeMeasuresOnTheTurnedMotion) {
  const double level = 0.05;  // g^2/Hz over 20-500 Hz: 4.9 g rms
  vibration::RandomProfile ia;
  ia.psd[IA] = test::flat_psd(20, 500, level);
  const plant::PlantConfig cfg = cross_terms_only();
  RunRecord r;
  r.id = "random-ia";
  r.random = ia;
  r.sine_part = false;
  r.frequency_Hz = 260, r.amplitude_g = std::sqrt(2 * level * 480), r.direction = Vec3::UnitX();
  r.orientation_g = Vec3(1, 0, 1).normalized();
  r.sigma_g = 1e-6;
  const std::vector<double> angles{0.1, -0.05};  // about OA, about PA (rad)
  const Effect& e = *find_effect("mounting_misalignment");
  const double unturned = predict_run_g(cfg, r), predicted = predict_run_g(cfg, r, e, angles);

  const Eigen::Matrix3d turn =
      (Eigen::AngleAxisd(angles[1], Vec3::UnitY()) * Eigen::AngleAxisd(angles[0], Vec3::UnitZ())).toRotationMatrix();
  const Vec3 u = turn.col(IA);
  ASSERT_GT(u.minCoeff(), 0.0);  // the hand-built profile needs every component >= 0
  vibration::RandomProfile along;
  for (int i = 0; i < 3; ++i) along.psd[static_cast<std::size_t>(i)] = test::flat_psd(20, 500, level * u[i] * u[i]);
  along.coupling = vibration::AxisCoupling::common;
  const vibration::RandomExcitation motion(along, 4000, 17);
  rectification::ShakeSettings s;
  s.blocks = 16;
  const rectification::ShakeResult ode = rectification::shake_excitation(cfg, r.orientation_g, motion, 20.0, s);
  std::printf("  unturned %.4f ug; turned: predicted %.4f ug, ODE %.4f +- %.4f ug\n", unturned * 1e6, predicted * 1e6,
              ode.measured_g * 1e6, ode.sigma_g * 1e6);
  EXPECT_LT(std::abs(unturned), 1e-9);  // along IA the cross terms see nothing
  ASSERT_GT(std::abs(predicted), 10 * ode.sigma_g);
  EXPECT_NEAR(ode.measured_g, predicted, 3 * ode.sigma_g + 0.01 * std::abs(predicted));
}

}  // namespace test_misalignment_random
