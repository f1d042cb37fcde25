#pragma once
// plant/effects/current_saturation.hpp -- the torquer current clips.
#include "plant/effects/effect.hpp"

namespace vrelab::plant {

// Current saturation: the torquer current (in g of rebalance) clips at +-limit_g.
class CurrentSaturation final : public Effect {
 public:
  explicit CurrentSaturation(double limit_g);
  std::string name() const override { return "current_saturation"; }
  double current(double i) const override;

 private:
  double limit_g_;
};

}  // namespace vrelab::plant
