#pragma once
// io/services/diagnosis_json.hpp -- the JSON and CSV forms of the diagnosis stage's results, shared by
// the CLI and the library's other users. Every result carries the settings that made it.
//
//   to_json(FolderDiagnosis)   `diagnose --json`: program, data, campaign, nominal dynamics,
//                              settings, the diagnosis (per effect, pair and run), units; a
//                              folder read only (not diagnosed): the runs as read, "diagnosed": false
//   to_json(BlindResult)       `blind`'s scores.json: settings, scores, confusion, campaigns
//   confusion_csv(BlindResult) `blind`'s confusion.csv: rows the truth, columns what was called
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "io/services/diagnosis.hpp"
#include "validation/diagnosis/blind.hpp"
#include "validation/diagnosis/diagnose.hpp"

namespace vrelab::io {

nlohmann::json to_json(const validation::DiagnoseSettings& s);
nlohmann::json to_json(const validation::BlindSettings& s);
nlohmann::json to_json(const plant::Dynamics& d);
// The diagnosis of campaign c (same runs, same order): gap, effects, pairs, shrinkage, runs.
nlohmann::json to_json(const validation::Diagnosis& d, const validation::Campaign& c);
nlohmann::json to_json(const FolderDiagnosis& f);
// Reference channels (docs/data-format.md): how a run's measured motion departs from the
// command (`motion` of a run), the campaign's summary (`motion` at the top; only when some
// run has reference channels), and its line in the text report ("" when no run has them).
nlohmann::json to_json(const rectification::MotionDeparture& m);
nlohmann::json motion_summary_json(const validation::Diagnosis& d, const validation::Campaign& c);
std::string motion_summary_text(const validation::Diagnosis& d, const validation::Campaign& c);
nlohmann::json to_json(const validation::BlindResult& r);
// Blind's confusion matrix: counts[i][j] campaigns of truth truths[i] called called[j]; every
// campaign in one cell (confusion_csv writes it; the report shows it).
struct ConfusionMatrix {
  std::vector<std::string> called, truths;
  std::vector<std::vector<int>> counts;
};
ConfusionMatrix confusion_matrix(const validation::BlindResult& r);
std::string confusion_csv(const validation::BlindResult& r);

}  // namespace vrelab::io
