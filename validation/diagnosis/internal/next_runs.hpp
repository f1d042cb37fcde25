#pragma once
// validation/diagnosis/internal/next_runs.hpp -- advice on the runs to add, for an ambiguous
// or unexplained gap (docs/diagnose.md, "11. Next runs").
//
// Takes: the campaign model (the identified plant, the runs with their variances g^2, the
//        coefficients' covariance, what the static test takes up) and the Diagnosis with its
//        ranked effects, verdict, ties and the gap's runs.
// Gives: d.next_runs, up to three distinct experiments (any two differ in at least two of
//        frequency, direction, amplitude and static orientation):
//        - ambiguous: the sine runs (direction, 10 Hz - 2 kHz, a quarter to all of the largest
//          amplitude, static orientation) where the tied effects, each at its fitted values,
//          are furthest apart in the rise of the rival's -2 ln L (rival_rise_sigma);
//        - not explained: runs that locate the gap beside its largest run: on the axis the
//          campaign lacks, in the frequency band next to it, at another amplitude
//          (locating_runs), each with the gap it expects there.
//        Nothing for an explained unambiguous or insignificant gap.
#include <vector>

#include <Eigen/Dense>

#include "validation/diagnosis/diagnose.hpp"
#include "validation/diagnosis/internal/identification.hpp"

namespace vrelab::validation::internal {

// One hypothesis at a run it has not seen, given every run of the campaign: its best estimate
// (the prediction at its values plus the coefficients' correction the runs estimate under it,
// g) and that estimate's variance from the coefficients' remaining uncertainty and its fitted
// parameters' sigma (each parameter moved by its sigma, the correction re-estimated), g^2.
struct Conditional {
  Eigen::VectorXd mean, variance;
};
// e null: the nominal simulation. `at`: the runs to predict (sine runs); throws
// std::invalid_argument where the plant cannot take the values.
Conditional conditional(const CampaignModel& m, const Effect* e, const EffectFit* fit, const std::vector<RunRecord>& at);

// The separation a run gives when hypothesis T is true and R its rival, from their
// conditionals at the run (mean_X, var_X) and the run's own variance s2 (its sigma with the
// simulation's accuracy): appended with a value drawn from T's predictive distribution
// N(mean_T, s2 + var_T), the rival's chi^2 at its refit rises over T's by
//   E[Delta chi^2] = (mean_T - mean_R)^2 / (s2 + var_R) + (s2 + var_T) / (s2 + var_R) - 1
// (for a linear model a new datum raises the minimum chi^2 by its squared predictive residual
// over its predictive variance: the recursive least-squares update); the separation is its
// square root (0 where it is negative). A run is ranked by the smaller of its two sides
// (either may be the truth).
double rival_rise_sigma(double mean_truth, double var_truth, double mean_rival, double var_rival, double s2);

void suggest_next_runs(const CampaignModel& m, Diagnosis& d);

}  // namespace vrelab::validation::internal
