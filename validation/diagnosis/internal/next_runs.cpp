#include "validation/diagnosis/internal/next_runs.hpp"

#include <algorithm>
#include <cmath>
#include <exception>
#include <string>
#include <utility>
#include <vector>

namespace vrelab::validation::internal {

// Advice on the next runs: for an ambiguous or unexplained gap, the runs (direction,
// frequency, amplitude, static orientation) where the candidates' predictions differ most,
// in a run's sigma (the campaign's median, with the simulation's accuracy). The candidates: the
// ambiguous ones, else the three best by evidence, each at its fitted value; predicted from
// the identified coefficients (what the static test took up of an effect acting at rest is
// not given back here: a small part of such an effect's prediction).
void suggest_next_runs(const plant::PlantConfig& plant, const Campaign& c, double simulation_rel_accuracy, Diagnosis& d) {
  if (!(d.gap_significant && (!d.ambiguous_with.empty() || !d.explained()))) return;
  std::vector<std::pair<const Effect*, std::vector<double>>> cand;
  if (!d.ambiguous_with.empty()) {
    for (const auto& name : d.ambiguous_with)
      for (const EffectFit& f : d.effects)
        if (f.name == name) cand.emplace_back(find_effect(name), f.values());
  } else {
    for (std::size_t i = 0; i < d.effects.size() && cand.size() < 3; ++i)
      if (d.effects[i].not_ranked.empty()) cand.emplace_back(find_effect(d.effects[i].name), d.effects[i].values());
  }
  std::vector<double> sig;
  for (const RunRecord& run : c.runs) sig.push_back(run.sigma_g);
  std::nth_element(sig.begin(), sig.begin() + static_cast<std::ptrdiff_t>(sig.size() / 2), sig.end());
  const double sigma_run = sig[sig.size() / 2];
  double amax = 0;
  for (const RunRecord& run : c.runs) amax = std::max(amax, run.amplitude_g);
  std::vector<NextRun> options;
  const std::vector<Vec3> next_dirs = {Vec3(1, 0, 0), Vec3(0, 1, 0), Vec3(0, 0, 1), Vec3(1, 1, 0).normalized(),
                                  Vec3(1, 0, 1).normalized(), Vec3(0, 1, 1).normalized()};
  const std::vector<Vec3> orients = {Vec3(1, 0, 1).normalized(), Vec3(-1, 0, 1).normalized(), Vec3(1, 0, 0), Vec3(0, 1, 0)};
  for (const Vec3& dir : next_dirs)
    for (const Vec3& o : orients)
      for (double a : {amax / 4, amax / 2, amax})
        for (double f : {10.0, 30.0, 100.0, 300.0, 1000.0, 2000.0}) {
          RunRecord run;
          run.frequency_Hz = f, run.amplitude_g = a, run.direction = dir, run.orientation_g = o;
          try {
            const double p0 = predict_run_g(plant, run, nullptr, 0);
            const double sg = std::hypot(sigma_run, simulation_rel_accuracy * p0);
            std::vector<double> pr;
            for (const auto& [e, v] : cand) pr.push_back(predict_run_g(plant, run, *e, v));
            NextRun nr{f, a, dir, o, INFINITY, ""};
            for (std::size_t i = 0; i < pr.size(); ++i)
              for (std::size_t j = i + 1; j < pr.size(); ++j) {
                const double sep = std::abs(pr[i] - pr[j]) / sg;
                if (sep < nr.separation_sigma) nr.separation_sigma = sep, nr.between = cand[i].first->name + " vs " + cand[j].first->name;
              }
            if (std::isfinite(nr.separation_sigma)) options.push_back(nr);
          } catch (const std::exception&) {  // a candidate's plant that cannot run there: not advised
          }
        }
  std::sort(options.begin(), options.end(), [](const NextRun& x, const NextRun& y) { return x.separation_sigma > y.separation_sigma; });
  // The best three, each a different direction or orientation where possible (else the next best).
  for (const NextRun& nr : options) {
    if (d.next_runs.size() == 3) break;
    const bool alike = std::any_of(d.next_runs.begin(), d.next_runs.end(), [&](const NextRun& x) {
      return (x.direction - nr.direction).norm() < 1e-9 && (x.orientation_g - nr.orientation_g).norm() < 1e-9;
    });
    if (!alike) d.next_runs.push_back(nr);
  }
  for (const NextRun& nr : options) {
    if (d.next_runs.size() == 3) break;
    if (std::none_of(d.next_runs.begin(), d.next_runs.end(), [&](const NextRun& x) { return &x == &nr || (x.frequency_Hz == nr.frequency_Hz && x.amplitude_g == nr.amplitude_g && (x.direction - nr.direction).norm() < 1e-9 && (x.orientation_g - nr.orientation_g).norm() < 1e-9); }))
      d.next_runs.push_back(nr);
  }
}

}  // namespace vrelab::validation::internal
