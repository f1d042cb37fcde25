#pragma once
// plant/effects/output_polynomial.hpp -- a polynomial on the readout.
#include <array>
#include <string>

#include "plant/effects/effect.hpp"

namespace vrelab::plant {

// A polynomial on the readout: U/K1 = u -> u + sum_n c_n u^n, n = 2..6 (u in g, c_n in
// 1/g^(n-1)). One mechanism for two effects of the diagnosis' library: the instrument's
// terms of higher order than model (1) identifies (k5 u^5, k6 u^6: they act at rest too, and
// in the loop they would rectify alike, the averaged torque balance making loop and output
// equivalent), and the nonlinearity of the data acquisition that records the shaker runs
// (q2 u^2; a lab reads its static test with another instrument). The prediction averages it
// over the output's oscillation.
class OutputPolynomial final : public Effect {
 public:
  OutputPolynomial(std::string name, const std::array<double, 7>& c);  // c[n] multiplies u^n; c[0], c[1] must be 0
  std::string name() const override { return name_; }
  double readout(double u) const override;
  const std::array<double, 7>& coefficients() const { return c_; }
  bool readout_averaged_in_prediction() const override { return true; }

 private:
  std::string name_;
  std::array<double, 7> c_;
};

}  // namespace vrelab::plant
