#include "validation/identification/static_test.hpp"

#include <algorithm>
#include <random>
#include <stdexcept>
#include <string>

namespace vrelab::validation {

StaticTestReport run_static_test(const plant::Coefficients& truth, const std::vector<Position>& positions,
                                 const StaticTestErrors& errors, const StaticTestSettings& settings,
                                 const OutputSource& given_source) {
  StaticTestReport report;
  std::mt19937_64 rng(settings.seed);
  const OutputSource source = given_source ? given_source : model1_source(truth);
  report.readings = simulate_static_test(source, truth[plant::K1], positions, errors, rng);

  // Weights: 1 / first-order variance of each reading at an unweighted first fit.
  const LeastSquaresResult first = least_squares(positions, report.readings, {}, settings.fixed);
  const ReadingBudget budget = reading_budget(first.estimate.value, positions, report.readings, errors);
  std::vector<double> weights;
  const double max_var = *std::max_element(budget.variance.begin(), budget.variance.end());
  if (max_var > 0)
    for (double v : budget.variance) weights.push_back(1.0 / std::max(v, 1e-12 * max_var));

  std::vector<std::pair<std::string, Estimator>> estimators;
  const std::optional<double> k1_tilde = settings.fixed[plant::k1_asym];
  if (!is_paper_set(positions)) {
    report.notes.push_back("paper_printed and paper_corrected need the paper's 3 x 8 position set; not run");
  } else if (!k1_tilde) {
    report.notes.push_back("paper_printed and paper_corrected take k1' from elsewhere: give k1_asym in "
                           "[identification] fixed to run them; not run");
  } else {
    estimators.emplace_back("paper_printed", [&positions, k1 = *k1_tilde](const std::vector<Reading>& r) {
      return paper_printed(*paper_table(positions, r), k1);
    });
    const double kpp = settings.fixed[plant::k_PP].value_or(0.0), koo = settings.fixed[plant::k_OO].value_or(0.0);
    estimators.emplace_back("paper_corrected", [&positions, k1 = *k1_tilde, kpp, koo](const std::vector<Reading>& r) {
      return paper_corrected(*paper_table(positions, r), k1, kpp, koo);
    });
    if (kpp != 0 || koo != 0)
      report.notes.push_back("paper_printed assumes k_PP = k_OO = 0 (as printed); paper_corrected uses the fixed values");
    for (int i : {plant::K1, plant::k0, plant::k2, plant::k3, plant::k4, plant::delta_OA, plant::delta_PA, plant::k_IP,
                  plant::k_IO, plant::k_PO})
      if (settings.fixed[i])
        report.notes.push_back(std::string("the paper's formulas estimate ") + std::string(plant::coefficient_name(i)) +
                               " and ignore its fixed value; least_squares holds it");
  }
  const FixedSet fixed = settings.fixed;
  estimators.emplace_back("least_squares", [&positions, weights, fixed](const std::vector<Reading>& r) {
    return least_squares(positions, r, weights, fixed).estimate;
  });
  report.identifiability = least_squares(positions, report.readings, weights, fixed).identifiability;

  std::vector<Estimator> fns;
  for (const auto& [name, fn] : estimators) {
    MethodResult m;
    m.name = name;
    m.estimate = fn(report.readings);
    m.first_order = propagate_first_order(fn, report.readings, budget);
    report.methods.push_back(m);
    fns.push_back(fn);
  }
  // An accepted identification must reproduce its readings (identification.hpp).
  report.fit = check_fit(positions, report.readings, report.methods.back().estimate, budget.variance,
                         report.identifiability.parameters);
  if (!report.fit.problem.empty()) throw std::invalid_argument("least squares: " + report.fit.problem);
  if (settings.monte_carlo_trials > 0) {
    const auto stats = monte_carlo(fns, truth, source, positions, errors, settings.monte_carlo_trials, settings.seed + 1,
                                    0, settings.monte_carlo_checkpoint);
    for (std::size_t i = 0; i < stats.size(); ++i) report.methods[i].monte_carlo = stats[i];
  }
  return report;
}

}  // namespace vrelab::validation
