#include "validation/diagnosis/internal/identification.hpp"

#include <array>
#include <cmath>
#include <map>
#include <optional>
#include <stdexcept>
#include <string>

#include "validation/diagnosis/internal/tabulate.hpp"

namespace vrelab::validation {

using plant::Coefficients;
using plant::PlantConfig;

namespace {
// The fit to the plant's own readings at rest (the "without" of taken_up_by_static_test; the
// same for every effect: diagnose computes it once). A reading is the plant's equilibrium at
// the position (plant::rest_output_g: what a static test settles to, without the ODE).
Coefficients rest_fit(const PlantConfig& plant, const std::vector<Position>& positions, const std::vector<double>& weights,
                         const FixedSet& fixed) {
  std::vector<Reading> readings;
  const double K1 = plant.coefficients[plant::K1];
  // A position read more than once (a static test's repeats) is solved once: the same plant
  // at the same orientation rests at the same number.
  std::map<std::array<double, 3>, double> at_rest;
  for (std::size_t i = 0; i < positions.size(); ++i) {
    const Vec3& g = positions[i].nominal_g;
    const std::array<double, 3> at{g[0], g[1], g[2]};
    auto it = at_rest.find(at);
    if (it == at_rest.end()) it = at_rest.emplace(at, plant::rest_output_g(plant, g)).first;
    readings.push_back({static_cast<int>(i), K1 * it->second});
  }
  return least_squares(positions, readings, weights, fixed).estimate.value;
}

Coefficients taken_up_given_base(const Effect& e, const PlantConfig& plant, const std::vector<Position>& positions,
                                 const std::vector<double>& weights, const FixedSet& fixed, const Coefficients& b) {
  if (!e.fitted().linear) throw std::logic_error("diagnose: " + e.name + " acts at rest but is not linear");
  PlantConfig with = plant;
  TableMotion unused;
  e.apply(e.fitted().unit_value, with, unused);
  // Least squares is linear in the readings: the difference of the fits to the plant's
  // readings at rest with and without the effect.
  const Coefficients m = rest_fit(with, positions, weights, fixed);
  Coefficients diff;
  for (int i = 0; i < plant::kNumCoefficients; ++i) diff[i] = (m[i] - b[i]) / (e.fitted().unit_value - e.fitted().nominal);
  return diff;
}
}  // namespace

Coefficients taken_up_by_static_test(const Effect& e, const PlantConfig& plant, const std::vector<Position>& positions,
                                     const std::vector<double>& weights, const FixedSet& fixed) {
  if (!e.fitted().linear) throw std::logic_error("diagnose: " + e.name + " acts at rest but is not linear");
  return taken_up_given_base(e, plant, positions, weights, fixed, rest_fit(plant, positions, weights, fixed));
}

namespace internal {

Identified identify(const Campaign& c) {
  if (c.statics.empty()) throw std::invalid_argument("diagnose: the campaign has no static readings");
  if (c.runs.empty()) throw std::invalid_argument("diagnose: the campaign has no usable shaker runs");
  Identified id;
  std::vector<Reading> readings;
  ReadingBudget budget;
  for (std::size_t i = 0; i < c.statics.size(); ++i) {
    id.positions.push_back(vector_position(c.statics[i].orientation_g.normalized()));
    readings.push_back({static_cast<int>(i), c.statics[i].output});
    const double var = std::max(c.statics[i].sigma_output * c.statics[i].sigma_output, 1e-30);
    id.weights.push_back(1 / var);
    budget.variance.push_back(var);
    budget.bias.push_back(0.0);
  }
  const LeastSquaresResult ls = least_squares(id.positions, readings, id.weights, c.fixed);
  if (!ls.identifiability.full_rank()) {
    std::string msg = "the static readings do not determine the free coefficients (rank " +
                      std::to_string(ls.identifiability.rank) + " of " + std::to_string(ls.identifiability.parameters) + ")";
    for (const auto& w : ls.identifiability.confounded) msg += "; " + w;
    throw std::invalid_argument(msg + ": hold more coefficients in the manifest's [identification] fixed, or add positions");
  }
  const Estimator est = [&](const std::vector<Reading>& r) { return least_squares(id.positions, r, id.weights, c.fixed).estimate; };
  id.uncertainty = propagate_first_order(est, readings, budget);
  id.plant.coefficients = ls.estimate.value;
  id.plant.dynamics = c.dynamics;
  const int n = static_cast<int>(c.runs.size());
  Data& data = id.data;
  data.measured.resize(n), data.sigma2.resize(n);
  for (int k = 0; k < n; ++k) {
    data.measured(k) = c.runs[static_cast<std::size_t>(k)].measured_g;
    data.sigma2(k) = std::pow(c.runs[static_cast<std::size_t>(k)].sigma_g, 2);
  }
  data.Sigma.resize(plant::kNumCoefficients, plant::kNumCoefficients);
  for (int i = 0; i < plant::kNumCoefficients; ++i)
    for (int j = 0; j < plant::kNumCoefficients; ++j) data.Sigma(i, j) = id.uncertainty.covariance[i][j];
  return id;
}

void nominal_model(const Identified& id, CampaignModel& m) {
  const Campaign& c = m.campaign;
  const std::vector<Position>& positions = id.positions;
  const std::vector<double>& weights = id.weights;
  m.plant = id.plant;
  const PlantConfig& plant = m.plant;
  ResponseCache& cache = m.cache;
  m.n = static_cast<int>(c.runs.size());
  const int n = m.n;
  m.data = id.data;
  Data& data = m.data;

  // What the static test takes up of each effect that acts at rest: the identification of the
  // change the effect (at its unit value) makes to the readings, at the campaign's own
  // positions and weights (least squares is linear in the readings: the difference of two fits).
  // (The plant's own fit is the same for every effect; all of it is kept in the cache for the
  // wrapper's second pass, whose static test is the same.)
  Absorbed& absorbed = m.absorbed;
  cache.bind(plant);
  std::optional<Coefficients> base_fit;
  for (const Effect& e : effect_library()) {
    if (!e.acts_at_rest) continue;
    auto it = cache.absorbed_.find(e.name);
    if (it == cache.absorbed_.end()) {
      if (!base_fit) base_fit = rest_fit(plant, positions, weights, c.fixed);
      it = cache.absorbed_.emplace(e.name, taken_up_given_base(e, plant, positions, weights, c.fixed, *base_fit)).first;
    }
    absorbed[e.name] = it->second;
  }


  // The nominal simulation; the simulation's own accuracy at each run's best estimate joins its variance.
  m.nominal = tabulate(plant, c.runs, nullptr, 0, cache, absorbed);
  add_simulation_accuracy(data, m.nominal, m.simulation_rel_accuracy);
  m.all.resize(static_cast<std::size_t>(n));
  for (int k = 0; k < n; ++k) m.all[static_cast<std::size_t>(k)] = k;
}

}  // namespace internal
}  // namespace vrelab::validation
