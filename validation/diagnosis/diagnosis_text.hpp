#pragma once
// validation/diagnosis/diagnosis_text.hpp -- a diagnosis' typed results in words, for the
// writers alone (the text reports, the JSON, the CSV summary, blind's results, Python): a
// parameter's status, the chosen effects, the verdict. The readers of blind's results file take
// the words back with the *_from_text functions.
#include <optional>
#include <string>

#include "validation/diagnosis/diagnose.hpp"

namespace vrelab::validation {

// "fitted", "chosen", "held".
const char* to_string(ParameterStatus s);
// The effect's name, "<A> + <B>" for a pair, "" for none.
std::string to_string(const ChosenEffects& c);

// The verdict in words: "" (not diagnosed), "no significant gap", "explained by <name>" (or "<A> + <B>"), "not
// explained by any known effect", "ambiguous between <A>, <B> and <C>"; then each nuisance
// applied to the data: the stated sigma scaled, the bias drift removed.
std::string verdict_text(const Diagnosis& d);

// A parameter in a datasheet's units (IEEE Std 1293's K_n in ug/g^n, an angle per g in urad/g):
// a coefficient in 1/g^n (the model's, output in g) is value x 1e6 ug/g^(n+1); rad/g is x 1e6
// urad/g. Other units (a ratio, a frequency, 1/rad, a phase) have no datasheet form: nullopt.
struct DatasheetValue {
  double value = 0, sigma = 0;  // sigma NaN where the model's is not finite
  std::string unit;             // "ug/g^2", "urad/g"
};
std::optional<DatasheetValue> datasheet_form(double value, double sigma, const std::string& unit);

// The inverses of to_string; std::invalid_argument for words that are none of them.
ParameterStatus parameter_status_from_text(const std::string& text);
ChosenEffects chosen_from_text(const std::string& text);

}  // namespace vrelab::validation
