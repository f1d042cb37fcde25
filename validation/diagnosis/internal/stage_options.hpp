#pragma once
// validation/diagnosis/internal/stage_options.hpp -- each stage's parameters, filled from the
// DiagnoseSettings in one place (stage_options, defined in diagnose.cpp): no stage reads the
// settings themselves.
#include "validation/diagnosis/internal/gap.hpp"
#include "validation/diagnosis/internal/nuisances.hpp"
#include "validation/diagnosis/internal/verdict.hpp"
#include "validation/diagnosis/settings.hpp"

namespace vrelab::validation::internal {

struct StageOptions {
  double simulation_rel_accuracy = 0.002;  // the campaign model's (CampaignModel) and the next runs'
  GapOptions gap;
  VerdictOptions verdict;
  SigmaScaleOptions scatter;
  bool next_runs = true;         // suggest the next runs for an ambiguous or unexplained gap
  int max_resimulated_runs = 0;  // the ODE confirmation's
};

StageOptions stage_options(const DiagnoseSettings& s);

}  // namespace vrelab::validation::internal
