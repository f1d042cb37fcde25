#pragma once
// io/services/studies.hpp -- the CLI's studies on a case file, one call each, and their reports.
//
// Takes: a Case (io/formats/case_file.hpp) and the few choices a command line adds (Monte Carlo
//        trials, a series file, an output folder).
// Gives: a result struct (io/services/study_results.hpp) holding the settings it ran with
//        and what the library computed; *_report() gives the text the CLI prints (formatting
//        only), results_json.hpp the JSON. Each checks the settings (IsValid) before any
//        work: invalid input is InputError (io/formats/error.hpp) naming the case file and
//        the table or key (exit code 2).
#include <cstdint>
#include <optional>
#include <ostream>
#include <string>
#include <vector>

#include "io/formats/case_file.hpp"
#include "io/services/study_results.hpp"
#include "rectification/prediction/eq3.hpp"
#include "rectification/measurement/series.hpp"
#include "rectification/simulation/shake.hpp"

namespace vrelab::io {

// "vrelab <version> (<git>) <command> <case>  [seed <n>]"
std::string header_line(const std::string& command, const Case& c, std::uint64_t seed);

// ---- identify: the static test on the dividing head.
// Needs [coefficients] and [dividing_head]; a rank-deficient set is InputError in words.
// checkpoint: the Monte Carlo's resume file (empty: none; docs/mpi.md).
IdentifyStudy identify(const Case& c, int monte_carlo_trials, const std::string& checkpoint = "");
std::string identify_report(const Case& c, const IdentifyStudy& s);

// ---- predict: eq. (3) corrected for the case's vibration, and through the dynamics.
// Eq. (3) corrected, quasi-static, for the case's [vibration] (sine, random, sine-on-random).
rectification::Eq3Terms predict_terms(const Case& c);
PredictStudy predict(const Case& c, bool frequency_dependent);
std::string predict_report(const Case& c, const PredictStudy& s);

// ---- shake: one run on the virtual shaker.
// `series_path` non-empty: the sampled record is written there (atomically).
ShakeStudy shake(const Case& c, const std::string& series_path);
// `sink` given: called for every sample of the record (as with a series file, the run is then
// a sampled record; rectification/simulation/shake.hpp). A sink that throws ends the run.
ShakeStudy shake(const Case& c, const rectification::SampleSink& sink);
std::string shake_report(const Case& c, const ShakeStudy& s);

// ---- measure: the vibration error of a recorded series (io/formats/csv.hpp).
// K1: the scale factor (output units per g); nullopt: the one the series states in a comment
// (`# ... K1 = 1.25 mA/g`), else 1 (output in g), refused (InputError) when the output column
// says another unit (output_mA) and nothing states K1.
MeasureStudy measure(const std::string& series_path, const std::string& column, rectification::SeriesWindows w,
                     std::optional<double> K1 = std::nullopt);
std::string measure_report(const MeasureStudy& s);

// ---- sweep: a grid of shaker runs into a resumable CSV file.
// Announces the grid on `out` before running; with `progress`, draws core::Progress on stderr.
// threads < 0: the case's [sweep] threads (0: all cores).
SweepStudy sweep(const Case& c, const std::string& out_path, bool restart, int threads, bool progress, std::ostream& out);
std::string sweep_report(const SweepStudy& s, const std::string& out_path);

// ---- frequency: eq. (3) through the dynamics against the ODE, per mechanism.
FrequencyStudy frequency(const Case& c);
std::string frequency_report(const Case& c, const FrequencyStudy& s);
// frequency.csv, ode_points.csv, summary.md, summary.json in `dir`.
void write_frequency_data(const Case& c, const FrequencyStudy& s, const std::string& dir);

}  // namespace vrelab::io
