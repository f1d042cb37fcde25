#pragma once
// io/formats/case_file.hpp -- reading a case file (TOML) into the library's inputs.
//
// Takes: the path of a case file (keys in docs/case-files.md).
// Gives: a Case whose tables are present only where the file has them; the parsed file as
//        JSON (recorded in every result). Throws FormatError (io/formats/error.hpp) with the
//        file, the line, the table and the key for anything wrong: a syntax error, an unknown
//        key (with a suggestion), a missing or non-finite number, a negative sigma, an empty
//        position set.
#include <cstdint>
#include <optional>
#include <stdexcept>
#include <string>
#include <variant>

#include <nlohmann/json.hpp>

#include "io/formats/error.hpp"
#include "plant/accelerometer.hpp"
#include "plant/model1.hpp"
#include "plant/physical.hpp"
#include "rectification/simulation/shake.hpp"
#include "rectification/prediction/frequency_study.hpp"
#include "rectification/simulation/sweep.hpp"
#include "rectification/simulation/shaker_motion.hpp"
#include "validation/identification/dividing_head.hpp"
#include "validation/identification/identification.hpp"
#include "validation/diagnosis/campaign.hpp"
#include "validation/reproduce/reproduce.hpp"
#include "vibration/decorators.hpp"
#include "vibration/demand.hpp"
#include "vibration/profile.hpp"
#include "vibration/random.hpp"
#include "vibration/sweep.hpp"

namespace vrelab::io {

struct DividingHead {
  std::vector<validation::Position> positions;
  validation::StaticTestErrors errors;
  std::string description;  // e.g. "3 series x 8 positions"
  bool from_ode = false;    // source = "ode": readings from the ODE plant, else model (1)
};

using rectification::VibrationKind;

// The [vibration] table. type: sine | random | sine_on_random | swept_sine. The request a
// shaker run builds its table motion from (rectification/simulation/shaker_motion.hpp), and
// what eq. (3) needs.
struct VibrationSpec : rectification::VibrationRequest {
  std::optional<vibration::RandomVibration> gaussian;  // random, sine_on_random (from rms_g or the PSD)
  double duration_s = 10.0;  // measuring time of a non-periodic run
  int line = 0;              // of the [vibration] table, for messages
};

// The [shaker] table: limits and imperfections, each off unless given.
struct ShakerSpec : rectification::ShakerImperfections {
  vibration::ShakerLimits limits;
  int line = 0;  // of the [shaker] table, for messages; 0: no such table
};

// The [campaign] table: what `vrelab campaign` hides in the truth and how the lab tests it.
struct CampaignSpec {
  std::vector<validation::HiddenEffect> hidden;
  validation::CampaignDesign design = validation::default_design();
  bool raw_series = false;  // write each run's record (time, output) instead of its summary
  std::string name = "campaign";
};

struct Case {
  std::string path;
  nlohmann::json content;  // the file, as JSON
  double g_m_per_s2 = 9.80665;
  std::string instrument = "accelerometer";
  std::string output_unit = "mA";
  bool output_unit_given = false;
  std::optional<plant::Coefficients> coefficients;
  std::optional<Vec3> orientation_g;
  std::optional<VibrationSpec> vibration;
  ShakerSpec shaker;
  std::optional<double> range_limit_g;
  std::optional<DividingHead> dividing_head;
  validation::FixedSet fixed{};
  std::uint64_t seed = 1;
  // The ODE plant: [plant] (defaults when absent: from the coefficients, default dynamics).
  plant::PlantConfig plant;
  std::optional<plant::PhysicalParameters> physical;  // [plant] type = "physical"
  rectification::ShakeSettings shake;  // [shake] and [readout]
  std::optional<rectification::SweepGrid> sweep;  // [sweep]
  std::optional<rectification::FrequencyStudySettings> frequency_study;  // [frequency_study]
  int sweep_threads = 0;                          // 0: all cores
  // [reproduce] with the static test ([dividing_head], [identification] fixed), the seed and
  // [shake]/[readout]: the whole configuration of `vrelab reproduce`.
  std::optional<validation::ReproduceSettings> reproduce;
  std::optional<CampaignSpec> campaign;           // [campaign]
};

Case read_case(const std::string& path);

// Throws FormatError "<file>: <what>" when the case lacks a table a command needs.
void require(const Case& c, bool present, const std::string& table, const std::string& command);

}  // namespace vrelab::io
