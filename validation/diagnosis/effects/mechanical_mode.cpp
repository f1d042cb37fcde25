// A second mechanical mode (plant::MechanicalMode): its frequency, damping and axis.
#include <memory>

#include "plant/effects/mechanical_mode.hpp"
#include "validation/diagnosis/effects/common.hpp"

namespace vrelab::validation {

namespace {
constexpr double kDampingRatio = 0.05;  // the library's default form: damping 0.05, along IA
// The mode's axis as plant::MechanicalMode's mask: 0 IA, 1 PA, 2 OA.
Vec3 axis_mask(double axis) { return Vec3::Unit(static_cast<int>(axis)); }
}  // namespace

Effect effect_mechanical_mode() {
  Effect e;
  e.name = "mechanical_mode";
  e.rank = 7;
  e.acts_on = ActsOn::instrument;
  e.changes_dynamics = true;
  e.physics = "a second mechanical mode (flexure or mount; along IA, PA or OA; damping 0.05 by default) amplifies "
              "the vibration along its axis that reaches the pendulum near its frequency: a resonance in the gap "
              "over frequency, in the runs with motion along that axis";
  EffectParameter p("frequency_Hz", "Hz");
  p.example = 700;
  p.nominal = 0;  // 0: no mode
  p.grid = effects::geometric(100, 5000, 41);
  // The natural form. Damping: continuous, pinned only by runs near the resonance (below it the
  // transmissibility 1/(1 - r^2) does not depend on it).
  EffectParameter z("damping_ratio", "1");
  z.nominal = kDampingRatio, z.lower = 0.005, z.upper = 0.3, z.example = 0.02;
  z.prior_sigma = 0.1, z.step = 5e-4;
  // Axis: a discrete choice (0 IA, 1 PA, 2 OA), each a start of the frequency's grid fit.
  // plant::MechanicalMode acts per sensor axis; a mount's mode along a slanted direction
  // would need a module with one relative coordinate along it (not written): a mode along
  // IA and PA at once is the nearest the library has, and a fixture's modes are mostly along
  // its own axes, which are the sensor's.
  EffectParameter ax("axis", "0 IA, 1 PA, 2 OA");
  ax.nominal = 0, ax.lower = 0, ax.upper = 2, ax.example = 1;
  ax.discrete = true, ax.starts = {0, 1, 2};
  e.parameters = {p, z, ax};
  e.hypothesis = [](ParameterValues v, plant::PlantConfig& c, TableMotion&) {
    if (v[0] > 0) c.effects.push_back(std::make_shared<plant::MechanicalMode>(v[0], v[1], axis_mask(v[2])));
  };
  e.truth = [](ParameterValues v, VirtualLab& lab) {
    if (v[0] <= 0) return;
    Vec3 mask = Vec3::Zero();
    mask[static_cast<int>(v[2])] = 1;  // written out: the truth does not share the hypothesis' helper
    lab.instrument.effects.push_back(std::make_shared<plant::MechanicalMode>(v[0], v[1], mask));
  };
  e.draw = [](std::mt19937_64& rng) {
    effects::random_sign(rng);
    return std::vector<double>{effects::log_uniform(rng, 300, 1200)};
  };
  // The natural form: damping 0.01-0.2 (log-uniform), any of the three axes.
  e.draw_form = [](std::mt19937_64& rng) {
    const double zeta = effects::log_uniform(rng, 0.01, 0.2);
    return std::vector<double>{zeta, static_cast<double>(std::uniform_int_distribution<int>(0, 2)(rng))};
  };
  e.check = [name = e.name](ParameterValues v, std::string* why) {
    if (!(v[0] >= 0)) {
      if (why) *why = name + " is the mode's frequency in Hz (0: none), >= 0, got " + std::to_string(v[0]);
      return false;
    }
    if (!(v[1] > 0)) {
      if (why) *why = name + ": damping_ratio must be positive, got " + std::to_string(v[1]);
      return false;
    }
    if (!(v[2] == 0 || v[2] == 1 || v[2] == 2)) {
      if (why) *why = name + ": axis is 0 (IA), 1 (PA) or 2 (OA), got " + std::to_string(v[2]);
      return false;
    }
    return true;
  };
  return e;
}

}  // namespace vrelab::validation
