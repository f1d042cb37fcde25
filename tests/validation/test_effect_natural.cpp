// Effects in their natural form (issue 15): a campaign made by the virtual lab's truth hooks
// (plant modules, shaker decorators; never the hypotheses) with a parameter set away from the
// library's default form is diagnosed to the right effect, every fitted parameter within 3
// sigma of the truth; and a clean campaign is not explained by the richer effects (the extra
// freedom is judged on held-out runs fitted the same way). Seeds 51-54 were not used to develop
// the fit. Each diagnoses a whole simulated campaign: label "campaign" (tests/CMakeLists.txt).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <numbers>
#include <string>

#include "support/diagnosis_lookup.hpp"
#include "support/instrument.hpp"
#include "validation/diagnosis/campaign.hpp"
#include "validation/diagnosis/diagnose.hpp"
#include "validation/diagnosis/diagnosis_text.hpp"

namespace test_effect_natural {

using namespace vrelab;
using namespace vrelab::validation;
using vrelab::test::parameter_named;

namespace {

plant::PlantConfig truth() { return test::paper_like_plant(); }

// One static orientation (the odd/even split is not what these tests are about), three
// amplitudes (the folds leave one out), the directions each natural form needs.
CampaignDesign design(std::vector<double> frequencies_Hz, std::vector<Vec3> directions) {
  CampaignDesign d = default_design();
  d.frequencies_Hz = std::move(frequencies_Hz);
  d.amplitudes_g = {1, 2, 4};
  d.directions = std::move(directions);
  d.orientations_g = {Vec3(1, 0, 1).normalized()};
  return d;
}

// Every parameter the fit reports as fitted lies within 3 sigma of the truth (3 sigma: the
// issue's bound; the first-order model's own error, 1 % of the change at most
// (test_effect_sweep.cpp), is far inside it at these gaps); a chosen one equals the truth; a
// held one sits at its nominal (the registry's). The first parameter (the effect's size) is
// always fitted, so a fit that held everything fails here.
void expect_within_3_sigma(const EffectFit& e, const std::vector<double>& truth_values) {
  ASSERT_EQ(e.parameters.size(), truth_values.size());
  const Effect* registered = find_effect(e.name);
  ASSERT_NE(registered, nullptr) << e.name;
  ASSERT_EQ(registered->parameters.size(), e.parameters.size());
  EXPECT_EQ(e.parameters.front().status, ParameterStatus::fitted) << e.name << ": its size not fitted";
  int judged = 0;
  for (std::size_t j = 0; j < truth_values.size(); ++j) {
    const FittedParameter& q = e.parameters[j];
    std::printf("  %s %s: %s %.6g +- %.3g (truth %.6g)\n", e.name.c_str(), q.name.c_str(), to_string(q.status), q.value, q.sigma,
                truth_values[j]);
    SCOPED_TRACE(q.name + " " + to_string(q.status));
    if (q.status == ParameterStatus::fitted) {
      ASSERT_TRUE(std::isfinite(q.sigma) && q.sigma > 0);
      double diff = q.value - truth_values[j];
      if (q.unit == "rad" && q.name.find("phase") != std::string::npos)
        diff = std::remainder(diff, 2 * std::numbers::pi);  // a phase: the nearest turn
      EXPECT_LE(std::abs(diff), 3 * q.sigma) << q.value << " +- " << q.sigma << " for " << truth_values[j];
      ++judged;
    } else if (q.status == ParameterStatus::chosen) {
      EXPECT_EQ(q.value, truth_values[j]);
      ++judged;
    } else {
      EXPECT_EQ(q.status, ParameterStatus::held);
      EXPECT_EQ(q.value, registered->parameters[j].nominal) << "held, but not at its nominal";
    }
  }
  EXPECT_GE(judged, 1);
}

}  // namespace

// A mode at 1.8 kHz, damping 0.02, along PA (the default form: damping 0.05 along IA). Along
// PA it reaches the output through k_IP (IA+PA runs) and the pendulum geometry; runs around
// the resonance pin its damping. The axis is a discrete choice (docs/diagnose.md).
TEST(NaturalFormCampaign, AModeAlongPaWithLowDampingIsFoundWithItsParameters) {
  const std::vector<double> v = {1800, 0.02, 1};
  const Campaign c = simulate_campaign(truth(), {HiddenEffect("mechanical_mode", v[0], {v[1], v[2]})},
                                       design({100, 600, 1200, 1600, 1700, 1900, 2000},
                                              {Vec3(1, 0, 0), Vec3(0, 1, 0), Vec3(1, 1, 0).normalized()}),
                                       51, 2);
  const Diagnosis d = diagnose(c);
  ASSERT_TRUE(d.gap_significant) << d.where;
  EXPECT_TRUE(d.explained()) << verdict_text(d);
  ASSERT_EQ(d.effects.front().name, "mechanical_mode") << verdict_text(d);
  const EffectFit& e = d.effects.front();
  EXPECT_EQ(parameter_named(e, "axis").status, ParameterStatus::chosen);
  EXPECT_EQ(parameter_named(e, "damping_ratio").status, ParameterStatus::fitted);
  expect_within_3_sigma(e, v);
}

// A 2nd harmonic at 90 degrees (the default form: phase 0): <a^3> = -(3/4) h sin(phi) w^3 acts
// at the input, first order in h, so the phase is pinned.
TEST(NaturalFormCampaign, ASecondHarmonicAtNinetyDegreesIsFoundWithItsPhase) {
  const std::vector<double> v = {0.2, std::numbers::pi / 2};
  const Campaign c = simulate_campaign(truth(), {HiddenEffect("shaker_harmonic_distortion", v[0], {v[1]})},
                                       design({10, 100, 400, 1000}, {Vec3(1, 0, 0), Vec3(0, 1, 0), Vec3(1, 1, 0).normalized()}),
                                       52, 2);
  const Diagnosis d = diagnose(c);
  ASSERT_TRUE(d.gap_significant) << d.where;
  EXPECT_TRUE(d.explained()) << verdict_text(d);
  ASSERT_EQ(d.effects.front().name, "shaker_harmonic_distortion") << verdict_text(d);
  EXPECT_EQ(parameter_named(d.effects.front(), "second_harmonic_phase_rad").status, ParameterStatus::fitted);
  expect_within_3_sigma(d.effects.front(), v);
}

// A fixture turned 0.03 rad about OA and 0.05 rad about PA (the default form: about OA only):
// the turn about PA mixes IA and OA through k_IO, so runs along OA and between IA and OA are
// needed. Without the IA-OA diagonal the PA angle is pinned only to ~0.03 rad and a transverse
// motion on the other axis cycle (three continuous parameters) imitates the turn: it beat the
// misalignment on 1 of seeds 53-62 (evidence 189 against 181 on 53) and came within 6 on one
// more; with the diagonal the misalignment leads by 140-290 on all ten.
TEST(NaturalFormCampaign, AMisalignmentAboutPaAndOaIsFoundWithBothAngles) {
  const std::vector<double> v = {0.03, 0.05};
  const Campaign c = simulate_campaign(truth(), {HiddenEffect("mounting_misalignment", v[0], {v[1]})},
                                       design({10, 100, 400}, {Vec3(1, 0, 0), Vec3(0, 1, 0), Vec3(0, 0, 1),
                                                               Vec3(1, 1, 0).normalized(), Vec3(1, 0, 1).normalized()}),
                                       53, 2);
  const Diagnosis d = diagnose(c);
  ASSERT_TRUE(d.gap_significant) << d.where;
  EXPECT_TRUE(d.explained()) << verdict_text(d);
  ASSERT_EQ(d.effects.front().name, "mounting_misalignment") << verdict_text(d);
  EXPECT_EQ(parameter_named(d.effects.front(), "angle_about_PA_rad").status, ParameterStatus::fitted);
  expect_within_3_sigma(d.effects.front(), v);
}

// No false alarm from the extra freedom: a clean campaign in the mode's design (every natural
// form has something to fit there) has no gap, and no effect's held-out evidence reaches the
// targeted test's 25 (the richer effects are fitted on the training runs as on all).
TEST(NaturalFormCampaign, ACleanCampaignIsNotExplainedByTheRicherEffects) {
  const Campaign c = simulate_campaign(truth(), {},
                                       design({100, 600, 1200, 1600, 1700, 1900, 2000},
                                              {Vec3(1, 0, 0), Vec3(0, 1, 0), Vec3(0, 0, 1), Vec3(1, 1, 0).normalized()}),
                                       54, 2);
  const Diagnosis d = diagnose(c);
  EXPECT_FALSE(d.gap_significant) << d.where << "; " << verdict_text(d);
  EXPECT_FALSE(d.explained()) << verdict_text(d);
  // Every library effect is judged (none left out of the list, so none escapes the bound).
  ASSERT_EQ(d.effects.size(), effect_library().size()) << verdict_text(d);
  for (const EffectFit& e : d.effects) {
    EXPECT_LT(e.evidence, 25) << e.name;
    // No discrete form chosen for an effect the runs do not see.
    for (const FittedParameter& q : e.parameters) EXPECT_NE(q.status, ParameterStatus::chosen) << e.name << " " << q.name;
    for (std::size_t j = 1; j < e.parameters.size(); ++j)
      std::printf("  %s %s: %s %.6g (evidence %.2f)\n", e.name.c_str(), e.parameters[j].name.c_str(), to_string(e.parameters[j].status),
                  e.parameters[j].value, e.evidence);
  }
  // The top effect's fitted parameters carry its held ones' spread over their ranges (the held
  // parameters marginalised): still a claim, sigma below half the parameter's range. At least
  // one such parameter (fitted, a finite range, inside it) must be there to judge.
  int claims = 0;
  for (const FittedParameter& q : d.effects.front().parameters) {
    std::printf("  top %s %s: %s %.6g +- %.3g\n", d.effects.front().name.c_str(), q.name.c_str(), to_string(q.status), q.value, q.sigma);
    if (q.status == ParameterStatus::fitted && std::isfinite(q.upper - q.lower) && !q.at_bound) {
      EXPECT_LT(q.sigma, (q.upper - q.lower) / 2) << q.name;
      ++claims;
    }
  }
  EXPECT_GE(claims, 1) << d.effects.front().name << ": no fitted parameter inside a finite range to judge";
}

// Transverse motion in its natural form: 6.6 % at 1 kHz in phase and 4.5 % in quadrature (8 %
// at 0.6 rad), growing as f^2, on the other transverse axis (IA -> OA, PA -> IA, OA -> PA; the
// default form: in phase, as f, IA -> PA). Along IA it meets k_IO, along PA k_IP: runs along
// IA, PA and OA over a decade and a half pin the in-phase ratio, the power and the axis; the
// quadrature part reaches the output only through the quadratic terms (k2 from PA runs, at
// (r A)^2), which may leave it held: then the in-phase ratio is what the cross terms measure.
// Seed 6010 (a development seed).
TEST(NaturalFormCampaign, TransverseMotionOutOfPhaseOnTheOtherAxisIsFoundWithItsLaw) {
  const std::vector<double> v = {0.08 * std::cos(0.6), 0.08 * std::sin(0.6), 2, 1};
  const Campaign c = simulate_campaign(truth(), {HiddenEffect("shaker_transverse_motion", v[0], {v[1], v[2], v[3]})},
                                       design({10, 100, 400, 800, 1500}, {Vec3(1, 0, 0), Vec3(0, 1, 0), Vec3(0, 0, 1)}), 6010, 2);
  const Diagnosis d = diagnose(c);
  ASSERT_TRUE(d.gap_significant) << d.where;
  EXPECT_TRUE(d.explained()) << verdict_text(d);
  ASSERT_EQ(d.effects.front().name, "shaker_transverse_motion") << verdict_text(d);
  EXPECT_EQ(parameter_named(d.effects.front(), "axis_cycle").status, ParameterStatus::chosen);
  EXPECT_EQ(parameter_named(d.effects.front(), "frequency_power").status, ParameterStatus::fitted);
  expect_within_3_sigma(d.effects.front(), v);
}

// A fixture rocking about PA (the default form: about OA), 2 urad/g, the sensor 30 mm out
// along OA: along IA the table's motion turned by the rocking puts -alpha a_IA on OA and
// gravity's OA part on IA, along OA alpha a_OA on IA (a first-order mean, as about OA with
// PA). Seed 6011.
TEST(NaturalFormCampaign, RockingAboutPaIsFoundWithItsAxis) {
  const std::vector<double> v = {2e-6, 1};
  const Campaign c = simulate_campaign(truth(), {HiddenEffect("fixture_rocking", v[0], {v[1]})},
                                       design({10, 100, 400, 1000}, {Vec3(1, 0, 0), Vec3(0, 1, 0), Vec3(0, 0, 1)}), 6011, 2);
  const Diagnosis d = diagnose(c);
  ASSERT_TRUE(d.gap_significant) << d.where;
  EXPECT_TRUE(d.explained()) << verdict_text(d);
  ASSERT_EQ(d.effects.front().name, "fixture_rocking") << verdict_text(d);
  EXPECT_EQ(parameter_named(d.effects.front(), "axis").status, ParameterStatus::chosen);
  expect_within_3_sigma(d.effects.front(), v);
}

}  // namespace test_effect_natural
