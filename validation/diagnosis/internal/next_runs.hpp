#pragma once
// validation/diagnosis/internal/next_runs.hpp -- advice on the runs to add, for an ambiguous
// or unexplained gap.
//
// Takes: the identified plant, the campaign's runs (their sigma in g and largest amplitude in
//        g), the simulation's relative accuracy and the Diagnosis with its ranked effects,
//        verdict and ties.
// Gives: d.next_runs: up to three runs (direction, frequency in Hz among 10-2000, amplitude in
//        g among a quarter, half and all of the largest, static orientation) where the
//        candidates' predictions differ most, in a run's sigma (the campaign's median with the
//        simulation's accuracy at the nominal prediction), each a different direction or orientation
//        where possible. The candidates: the tied effects, else the three best ranked, each at
//        its fitted values. Nothing for an explained unambiguous or insignificant gap.
#include "validation/diagnosis/diagnose.hpp"

namespace vrelab::validation::internal {

void suggest_next_runs(const plant::PlantConfig& plant, const Campaign& c, double simulation_rel_accuracy, Diagnosis& d);

}  // namespace vrelab::validation::internal
