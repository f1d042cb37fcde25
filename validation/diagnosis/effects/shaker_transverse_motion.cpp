// The shaker moves transversely, on the next sensor axis, growing with frequency; in its
// natural form on the other transverse axis, at any phase and with any power of frequency.
#include "validation/diagnosis/effects/common.hpp"

namespace vrelab::validation {

Effect effect_shaker_transverse_motion() {
  Effect e;
  e.name = "shaker_transverse_motion";
  e.rank = 8;
  e.acts_on = ActsOn::table_motion;
  e.physics = "the shaker moves transversely, in phase, by ratio x (f / 1 kHz) of the commanded amplitude, on the "
              "next sensor axis (IA -> PA -> OA -> IA): the cross terms and the other axis's quadratic terms "
              "rectify, growing with frequency (natural form: a part in quadrature, as (f / 1 kHz)^power, on the "
              "other transverse axis, IA -> OA -> PA -> IA)";
  EffectParameter p("ratio_at_1kHz", "1");
  p.example = 0.05;
  p.grid = {-0.2, -0.15, -0.1, -0.07, -0.05, -0.03, -0.02, -0.01, -0.005, 0, 0.005, 0.01, 0.02, 0.03, 0.05, 0.07, 0.1, 0.15, 0.2};
  // The natural form. The transverse motion's part in quadrature with the commanded motion
  // (ratio at 1 kHz; the first parameter is the part in phase): r e^{j phi} = ratio + j
  // quadrature. In this form the phase has no sign ambiguity (-r at phi + pi is r at phi) and,
  // where the data see only the cross terms (which take the in-phase part), the in-phase ratio
  // is still what they measure with the quadrature held at 0. Its sign is not identifiable:
  // every run the hypothesis is applied to moves the table along a real direction (the axes in
  // phase) and only IA drives the pendulum, so the loop-placed terms see |H_IA W'_IA|^2 and
  // the input-placed ones Re(W'_a conj W'_b), where the quadrature enters as its square (the
  // prediction at -q equals that at +q to rounding; a mode that turns one axis's phase against
  // another's would tell them apart, but a fit of this effect alone has none). The fit takes
  // its magnitude, 0 .. 0.3; the truth hook acts with either sign. Starts at 0 and 0.05 (at 0 the
  // quadratic terms, the only ones to see it, have no slope); a weak prior (0.1).
  EffectParameter ph("quadrature_ratio_at_1kHz", "1");
  ph.nominal = 0, ph.lower = 0, ph.upper = 0.3, ph.example = 0.03;
  ph.starts = {0, 0.05}, ph.prior_sigma = 0.1, ph.step = 1e-4;
  ph.sign_identifiable = false;
  // Its frequency law: ratio x (f / 1 kHz)^power (nominal 1), continuous.
  EffectParameter pw("frequency_power", "1");
  pw.nominal = 1, pw.lower = 0, pw.upper = 3, pw.example = 2, pw.prior_sigma = 0.75, pw.step = 2e-3;
  pw.starts = {1, 0};
  // The transverse axis: 0 the next (IA -> PA -> OA -> IA, nominal), 1 the other (IA -> OA -> PA -> IA).
  EffectParameter cy("axis_cycle", "0 next, 1 other");
  cy.nominal = 0, cy.lower = 0, cy.upper = 1, cy.example = 1;
  cy.discrete = true, cy.starts = {0, 1};
  e.parameters = {p, ph, pw, cy};
  e.hypothesis = [](ParameterValues v, plant::PlantConfig&, TableMotion& m) {
    if (v[0] == 0 && v[1] == 0) return;
    const double f = m.sine.frequency_Hz / 1000;
    if (v[1] == 0 && v[2] == 1 && v[3] == 0) {  // the default form: in-phase amplitudes
      const double r = v[0] * f;
      const Vec3 a = effects::signed_in_phase(m.sine);
      effects::set_in_phase(m.sine, a + r * Vec3(a[2], a[0], a[1]));
      return;
    }
    const std::complex<double> r = std::complex<double>(v[0], v[1]) * std::pow(f, v[2]);
    const Eigen::Vector3cd w = effects::phasors(m.sine);
    const Eigen::Vector3cd moved = v[3] == 0 ? Eigen::Vector3cd(w[2], w[0], w[1]) : Eigen::Vector3cd(w[1], w[2], w[0]);
    effects::set_phasors(m.sine, w + r * moved);
  };
  // The table's sine: each axis's motion, at the phase, also on the transverse axis (phasors).
  e.truth = [](ParameterValues v, VirtualLab& lab) {
    if (v[0] == 0 && v[1] == 0) return;
    const double scale = std::pow(lab.table.frequency_Hz / 1000, v[2]);
    const double magnitude = std::hypot(v[0], v[1]), phase = std::atan2(v[1], v[0]);  // r e^{j phi}
    const int step = v[3] == 0 ? 1 : 2;
    const Eigen::Vector3cd w = effects::phasors(lab.table);
    Eigen::Vector3cd moved = w;
    for (int from = 0; from < 3; ++from) moved[(from + step) % 3] += std::polar(magnitude * scale, phase) * w[from];
    effects::set_phasors(lab.table, moved);
  };
  e.draw = [](std::mt19937_64& rng) {
    const double s = effects::random_sign(rng);
    return std::vector<double>{s * effects::log_uniform(rng, 0.02, 0.1)};
  };
  // The natural form: a quadrature part 0.01-0.05 either sign (beside the in-phase 0.02-0.1 of
  // `draw`: a phase of 6-68 deg), a power 0.5-2, either transverse axis.
  e.draw_form = [](std::mt19937_64& rng) {
    const double s = effects::random_sign(rng);
    const double quadrature = s * effects::log_uniform(rng, 0.01, 0.05);
    const double power = std::uniform_real_distribution<double>(0.5, 2)(rng);
    return std::vector<double>{quadrature, power, effects::coin(rng) ? 1.0 : 0.0};
  };
  e.check = [name = e.name](ParameterValues v, std::string* why) {
    if (!(v[2] >= 0 && v[2] <= 3)) {
      if (why) *why = name + ": frequency_power is in [0, 3], got " + std::to_string(v[2]);
      return false;
    }
    if (v[3] != 0 && v[3] != 1) {
      if (why) *why = name + ": axis_cycle is 0 (the next axis) or 1 (the other), got " + std::to_string(v[3]);
      return false;
    }
    return true;
  };
  return e;
}

}  // namespace vrelab::validation
