#pragma once
// validation/diagnosis/internal/effect_fitter.hpp -- the fit of one effect's parameters to a
// campaign's runs (docs/diagnose.md, "Natural forms").
//
// Takes: an effect's parameters (nominal values, ranges, priors, the further parameters' starts,
//        a nonlinear first parameter's grid), the table of the runs without it, a model that
//        tabulates the runs at any parameter values (predictions in g and their gradient in the
//        coefficients), the runs' data (measured g, variances g^2, the coefficients' covariance)
//        and the runs to fit on (indices).
// Gives: the maximum-likelihood values of the parameters the runs pin (the first by a grid
//        scan and parabolic refinement, the further continuous ones with it by Levenberg-
//        Marquardt with a narrow-valley Newton step, a discrete one chosen by likelihood), in
//        the parameters' units; their covariance from the objective's Hessian; which further
//        parameters are held at nominal (not pinned: sigma not below the prior width, or a
//        slope in the others' span); the slopes d pred / d parameter over every run; and the
//        reported sigma widened by the hypothesis' own accuracy and by the held parameters'
//        spread.
//
// The objective is -2 ln L of the runs with V = diag(sigma2) + G Sigma G^T at the current
// values (internal/likelihood.hpp) plus the further parameters' weak Gaussian priors.
// Implementation: effect_fitter.cpp (tables, the fits' driver, the first parameter's fit),
// effect_fitter_descent.cpp (Jacobian, held parameters, Levenberg-Marquardt, the valley step),
// effect_fitter_covariance.cpp (the Hessian covariance, model error, held spread, profiles).
#include <cmath>
#include <cstdint>
#include <functional>
#include <map>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/Dense>

#include "validation/diagnosis/diagnose.hpp"
#include "validation/diagnosis/effect.hpp"
#include "validation/diagnosis/internal/likelihood.hpp"
#include "validation/diagnosis/internal/response_cache.hpp"

namespace vrelab::validation::internal {

// One effect: its tables (linear effects: nominal and unit, interpolated), the fit of its
// parameters on a set of runs, the model at any parameter value.
class EffectFitter {
 public:
  // The simulation of every run at one value per parameter of the effect (g, and the gradient
  // in the coefficients); throws std::invalid_argument where the plant cannot take the values.
  // The diagnosis' is tabulate() under the effect's hypothesis (make_effect_fitter).
  using TableAt = std::function<Table(const std::vector<double>& values)>;
  // e: the parameters' nominal values, ranges, priors, starts and grid, and the hypothesis'
  // accuracy (its hooks are not called); nominal: the table without the effect (kept by
  // reference: it must outlive the fitter). A linear first parameter is tabulated once at its
  // unit value, a nonlinear one on its grid.
  EffectFitter(const Effect& e, const Table& nominal, TableAt table_at);
  const Effect& effect() const { return e_; }
  // A nonlinear first parameter's grid (the values the plant takes; empty for a linear one).
  const std::vector<double>& grid() const { return values_; }
  Table at(double p) const;
  // At every parameter's value (the further ones nominal: the tables above). A linear first
  // parameter stays linear at any value of the others.
  Table at(const std::vector<double>& v) const;
  // d pred / d p at p: exact for linear effects, central over +-h for the others (a value the
  // plant refuses: one-sided).
  Eigen::VectorXd slope(double p, double h) const;
  // Maximum likelihood of the first parameter over the runs `idx`, the others nominal; sigma
  // from the curvature of -2 log L.
  std::pair<double, double> fit(const Data& d, const std::vector<int>& idx) const { return fit_first(d, idx, nominal_values_); }
  // The first parameter's fit with the others at base's values. A function of its inputs
  // alone: kept per (data, runs, base), bit for bit (the folds' fits, the final fit, the
  // pairs' and the natural forms' starts ask for the same fits again).
  std::pair<double, double> fit_first(const Data& d, const std::vector<int>& idx, const std::vector<double>& base) const;
  // The first parameter's fit (the others nominal) beside another effect that changes the
  // coefficients' gradient: every table's G with dG added (a pair's G_A - G_0), as the pair's
  // likelihood takes it. Not kept.
  std::pair<double, double> fit_beside(const Data& d, const std::vector<int>& idx, const Eigen::MatrixXd& dG) const {
    return fit_first_uncached(d, idx, nominal_values_, &dG);
  }

  // Every parameter the runs `idx` pin (docs/diagnose.md, "Natural forms"): the first
  // parameter's fit at each start of the further ones (their `starts`, the nominal first); a
  // discrete parameter's value (the form) chosen by the fitted forms' objectives (fit_forms:
  // the default form unless another lowers it by kDiscreteGain and lowers -2 ln L against no
  // effect by kSeen); in each form, Levenberg-Marquardt on the first and the continuous further
  // parameters, on -2 ln L with the weak Gaussian priors of the further ones, each step's
  // covariance V at the current value (the coefficients' errors taken out as in the one-
  // parameter fit). A further parameter whose sigma from the data alone is not smaller than
  // its prior width, or whose slope the others' span (ColPivHouseholderQR's rank), is held at
  // its nominal. When every further parameter is held, the result is the one-parameter fit.
  struct Multi {
    std::vector<double> values;
    std::vector<int> free;         // the parameters fitted continuously (the first among them when any further is)
    Eigen::MatrixXd cov;           // their covariance (free.size() square); empty: the one-parameter fit
    std::vector<ParameterStatus> status;
    std::vector<double> sigma;     // per parameter (NaN: held or chosen)
    Eigen::MatrixXd slopes;        // n x free.size(), over every run
  };
  static constexpr double kDiscreteGain = 4, kSeen = 25;
  Multi fit_all(const Data& d, const std::vector<int>& idx) const;

  // A natural form with a discrete parameter, fitted in each of its forms (a mode on each
  // axis): what a fold's training runs say when they cannot choose (docs/diagnose.md, "Natural
  // forms", step 5). Each form (its best start) is fitted as fit_all fits its chosen one,
  // whatever its start's -2 ln L; m2logl is its objective at its fit (-2 ln L with the
  // further parameters' priors) plus -2 ln of its prior odds against the default form
  // (kDiscreteGain for any other form, the choice's own Bayes factor). An effect without a
  // discrete parameter: fit_all's fit alone, or where the descents from its starts end in
  // distinct valleys (a harmonic's phase on either side of the circle, which 1 and 2 g runs
  // cannot tell apart), each valley as a form weighted by its objective (no prior odds: one
  // form's valleys), so that the held-out runs choose between them.
  struct Form {
    Multi mf;
    double m2logl = 0;
  };
  std::vector<Form> fit_forms(const Data& d, const std::vector<int>& idx) const;

  // The fitted parameters' sigma with the hypothesis' own error added: the change the effect
  // makes, Delta = pred(v) - pred(nominal), is right to hypothesis_accuracy f (not better:
  // test_effect_sweep.cpp). That error is systematic (the same approximation at every run,
  // smooth in frequency and amplitude), not noise: taken as one common relative error
  // e = eps f Delta, eps ~ N(0, 1), it moves the estimate by b eps, and the covariance gains
  // b b^T. b comes from two refits: the fit repeated on the data shifted by +f Delta and by
  // -f Delta (the effect's change scaled by 1 -+ f), each a Levenberg-Marquardt descent from the
  // fitted values over the same free parameters (not the multi-start: the shift is small), and
  // b = (v+ - v-) / 2 (each refit's shift of a phase taken the short way round, within +-pi). For a linear one-parameter
  // effect b = f p (the parameter known to f of itself); errors independent run by run would
  // give f p / sqrt(N) of N like runs, which a systematic error does not average down. Without it a
  // large effect seen at hundreds of sigma has sigma from the noise only (a harmonic's phase 4
  // sigma off its truth at 0.056 rad); a small one's covariance barely changes (f Delta <<
  // sigma_run). The refits, not the first-order shift b = C J^T V^-1 f Delta: that mixes the
  // objective's Hessian (C) with the Gauss-Newton slopes J, which overstate a harmonic's phase
  // curvature hundredfold, and would report phases within 0.04-0.39 rad of their truth
  // +- 5-12 rad (seeds 8801, 8901).
  // A refit that fails (the plant refuses a value) or ends on a non-periodic parameter's bound
  // is not used: the other side's shift alone (v -+ v, one-sided) stands for it, and with neither
  // the first-order shift does. Reported only: the folds' fits, the evidence and the verdict do
  // not use it.
  void add_model_error(const Data& d, const std::vector<int>& idx, Multi& mf) const;

  // What a held further parameter's uncertainty does to the fitted parameters (docs/diagnose.md,
  // "Natural forms"). Held at its nominal because the data do not pin it there, it is
  // not known to be there: the fitted parameters' values depend on where it is (a 2nd
  // harmonic's ratio fitted with its phase held at 0 comes out 0.072 +- 0.015 for a truth of
  // 0.142 at 0.97 rad: seed 8901, campaign 90, with a descent that has no trust step). It is
  // marginalised over its range: at kHeldPoints values x spread evenly across the range (a
  // phase's round the circle, its nominal 0 among them), the fitted parameters are refitted
  // with it held at x (the first by its one-parameter fit, then the others with it by
  // Levenberg-Marquardt from there), and each x is weighted by its likelihood exp(-(F(x) -
  // F_min)/2), F the objective with the fitted parameters' and its own prior (a phase has none:
  // uniform round the circle) -- a quadrature of the marginal posterior, the Laplace factor
  // det C(x)^(1/2) left out. The weighted second moment of the refitted values about the
  // reported ones joins their covariance (a phase's differences taken round the circle). The
  // grid resolves what it marginalises: a held parameter's sigma from the data is at least its
  // prior width, a quarter of its range, and the grid's step is an eighth of it; a narrow
  // valley elsewhere that the grid misses weighs too little (a fit that missed it is the
  // descent's to find). Each held continuous parameter on its own, the others at their nominals,
  // their shares added; a discrete one held at its nominal is a choice (the Bayes factor of
  // step 2), not profiled. Reported only, as the hypothesis' accuracy: the folds, the evidence
  // and the verdict do not use it.
  static constexpr int kHeldPoints = 8;
  void add_held_spread(const Data& d, const std::vector<int>& idx, Multi& mf) const;

  // -2 ln L's profile over parameter j: at each x of xs, the other parameters of mf's fit
  // refitted with j held at x (the first by its one-parameter fit, robust to a far valley; the
  // further ones of mf's free set with it by Levenberg-Marquardt from there); the objective
  // with the priors of every further parameter among them and j's.
  struct ProfilePoint {
    double x = 0, objective = INFINITY;
    std::vector<double> values;
  };
  std::vector<ProfilePoint> profile(const Data& d, const std::vector<int>& idx, const Multi& mf, int j,
                                    const std::vector<double>& xs) const;

 private:
  // The first parameter's fit with the others nominal, and each start of the further ones
  // (the nominal first) with the first fitted there and -2 ln L over the runs at it.
  struct Starts {
    std::pair<double, double> first;
    std::vector<std::vector<double>> v;
    std::vector<double> l;
  };
  Starts starts(const Data& d, const std::vector<int>& idx) const;
  // fit_all's steps 3-4 from start `best` (its form's discrete values kept).
  // valleys (when given): every descent's end as a form (its objective the weight), one per
  // valley (same_valley), the lower kept.
  Multi fit_from(const Data& d, const std::vector<int>& idx, const Starts& s, std::size_t best,
                 std::vector<Form>* valleys = nullptr) const;
  // The same valley: the same parameters fitted, each within 3 sigma (the larger) of the other
  // (a periodic one round the circle).
  bool same_valley(const Multi& a, const Multi& b) const;
  std::vector<Form> fit_forms(const Data& d, const std::vector<int>& idx, const Starts& s) const;
  bool any_discrete() const;                                                         // a further parameter is discrete
  bool discrete_nominal(const std::vector<double>& v) const;                       // every discrete parameter at its nominal
  bool same_form(const std::vector<double>& a, const std::vector<double>& b) const;  // the same discrete values
  // The parameters mf fitted: its free set, or the first alone (the one-parameter fit).
  static std::vector<int> fitted_set(const Multi& mf) { return mf.cov.size() > 0 ? mf.free : std::vector<int>{0}; }
  bool further_nominal(const std::vector<double>& v) const;
  // The continuous further parameters not in fr set to their nominal.
  void hold_nominal(std::vector<double>& v, const std::vector<int>& fr) const;
  // Levenberg-Marquardt from one start, the unpinned further parameters held (`fr` shrinks to
  // what is left); false when every continuous further parameter ended held. res: the fitted
  // values, free set, slopes, covariance, status and sigma.
  bool descend(const Data& d, const std::vector<int>& idx, const std::vector<double>& from, std::vector<int>& fr, Multi& res) const;
  static std::vector<double> with_first(std::vector<double> v, double p);
  // The tabulation at v, kept (the folds and the final fit revisit the same values).
  Table table(const std::vector<double>& v) const;
  // The weak Gaussian prior's weight 1 / width^2 of a further parameter (none on an angle
  // that wraps round: its range is the whole circle).
  double prior_weight(int j) const;
  // The first parameter's range (its grid's for a nonlinear one) and each further one's.
  std::pair<double, double> range(int j) const;
  // A periodic further parameter (a phase) has no bound: x taken round into [lo, hi) (a phase
  // in [-pi, pi): +pi is -pi; a value inside is kept as it is, to the bit).
  bool wraps(int j) const { return j > 0 && e_.parameters[static_cast<std::size_t>(j)].periodic; }
  double wrapped(int j, double x) const;
  double step(const std::vector<double>& v, int j) const;
  // d pred / d v_j over every run for j in `free`: central differences (one-sided at a bound
  // or where the plant refuses a value; a phase's taken round the circle: it has no bound).
  Eigen::MatrixXd jacobian(const std::vector<double>& v, const std::vector<int>& free) const;
  // The further parameters of `free` the runs idx do not pin at v: a rank-deficient whitened
  // Jacobian (the first such column, in ColPivHouseholderQR's pivot order, beyond the rank),
  // else those whose sigma from the data alone is not below their prior width.
  std::vector<int> unpinned(const Data& d, const std::vector<int>& idx, const std::vector<double>& v,
                            const std::vector<int>& free) const;
  // -2 ln L over idx at v with the further parameters' priors (those in `free`).
  double objective_at(const Data& d, const std::vector<int>& idx, const std::vector<double>& w,
                      const std::vector<int>& free) const;
  // The fitted parameters' covariance at v: the inverse of half the objective's Hessian
  // (-2 ln L with the priors), every entry by central differences, each parameter stepped by
  // half its Gauss-Newton sigma (J^T V^-1 J with the priors; J over every run, `slopes`). The
  // Levenberg-Marquardt information took its diagonal from second differences over the slopes'
  // step (1e-3 rad for a phase), where -2 ln L (about -4800 on 168 runs) changes by less than the
  // simulation's own rounding and tolerances: a harmonic's phase got 0.0094 rad where -2 ln L
  // rose by 0.13 over 0.1 rad (sigma ~0.28; the truth 0.076 rad away, 0.29 above the minimum:
  // "7.6 sigma off"). Falls back to that information where the Hessian is not positive
  // definite or a step would leave the range.
  Eigen::MatrixXd covariance_at(const Data& d, const std::vector<int>& idx, const std::vector<double>& v,
                                const std::vector<int>& free, const Eigen::MatrixXd& slopes) const;
  // One descent step in a valley narrower than the differences (docs/diagnose.md, "Natural
  // forms", step 3): where a parameter's difference step spans more than kNarrowSigmas of its
  // conditional sigma 1/sqrt(c) (c the objective's curvature along it over that step: -2 ln L
  // rises by more than kNarrowSigmas^2 across the step), the differences straddle a curved
  // valley's walls and their slope can have the wrong sign (seed 9601, campaign 30: a mode's
  // frequency and damping, correlation -0.998, differences 50 and 10 conditional sigma wide;
  // the descent stopped 23.6 of -2 ln L above the truth). The gradient and the whole Hessian
  // (the mixed terms too: Gauss-Newton's correlations miss what the parameters do to V and the
  // prediction's curvature, and a valley's direction is the small difference of two large
  // numbers) are then taken by central differences over kLocalSigmas of each parameter's
  // conditional sigma (at most its usual step), and the step is Newton's, halved until the
  // objective falls (a backtracking line search: the descent stays monotone and follows the
  // valley instead of zig-zagging across it as Levenberg-Marquardt's damping towards the
  // gradient makes it). Over 0.3 sigma the differences' -2 ln L changes by ~0.1, far above its
  // rounding. v and f move to the accepted point. Returns nothing where the valley is not
  // narrow, the local Hessian is not positive definite or its step finds no decrease
  // (Levenberg-Marquardt's step then), else whether the descent stops (every move below 1e-3
  // conditional sigma).
  static constexpr double kNarrowSigmas = 1, kLocalSigmas = 0.3;
  std::optional<bool> valley_step(const Data& d, const std::vector<int>& idx, const std::vector<int>& free,
                                  std::vector<double>& v, double& f, const Eigen::VectorXd& steps,
                                  const Eigen::VectorXd& curv) const;
  // Levenberg-Marquardt on -2 ln L + the further parameters' priors over `free`, from v.
  std::vector<double> levenberg_marquardt(const Data& d, const std::vector<int>& idx, std::vector<double> v,
                                          const std::vector<int>& free) const;
  std::pair<double, double> fit_first_uncached(const Data& d, const std::vector<int>& idx, const std::vector<double>& base,
                                               const Eigen::MatrixXd* dG = nullptr) const;

  const Effect& e_;
  const Table& nominal_;
  TableAt table_at_;
  Table unit_;
  std::vector<Table> grid_;
  std::vector<double> values_;  // the grid's values the plant can take
  mutable std::map<double, Table> extra_;
  std::vector<double> nominal_values_;
  mutable std::map<std::vector<double>, Table> tables_;
  mutable bool cov_never_definite_ = false;  // covariance_at's Hessian never positive definite
  mutable Eigen::MatrixXd last_info_;  // levenberg_marquardt's information matrix at its last point
  mutable std::map<std::vector<std::uint64_t>, std::pair<double, double>> fits_;  // fit_first's, by its inputs' bits
};

// The diagnosis' fitter of e: its tables by tabulate() from the identified plant, the runs,
// the cache and what the static test takes up (each kept by reference: they must outlive it).
EffectFitter make_effect_fitter(const Effect& e, const Table& nominal, const plant::PlantConfig& plant,
                                const std::vector<RunRecord>& runs, ResponseCache& cache, const Absorbed& absorbed);

// Each parameter of e as fitted (value, sigma, status, range, at_bound:
// the first one's sigma not finite or its value on its range's edge, a further fitted one's
// value on its edge (a periodic one has none)).
std::vector<FittedParameter> fitted_parameters(const Effect& e, const EffectFitter::Multi& mf);

}  // namespace vrelab::validation::internal
