// validation/diagnosis/settings.cpp -- DiagnoseSettings::IsValid.
#include "validation/diagnosis/settings.hpp"

#include <cmath>

#include <fmt/format.h>

namespace vrelab::validation {

bool DiagnoseSettings::IsValid(std::string* why) const {
  const DiagnoseSettings& s = *this;
  std::string w;
  if (!(std::isfinite(s.model_accuracy) && s.model_accuracy >= 0 && s.model_accuracy < 1))
    w = fmt::format("model_accuracy = {}: the simulation's relative accuracy must be in [0, 1)", s.model_accuracy);
  else if (!(std::isfinite(s.significance_sigma) && s.significance_sigma > 0))
    w = fmt::format("significance_sigma = {}: must be a positive number of sigma", s.significance_sigma);
  else if (!(s.explained_shrinkage > 0 && s.explained_shrinkage <= 1))
    w = fmt::format("explained_shrinkage = {}: a fraction of the held-out gap rms, in (0, 1]", s.explained_shrinkage);
  else if (s.resimulate_runs < 0)
    w = fmt::format("resimulate_runs = {}: must not be negative (0: none)", s.resimulate_runs);
  else if (!(std::isfinite(s.structure_sigma) && s.structure_sigma > 0))
    w = fmt::format("structure_sigma = {}: must be a positive number of sigma", s.structure_sigma);
  else if (!(std::isfinite(s.ambiguity_evidence) && s.ambiguity_evidence >= 0))
    w = fmt::format("ambiguity_evidence = {}: must be a non-negative evidence difference", s.ambiguity_evidence);
  if (why) *why = w;
  return w.empty();
}

}  // namespace vrelab::validation
