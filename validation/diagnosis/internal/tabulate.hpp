#pragma once
// validation/diagnosis/internal/tabulate.hpp -- the simulation of a campaign's runs under an
// effect hypothesis: the table every fit and score reads.
//
// Takes: the identified plant (coefficients, nominal dynamics), the runs (frequency Hz,
//        amplitude g, direction, static orientation g, random PSD or measured motion), an
//        effect with one value per parameter (or none: the nominal simulation), what the static
//        test took up of the effects that act at rest (per unit of the first parameter), and
//        the response cache bound to that plant.
// Gives: per run the prediction of the frequency-dependent eq. (3) (g) and its gradient in
//        the coefficients (g per coefficient unit), as a Table; computed once per (effect,
//        values) and plant and kept in the cache. What the static test took up is removed from
//        the coefficients of an effect that acts at rest.
#include <vector>

#include "plant/accelerometer.hpp"
#include "validation/diagnosis/diagnose.hpp"
#include "validation/diagnosis/internal/likelihood.hpp"
#include "validation/diagnosis/internal/response_cache.hpp"

namespace vrelab::validation::internal {

// A run whose table motion was measured by reference channels (RunRecord::motion): the
// table-motion effects are measured in it, not applied to it.
bool motion_used(const RunRecord& r);

// The table of every run under (e, values), computed once per plant the cache is bound to.
// (values: every parameter of e; empty without e.)
Table tabulate(const plant::PlantConfig& nominal, const std::vector<RunRecord>& runs, const Effect* e,
               const std::vector<double>& values, ResponseCache& cache, const Absorbed& absorbed);
// At one value of the effect's first parameter, the others nominal.
Table tabulate(const plant::PlantConfig& nominal, const std::vector<RunRecord>& runs, const Effect* e, double p,
               ResponseCache& cache, const Absorbed& absorbed);

}  // namespace vrelab::validation::internal
