// validation/diagnosis/diagnosis_text.cpp -- a diagnosis' typed results in words.
#include "validation/diagnosis/diagnosis_text.hpp"

#include <cmath>

#include <cstdio>
#include <stdexcept>

#include "plant/model1.hpp"

namespace vrelab::validation {

namespace {
constexpr const char* kPairJoin = " + ";
}  // namespace

const char* to_string(ParameterStatus s) {
  switch (s) {
    case ParameterStatus::fitted: return "fitted";
    case ParameterStatus::chosen: return "chosen";
    case ParameterStatus::held: return "held";
  }
  return "?";
}

std::string to_string(const ChosenEffects& c) {
  std::string t;
  for (std::size_t i = 0; i < c.names.size(); ++i) t += (i > 0 ? kPairJoin : "") + c.names[i];
  return t;
}

std::string verdict_text(const Diagnosis& d) {
  std::string t;
  const Nuisance* scale = d.nuisance("sigma_scale");
  // An overstated covariance (sigma_scale below 1, flagged, not applied) may hide a gap.
  const bool overstated = scale && scale->significant && !scale->applied && scale->value < 1;
  switch (d.verdict) {
    case Verdict::none: break;
    case Verdict::no_significant_gap: t = overstated ? "no gap can be judged" : "no significant gap"; break;
    case Verdict::explained: t = "explained by " + to_string(d.chosen); break;
    case Verdict::not_explained: t = "not explained by any known effect"; break;
    case Verdict::ambiguous:
      t = "ambiguous between ";
      for (std::size_t i = 0; i < d.ambiguous_with.size(); ++i)
        t += (i == 0 ? "" : i + 1 == d.ambiguous_with.size() ? " and " : ", ") + d.ambiguous_with[i];
      break;
  }
  char buf[120];
  if (scale && scale->applied) {
    std::snprintf(buf, sizeof buf, " (sigma understated x%.2f; judged with the corrected sigma)", scale->value);
    t += buf;
  }
  if (overstated) {
    std::snprintf(buf, sizeof buf, " (covariance overstated: the gaps scatter x%.2f of their sigma; a gap may be hidden)", scale->value);
    t += buf;
  }
  if (const Nuisance* drift = d.nuisance("bias_drift"); drift && drift->significant) {
    std::snprintf(buf, sizeof buf, " (bias drift %.3g +- %.2g ug/h removed)", drift->value, drift->sigma);
    t += buf;
  }
  return t;
}

ParameterStatus parameter_status_from_text(const std::string& text) {
  for (ParameterStatus s : {ParameterStatus::fitted, ParameterStatus::chosen, ParameterStatus::held})
    if (text == to_string(s)) return s;
  throw std::invalid_argument("not a parameter's status: \"" + text + "\"");
}

ChosenEffects chosen_from_text(const std::string& text) {
  ChosenEffects c;
  if (text.empty()) return c;
  const std::size_t join = text.find(kPairJoin);
  if (join == std::string::npos) return {{text}};
  c.names = {text.substr(0, join), text.substr(join + std::char_traits<char>::length(kPairJoin))};
  if (c.names[0].empty() || c.names[1].empty() || c.names[1].find(kPairJoin) != std::string::npos)
    throw std::invalid_argument("not one effect or a pair: \"" + text + "\"");
  return c;
}

std::optional<DatasheetValue> datasheet_form(double value, double sigma, const std::string& unit) {
  // An effect's parameter in 1 or rad is a ratio or a phase, not a coefficient: no datasheet form.
  if (unit == "1" || unit == "rad") return std::nullopt;
  const auto u = plant::datasheet_unit(unit);
  if (!u) return std::nullopt;
  return DatasheetValue{u->second * value, std::isfinite(sigma) ? u->second * sigma : NAN, u->first};
}

}  // namespace vrelab::validation
