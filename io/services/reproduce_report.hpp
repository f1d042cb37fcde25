#pragma once
// io/services/reproduce_report.hpp -- what `vrelab reproduce` writes: the data files, the report and
// the console summary of a validation::ReproduceResult.
//
// Takes: the case (its path, units and dividing head, for the record), the settings the
//        run used, the result (its analysis included) and the wall time.
// Gives: the CSV/JSON files in a folder (docs/reproduce.md), the report (Markdown and HTML,
//        io/formats/report.hpp) and the brief summary the CLI prints. Formatting only: every number
//        comes from the result.
#include <string>

#include "io/formats/case_file.hpp"
#include "io/formats/report.hpp"
#include "validation/reproduce/reproduce.hpp"

namespace vrelab::io {

// static.csv, confirmation.{csv,json}, amplitude.csv, amplitude_curves.csv, frequency.csv and
// frequency_curves.csv (when run), invisible.csv (when run), summary.json; removes the files
// of a section not run (and its figure) left by an earlier run. Starts the report folder
// (begin_report_folder: the old report and its files removed first); the report is then
// written with write_report_folder.
void write_reproduce_data(const Case& c, const validation::ReproduceSettings& s, const validation::ReproduceResult& res,
                          double wall_s, const std::string& dir);

// The full report; `figures_missing`: "" when the figures were drawn, else why not.
Report reproduce_full_report(const Case& c, const validation::ReproduceSettings& s,
                             const validation::ReproduceResult& res, double wall_s, const std::string& figures_missing);

// The console summary: the static test, the confirmation, the amplitude study, the frequency
// departure and the invisible shift, a line each.
std::string reproduce_brief_report(const validation::ReproduceResult& res);

}  // namespace vrelab::io
