// Model (1): the output written out term by term, the asymmetric scale factor, and the
// gradient used by the first-order error budget.
#include <gtest/gtest.h>

#include <random>

#include "plant/model1.hpp"
#include "support/random_coefficients.hpp"

namespace test_model1 {

using namespace vrelab;
using namespace vrelab::plant;

TEST(Model1, OutputEqualsTheEquationWrittenOutByHand) {
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> u(-3, 3);
  for (int n = 0; n < 200; ++n) {
    const Coefficients c = test::random_coefficients(rng);
    const double x = u(rng), y = u(rng), z = u(rng);
    const double sgn = x > 0 ? 1 : (x < 0 ? -1 : 0);
    const double expected =
        c[K1] * (c[k0] + (1 + c[k1_asym] / 2 * sgn) * x + c[k2] * x * x + c[k3] * x * x * x +
                 c[k4] * x * x * x * x + c[delta_OA] * y + c[delta_PA] * z + c[k_IP] * x * y +
                 c[k_IO] * x * z + c[k_PO] * y * z + c[k_PP] * y * y + c[k_OO] * z * z);
    // Same sum in another order: agreement to a few ulps of the largest term (|U| <~ 10).
    EXPECT_NEAR(output(c, Vec3(x, y, z)), expected, 1e-13);
    EXPECT_NEAR(output_g(c, Vec3(x, y, z)) * c[K1], expected, 1e-13);
  }
}

TEST(Model1, ScaleFactorIsK1TimesOnePlusOrMinusHalfAsymmetry) {
  Coefficients c;
  c[K1] = 1.3;
  c[k1_asym] = 4e-3;
  // Only K1 and k1' set: the slope between 0 and +1 g and between -1 g and 0.
  const double up = output(c, Vec3(1, 0, 0)) - output(c, Vec3(0, 0, 0));
  const double down = output(c, Vec3(0, 0, 0)) - output(c, Vec3(-1, 0, 0));
  EXPECT_NEAR(up, 1.3 * (1 + 2e-3), 1e-15);
  EXPECT_NEAR(down, 1.3 * (1 - 2e-3), 1e-15);
}

TEST(Model1, GradientMatchesCentralDifferences) {
  std::mt19937_64 rng(12);
  std::uniform_real_distribution<double> u(-2, 2);
  for (int n = 0; n < 100; ++n) {
    const Coefficients c = test::random_coefficients(rng);
    Vec3 a(u(rng), u(rng), u(rng));
    if (std::abs(a[IA]) < 0.01) a[IA] = 0.5;  // away from the kink of |a_IA|
    const Vec3 g = output_gradient(c, a);
    const double h = 1e-5;
    for (int k = 0; k < 3; ++k) {
      Vec3 up = a, down = a;
      up[k] += h;
      down[k] -= h;
      // Central difference of a quartic: truncation ~ h^2 * |U'''| ~ 1e-10 * 1e-2, rounding
      // ~ 1e-16 * |U| / h ~ 1e-11.
      EXPECT_NEAR(g[k], (output(c, up) - output(c, down)) / (2 * h), 1e-9);
    }
  }
}

TEST(Model1, NamesRoundTrip) {
  for (int i = 0; i < kNumCoefficients; ++i) EXPECT_EQ(*coefficient_from_name(coefficient_name(i)), i);
  EXPECT_FALSE(coefficient_from_name("k5").has_value());
}

}  // namespace test_model1
