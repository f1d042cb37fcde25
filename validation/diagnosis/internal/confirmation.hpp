#pragma once
// validation/diagnosis/internal/confirmation.hpp -- the diagnosis' fifth stage: the explained
// gap confirmed on the ODE plant.
//
// Takes: the campaign model (identified plant, runs, data, nominal table, what the static test
//        takes up), the chosen effect(s) with their values, the nominal gap r (g, per run) and
//        how many runs to re-simulate at most.
// Gives: for an explained gap, the runs with the largest |r| (sine runs without measured
//        motion) simulated on the ODE with the coefficients corrected by all runs under the
//        chosen effect(s), with and without the effect(s): d.resimulated_runs, the rms of
//        measured - ODE before and after (g), and the runs whose simulation failed (id: why).
#include <Eigen/Dense>

#include "validation/diagnosis/diagnose.hpp"
#include "validation/diagnosis/internal/identification.hpp"
#include "validation/diagnosis/internal/verdict.hpp"

namespace vrelab::validation::internal {

void confirm_on_ode(const CampaignModel& m, const Chosen& chosen, const Eigen::VectorXd& r, int max_runs, Diagnosis& d);

}  // namespace vrelab::validation::internal
