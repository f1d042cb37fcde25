#pragma once
// validation/diagnosis/internal/evidence.hpp -- the diagnosis' third stage: each library
// effect fitted on training runs and scored on the held-out ones.
//
// Takes: the campaign model (identification.hpp: the runs' data, the nominal table, the
//        identified plant, what the static test takes up) and the effects left out as measured
//        (reference channels).
// Gives: the folds (leave one amplitude out, else one frequency, else in-sample); the nominal's
//        held-out adjusted gap per run (g); per effect its fit on all runs (each parameter's
//        value, sigma with the hypothesis' accuracy, status), its held-out evidence (the fall of
//        -2 ln p(held-out | training), summed over folds) and held-out chi^2, its held-out
//        adjusted residual per run (g); the effects ranked by evidence (those whose evidence or
//        chi^2 is not finite listed last, not ranked); each effect's fitter, kept for the
//        verdict's pairs and held spread.
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include <Eigen/Dense>

#include "validation/diagnosis/diagnose.hpp"
#include "validation/diagnosis/internal/effect_fitter.hpp"
#include "validation/diagnosis/internal/identification.hpp"

namespace vrelab::validation::internal {

// The held-out folds: leave one amplitude out, so every frequency and direction stays in
// training (a resonance cannot be located from the other frequencies) and the held-out runs
// test the effect's scaling with amplitude, which tells most effects apart; with one amplitude,
// leave one frequency out; with neither, no cross-validation (in-sample).
struct Folds {
  std::string description;
  std::vector<double> key;                   // each run's fold
  std::map<double, std::vector<int>> test;   // each fold's held-out runs
  std::vector<int> train(double k) const;    // the other folds' runs (every run when none is left)
};
Folds folds_of(const std::vector<RunRecord>& runs);

// Reference channels: when every sine run's motion is measured, the table-motion effects have
// nothing left to explain (docs/data-format.md, "Reference channels"): d.measured_effects and
// d.runs_with_measured_motion.
void note_measured_motion(const Campaign& c, Diagnosis& d);

// A candidate (an effect or a pair) as scored.
struct Scored {
  EffectFit fit;
  Eigen::VectorXd heldout;  // held-out adjusted residual per run, g
  EffectFitter::Multi all;  // the fit on all runs (its sigma with the hypothesis' accuracy)
};

// A candidate fitted on some runs: its table, and its fitted parameters' slopes over every run
// (n x k; k = 0 when a parameter ended on a bound) and covariance (k x k).
struct Fitted {
  Table t;
  Eigen::MatrixXd slopes;
  Eigen::MatrixXd cov;
};

// Scores a candidate on each fold: -2 ln p(held-out | training) and the held-out chi^2, with
// the coefficients and the candidate's parameters uncertain: the parameters, fitted on the
// training runs, enter like the coefficients, with their slopes S = d pred / d p as columns of
// G and their fitted variances beside Sigma. So an effect whose parameter the training runs pin
// only loosely (k6 from 1 and 2 g, extrapolated to 4 g) is judged with that looseness. (The
// training runs then count twice for the parameters, which makes the judgement a little strict.)
class Scorer {
 public:
  Scorer(const CampaignModel& m, const Folds& folds) : m_(m), folds_(folds) {}
  // fit_on(runs) fits the candidate on `runs`; adds to sc.fit's evidence and heldout_chi2 and
  // fills sc.heldout.
  void score(const std::function<Fitted(const std::vector<int>&)>& fit_on, Scored& sc) const;
  // A candidate with a discrete form (EffectFitter::fit_forms): fit_on(runs) fits it in each
  // form the runs leave open, with -2 ln of the form's weight (its training objective and prior
  // odds; any common constant). Each fold's held-out runs are scored by the forms' mixture:
  // -2 ln sum_c pi_c p_c(held-out | training), pi_c the normalised weights; the held-out
  // residual is the forms' mean under their posterior weights rho_c (pi_c p_c normalised) and
  // chi^2 theirs plus 2 KL(rho || pi), the price of what the held-out runs overturned of the
  // training runs' choice. So a fold whose training runs cannot choose the form (a transverse
  // motion's axis cycle from 1 and 2 g) is not judged on the one it happened to prefer.
  struct Form {
    Fitted f;
    double m2logl = 0;
  };
  void score_forms(const std::function<std::vector<Form>(const std::vector<int>&)>& fit_on, Scored& sc) const;
  // A fold whose training runs do not see the effect: its forms over the first parameter's
  // grid, each weighted by the training runs' likelihood there (docs/diagnose.md, "Held-out
  // evidence"); empty where the fold's fit stands (see evidence.cpp).
  std::vector<Form> unseen_forms(const EffectFitter& fitter, const EffectFitter::Multi& mf, const Data& dd,
                                 const std::vector<int>& train) const;
  // A fitted effect with its slope (none at a bound: sp not finite).
  Fitted fitted_at(const EffectFitter& fitter, double p, double sp) const;
  // Every parameter the runs pin (EffectFitter::fit_all): the one-parameter fit when the
  // further ones are held, else the fitted parameters' slopes and covariance.
  Fitted fitted_multi(const EffectFitter& fitter, const EffectFitter::Multi& mf) const;

 private:
  // -2 ln p(test | train) = -2 ln L(all) + 2 ln L(train): the held-out runs given what the
  // training runs say about the coefficients (the same conditioning as the shrinkage's).
  Likelihood conditional_on(const Data& dd, const Eigen::VectorXd& pred, const Eigen::MatrixXd& G,
                            const std::vector<int>& train) const;
  const CampaignModel& m_;
  const Folds& folds_;
  // The nominal's held-out -2 ln L per fold, computed once (the effects' fits on several
  // threads ask for it: under the lock).
  mutable std::map<double, Likelihood> nominal_heldout_;
  mutable std::mutex nominal_heldout_lock_;
};

struct Evidence {
  Folds folds;
  Eigen::VectorXd heldout_nominal;  // the nominal's held-out adjusted gap per run, g
  // Its expected square with no gap (g^2): the run's variance and the coefficients' error
  // left after its fold's training runs, sigma2 + G P G^T (P their conditional covariance):
  // the floor no effect can remove.
  Eigen::VectorXd heldout_floor2;
  std::vector<Scored> scored;       // ranked: best evidence first, the not ranked last
  std::map<std::string, std::unique_ptr<EffectFitter>> fitters;
};

// The folds and the nominal's held-out gap (d.folds said).
void heldout_nominal(const CampaignModel& m, Evidence& ev, Diagnosis& d);
// Every library effect not in d.measured_effects fitted, scored and ranked; d.effects filled.
// The effects on `threads` threads (0: all cores), each effect's fits and folds on one: the
// same numbers whatever the count (each is a function of the data and the effect alone; the
// response cache they share keeps what is computed first, the same numbers by any thread).
// progress: told after each effect (diagnose's EffectsProgress).
void score_effects(const CampaignModel& m, const Scorer& scorer, Evidence& ev, Diagnosis& d, int threads = 1,
                   const EffectsProgress& progress = {});

}  // namespace vrelab::validation::internal
