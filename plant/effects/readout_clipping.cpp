#include "plant/effects/readout_clipping.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace vrelab::plant {

ReadoutClipping::ReadoutClipping(double full_scale_g) : full_scale_g_(full_scale_g) {
  if (!(full_scale_g > 0) || !std::isfinite(full_scale_g)) throw std::invalid_argument("readout clipping full_scale_g must be positive");
}

double ReadoutClipping::readout(double u) const { return std::clamp(u, -full_scale_g_, full_scale_g_); }

}  // namespace vrelab::plant
