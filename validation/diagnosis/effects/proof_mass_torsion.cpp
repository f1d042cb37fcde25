// Outside the library: the proof mass twists about PA under an OA acceleration
// (plant::ProofMassTorsion).
#include <memory>

#include "plant/effects/proof_mass_torsion.hpp"
#include "validation/diagnosis/effects/common.hpp"

namespace vrelab::validation {

Effect effect_proof_mass_torsion() {
  Effect e;
  e.name = "proof_mass_torsion";
  e.rank = 105;
  e.in_library = false;
  e.acts_on = ActsOn::instrument;
  e.physics = "the proof mass's centre lies off the hinge's plane, so an OA acceleration twists the flexure about PA "
              "(a 600 Hz torsion mode) and turns the input axis toward OA: statically a k_OO term, under an OA "
              "vibration kappa A^2 Re H / 2 with H the torsion's response, a dispersive resonance along OA alone "
              "(outside the diagnosis' library)";
  EffectParameter p("kappa_rad_per_g", "rad/g");
  p.example = 2e-6;
  p.nominal = 0;
  e.parameters = {p};
  e.truth = [](ParameterValues v, VirtualLab& lab) {
    if (v[0] != 0) lab.instrument.effects.push_back(std::make_shared<plant::ProofMassTorsion>(v[0]));
  };
  // 0.5-3 urad/g either sign: at 4 g along OA, kappa * 8 g^2 * (Re H - 1) is -2.25 kappa*8 at
  // 800 Hz: 9-54 ug, i.e. 18-110 sigma of a run.
  e.draw = [](std::mt19937_64& rng) {
    const double s = effects::random_sign(rng);
    return std::vector<double>{s * effects::log_uniform(rng, 0.5e-6, 3e-6)};
  };
  return e;
}

}  // namespace vrelab::validation
