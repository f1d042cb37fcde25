#include "validation/diagnosis/internal/confirmation.hpp"

#include <algorithm>
#include <cmath>
#include <exception>
#include <string>
#include <vector>

#include "rectification/simulation/shake.hpp"
#include "validation/diagnosis/internal/tabulate.hpp"

namespace vrelab::validation::internal {

using plant::PlantConfig;

// 5. Confirmation on the ODE plant: the runs with the largest gaps re-simulated with the
// coefficients corrected by all runs (under the chosen effect) and the effect added, and
// without it.
void confirm_on_ode(const CampaignModel& m, const Chosen& chosen, const Eigen::VectorXd& r, int max_runs, Diagnosis& d) {
  if (!(max_runs > 0 && d.explained())) return;
  const Campaign& c = m.campaign;
  const PlantConfig& plant = m.plant;
  const Data& data = m.data;
  const Table& nominal = m.nominal;
  const Absorbed& absorbed = m.absorbed;
  const std::vector<int>& all = m.all;
  ResponseCache& cache = m.cache;
  // The chosen effect(s) applied to a plant and a table motion; less what the static test
  // took up of those that act at rest.
  const auto apply_chosen = [&](PlantConfig& cfg, TableMotion& v, bool give_back) {
    for (const auto& [e, values] : chosen) {
      e->apply(values, cfg, v);
      if (give_back && e->acts_at_rest)
        for (int i = 0; i < plant::kNumCoefficients; ++i)
          cfg.coefficients[i] -= (values.front() - e->fitted().nominal) * absorbed.at(e->name)[i];
    }
  };
  Table t = tabulate(plant, c.runs, chosen[0].first, chosen[0].second, cache, absorbed);
  for (std::size_t q = 1; q < chosen.size(); ++q) {
    const Table u = tabulate(plant, c.runs, chosen[q].first, chosen[q].second, cache, absorbed);
    t.pred += u.pred - nominal.pred, t.G += u.G - nominal.G;
  }
  const Eigen::VectorXd dc = factored(data, t.G, all).conditional_mean(data.measured - t.pred);
  PlantConfig corrected = plant;
  for (int i = 0; i < plant::kNumCoefficients; ++i) corrected.coefficients[i] += dc(i);
  std::vector<int> order = all;
  // Random runs are not re-simulated here (the ODE measures them statistically, seconds each).
  // Nor are runs with measured motion (the ODE takes the commanded sine and the effects).
  std::erase_if(order, [&](int k) {
    return c.runs[static_cast<std::size_t>(k)].random.has_value() || c.runs[static_cast<std::size_t>(k)].motion.has_value();
  });
  std::sort(order.begin(), order.end(), [&](int a, int b) { return std::abs(r(a)) > std::abs(r(b)); });
  order.resize(std::min<std::size_t>(order.size(), static_cast<std::size_t>(max_runs)));
  double sb = 0, sa = 0;
  int done = 0;
  for (int k : order) {
    const RunRecord& run = c.runs[static_cast<std::size_t>(k)];
    const vibration::SineVibration commanded = run.vibration();
    PlantConfig with = corrected;
    TableMotion table = table_motion(run);
    apply_chosen(with, table, true);
    try {
      const double ode_with = rectification::shake_sine(with, run.orientation_g, commanded, {}, {}, table.excitation().get()).measured_g;
      const double ode_without = rectification::shake_sine(corrected, run.orientation_g, commanded).measured_g;
      sb += std::pow(run.measured_g - ode_without, 2), sa += std::pow(run.measured_g - ode_with, 2);
      ++done;
    } catch (const std::exception& x) {  // a solver failure: said, and the other runs still count
      d.resimulation_failures.push_back(run.id + ": " + x.what());
    }
  }
  d.resimulated_runs = done;
  if (done > 0) {
    d.resimulated_rms_before_g = std::sqrt(sb / done);
    d.resimulated_rms_after_g = std::sqrt(sa / done);
  }
}

}  // namespace vrelab::validation::internal
