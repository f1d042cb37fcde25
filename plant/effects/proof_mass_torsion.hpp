#pragma once
// plant/effects/proof_mass_torsion.hpp -- the proof mass twists about its pendulous axis under
// a cross-axis (OA) acceleration and turns its input axis toward OA. Header-only (no build file
// to touch): the virtual lab's out-of-library truth module.
#include <cmath>
#include <stdexcept>

#include "plant/effects/effect.hpp"

namespace vrelab::plant {

// Proof-mass torsion (a second, passive degree of freedom of the pendulum). The proof mass's
// centre of mass lies off the hinge's plane along IA, so an acceleration along OA twists the
// flexure about PA; the torsion psi (rad) is a lightly damped mode of its own:
//   psi'' = -2 zeta_t w_t psi' - w_t^2 (psi - kappa a_OA),   kappa: the static twist, rad/g,
// and the input axis turns with it: the pendulum feels a_IA cos psi + a_OA sin psi along IA.
// At rest psi = kappa a_OA: a static term kappa a_OA^2 that a 1 g static test takes as k_OO
// (or spreads over k0, k2, k_PP: quadratic_cross_axis' give-back). Under an OA sine of
// amplitude A the twist follows through H(w) = 1 / (1 - (w / w_t)^2 + 2 j zeta_t w / w_t) and the
// mean of psi a_OA is kappa (a_OA0^2 + Re H A^2 / 2): against the static k_OO the gap is
// kappa A^2 / 2 (Re H - 1), which changes sign across the torsion mode (a dispersive resonance
// along OA alone; |H|^2 of a base mode, the library's `mechanical_mode`, does not) and
// vanishes at low frequency. A linear 2-state oscillator: smooth, cheap for CVODE.
class ProofMassTorsion final : public Effect {
 public:
  ProofMassTorsion(double kappa_rad_per_g, double torsion_Hz = 600, double torsion_zeta = 0.05)
      : kappa_(kappa_rad_per_g), wt_(6.283185307179586 * torsion_Hz), zeta_(torsion_zeta) {
    if (!std::isfinite(kappa_)) throw std::invalid_argument("proof mass torsion kappa_rad_per_g must be finite");
    if (!(torsion_Hz > 0) || !std::isfinite(torsion_Hz)) throw std::invalid_argument("proof mass torsion torsion_Hz must be positive");
    if (!(zeta_ > 0)) throw std::invalid_argument("proof mass torsion torsion_zeta must be positive");
  }
  std::string name() const override { return "proof_mass_torsion"; }
  int num_states() const override { return 2; }
  double state_scale(int k) const override { return k == 0 ? std::abs(kappa_) + 1e-12 : (std::abs(kappa_) + 1e-12) * wt_; }
  void rest_state(const Vec3& a, double* s) const override { s[0] = kappa_ * a[OA], s[1] = 0; }
  Vec3 input(const Vec3& a, const double* s, double* ds) const override {
    ds[0] = s[1];
    ds[1] = -2 * zeta_ * wt_ * s[1] - wt_ * wt_ * (s[0] - kappa_ * a[OA]);
    Vec3 out = a;
    out[IA] = a[IA] * std::cos(s[0]) + a[OA] * std::sin(s[0]);
    return out;
  }

 private:
  double kappa_, wt_, zeta_;
};

}  // namespace vrelab::plant
