// The shaker moves transversely, on the next sensor axis, growing with frequency.
#include "validation/diagnosis/effects/common.hpp"

namespace vrelab::validation {

Effect effect_shaker_transverse_motion() {
  Effect e;
  e.name = "shaker_transverse_motion";
  e.rank = 8;
  e.acts_on = ActsOn::table_motion;
  e.physics = "the shaker moves transversely, in phase, by ratio x (f / 1 kHz) of the commanded amplitude, on the "
              "next sensor axis (IA -> PA -> OA -> IA): the cross terms and the other axis's quadratic terms "
              "rectify, growing with frequency";
  EffectParameter p("ratio_at_1kHz", "1");
  p.example = 0.05;
  p.grid = {-0.2, -0.15, -0.1, -0.07, -0.05, -0.03, -0.02, -0.01, -0.005, 0, 0.005, 0.01, 0.02, 0.03, 0.05, 0.07, 0.1, 0.15, 0.2};
  e.parameters = {p};
  e.hypothesis = [](ParameterValues v, plant::PlantConfig&, TableMotion& m) {
    if (v[0] == 0) return;
    const double r = v[0] * m.sine.frequency_Hz / 1000;
    const Vec3 a = effects::signed_in_phase(m.sine);
    effects::set_in_phase(m.sine, a + r * Vec3(a[2], a[0], a[1]));
  };
  // The table's sine: each axis's motion, in phase, also on the next axis (phasors, any phase).
  e.truth = [](ParameterValues v, VirtualLab& lab) {
    if (v[0] == 0) return;
    const double ratio = v[0] * lab.table.frequency_Hz / 1000;
    const Eigen::Vector3cd w = effects::phasors(lab.table);
    Eigen::Vector3cd moved = w;
    for (int from = 0; from < 3; ++from) moved[(from + 1) % 3] += ratio * w[from];
    effects::set_phasors(lab.table, moved);
  };
  e.draw = [](std::mt19937_64& rng) {
    const double s = effects::random_sign(rng);
    return std::vector<double>{s * effects::log_uniform(rng, 0.02, 0.1)};
  };
  return e;
}

}  // namespace vrelab::validation
