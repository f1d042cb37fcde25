// random_response in steps (rectification/prediction/random.hpp: random_grid, turned_grid,
// random_response of a grid and its responses), as the diagnosis takes it, against the
// covariance integral written out independently: C = sum_k w_k Re(H_k S_k H_k^H) with the
// 5 x 3 matrix H_k of each point's loop response (Eigen's dense products, no structure used),
// S_k the profile's cross-spectral density turned by M (M S M^T), the points as the quadrature
// lays them out. A random motion along IA alone, along all three axes with common phases, and
// the latter turned by a fixture's small rotation (every entry of S nonzero), behind a plant
// with a mode on IA and PA. The sums are the same numbers in another order: 1e-13 relative.
#include <gtest/gtest.h>

#include <cmath>
#include <complex>
#include <memory>
#include <string>
#include <vector>

#include <Eigen/Dense>
#include <Eigen/Geometry>

#include "plant/effects/effects.hpp"
#include "rectification/prediction/frequency.hpp"
#include "rectification/prediction/random.hpp"
#include "support/instrument.hpp"
#include "support/vibrations.hpp"
#include "vibration/random.hpp"

namespace test_random_grid {

using namespace vrelab;

TEST(RandomGrid, TheCovariancesOfAGridAreTheIntegralWrittenOut) {
  plant::PlantConfig cfg = test::paper_like_linear_plant();
  cfg.effects.push_back(std::make_shared<plant::MechanicalMode>(900.0, 0.03, Vec3(1, 1, 0)));
  const rectification::LoopResponder responder(cfg);
  vibration::RandomProfile along_ia;
  along_ia.psd[0] = test::flat_psd(20, 2000, 0.04);
  vibration::RandomProfile three = along_ia;
  three.psd[1] = test::flat_psd(50, 1500, 0.01);
  three.psd[2] = test::flat_psd(20, 800, 0.02);
  three.coupling = vibration::AxisCoupling::common;
  const Eigen::Matrix3d identity = Eigen::Matrix3d::Identity();
  const Eigen::Matrix3d turn = Eigen::AngleAxisd(0.03, Eigen::Vector3d(0.2, 1, -0.4).normalized()).toRotationMatrix();
  const struct {
    std::string name;
    const vibration::RandomProfile* profile;
    const Eigen::Matrix3d* turn;
  } cases[] = {{"along IA", &along_ia, &identity}, {"three axes", &three, &identity}, {"three axes turned", &three, &turn}};
  const rectification::RandomQuadrature q{0.1, true};
  for (const auto& c : cases) {
    const rectification::RandomGrid grid = rectification::turned_grid(rectification::random_grid(*c.profile, q), *c.turn);
    std::vector<rectification::LoopResponse> responses;
    std::vector<const rectification::LoopResponse*> pointers;
    for (double f : grid.frequency_Hz) responses.push_back(responder(f));
    for (const auto& r : responses) pointers.push_back(&r);
    const rectification::RandomResponse got = rectification::random_response(grid, pointers);

    Eigen::Matrix<double, 5, 5> want = Eigen::Matrix<double, 5, 5>::Zero();
    Eigen::Matrix3d input = Eigen::Matrix3d::Zero();
    for (std::size_t k = 0; k < grid.frequency_Hz.size(); ++k) {
      const rectification::LoopResponse& r = responses[k];
      Eigen::Matrix<std::complex<double>, 5, 3> h = Eigen::Matrix<std::complex<double>, 5, 3>::Zero();
      for (int j = 0; j < 3; ++j) {
        const auto sj = static_cast<std::size_t>(j);
        h(j, j) = r.mechanical[sj], h(3, j) = r.current[sj], h(4, j) = r.angle_rad[sj];
      }
      // The density from the profile's own function, turned here.
      const Eigen::Matrix3cd s = *c.turn * rectification::cross_spectral_matrix_g2_per_Hz(*c.profile, grid.frequency_Hz[k]) *
                                 c.turn->transpose();
      want += grid.weight_Hz[k] * (h * s * h.adjoint()).real();
      input += grid.weight_Hz[k] * s.real();
    }
    ASSERT_GT(grid.frequency_Hz.size(), 300u) << c.name;
    EXPECT_EQ(got.frequencies, static_cast<int>(grid.frequency_Hz.size())) << c.name;
    const double scale = want.cwiseAbs().maxCoeff();
    for (int a = 0; a < 5; ++a)
      for (int b = 0; b < 5; ++b)
        EXPECT_NEAR(got.covariance(a, b), want(a, b), 1e-13 * scale) << c.name << " (" << a << ", " << b << ")";
    EXPECT_LE((got.input_covariance_g2 - input).cwiseAbs().maxCoeff(), 1e-13 * input.cwiseAbs().maxCoeff()) << c.name;
    // The grid's input covariance is the profile's rms^2: 0.04 g^2/Hz over 1980 Hz along IA.
    if (c.profile == &along_ia) {
      EXPECT_NEAR(got.input_covariance_g2(0, 0), 0.04 * 1980, 1e-9 * 79.2);
    }
    // The one-step random_response of the same profile and turn: the same numbers.
    const rectification::RandomResponse direct = rectification::random_response(*c.profile, responder, q, *c.turn);
    EXPECT_EQ(direct.covariance, got.covariance) << c.name;
  }
}

}  // namespace test_random_grid
