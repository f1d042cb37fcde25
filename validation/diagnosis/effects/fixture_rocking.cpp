// The fixture rocks in phase with the table (vibration::Rocking): about OA by default, about
// any sensor axis in its natural form.
#include <numbers>

#include "validation/diagnosis/effects/common.hpp"

namespace vrelab::validation {

Effect effect_fixture_rocking() {
  Effect e;
  e.name = "fixture_rocking";
  e.rank = 15;
  e.acts_on = ActsOn::table_motion;
  e.physics = "the fixture rocks about OA (or another sensor axis) in phase with the table, by the parameter per g of amplitude, the "
              "sensor 30 mm from the axis along IA: a tangential acceleration along PA growing as f^2, "
              "rectified with the IA motion through k_IP and by itself through k_PP, the centripetal "
              "acceleration (-r <alpha'^2>, along -IA, as f^2 alpha^2) and gravity turning with the fixture";
  EffectParameter p("rocking_rad_per_g", "rad/g");
  p.example = -1e-6;
  p.nominal = 0;
  p.grid = effects::symmetric_geometric(0.03e-6, 5e-6, 12);
  // The natural form: the rocking axis (discrete: 0 IA, 1 PA, 2 OA; nominal OA), the sensor
  // 30 mm from it along the next axis (IA -> PA -> OA -> IA: along IA for OA, the default form).
  EffectParameter ax("axis", "0 IA, 1 PA, 2 OA");
  ax.nominal = 2, ax.lower = 0, ax.upper = 2, ax.example = 1;
  ax.discrete = true, ax.starts = {0, 1, 2};
  e.parameters = {p, ax};
  e.hypothesis = [](ParameterValues v, plant::PlantConfig&, TableMotion& m) {
    m.rocking_rad_per_g = v[0];
    m.rocking_axis = static_cast<int>(v[1]);
  };
  // The fixture turns about OA with the commanded tone, the sensor 30 mm out along IA: gravity
  // and the shaker's motion turn with it, the lever arm adds the rigid-body acceleration.
  e.truth = [](ParameterValues v, VirtualLab& lab) {
    if (v[0] == 0) return;
    vibration::RockingSpec rs;
    const int axis = static_cast<int>(v[1]);
    rs.axis = Vec3::Zero();
    rs.axis[axis] = 1;
    rs.amplitude_rad = std::abs(v[0]) * lab.commanded_amplitude_g;
    rs.phase_rad = v[0] < 0 ? std::numbers::pi : 0.0;
    rs.static_gravity_g = lab.static_gravity_g;
    rs.rotate_shaker_motion = true;
    Vec3 arm = Vec3::Zero();
    arm[(axis + 1) % 3] = 0.03;  // written out: the truth does not take the hypothesis' lever arm
    rs.lever_arm_m = arm;
    rs.g_m_per_s2 = 9.80665;
    lab.rocking = rs;
  };
  e.draw = [](std::mt19937_64& rng) {
    const double s = effects::random_sign(rng);
    return std::vector<double>{s * effects::log_uniform(rng, 0.2e-6, 1e-6)};
  };
  // The natural form: any of the three axes.
  e.draw_form = [](std::mt19937_64& rng) {
    return std::vector<double>{static_cast<double>(std::uniform_int_distribution<int>(0, 2)(rng))};
  };
  e.check = [name = e.name](ParameterValues v, std::string* why) {
    if (v[1] == 0 || v[1] == 1 || v[1] == 2) return true;
    if (why) *why = name + ": axis is 0 (IA), 1 (PA) or 2 (OA), got " + std::to_string(v[1]);
    return false;
  };
  return e;
}

}  // namespace vrelab::validation
