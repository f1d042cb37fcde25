#pragma once
// validation/diagnosis/internal/shrinkage.hpp -- the held-out gap before and after the chosen
// effect(s): how far the gap shrinks.
//
// Takes: each run's held-out adjusted gap (g) of the nominal simulation, or of the chosen
//        candidate (fitted without the run's fold), and the runs' variances (g^2).
// Gives: in the Diagnosis, each run's held-out gap before (heldout_before_g) or after
//        (heldout_after_g) and their rms over the runs, in g and in each run's sigma; after:
//        no shrinkage when no effect was ranked. And the floor: the rms the held-out gap has
//        with no gap at all (each run's noise and simulation accuracy, and the coefficients'
//        error its fold's training runs leave, extrapolated to it), which no effect removes;
//        the shrinkage of what lies above it.
#include <Eigen/Dense>

#include "validation/diagnosis/diagnose.hpp"
#include "validation/diagnosis/internal/evidence.hpp"
#include "validation/diagnosis/internal/likelihood.hpp"

namespace vrelab::validation::internal {

void shrinkage_before(const Eigen::VectorXd& heldout_nominal, const Eigen::VectorXd& heldout_floor2, const Data& data,
                      Diagnosis& d);
void shrinkage_after(const Scored& best, const Data& data, Diagnosis& d);

}  // namespace vrelab::validation::internal
