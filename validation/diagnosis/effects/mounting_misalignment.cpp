// The shaker fixture holds the sensor turned about OA and about PA from where the static test held it.
#include <Eigen/Geometry>

#include "validation/diagnosis/effects/common.hpp"

namespace vrelab::validation {

namespace {
// The turn about OA by a, then about PA by b, as a matrix: R_PA(b) R_OA(a).
Eigen::Matrix3d turn_matrix(double a_rad, double b_rad) {
  return (Eigen::AngleAxisd(b_rad, Vec3::UnitY()) * Eigen::AngleAxisd(a_rad, Vec3::UnitZ())).toRotationMatrix();
}
}  // namespace

Effect effect_mounting_misalignment() {
  Effect e;
  e.name = "mounting_misalignment";
  e.rank = 12;
  e.acts_on = ActsOn::table_motion;
  e.physics = "the shaker fixture holds the sensor turned by small angles about OA and about PA from where the static "
              "test held it: a turn about OA puts angle x w of the IA motion on PA and -angle x w of the PA motion on "
              "IA, so k_IP rectifies angle k_IP (w_IA^2 - w_PA^2) / 2 and k2 sees angle^2 w_PA^2; a turn about PA does "
              "the same with OA (k_IO); flat in frequency where the terms are at the input, opposite in sign along "
              "the two axes the turn mixes";
  EffectParameter p("angle_about_OA_rad", "rad");
  p.example = 0.05;
  p.nominal = 0;
  p.grid = effects::symmetric_geometric(0.002, 0.2, 12);
  // The natural form: the turn about PA, continuous (LM from 0), its prior +-0.2 rad.
  EffectParameter b("angle_about_PA_rad", "rad");
  b.nominal = 0, b.lower = -0.2, b.upper = 0.2, b.example = 0.05, b.prior_sigma = 0.1, b.step = 1e-3;
  e.parameters = {p, b};
  // The in-phase amplitudes turned by hand: about OA by a, then about PA by b (R_PA(b) R_OA(a)).
  e.hypothesis = [](ParameterValues v, plant::PlantConfig&, TableMotion& m) {
    const double a0 = v[0], b0 = v[1];
    if (a0 == 0 && b0 == 0) return;
    const Vec3 a = effects::signed_in_phase(m.sine);
    const Vec3 t(std::cos(a0) * a[0] - std::sin(a0) * a[1], std::sin(a0) * a[0] + std::cos(a0) * a[1], a[2]);
    effects::set_in_phase(m.sine, Vec3(std::cos(b0) * t[0] + std::sin(b0) * t[2], t[1], -std::sin(b0) * t[0] + std::cos(b0) * t[2]));
    // A random part turned alike, its cross-spectra and all (S' = R S R^T).
    m.random_turn = turn_matrix(a0, b0) * m.random_turn;
  };
  // The table's motion in sensor axes turned by the rotation matrices: the sine's phasors, a
  // random part's samples (the static gravity is the run's stated orientation).
  e.truth = [](ParameterValues v, VirtualLab& lab) {
    if (v[0] == 0 && v[1] == 0) return;
    effects::set_phasors(lab.table, turn_matrix(v[0], v[1]).cast<std::complex<double>>() * effects::phasors(lab.table));
    lab.random_turn = turn_matrix(v[0], v[1]) * lab.random_turn;
  };
  e.draw = [](std::mt19937_64& rng) {
    const double s = effects::random_sign(rng);
    return std::vector<double>{s * effects::log_uniform(rng, 0.02, 0.06)};  // 1.1-3.4 deg
  };
  e.draw_form = [](std::mt19937_64& rng) {
    const double s = effects::random_sign(rng);
    return std::vector<double>{s * effects::log_uniform(rng, 0.02, 0.06)};
  };
  return e;
}

}  // namespace vrelab::validation
