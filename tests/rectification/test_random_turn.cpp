// random_response's turn: a fixed linear map M of the case's motion (a fixture's turn, the
// diagnosis' mounting_misalignment on random runs), S'(f) = M S(f) M^T, against two answers
// it does not compute:
//  - the input's covariance is M C M^T, C the unturned response's (the same weights summed);
//  - a turn of a one-axis motion whose direction u = M e_IA has no negative component is the
//    profile with tables u_i^2 G on every axis and common phases (S_ij = u_i u_j G), built
//    by hand: the loop's covariances are the same to rounding.
// The identity is the profile as it is, to the bit.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>

#include "plant/accelerometer.hpp"
#include "rectification/prediction/frequency.hpp"
#include "rectification/prediction/random.hpp"
#include "support/instrument.hpp"
#include "support/vibrations.hpp"
#include "vibration/random.hpp"

namespace test_random_turn {

using namespace vrelab;

namespace {

rectification::RandomResponse response(const vibration::RandomProfile& p, const Eigen::Matrix3d& turn) {
  const plant::PlantConfig cfg = test::paper_like_plant();
  return rectification::random_response(p, [&cfg](double f) { return rectification::loop_response(cfg, f); }, {0.05, false},
                                        turn);
}

}  // namespace

TEST(RandomTurn, TheInputCovarianceIsTurnedAndTheIdentityChangesNothing) {
  vibration::RandomProfile p;
  p.psd[IA] = test::gevs_psd(1.0);
  p.psd[PA] = test::gevs_psd(0.5);
  p.coupling = vibration::AxisCoupling::independent;
  const Eigen::Matrix3d m =
      (Eigen::AngleAxisd(-0.07, Vec3::UnitY()) * Eigen::AngleAxisd(0.12, Vec3::UnitZ())).toRotationMatrix();
  const rectification::RandomResponse plain = response(p, Eigen::Matrix3d::Identity());
  const rectification::RandomResponse turned = response(p, m);
  const rectification::RandomResponse none = rectification::random_response(
      p, [](double f) { return rectification::loop_response(test::paper_like_plant(), f); }, {0.05, false});
  EXPECT_EQ(plain.covariance, none.covariance);  // the default turn: the same numbers
  const Eigen::Matrix3d expected = m * plain.input_covariance_g2 * m.transpose();
  // A sum of ~10^3 terms of 0.1-10 g^2: rounding ~1e-13 of the largest.
  EXPECT_LT((turned.input_covariance_g2 - expected).cwiseAbs().maxCoeff(), 1e-12 * expected.cwiseAbs().maxCoeff())
      << turned.input_covariance_g2 << "\n" << expected;
  // The turn moves a part of the motion onto OA, where the unturned profile has none.
  EXPECT_GT(turned.input_covariance_g2(OA, OA), 1e-3 * expected(IA, IA));
}

TEST(RandomTurn, AOneAxisMotionTurnedIsTheHandBuiltProfileAlongItsNewDirection) {
  vibration::RandomProfile ia;
  ia.psd[IA] = test::gevs_psd(1.0);
  // About OA by +0.1 rad, then about PA by -0.05 rad: u = (0.993, 0.0998, 0.0497) > 0.
  const Eigen::Matrix3d m =
      (Eigen::AngleAxisd(-0.05, Vec3::UnitY()) * Eigen::AngleAxisd(0.1, Vec3::UnitZ())).toRotationMatrix();
  const Vec3 u = m.col(IA);
  ASSERT_GT(u.minCoeff(), 0.0);
  vibration::RandomProfile along;  // the same motion along u, by the tables
  for (int i = 0; i < 3; ++i) along.psd[static_cast<std::size_t>(i)] = test::gevs_psd(u[i] * u[i]);
  along.coupling = vibration::AxisCoupling::common;
  const rectification::RandomResponse turned = response(ia, m), by_hand = response(along, Eigen::Matrix3d::Identity());
  ASSERT_EQ(turned.frequencies, by_hand.frequencies);
  // Each S_ij is u_i u_j G either way (sqrt(u_i^2 G u_j^2 G) by hand): equal to a few ulp.
  const double scale = by_hand.covariance.cwiseAbs().maxCoeff();
  EXPECT_LT((turned.covariance - by_hand.covariance).cwiseAbs().maxCoeff(), 1e-12 * scale) << turned.covariance << "\n"
                                                                                               << by_hand.covariance;
  // The cross terms the turn makes are there (felt IA x PA), not a zero compared with a zero.
  EXPECT_GT(std::abs(turned.covariance(0, 1)), 0.05 * turned.covariance(0, 0));
}

}  // namespace test_random_turn
