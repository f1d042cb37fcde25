#pragma once
// validation/diagnosis/diagnosis_text.hpp -- a diagnosis' typed results in words, for the
// writers alone (the text reports, the JSON, the CSV summary, blind's results, Python): a
// parameter's status, the chosen effects, the verdict. The readers of blind's results file take
// the words back with the *_from_text functions.
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

// The inverses of to_string; std::invalid_argument for words that are none of them.
ParameterStatus parameter_status_from_text(const std::string& text);
ChosenEffects chosen_from_text(const std::string& text);

}  // namespace vrelab::validation
