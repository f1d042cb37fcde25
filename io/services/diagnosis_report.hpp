#pragma once
// io/services/diagnosis_report.hpp -- `diagnose --report`: a diagnosis as a report (io/formats/report.hpp).
//
// Takes: a FolderDiagnosis and a folder.
// Gives: in the folder, diagnosis.json (io/services/diagnosis_json.hpp), report.md and report.html (where
//        the gap lies, which effect, how far it shrinks) and the figures of
//        tools/plots/diagnose.py (gap_map, residuals); a figure that cannot be drawn is said so.
#include <string>

#include "io/services/diagnosis.hpp"

namespace vrelab::io {

void write_diagnosis_report(const FolderDiagnosis& f, const std::string& dir);

}  // namespace vrelab::io
