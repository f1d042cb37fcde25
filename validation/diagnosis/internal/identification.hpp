#pragma once
// validation/diagnosis/internal/identification.hpp -- the diagnosis' first stage: the static
// test's coefficients and what every later stage reads of the campaign.
//
// Takes: a campaign (its static readings: orientation in g, mean output in output units and
//        its sigma; the coefficients the identification holds; the nominal dynamics; the runs'
//        measured vibration error and sigma in g) and the simulation's relative accuracy (its
//        error's sigma over its prediction).
// Gives: the identified coefficients (model (1)'s units) and their first-order covariance from
//        the readings' sigma; the runs' data (measured g, variance g^2, the coefficients'
//        covariance); what the static test takes up of each library effect that acts at rest
//        (coefficient units per unit of its parameter); the nominal simulation's table of the
//        runs; and the runs' variances with the simulation's own, (relative accuracy x the
//        run's best estimate)^2, added (likelihood.hpp, best_estimate). Throws std::invalid_argument without static readings or runs,
//        or when the readings do not determine the free coefficients.
#include <vector>

#include "validation/diagnosis/diagnose.hpp"
#include "validation/diagnosis/internal/likelihood.hpp"
#include "validation/diagnosis/internal/response_cache.hpp"

namespace vrelab::validation::internal {

// The identification from the static readings, weighted by their sigma, with its first-order
// covariance, and the runs' data (sigma2 the runs' own variance: the simulation's accuracy is
// added at the runs' best estimate by nominal_model).
struct Identified {
  std::vector<Position> positions;
  std::vector<double> weights;
  Propagation uncertainty;
  plant::PlantConfig plant;  // the identified coefficients, the manifest's dynamics
  Data data;
};
Identified identify(const Campaign& c);

// What every stage after the identification reads: the campaign, the simulation's relative
// accuracy (its error's sigma over its prediction, 1), the identified
// plant, the runs' data with the simulation's accuracy in sigma2, the nominal table, every
// run's index, what the static test takes up, and the cache the tables live in. The stages keep
// references to its members (the fitters to `nominal`): it is not moved once built.
struct CampaignModel {
  CampaignModel(const Campaign& c, double simulation_rel_accuracy_, ResponseCache& response_cache)
      : campaign(c), simulation_rel_accuracy(simulation_rel_accuracy_), cache(response_cache) {}
  const Campaign& campaign;
  const double simulation_rel_accuracy;
  ResponseCache& cache;
  plant::PlantConfig plant;
  Data data;
  Absorbed absorbed;
  Table nominal;
  std::vector<int> all;
  int n = 0;
};

// Fills m.plant, m.data, m.absorbed (computed once per cache: the wrapper's second pass reuses
// them), m.nominal (the nominal simulation), m.data.sigma2's simulation accuracy, m.all and m.n.
void nominal_model(const Identified& id, CampaignModel& m);

}  // namespace vrelab::validation::internal
