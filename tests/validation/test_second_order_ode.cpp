// The pickoff nonlinearity beyond first order under random motion (rectification/prediction/
// second_order.hpp): the shipped case cases/shake-second-order-navmat.toml (p2 = 40 /rad, a
// 620 Hz mode, k3 in the loop, 5.66 g rms of NAVMAT-shaped motion) through `predict
// --frequency-dependent` against its ODE (`shake`, 40 s in 16 blocks, sigma 64 ug). Seen:
// 8172.0 ug against 8153.9 ug (0.3 sigma); the first order's 8994.7 ug is 13 sigma off. Bar:
// 3 sigma and 2 % (the issue's), the first order beyond 6 sigma (so that the test can fail).
#include <gtest/gtest.h>

#include <cmath>

#include "io/formats/case_file.hpp"
#include "io/services/studies.hpp"

namespace test_second_order_ode {

using namespace vrelab;

TEST(SecondOrderOde, TheShippedNavmatCaseIsItsOde) {
  const io::Case c = io::read_case(std::string(VRELAB_CASES_DIR) + "/shake-second-order-navmat.toml");
  const io::PredictStudy p = io::predict(c, true);
  ASSERT_TRUE(p.at_frequency);
  const io::ShakeStudy s = io::shake(c, std::string());
  const double ode = s.result.measured_g, sigma = s.result.sigma_g, pred = p.at_frequency->total_g();
  EXPECT_LT(std::abs(pred - ode), 3 * sigma);
  EXPECT_LT(std::abs(pred - ode), 0.02 * std::abs(ode));
  EXPECT_GT(std::abs(pred - p.at_frequency->second_order_g - ode), 6 * sigma);
  EXPECT_FALSE(p.at_frequency->second_order_left_out);
  EXPECT_LT(p.at_frequency->second_order_error_g, 3 * sigma);
}

}  // namespace test_second_order_ode
