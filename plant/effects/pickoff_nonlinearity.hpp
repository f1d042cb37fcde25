#pragma once
// plant/effects/pickoff_nonlinearity.hpp -- a quadratic pickoff.
#include "plant/effects/effect.hpp"

namespace vrelab::plant {

// Pickoff nonlinearity: the pickoff reads theta + p2 theta^2 (p2 in 1/rad). With the
// integrator the loop nulls the reading, so theta settles at 0 statically; under vibration
// <theta> = -p2 <theta^2> and the hinge stiffness turns it into an output shift.
class PickoffNonlinearity final : public Effect {
 public:
  explicit PickoffNonlinearity(double p2_per_rad);
  std::string name() const override { return "pickoff_nonlinearity"; }
  double pickoff(double theta) const override { return theta + p2_ * theta * theta; }
  double p2_per_rad() const { return p2_; }
  double pickoff_p2_per_rad() const override { return p2_; }

 private:
  double p2_;
};

}  // namespace vrelab::plant
