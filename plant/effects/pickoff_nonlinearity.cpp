#include "plant/effects/pickoff_nonlinearity.hpp"

#include <cmath>
#include <stdexcept>

namespace vrelab::plant {

PickoffNonlinearity::PickoffNonlinearity(double p2) : p2_(p2) {
  if (!std::isfinite(p2)) throw std::invalid_argument("pickoff p2_per_rad must be finite");
}

}  // namespace vrelab::plant
