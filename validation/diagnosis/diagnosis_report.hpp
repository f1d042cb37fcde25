#pragma once
// validation/diagnosis/diagnosis_report.hpp -- a diagnosis in words, and the check of its
// settings (free functions beside validation/diagnosis/diagnose.hpp's Diagnosis and
// DiagnoseSettings; they may become their BriefReport(), FullReport() and IsValid()).
//
// Takes: a Diagnosis and the Campaign it was made from (same runs, same order).
// Gives: text for a terminal: brief (the verdict and how far the gap shrinks), full (where
//        the gap lies, the cross-validation, every effect and pair tried, the confirmation on
//        the ODE plant). The campaign's own header (counts, skipped runs) is the caller's.
#include <string>

#include "validation/diagnosis/diagnose.hpp"

namespace vrelab::validation {

// False with `why` naming the setting (its field name), its value and the rule it breaks.
bool is_valid(const DiagnoseSettings& s, std::string* why);

std::string brief_report(const Diagnosis& d, const Campaign& c);
// wall_s >= 0: the diagnosis' wall time is given on the held-out line.
std::string full_report(const Diagnosis& d, const Campaign& c, double wall_s = -1);

}  // namespace vrelab::validation
