#include "plant/effects/current_saturation.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace vrelab::plant {

CurrentSaturation::CurrentSaturation(double limit_g) : limit_g_(limit_g) {
  if (!(limit_g > 0) || !std::isfinite(limit_g)) throw std::invalid_argument("saturation limit_g must be positive");
}

double CurrentSaturation::current(double i) const { return std::clamp(i, -limit_g_, limit_g_); }

}  // namespace vrelab::plant
