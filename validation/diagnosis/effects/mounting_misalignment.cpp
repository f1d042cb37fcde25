// The shaker fixture holds the sensor turned about OA from where the static test held it.
#include <Eigen/Geometry>

#include "validation/diagnosis/effects/common.hpp"

namespace vrelab::validation {

Effect effect_mounting_misalignment() {
  Effect e;
  e.name = "mounting_misalignment";
  e.rank = 12;
  e.acts_on = ActsOn::table_motion;
  e.physics = "the shaker fixture holds the sensor turned by the angle about OA from where the static test "
              "held it: the table's IA motion puts angle x w on PA and its PA motion -angle x w on IA, so the "
              "cross term k_IP rectifies angle k_IP (w_IA^2 - w_PA^2) / 2 and k2 sees angle^2 w_PA^2; flat in "
              "frequency where the terms are at the input, opposite in sign along IA and PA, nothing along OA";
  EffectParameter p("angle_about_OA_rad", "rad");
  p.example = 0.05;
  p.nominal = 0;
  p.grid = effects::symmetric_geometric(0.002, 0.2, 12);
  e.parameters = {p};
  e.hypothesis = [](ParameterValues v, plant::PlantConfig&, TableMotion& m) {
    const double a0 = v[0];
    if (a0 == 0) return;
    const Vec3 a = effects::signed_in_phase(m.sine);  // turned about OA by a0
    effects::set_in_phase(m.sine, Vec3(std::cos(a0) * a[0] - std::sin(a0) * a[1], std::sin(a0) * a[0] + std::cos(a0) * a[1], a[2]));
  };
  // The table's motion in sensor axes turned by the rotation about OA (the static gravity is
  // the run's stated orientation).
  e.truth = [](ParameterValues v, VirtualLab& lab) {
    if (v[0] == 0) return;
    const Eigen::Matrix3d turn = Eigen::AngleAxisd(v[0], Vec3::UnitZ()).toRotationMatrix();
    effects::set_phasors(lab.table, turn.cast<std::complex<double>>() * effects::phasors(lab.table));
  };
  e.draw = [](std::mt19937_64& rng) {
    const double s = effects::random_sign(rng);
    return std::vector<double>{s * effects::log_uniform(rng, 0.02, 0.06)};  // 1.1-3.4 deg
  };
  return e;
}

}  // namespace vrelab::validation
