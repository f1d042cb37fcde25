#pragma once
// io/services/study_results.hpp -- what each study on a case file gives: the result structs of
// io/services/studies.hpp, apart so that their JSON forms (io/services/results_json.hpp) need
// not include the studies that make them.
//
// Takes: nothing (plain structs of the library's settings and results).
// Gives: IdentifyStudy, PredictStudy, ShakeStudy, MeasureStudy, SweepStudy, FrequencyStudy:
//        each the settings a study ran with and what the library computed.
#include <array>
#include <cstddef>
#include <optional>
#include <string>
#include <vector>

#include "rectification/measurement/reference.hpp"
#include "rectification/measurement/series.hpp"
#include "rectification/prediction/eq3.hpp"
#include "rectification/prediction/frequency.hpp"
#include "rectification/prediction/frequency_study.hpp"
#include "rectification/simulation/shake.hpp"
#include "rectification/simulation/shaker_motion.hpp"
#include "validation/identification/static_test.hpp"

namespace vrelab::io {

// ---- identify: the static test on the dividing head.
struct IdentifyStudy {
  validation::StaticTestSettings settings;
  validation::Identifiability position_set;  // the position set with the fixed coefficients
  validation::StaticTestReport report;
};

// ---- predict: eq. (3) corrected for the case's vibration, and through the dynamics.
struct PredictStudy {
  rectification::Eq3Terms terms;
  std::optional<double> printed_g;  // eq. (3) as printed (sine, swept sine)
  std::string description;          // the vibration in words
  std::optional<rectification::FrequencyPrediction> at_frequency;
};

// ---- shake: one run on the virtual shaker.
struct ShakeStudy {
  rectification::ShakerMotion table;
  rectification::ShakeResult result;
  double predicted_g = 0;  // eq. (3) corrected, the truth's coefficients
  // Eq. (3) through the plant's dynamics (predict --frequency-dependent) for a sine on a
  // perfect shaker, a random or a sine-on-random run given by PSD tables; nullopt otherwise
  // (a sweep, shaker imperfections, a Gaussian given by its rms).
  std::optional<double> frequency_dependent_g;
  double wall_s = 0;
  double cpu_s = 0;  // CPU time of the run's own thread (CLOCK_THREAD_CPUTIME_ID)
};

// ---- measure: the vibration error of a recorded series (io/formats/csv.hpp).
struct MeasureStudy {
  std::string path, column;
  // windows.K1's unit (output units per g; "" unknown), where it came from ("--K1", "stated by
  // the series, line 2", "none given: output in g") and a note when the two disagreed.
  std::string K1_unit, K1_source, K1_note;
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

// ---- sweep: a grid of shaker runs into a resumable CSV file.
struct SweepStudy {
  std::size_t conditions = 0, ran = 0, written = 0;
  std::vector<std::string> failures;
  // Rows of the resumed file whose checksum did not match (file:line, condition): run again.
  std::vector<std::string> recomputed;
  double wall_s = 0;
};

// ---- frequency: eq. (3) through the dynamics against the ODE, per mechanism.
struct FrequencyStudy {
  rectification::FrequencyStudySettings settings;
  std::vector<rectification::MechanismCurve> curves;
  double wall_s = 0;
};

}  // namespace vrelab::io
