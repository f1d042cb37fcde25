#pragma once
// validation/diagnosis/internal/gap.hpp -- the diagnosis' second stage: where the gap between
// the nominal simulation and the runs lies, and whether it is significant.
//
// Takes: the campaign model (identification.hpp: the runs' data, the nominal table) and the
//        significance level (GapOptions, sigma).
// Gives: in the Diagnosis, per run the nominal prediction and its sigma from the coefficients
//        (g), the gap measured - predicted and its sigma (V's diagonal, g), the gap the
//        coefficient errors cannot take up (g), its own sd with no gap (g) and its z in the
//        run's own sigma, the simulation's accuracy term (g); the nominal
//        chi^2, the significant runs, the largest |z| and where it is, the gap's power laws in
//        amplitude and frequency (pooled within groups), the rms z per direction, the share odd
//        in the static a_IA, the `where` summary and gap_significant (a run beyond the level,
//        or chi^2 as a normal deviate beyond it). Returns the gap r = measured - predicted (g).
#include <Eigen/Dense>

#include "validation/diagnosis/diagnose.hpp"
#include "validation/diagnosis/internal/identification.hpp"

namespace vrelab::validation::internal {

struct GapOptions {
  double threshold_sigma = 5;  // a run's gap (its z), or chi^2 as a normal deviate, beyond this is significant
};

Eigen::VectorXd locate_gap(const CampaignModel& m, const GapOptions& o, Diagnosis& d);

}  // namespace vrelab::validation::internal
