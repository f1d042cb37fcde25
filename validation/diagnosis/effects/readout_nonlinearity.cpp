// The shaker runs' data acquisition reads u + q2 u^2 (plant::OutputPolynomial on the readout).
#include <array>
#include <memory>

#include "plant/effects/output_polynomial.hpp"
#include "validation/diagnosis/effects/common.hpp"

namespace vrelab::validation {

Effect effect_readout_nonlinearity() {
  Effect e;
  e.name = "readout_nonlinearity";
  e.rank = 11;
  e.acts_on = ActsOn::data_acquisition;
  e.shaker_runs_only = true;
  e.physics = "the data acquisition that records the shaker runs reads u + q2 u^2 (integral nonlinearity of its "
              "ADC or amplifier, in g of input); the static test, read with another instrument, does not see "
              "it. It rectifies q2 |U|^2 / 2: the shape of a loop-placed k2 error, along IA only";
  EffectParameter p("q2", "1/g");
  p.example = 2e-6;
  p.linear = true, p.unit_value = 1e-6;
  e.parameters = {p};
  e.hypothesis = [name = e.name](ParameterValues v, plant::PlantConfig& c, TableMotion&) {
    if (v[0] != 0)
      c.effects.push_back(
          std::make_shared<plant::OutputPolynomial>(name, std::array<double, 7>{0, 0, v[0], 0, 0, 0, 0}));
  };
  e.truth = [name = e.name](ParameterValues v, VirtualLab& lab) {
    if (v[0] != 0)
      lab.run_acquisition.push_back(
          std::make_shared<plant::OutputPolynomial>(name, std::array<double, 7>{0, 0, v[0], 0, 0, 0, 0}));
  };
  e.draw = [](std::mt19937_64& rng) {
    const double s = effects::random_sign(rng);
    return std::vector<double>{s * effects::log_uniform(rng, 1e-5, 4e-5)};
  };
  return e;
}

}  // namespace vrelab::validation
