// The fixture rocks about OA in phase with the table (vibration::Rocking).
#include <numbers>

#include "validation/diagnosis/effects/common.hpp"

namespace vrelab::validation {

Effect effect_fixture_rocking() {
  Effect e;
  e.name = "fixture_rocking";
  e.rank = 15;
  e.acts_on = ActsOn::table_motion;
  e.physics = "the fixture rocks about OA in phase with the table, by the parameter per g of amplitude, the "
              "sensor 30 mm from the axis along IA: a tangential acceleration along PA growing as f^2, "
              "rectified with the IA motion through k_IP and by itself through k_PP, the centripetal "
              "acceleration (-r <alpha'^2>, along -IA, as f^2 alpha^2) and gravity turning with the fixture";
  EffectParameter p("rocking_rad_per_g", "rad/g");
  p.example = -1e-6;
  p.nominal = 0;
  p.grid = effects::symmetric_geometric(0.03e-6, 5e-6, 12);
  e.parameters = {p};
  e.hypothesis = [](ParameterValues v, plant::PlantConfig&, TableMotion& m) { m.rocking_rad_per_g = v[0]; };
  // The fixture turns about OA with the commanded tone, the sensor 30 mm out along IA: gravity
  // and the shaker's motion turn with it, the lever arm adds the rigid-body acceleration.
  e.truth = [](ParameterValues v, VirtualLab& lab) {
    if (v[0] == 0) return;
    vibration::RockingSpec rs;
    rs.axis = Vec3::UnitZ();
    rs.amplitude_rad = std::abs(v[0]) * lab.commanded_amplitude_g;
    rs.phase_rad = v[0] < 0 ? std::numbers::pi : 0.0;
    rs.static_gravity_g = lab.static_gravity_g;
    rs.rotate_shaker_motion = true;
    rs.lever_arm_m = Vec3(TableMotion::kRockingLeverArm_m, 0, 0);
    rs.g_m_per_s2 = 9.80665;
    lab.rocking = rs;
  };
  e.draw = [](std::mt19937_64& rng) {
    const double s = effects::random_sign(rng);
    return std::vector<double>{s * effects::log_uniform(rng, 0.2e-6, 1e-6)};
  };
  return e;
}

}  // namespace vrelab::validation
