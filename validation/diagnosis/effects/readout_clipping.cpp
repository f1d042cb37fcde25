// Outside the library: the shaker runs' DAQ clips at its full scale (plant::ReadoutClipping).
#include <memory>

#include "plant/effects/readout_clipping.hpp"
#include "validation/diagnosis/effects/common.hpp"

namespace vrelab::validation {

Effect effect_readout_clipping() {
  Effect e;
  e.name = "readout_clipping";
  e.rank = 101;
  e.in_library = false;
  e.acts_on = ActsOn::data_acquisition;
  e.shaker_runs_only = true;
  e.physics = "the data acquisition that records the shaker runs clips at its full scale: set too close to a run's "
              "peak output it clips one side more than the other when the sensor has a static a_IA, and the mean "
              "shifts; a lab sees it in the raw record (outside the diagnosis' library)";
  EffectParameter p("full_scale_g", "g");
  p.example = 4.5;
  p.nominal = INFINITY;
  e.parameters = {p};
  e.truth = [](ParameterValues v, VirtualLab& lab) { lab.run_acquisition.push_back(std::make_shared<plant::ReadoutClipping>(v[0])); };
  // The DAQ's full scale just below the 4 g IA runs' peak output (4.71 g).
  e.draw = [](std::mt19937_64& rng) {
    effects::random_sign(rng);
    return std::vector<double>{effects::log_uniform(rng, 4.2, 4.7)};
  };
  e.check = [name = e.name](ParameterValues v, std::string* why) {
    if (v[0] > 0) return true;
    if (why) *why = name + " is the DAQ's full scale in g, > 0, got " + std::to_string(v[0]);
    return false;
  };
  return e;
}

}  // namespace vrelab::validation
