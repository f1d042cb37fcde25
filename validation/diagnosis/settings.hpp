#pragma once
// validation/diagnosis/settings.hpp -- the diagnosis' settings (docs/diagnose.md): the
// simulation's accuracy, the significance levels, what the diagnosis tries and reports.
#include <string>

namespace vrelab::validation {

struct DiagnoseSettings {
  double model_accuracy = 0.002;      // relative accuracy of the simulation (f_model)
  // A run's gap is significant beyond this many sigma; the campaign's gap is when a run's is,
  // when chi^2 as a normal deviate is, or when one effect's held-out evidence exceeds its square.
  double significance_sigma = 5.0;
  // A gap is explained by the best effect when its evidence exceeds significance_sigma^2 and
  // either its held-out chi^2, as a normal deviate, stays below significance_sigma (the test
  // that found the gap no longer finds one on the held-out runs) or it removes at least
  // explained_shrinkage of the held-out gap rms (a large effect leaves the first-order
  // simulation's own error, which chi^2 alone would call unexplained).
  double explained_shrinkage = 0.9;
  int resimulate_runs = 12;             // runs (largest gaps first) re-simulated on the ODE; 0: none
  bool try_pairs = true;                // two effects at once when no one effect explains the gap
  // Stated sigma too small: a significant gap that no effect explains and whose runs' gaps are
  // not alike between neighbouring runs (the correlation of the gaps of runs one frequency or
  // one amplitude step apart, as a normal deviate, below this) is scatter, not physics: the
  // sigma is scaled by what the gaps say and the gap judged again.
  double structure_sigma = 3.0;
  // Two effects whose held-out evidence differs by less than this (2 ln of a Bayes factor;
  // 6: "strong" on Kass and Raftery's scale) and that both explain the gap: "ambiguous".
  double ambiguity_evidence = 6.0;
  bool advise_next_runs = true;         // next_runs for an ambiguous or unexplained gap
  // False with `why` naming the setting (its field name), its value and the rule it breaks.
  bool IsValid(std::string* why) const;
};

}  // namespace vrelab::validation
