#include "plant/effects/pendulum_geometry.hpp"

#include <cmath>

namespace vrelab::plant {

double PendulumGeometry::extra_input_g(double theta, double, double s1, const Vec3& a) const {
  return s1 * (std::cos(theta) - 1) - a[PA] * std::sin(theta);
}

}  // namespace vrelab::plant
