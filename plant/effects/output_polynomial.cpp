#include "plant/effects/output_polynomial.hpp"

#include <cmath>
#include <stdexcept>
#include <utility>

namespace vrelab::plant {

OutputPolynomial::OutputPolynomial(std::string name, const std::array<double, 7>& c) : name_(std::move(name)), c_(c) {
  if (c[0] != 0 || c[1] != 0) throw std::invalid_argument(name_ + ": the readout polynomial starts at u^2");
  for (double x : c)
    if (!std::isfinite(x)) throw std::invalid_argument(name_ + ": readout coefficients must be finite");
}

double OutputPolynomial::readout(double u) const {
  double s = 0;  // Horner on c_6 u^6 + ... + c_2 u^2
  for (int n = 6; n >= 2; --n) s = (s + c_[static_cast<std::size_t>(n)]) * u;
  return u + s * u;
}

}  // namespace vrelab::plant
