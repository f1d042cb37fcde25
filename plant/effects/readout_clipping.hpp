#pragma once
// plant/effects/readout_clipping.hpp -- the data acquisition's range.
#include "plant/effects/effect.hpp"

namespace vrelab::plant {

// The data acquisition's range: the readout clips at +-full_scale_g (in g of input). A DAQ
// set too close to a run's peak output clips one side more than the other when the sensor
// has a static a_IA, and the mean shifts (the virtual lab's effect outside the diagnosis'
// library: a lab sees it in the raw record). The prediction does not model it (its readout
// is not averaged there).
class ReadoutClipping final : public Effect {
 public:
  explicit ReadoutClipping(double full_scale_g);
  std::string name() const override { return "readout_clipping"; }
  double readout(double u) const override;

 private:
  double full_scale_g_;
};

}  // namespace vrelab::plant
