#pragma once
// io/services/results_json.hpp -- the JSON form of the library's settings and results, shared by the
// CLI and the Python module.
//
// Takes: settings structs and results (and the case they were made from, for the record).
// Gives: nlohmann::json objects; every result records its settings in a "settings" object
//        beside the case, the seed and the program (io/formats/output.hpp's result_record).
#include <nlohmann/json.hpp>

#include "io/formats/case_file.hpp"
#include "io/services/study_results.hpp"
#include "rectification/measurement/series.hpp"
#include "rectification/prediction/frequency_study.hpp"
#include "rectification/simulation/shake.hpp"
#include "rectification/simulation/sweep.hpp"
#include "validation/reproduce/reproduce.hpp"

namespace vrelab::io {

// ---- settings
nlohmann::json sweep_grid_json(const rectification::SweepGrid& g);
nlohmann::json frequency_study_settings_json(const rectification::FrequencyStudySettings& s);
nlohmann::json series_windows_json(const rectification::SeriesWindows& w);

// ---- the commands' results (each with its "settings")
nlohmann::json identify_json(const Case& c, const IdentifyStudy& s);
// The rms of the commanded dynamic input's magnitude, g (rectification/measurement/vrc.hpp):
// sqrt(sum_i w_i^2 / 2) for a (swept) sine, sqrt(sum_i rms_i^2) for random, both added for
// sine on random.
double vibration_input_rms_g(const VibrationSpec& v);
// VRC = error / rms^2 in ug/g^2, null where the rms is 0.
nlohmann::json vrc_json(double error_g, double input_rms_g);
nlohmann::json predict_json(const Case& c, const PredictStudy& s);
nlohmann::json shake_json(const Case& c, const ShakeStudy& s);
nlohmann::json measure_json(const MeasureStudy& s);
nlohmann::json frequency_json(const Case& c, const FrequencyStudy& s);
// The [vibration] table as recorded in predict's and shake's results.
nlohmann::json vibration_json(const VibrationSpec& v);

// ---- reproduce
nlohmann::json run_json(const validation::RunResult& r);
nlohmann::json agreement_json(const validation::Agreement& a);
// confirmation.json: the confirmation run's numbers.
nlohmann::json reproduce_confirmation_json(const Case& c, const validation::ReproduceSettings& s,
                                           const validation::ReproduceResult& res);
// summary.json: every number of the report, with the case, seed, plant, settings and program.
nlohmann::json reproduce_summary_json(const Case& c, const validation::ReproduceSettings& s,
                                      const validation::ReproduceResult& res, double wall_s);

}  // namespace vrelab::io
