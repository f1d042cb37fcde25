// The diagnosis as a pipeline of stages, in docs/diagnose.md's order (steps 1-11, "4. Lab
// nuisances" among them): each stage is a file of validation/diagnosis/internal/ with a header
// saying what it takes and gives.
#include "validation/diagnosis/diagnose.hpp"

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include <Eigen/Dense>

#include "validation/diagnosis/internal/confirmation.hpp"
#include "validation/diagnosis/internal/evidence.hpp"
#include "validation/diagnosis/internal/gap.hpp"
#include "validation/diagnosis/internal/identification.hpp"
#include "validation/diagnosis/internal/next_runs.hpp"
#include "validation/diagnosis/internal/nuisances.hpp"
#include "validation/diagnosis/internal/response_cache.hpp"
#include "validation/diagnosis/internal/stage_options.hpp"
#include "validation/diagnosis/internal/verdict.hpp"

namespace vrelab::validation {

std::vector<double> EffectFit::values() const {
  std::vector<double> v;
  for (const FittedParameter& q : parameters) v.push_back(q.value);
  if (v.empty()) v.push_back(value);
  return v;
}

const Nuisance* Diagnosis::nuisance(const std::string& name) const {
  for (const Nuisance& x : nuisances)
    if (x.name == name) return &x;
  return nullptr;
}

double Diagnosis::shrinkage_above_floor() const {
  // What lies above the floor, in quadrature (noise and a gap add as variances).
  const auto above = [&](double rms) { return std::sqrt(std::max(0.0, rms * rms - rms_floor_g * rms_floor_g)); };
  const double before = above(rms_before_g);
  return before > 0 ? 1 - above(rms_after_g) / before : NAN;
}

internal::StageOptions internal::stage_options(const DiagnoseSettings& s) {
  StageOptions o;
  o.simulation_rel_accuracy = s.model_accuracy;
  o.gap.threshold_sigma = s.significance_sigma;
  o.verdict = {.threshold_sigma = s.significance_sigma,
               .min_rms_removed = s.explained_shrinkage,
               .try_two_effects = s.try_pairs,
               .tie_evidence = s.ambiguity_evidence};
  o.scatter = {.structure_threshold_sigma = s.structure_sigma,
               .threshold_sigma = s.significance_sigma};
  o.next_runs = s.advise_next_runs;
  o.max_resimulated_runs = s.resimulate_runs;
  return o;
}

namespace {

// One diagnosis of a campaign whose drift is removed, with its runs' sigma as given. cache: the
// tables and what the static test takes up, shared by the wrapper's passes over the same
// campaign (the runs' sigma may differ between them, nothing else).
Diagnosis diagnose_once(const Campaign& c, const internal::StageOptions& o, internal::ResponseCache& cache, int threads,
                        const EffectsProgress& progress) {
  using namespace internal;
  Diagnosis d;
  note_measured_motion(c, d);  // the table-motion effects a reference channel measures
  // 1. Identification: the coefficients, their covariance, the runs' data.
  const Identified id = identify(c);
  d.identified = id.plant.coefficients;
  d.identified_uncertainty = id.uncertainty;
  // 2. The nominal simulation (and what the static test takes up of each effect acting at rest).
  CampaignModel m{c, o.simulation_rel_accuracy, cache};
  nominal_model(id, m);
  // 3. The gap and where it lies.
  const Eigen::VectorXd r = locate_gap(m, o.gap, d);
  // 4. Attribution: each effect fitted on training runs, scored on the held-out ones.
  Evidence ev;
  heldout_nominal(m, ev, d);
  const Scorer scorer(m, ev.folds);
  score_effects(m, scorer, ev, d, threads, progress);
  // 4-5. The verdict (pairs, ambiguity) and the held-out shrinkage.
  const Chosen chosen = judge(m, ev, scorer, o.verdict, d);
  if (o.next_runs) suggest_next_runs(m, d);  // for an ambiguous or unexplained gap
  // 6. Confirmation on the ODE.
  confirm_on_ode(m, chosen, r, o.max_resimulated_runs, d);
  return d;
}

}  // namespace

Diagnosis diagnose(const Campaign& c0, const DiagnoseSettings& s, int threads, const EffectsProgress& progress) {
  const internal::StageOptions o = internal::stage_options(s);
  Campaign c = c0;
  const Nuisance drift = remove_drift(c);  // the bias drift, removed first
  internal::ResponseCache cache;
  Diagnosis d = diagnose_once(c, o, cache, threads, progress);
  // The stated sigma: scaled and judged again when the gaps say it is scatter.
  const Nuisance scale =
      internal::sigma_scale(c, o.scatter, d, [&](const Campaign& scaled) { return diagnose_once(scaled, o, cache, threads, progress); });
  d.nuisances = {drift, scale};  // (a drift removed or a sigma scaled is said after the verdict: verdict_text)
  return d;
}

}  // namespace vrelab::validation
