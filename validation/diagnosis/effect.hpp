#pragma once
// validation/diagnosis/effect.hpp -- one effect as the diagnosis and the virtual lab know it.
//
// An Effect is one physical cause of a gap between the simulation and a shaker campaign: its
// name, its physics in words (docs and reports), its parameters (name, unit, the value
// without it, the fit's range and how the fit explores it), where it acts, and four hooks:
//  - hypothesis: the diagnosis' model of it, applied to the nominal plant and the table's
//    motion that the first-order prediction takes (validation/diagnosis/diagnose.hpp);
//  - truth: the virtual lab's, built from its physical description with the plant's modules
//    (plant/effects/) and the shaker's decorators (vibration/decorators.hpp), never through
//    the hypothesis, so that a wrong sign or axis in a hypothesis shows in `blind`;
//  - draw: a value of the first parameter for a blind campaign, where its gap is several sigma
//    in the default design (draw_form: the natural form's further parameters);
//  - check: the values a campaign may hide (beyond finiteness).
// Each effect is one file in validation/diagnosis/effects/; the registry (effect_registry())
// lists them all. The hooks take one value per parameter.
#include <cmath>
#include <functional>
#include <memory>
#include <optional>
#include <random>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include "plant/accelerometer.hpp"
#include "vibration/decorators.hpp"
#include "vibration/profile.hpp"

namespace vrelab::validation {

// The table's motion in one run as the diagnosis' prediction models it, in sensor axes: the
// sine the shaker makes (the commanded one, with any transverse part), its harmonic
// distortion, and the fixture's rocking. The hypotheses of the effects that live in the
// shaker set these.
struct TableMotion {
  vibration::SineVibration sine;
  // A random part's motion in sensor axes is random_turn times the profile's (S' = M S M^T,
  // rectification::random_response): the table-motion effects that are a linear map the same
  // at every frequency set it (mounting_misalignment); the identity otherwise.
  Eigen::Matrix3d random_turn = Eigen::Matrix3d::Identity();
  std::vector<vibration::Harmonic> harmonics;  // vibration/decorators.hpp's HarmonicDistortion
  // Rocking of the fixture about OA, rad per g of commanded amplitude, in phase with the
  // table (negative: in antiphase); the sensor 30 mm from the axis along IA. The natural
  // form: about another axis (rocking_axis: 0 IA, 1 PA, 2 OA), the sensor 30 mm from it along
  // the next axis (IA -> PA -> OA -> IA).
  double rocking_rad_per_g = 0;
  int rocking_axis = 2;
  double commanded_amplitude_g = 0;
  Vec3 static_gravity_g = Vec3::Zero();  // what the rocking turns
  static constexpr double kRockingLeverArm_m = 0.03;
  bool pure_sine() const { return harmonics.empty() && rocking_rad_per_g == 0; }
  // The acceleration the plant's case feels (the decorators of vibration/decorators.hpp).
  std::shared_ptr<const vibration::Excitation> excitation() const;
};

// The virtual lab's truth for the static test or one shaker run, as the effects' truth hooks
// build it up: the instrument, the shaker runs' data acquisition, and the table's motion.
struct VirtualLab {
  plant::PlantConfig instrument;  // the sensor: the static test and the shaker runs read it
  // The shaker runs' data acquisition (readout modules after the instrument's); the static
  // test is read with another instrument.
  std::vector<std::shared_ptr<const plant::Effect>> run_acquisition;
  // The run (zero amplitude for the static test): the commanded sine turned into what the
  // table does in sensor axes by the shaker's and the fixture's linear imperfections, then
  // the shaker's distortion and the fixture's rocking about the commanded tone.
  vibration::SineVibration table;
  double commanded_amplitude_g = 0;
  Vec3 static_gravity_g = Vec3::Zero();
  std::vector<vibration::Harmonic> harmonics;
  std::optional<vibration::RockingSpec> rocking;
  // A random part's motion in sensor axes: random_turn times the profile's, sample by sample
  // (the fixture's turn; the shaker's other imperfections act on the sine only).
  Eigen::Matrix3d random_turn = Eigen::Matrix3d::Identity();

  plant::PlantConfig run_plant() const;  // the instrument read by the run's acquisition
  std::shared_ptr<const vibration::Excitation> excitation() const;
};

enum class ActsOn { instrument, table_motion, data_acquisition };
const char* to_string(ActsOn a);

struct EffectParameter {
  EffectParameter() = default;
  EffectParameter(std::string name_, std::string unit_) : name(std::move(name_)), unit(std::move(unit_)) {}
  std::string name, unit;
  double nominal = 0;  // the value without the effect
  // The fit's physical range; for linear parameters left infinite, the registry sets
  // nominal +- 100 |unit_value - nominal|.
  double lower = -INFINITY, upper = INFINITY;
  bool linear = false;       // the prediction is linear in it: fitted from one signature
  double unit_value = 1;     // the value of that signature (linear)
  std::vector<double> grid;  // values tried (nonlinear)
  // A value where the effect is clearly seen in a 4 g run (the tests' value; docs).
  double example = NAN;
  // A further parameter (not the first): the natural form's departure from the library's
  // default form (nominal). The diagnosis fits it where the data pin it (docs/diagnose.md,
  // "Natural forms") and holds it at nominal where they do not.
  //  - discrete: one of `starts` (an axis, say), chosen by likelihood; else continuous in
  //    [lower, upper], fitted by Levenberg-Marquardt with a weak Gaussian prior of width
  //    prior_sigma (NaN: (upper - lower) / 4) about nominal;
  //  - starts: the values the first parameter's grid fit is repeated at (a phase's quadrants,
  //    the axes): a start far from the truth can leave the first parameter near zero, where
  //    the further one has no slope;
  //  - step: the finite-difference step of its slope (NaN: 1e-3 (upper - lower)).
  bool discrete = false;
  bool periodic = false;  // an angle: [lower, upper) wraps round
  // False: the hypothesis' prediction is even in this parameter for every run it is applied to
  // (tests/validation/test_transverse_quadrature.cpp checks it), so the runs cannot tell +x
  // from -x. The fit takes its magnitude (range from 0); the truth hook takes it signed (the
  // virtual lab acts with either sign); reports say the sign is not identifiable and blind
  // compares the magnitudes.
  bool sign_identifiable = true;
  std::vector<double> starts;
  double prior_sigma = NAN, step = NAN;
  double prior_width() const { return std::isfinite(prior_sigma) ? prior_sigma : (upper - lower) / 4; }
  double fd_step() const { return std::isfinite(step) ? step : 1e-3 * (upper - lower); }
};

using ParameterValues = std::span<const double>;  // one value per Effect::parameters entry

struct Effect {
  std::string name, physics;
  // At least one. The first is the effect's size (its nominal: no effect); the further ones its
  // natural form (their nominals: the library's default form). The diagnosis fits the first
  // and each further one the data pin (docs/diagnose.md, "Natural forms").
  std::vector<EffectParameter> parameters;
  ActsOn acts_on = ActsOn::instrument;
  bool in_library = true;         // false: only the virtual lab knows it (diagnose must call it unexplained)
  int rank = 1000;                // the registry's order (the diagnosis' order: ties, output); a new effect takes the next
  bool changes_dynamics = false;  // the loop's linear response depends on the parameter
  // The hypothesis' own accuracy: the relative error of the change it predicts against the
  // ODE with the truth (tests/validation/test_effect_sweep.cpp bounds it at 1 % over the band
  // and the drawn range; the squeeze film's harmonic balance 2 %,
  // test_squeeze_film_harmonic_balance.cpp). A fitted parameter's reported sigma adds what
  // that error, as one common relative error, moves the fit (diagnose.cpp,
  // EffectFitter::add_model_error); apart from the simulation's own accuracy (DiagnoseSettings).
  double hypothesis_accuracy = 0.01;
  // Acts at rest too (linear effects only): the static test took up part of it into the
  // identified coefficients; diagnose gives that part back (docs/diagnose.md).
  bool acts_at_rest = false;
  // Lives in the shaker runs' data acquisition only: a lab reads its static test apart.
  bool shaker_runs_only = false;

  std::function<void(ParameterValues, plant::PlantConfig&, TableMotion&)> hypothesis;  // null: not in the library
  std::function<void(ParameterValues, VirtualLab&)> truth;
  std::function<std::vector<double>(std::mt19937_64&)> draw;
  // The natural form's draw (blind): the further parameters (parameters[1..]) away from their
  // defaults (damping, axis, phase, a second angle); null: none. Apart from `draw`, so that a
  // seed's default-form draws do not depend on the natural forms.
  std::function<std::vector<double>(std::mt19937_64&)> draw_form;
  std::function<bool(ParameterValues, std::string* why)> check;  // null: any finite values

  const EffectParameter& fitted() const { return parameters.front(); }
  // The hypothesis at one value of the first parameter (the others nominal).
  void apply(double p, plant::PlantConfig& plant, TableMotion& motion) const;
  // The hypothesis at every parameter's value.
  void apply(ParameterValues values, plant::PlantConfig& plant, TableMotion& motion) const;
  // Every parameter at its nominal but the first at p.
  std::vector<double> values_at(double p) const;
  // The right number of finite values that `check` accepts; why says otherwise.
  bool is_valid(ParameterValues values, std::string* why = nullptr) const;
};

// Every effect, the library's first in the diagnosis' order, then those outside it.
const std::vector<Effect>& effect_registry();
// The library's effects (in_library), in the diagnosis' order.
const std::vector<Effect>& effect_library();
const Effect* find_effect(const std::string& name);  // any registered effect; null if none

}  // namespace vrelab::validation
