#pragma once
// io/services/studies.hpp -- the CLI's studies on a case file, one call each, and their reports.
//
// Takes: a Case (io/formats/case_file.hpp) and the few choices a command line adds (Monte Carlo
//        trials, a series file, an output folder).
// Gives: a result struct holding the settings it ran with and what the library computed;
//        *_report() gives the text the CLI prints (formatting only), results_json.hpp the
//        JSON. Each checks the settings (IsValid) before any work: invalid input is
//        InputError naming the case file and the key (exit code 2).
#include <cstdint>
#include <optional>
#include <ostream>
#include <string>
#include <vector>

#include "io/formats/case_file.hpp"
#include "rectification/measurement/reference.hpp"
#include "rectification/measurement/series.hpp"
#include "rectification/prediction/eq3.hpp"
#include "rectification/prediction/frequency.hpp"
#include "rectification/prediction/frequency_study.hpp"
#include "rectification/simulation/shake.hpp"
#include "rectification/simulation/shaker_motion.hpp"
#include "validation/identification/static_test.hpp"

namespace vrelab::io {

// "vrelab <version> (<git>) <command> <case>  [seed <n>]"
std::string header_line(const std::string& command, const Case& c, std::uint64_t seed);

// ---- identify: the static test on the dividing head.
struct IdentifyStudy {
  validation::StaticTestSettings settings;
  validation::Identifiability position_set;  // the position set with the fixed coefficients
  validation::StaticTestReport report;
};
// Needs [coefficients] and [dividing_head]; a rank-deficient set is InputError in words.
// checkpoint: the Monte Carlo's resume file (empty: none; docs/mpi.md).
IdentifyStudy identify(const Case& c, int monte_carlo_trials, const std::string& checkpoint = "");
std::string identify_report(const Case& c, const IdentifyStudy& s);

// ---- predict: eq. (3) corrected for the case's vibration, and through the dynamics.
// Eq. (3) corrected, quasi-static, for the case's [vibration] (sine, random, sine-on-random).
rectification::Eq3Terms predict_terms(const Case& c);
struct PredictStudy {
  rectification::Eq3Terms terms;
  std::optional<double> printed_g;  // eq. (3) as printed (sine, swept sine)
  std::string description;          // the vibration in words
  std::optional<rectification::FrequencyPrediction> at_frequency;
};
PredictStudy predict(const Case& c, bool frequency_dependent);
std::string predict_report(const Case& c, const PredictStudy& s);

// ---- shake: one run on the virtual shaker.
struct ShakeStudy {
  rectification::ShakerMotion table;
  rectification::ShakeResult result;
  double predicted_g = 0;  // eq. (3) corrected, the truth's coefficients
  double wall_s = 0;
  double cpu_s = 0;  // CPU time of the run's own thread (CLOCK_THREAD_CPUTIME_ID)
};
// `series_path` non-empty: the sampled record is written there (atomically).
ShakeStudy shake(const Case& c, const std::string& series_path);
// `sink` given: called for every sample of the record (as with a series file, the run is then
// a sampled record; rectification/simulation/shake.hpp). A sink that throws ends the run.
ShakeStudy shake(const Case& c, const rectification::SampleSink& sink);
std::string shake_report(const Case& c, const ShakeStudy& s);

// ---- measure: the vibration error of a recorded series (io/formats/csv.hpp).
struct MeasureStudy {
  std::string path, column;
  rectification::SeriesWindows windows;
  rectification::SeriesResult result;
  // With reference channels (io/formats/csv.hpp ReferenceSink): the measured motion over the vibration
  // window, per axis (mean removed, g; 0 for an axis without a column) and its magnitude's rms.
  bool reference = false;
  std::array<bool, 3> reference_axes{};
  Vec3 reference_rms_g = Vec3::Zero();
  double reference_input_rms_g = 0;
  // How the reference's motion departs from a pure motion along its dominant axis
  // (rectification/measurement/reference.hpp: with --frequency the harmonics and the
  // transverse fundamental, else Welch's PSD); motion_note says why not when it could not.
  std::optional<rectification::MotionDeparture> motion;
  std::string motion_note;
  // The input rms the VRC used: --input-rms-g, else the reference channels', else 0 (none).
  double vrc_input_rms_g() const { return windows.input_rms_g > 0 ? windows.input_rms_g : reference_input_rms_g; }
};
MeasureStudy measure(const std::string& series_path, const std::string& column, const rectification::SeriesWindows& w);
std::string measure_report(const MeasureStudy& s);

// ---- sweep: a grid of shaker runs into a resumable CSV file.
struct SweepStudy {
  std::size_t conditions = 0, ran = 0, written = 0;
  std::vector<std::string> failures;
  // Rows of the resumed file whose checksum did not match (file:line, condition): run again.
  std::vector<std::string> recomputed;
  double wall_s = 0;
};
// Announces the grid on `out` before running; with `progress`, draws core::Progress on stderr.
// threads < 0: the case's [sweep] threads (0: all cores).
SweepStudy sweep(const Case& c, const std::string& out_path, bool restart, int threads, bool progress, std::ostream& out);
std::string sweep_report(const SweepStudy& s, const std::string& out_path);

// ---- frequency: eq. (3) through the dynamics against the ODE, per mechanism.
struct FrequencyStudy {
  rectification::FrequencyStudySettings settings;
  std::vector<rectification::MechanismCurve> curves;
  double wall_s = 0;
};
FrequencyStudy frequency(const Case& c);
std::string frequency_report(const Case& c, const FrequencyStudy& s);
// frequency.csv, ode_points.csv, summary.md, summary.json in `dir`.
void write_frequency_data(const Case& c, const FrequencyStudy& s, const std::string& dir);

}  // namespace vrelab::io
