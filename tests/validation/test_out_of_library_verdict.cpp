// An out-of-library truth that a library effect imitates on the held-out runs: the verdict
// must not name the imitation. blind's own campaign (ODE truth, not the diagnosis' model),
// diagnosed as blind diagnoses it.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "validation/diagnosis/blind.hpp"
#include "validation/diagnosis/diagnose.hpp"

namespace vrelab::test_out_of_library_verdict {
namespace {

using namespace validation;

// chi^2 with n degrees of freedom as a normal deviate (Wilson-Hilferty), written out here.
double deviate(double chi2, int n) {
  const double v = 2.0 / (9.0 * n);
  return (std::cbrt(chi2 / n) - (1 - v)) / std::sqrt(v);
}

// Seed 11601 (mixed), campaign 8: a velocity-cubic damping (0.522), out of the library, 34
// sigma as the nominal model sees it. servo_dynamics, fitted on each fold's 1 and 2 g runs,
// predicts the held-out amplitude with a loose phase margin, whose spread joins the held-out
// covariance: held-out chi^2 under the 5 sigma that "explained" asks. Fitted on every run it
// leaves chi^2 160 for 41 (7.9 sigma): it was called "explained by servo_dynamics". With the
// all-run fit's chi^2 judged beside the held-out one, the servo is not the verdict. (Since
// folds that do not see a nonlinear effect are scored over its grid, a squeeze film of 1190
// /rad leads and fits every run, chi^2 39 for 42: the two dampings alike on these runs,
// docs/diagnose.md "Known misses".)
TEST(OutOfLibraryVerdictCampaign, AServoDynamicsImitatingAVelocityCubicDampingFailsItsFitOnEveryRun) {
  const BlindCampaign k = blind_key(8, 11601, true);
  ASSERT_EQ(k.category, "out_of_library");
  ASSERT_EQ(k.hidden.at(0).name, "velocity_cubic_damping");
  const Diagnosis d = diagnose(blind_lab_campaign(k), BlindSettings{}.diagnose);
  const auto servo = std::find_if(d.effects.begin(), d.effects.end(), [](const EffectFit& e) { return e.name == "servo_dynamics"; });
  ASSERT_NE(servo, d.effects.end());
  const int n = static_cast<int>(d.runs.size());
  std::printf("  %s; servo_dynamics: evidence %.1f, held-out chi2 %.1f for %d (%.2f sigma), all-run chi2 %.1f for %d (%.2f sigma)\n",
              verdict_text(d).c_str(), servo->evidence, servo->heldout_chi2, n, deviate(servo->heldout_chi2, n),
              servo->insample_chi2, servo->insample_dof, deviate(servo->insample_chi2, servo->insample_dof));
  EXPECT_TRUE(d.gap_significant);
  // What the test is about: the imitation passes held out and fails on every run, so it is not
  // the verdict.
  EXPECT_GT(servo->evidence, 25);
  EXPECT_LT(deviate(servo->heldout_chi2, n), 5);
  EXPECT_GT(deviate(servo->insample_chi2, servo->insample_dof), 5);
  EXPECT_TRUE(d.chosen.names.empty() || d.chosen.names.front() != "servo_dynamics") << verdict_text(d);
}

}  // namespace
}  // namespace vrelab::test_out_of_library_verdict
