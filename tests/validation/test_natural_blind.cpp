// blind's natural forms: the draw (a family of library effects away from their default form),
// the truth path (the plant module realises the natural form's parameter on the ODE), the
// scoring (parameters within 3 sigma) and the result line that carries the parameters.
#include <gtest/gtest.h>

#include <cmath>
#include <complex>
#include <map>
#include <memory>
#include <numbers>

#include "plant/effects/mechanical_mode.hpp"
#include "rectification/simulation/shake.hpp"
#include "support/instrument.hpp"
#include "support/result_line.hpp"
#include "validation/diagnosis/blind.hpp"

namespace vrelab::validation::test_natural_blind {
namespace {

// A mode along PA moves the pendulum's base along PA only (plant::MechanicalMode's mask), so
// on a linear instrument with k_PP = 1e-5 /g alone (an output term on the base's
// acceleration) a 2 g PA sine at 250 Hz rectifies k_PP A^2 |T|^2 / 2 with the base-excited
// transmissibility T = (w_m^2 + 2 z w_m s) / (s^2 + 2 z w_m s + w_m^2) of a 300 Hz mode at
// z = 0.02 (|T| = 3.27, written out here), against k_PP A^2 / 2 without it; an IA sine is left
// exactly unchanged. Tolerance 0.1 % + 1e-11 g: the solver's 1e-10 relative; a mode on IA
// instead (the default form) would leave the PA run unchanged (a 970 % miss).
TEST(NaturalBlind, AModeAlongPaMovesThePendulumsBaseAlongPa) {
  plant::PlantConfig c = test::paper_like_linear_plant();
  c.coefficients[plant::k_PP] = 1e-5;
  plant::PlantConfig moded = c;
  constexpr double f_mode = 300, zeta = 0.02, A = 2, f = 250;
  moded.effects.push_back(std::make_shared<plant::MechanicalMode>(f_mode, zeta, Vec3::UnitY()));
  const double wm = 2 * std::numbers::pi * f_mode;
  const std::complex<double> s(0, 2 * std::numbers::pi * f);
  const double T2 = std::norm((wm * wm + 2 * zeta * wm * s) / (s * s + 2 * zeta * wm * s + wm * wm));
  vibration::SineVibration pa;
  pa.amplitude_g = Vec3(0, A, 0), pa.frequency_Hz = f;
  const Vec3 g = Vec3(1, 0, 1).normalized();
  const double with = rectification::shake_sine(moded, g, pa).measured_g;
  const double without = rectification::shake_sine(c, g, pa).measured_g;
  EXPECT_NEAR(without, 1e-5 * A * A / 2, 1e-3 * 2e-5 + 1e-11);
  EXPECT_NEAR(with, 1e-5 * A * A / 2 * T2, 1e-3 * 2e-5 * T2 + 1e-11);
  vibration::SineVibration ia = pa;
  ia.amplitude_g = Vec3(A, 0, 0);
  EXPECT_NEAR(rectification::shake_sine(moded, g, ia).measured_g, rectification::shake_sine(c, g, ia).measured_g, 1e-12);
}

// The mix: per 12 campaigns 2 clean, 2 out of library (1 and 1 dynamics_off every other
// twelve), 1 pair, 1 sigma understated, 1 drift, 2 natural forms, 3 single; each natural form hides a library effect with further
// parameters drawn away from the defaults; the out-of-library ones come from several effects.
TEST(NaturalBlind, TheDrawHasNaturalFormsAndSeveralOutOfLibraryEffects) {
  std::map<std::string, int> categories;
  std::map<std::string, int> ool;
  for (int i = 0; i < 120; ++i) {
    const BlindCampaign k = blind_key(i, 6000);
    ++categories[k.category];
    if (k.category == "natural") {
      ASSERT_EQ(k.hidden.size(), 1u);
      const Effect* e = find_effect(k.hidden[0].name);
      ASSERT_TRUE(e && e->in_library && e->draw_form) << k.hidden[0].name;
      ASSERT_EQ(k.hidden[0].form.size() + 1, e->parameters.size());
      std::string why;
      EXPECT_TRUE(e->is_valid(k.hidden[0].values(*e), &why)) << why;
    }
    if (k.category == "out_of_library") {
      ASSERT_EQ(k.hidden.size(), 1u);
      EXPECT_FALSE(find_effect(k.hidden[0].name)->in_library);
      ++ool[k.hidden[0].name];
    }
    EXPECT_EQ(blind_key(i, 6000).hidden.size(), k.hidden.size());  // the key depends on the seed only
  }
  EXPECT_EQ(categories["natural"], 20);
  EXPECT_EQ(categories["out_of_library"], 15);  // the second slot every other twelve
  EXPECT_EQ(categories["dynamics_off"], 5);
  EXPECT_EQ(categories["clean"], 20);
  EXPECT_EQ(categories["single"], 30);
  EXPECT_GE(ool.size(), 3u);
}

Diagnosis fitted_mode(double f, double f_sigma, double zeta, ParameterStatus zeta_status, double axis) {
  Diagnosis d;
  EffectFit e;
  e.name = "mechanical_mode";
  e.parameters = {{"frequency_Hz", "Hz", f, f_sigma, ParameterStatus::fitted}, {"damping_ratio", "1", zeta, 0.001, zeta_status},
                  {"axis", "0 IA, 1 PA, 2 OA", axis, NAN, ParameterStatus::chosen}};
  d.effects = {e};
  return d;
}

// Within 3 sigma is right, beyond is not; a held parameter is not judged; a chosen axis must
// be the truth's; a phase's difference wraps round.
TEST(NaturalBlind, ParametersAreScoredWithinThreeSigma) {
  const HiddenEffect mode("mechanical_mode", 800, {0.03, 1});
  std::string why;
  EXPECT_TRUE(parameters_match(mode, fitted_mode(800.2, 0.1, 0.031, ParameterStatus::fitted, 1), &why)) << why;
  EXPECT_FALSE(parameters_match(mode, fitted_mode(800.4, 0.1, 0.031, ParameterStatus::fitted, 1), &why));
  EXPECT_NE(why.find("frequency_Hz"), std::string::npos) << why;
  EXPECT_FALSE(parameters_match(mode, fitted_mode(800.2, 0.1, 0.034, ParameterStatus::fitted, 1), &why));
  EXPECT_TRUE(parameters_match(mode, fitted_mode(800.2, 0.1, 0.05, ParameterStatus::held, 1), &why));
  EXPECT_NE(why.find("damping_ratio held"), std::string::npos) << why;
  EXPECT_FALSE(parameters_match(mode, fitted_mode(800.2, 0.1, 0.031, ParameterStatus::fitted, 0), &why));
  EXPECT_FALSE(parameters_match(HiddenEffect("servo_dynamics", 0.8), fitted_mode(800, 0.1, 0.03, ParameterStatus::fitted, 1), &why));
  // A phase of 3.1 rad fitted as -3.1 +- 0.05 is 0.083 rad away, within 3 sigma.
  Diagnosis h;
  EffectFit e;
  e.name = "shaker_harmonic_distortion";
  e.parameters = {{"second_harmonic_ratio", "1", 0.2, 0.01, ParameterStatus::fitted}, {"second_harmonic_phase_rad", "rad", -3.1, 0.05, ParameterStatus::fitted}};
  h.effects = {e};
  EXPECT_TRUE(parameters_match(HiddenEffect("shaker_harmonic_distortion", 0.21, {3.1}), h, &why)) << why;
  h.effects[0].parameters[1].value = 2.9;
  EXPECT_FALSE(parameters_match(HiddenEffect("shaker_harmonic_distortion", 0.21, {3.1}), h, &why));
  // A phase +- 1.1 rad (3 sigma over pi: within 3 sigma of any truth) claims nothing: not
  // judged, said as not pinned; +- 1.0 rad (3 sigma under pi) is judged, 3.1 rad off: wrong.
  h.effects[0].parameters[1] = {"second_harmonic_phase_rad", "rad", 0.0, 1.1, ParameterStatus::fitted};
  EXPECT_TRUE(parameters_match(HiddenEffect("shaker_harmonic_distortion", 0.21, {3.1}), h, &why)) << why;
  EXPECT_NE(why.find("second_harmonic_phase_rad not pinned"), std::string::npos) << why;
  h.effects[0].parameters[1].sigma = 1.0;
  EXPECT_FALSE(parameters_match(HiddenEffect("shaker_harmonic_distortion", 0.21, {3.1}), h, &why));
}

// The result line carries the top effect's parameters, read back exactly; cut short, refused.
TEST(NaturalBlind, TheResultLineCarriesTheTopEffectsParameters) {
  BlindCampaign k;
  k.called = "mechanical_mode", k.top = "mechanical_mode";
  k.diagnosis = fitted_mode(812.25, 0.125, 0.05, ParameterStatus::held, 2);
  k.diagnosis.effects[0].value = 812.25;
  k.diagnosis.effects[0].parameters[0].at_bound = true;
  BlindCampaign back;
  read_campaign_result(campaign_result_text(k), back);
  ASSERT_EQ(back.diagnosis.effects.size(), 1u);
  const auto& p = back.diagnosis.effects[0].parameters;
  ASSERT_EQ(p.size(), 3u);
  EXPECT_EQ(p[0].value, 812.25);
  EXPECT_EQ(p[0].sigma, 0.125);
  EXPECT_TRUE(p[0].at_bound);
  EXPECT_EQ(p[1].status, ParameterStatus::held);
  EXPECT_EQ(p[2].name, "axis");
  EXPECT_EQ(p[2].value, 2);
  EXPECT_TRUE(std::isnan(p[2].sigma));
  test::expect_refused_not_outdated(test::cut_before_gap(campaign_result_text(k)), "a line cut short");
}

}  // namespace
}  // namespace vrelab::validation::test_natural_blind
