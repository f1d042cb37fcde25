#include "validation/diagnosis/internal/shrinkage.hpp"

#include <cmath>

namespace vrelab::validation::internal {

void shrinkage_before(const Eigen::VectorXd& heldout_nominal, const Eigen::VectorXd& heldout_floor2, const Data& data,
                      Diagnosis& d) {
  const int n = static_cast<int>(heldout_nominal.size());
  double ss_b = 0, zs_b = 0, ss_f = 0, zs_f = 0;
  for (int k = 0; k < n; ++k) {
    ss_b += heldout_nominal(k) * heldout_nominal(k), zs_b += heldout_nominal(k) * heldout_nominal(k) / data.sigma2(k);
    ss_f += heldout_floor2(k), zs_f += heldout_floor2(k) / data.sigma2(k);
    d.runs[static_cast<std::size_t>(k)].heldout_before_g = heldout_nominal(k);
    d.runs[static_cast<std::size_t>(k)].heldout_floor_g = std::sqrt(heldout_floor2(k));
  }
  d.rms_before_g = std::sqrt(ss_b / n), d.rms_before_sigma = std::sqrt(zs_b / n);
  d.rms_floor_g = std::sqrt(ss_f / n), d.rms_floor_sigma = std::sqrt(zs_f / n);
}

void shrinkage_after(const Scored& best_candidate, const Data& data, Diagnosis& d) {
  const Scored* best = &best_candidate;
  const int n = static_cast<int>(best->heldout.size());
  double ss_a = 0, zs_a = 0;
  for (int k = 0; k < n; ++k) {
    ss_a += best->heldout(k) * best->heldout(k), zs_a += best->heldout(k) * best->heldout(k) / data.sigma2(k);
    d.runs[static_cast<std::size_t>(k)].heldout_after_g = best->heldout(k);
  }
  d.rms_after_g = std::sqrt(ss_a / n), d.rms_after_sigma = std::sqrt(zs_a / n);
  if (!best->fit.not_ranked.empty()) {  // no effect ranked: nothing removed
    d.rms_after_g = d.rms_before_g, d.rms_after_sigma = d.rms_before_sigma;
    for (RunDiagnosis& rd : d.runs) rd.heldout_after_g = rd.heldout_before_g;
  }
}

}  // namespace vrelab::validation::internal
