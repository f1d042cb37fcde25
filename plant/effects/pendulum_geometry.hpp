#pragma once
// plant/effects/pendulum_geometry.hpp -- the input axis turns with the pendulum.
#include "plant/effects/effect.hpp"

namespace vrelab::plant {

// Pendulum geometry: the input axis turns with the pendulum, so the drive is
// a_IA cos(theta) - a_PA sin(theta) instead of a_IA. The a_PA sin(theta) part is the
// vibropendulous coupling: under vibration along IA and PA it rectifies as
// -<a_PA theta>, zero statically (theta = 0 at rest with the integrator).
class PendulumGeometry final : public Effect {
 public:
  std::string name() const override { return "pendulum_geometry"; }
  double extra_input_g(double theta, double, double s1, const Vec3& a) const override;
  bool vibropendulous() const override { return true; }
};

}  // namespace vrelab::plant
