#pragma once
// validation/diagnosis/settings.hpp -- the diagnosis' settings (docs/diagnose.md): the
// simulation's accuracy, the significance levels, what the diagnosis tries and reports.
// Describe lists each field once (core/settings_description.hpp): the manifest's [diagnose]
// table, the CLI's flags, the Python keywords and the JSON record of the settings used all
// iterate it.
#include <string>

#include "core/settings_description.hpp"

namespace vrelab::validation {

struct DiagnoseSettings {
  double model_accuracy = 0.002;
  double significance_sigma = 5.0;
  double explained_shrinkage = 0.9;
  int resimulate_runs = 12;
  bool try_pairs = true;
  double structure_sigma = 3.0;
  double ambiguity_evidence = 6.0;
  bool advise_next_runs = true;

  template <class V>
  static void Describe(V& v) {
    using S = DiagnoseSettings;
    using core::field;
    v(field("model_accuracy", &S::model_accuracy, "", core::closed_open(0, 1),
            "The simulation's relative accuracy (f_model)"));
    // A run's gap is significant beyond this many sigma; the campaign's gap is when a run's
    // is, when chi^2 as a normal deviate is, or when one effect's held-out evidence exceeds
    // its square.
    v(field("significance_sigma", &S::significance_sigma, "sigma", core::above(0),
            "A gap is significant beyond this many sigma"));
    // A gap is explained by the best effect when its evidence exceeds significance_sigma^2
    // and either its held-out chi^2, as a normal deviate, stays below significance_sigma (the
    // test that found the gap no longer finds one on the held-out runs) or it removes at
    // least explained_shrinkage of the held-out gap rms (a large effect leaves the
    // first-order simulation's own error, which chi^2 alone would call unexplained).
    v(field("explained_shrinkage", &S::explained_shrinkage, "", core::open_closed(0, 1),
            "Held-out gap rms share an effect must remove to explain the gap"));
    v(field("resimulate_runs", &S::resimulate_runs, "runs", core::closed(0, 1000000),
            "Runs (largest gaps first) re-simulated on the ODE plant; 0: none"));
    v(field("try_pairs", &S::try_pairs, "", core::any_value(),
            "Try two effects at once when one leaves a gap or a second is still needed", "no-pairs"));
    // Stated sigma too small: gaps that no effect explains, not alike between neighbouring
    // runs (the correlation of the gaps of runs one frequency or one amplitude step apart, as
    // a normal deviate, below this) and whose means and spreads depend on no frequency,
    // amplitude, direction, orientation or time order (the structure tests' deviate below
    // this) are scatter, not physics: the sigma is scaled by what the gaps say and the gap
    // judged again.
    v(field("structure_sigma", &S::structure_sigma, "sigma", core::above(0),
            "Unexplained gaps whose neighbours' correlation and structure tests stay below this (normal deviate) "
            "are scatter: the stated sigma is scaled"));
    // 6: "strong" on Kass and Raftery's scale.
    v(field("ambiguity_evidence", &S::ambiguity_evidence, "", core::at_least(0),
            "Two effects that both explain the gap with held-out evidence (2 ln Bayes factor) closer than "
            "this: ambiguous"));
    v(field("advise_next_runs", &S::advise_next_runs, "", core::any_value(),
            "Advise the next runs for an ambiguous or unexplained gap"));
  }

  // False with `why` naming the setting (its field name), its value and the rule it breaks.
  bool IsValid(std::string* why) const;
};

}  // namespace vrelab::validation
