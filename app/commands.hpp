#pragma once
// app/commands.hpp -- the CLI's commands: parse the case, call the library, write results.
// Each prints a human-readable summary on `out` and, when json_path is set, writes the JSON
// result atomically. Bad input throws InputError (the CLI exits with code 2).
#include <cstdint>
#include <optional>
#include <ostream>
#include <string>
#include <vector>

#include "io/formats/case_file.hpp"
#include "io/services/diagnosis.hpp"
#include "validation/diagnosis/blind.hpp"

namespace vrelab::app {

struct IdentifyOptions {
  std::string case_path;
  std::string json_path;
  int monte_carlo = 0;
  std::string checkpoint_path;  // --checkpoint: the Monte Carlo's resume file
  std::optional<std::uint64_t> seed;
  bool work_limit = true;  // false: --no-work-limit
};
void run_identify(const IdentifyOptions& o, std::ostream& out);

struct PredictOptions {
  std::string case_path;
  std::string json_path;
  bool frequency_dependent = false;  // through the plant's dynamics at [vibration] frequency_Hz
};
void run_predict(const PredictOptions& o, std::ostream& out);

struct ShakeOptions {
  std::string case_path;
  std::string json_path;
  std::string series_path;  // CSV of the sampled record
  std::optional<std::uint64_t> seed;
  bool work_limit = true;
};
void run_shake(const ShakeOptions& o, std::ostream& out);

struct MeasureOptions {
  std::string series_path;  // CSV: time in the first column; '#' lines are comments
  std::string json_path;
  std::vector<double> on_s, baseline_s;  // [from, to] each
  double frequency_Hz = 0;
  std::optional<double> K1;  // nullopt: the series' stated K1, else output in g
  std::string column;  // output column name; default the last column
  int blocks = 4;
  double input_rms_g = 0;  // > 0: the VRC is reported too
};
void run_measure(const MeasureOptions& o, std::ostream& out);

struct SweepOptions {
  std::string case_path;
  std::string out_path;  // CSV, appended as conditions finish; resumed if it exists
  bool restart = false;  // discard an existing file
  int threads = -1;      // -1: the case's [sweep] threads (0: all cores)
  bool progress = true;
  bool work_limit = true;
};
// Returns the number of conditions that failed (their rows are not written).
int run_sweep(const SweepOptions& o, std::ostream& out);

struct FrequencyOptions {
  std::string case_path;
  std::string out_dir;
  bool work_limit = true;
};
void run_frequency(const FrequencyOptions& o, std::ostream& out);

struct ReproduceOptions {
  std::string case_path = "cases/paper.toml";
  std::string out_dir = "out/paper";
  int threads = -1;   // -1: the case's [reproduce] threads (0: all cores)
  bool plots = true;  // false: data and report without figures
  bool work_limit = true;
};
// The paper's experiment end to end: report.html, report.md, figures, CSV/JSON (app/reproduce.cpp).
void run_reproduce(const ReproduceOptions& o, std::ostream& out);

// app/diagnose.cpp: the virtual lab, the diagnosis, and the blind test.
struct CampaignOptions {
  std::string case_path, out_dir, key_path;  // key: default <out_dir>.key.json
  std::optional<std::uint64_t> seed;
  bool progress = true;
  bool work_limit = true;
  std::string raw_format = "csv";  // --raw-format: the raw records' files, csv or hdf5
};
void run_campaign(const CampaignOptions& o, std::ostream& out);

struct DiagnoseOptions {
  std::string dir, json_path, report_dir;
  bool check = false;  // read and check the folder only (no diagnosis, nothing written)
  io::DiagnoseOverrides settings;  // over the manifest's [diagnose]
  // Many campaigns (io/services/batch.hpp): the folders given, the summary CSV, threads, progress.
  std::vector<std::string> dirs;
  std::string summary_path;
  int threads = 0;
  bool progress = true;
};
// Exit code: 2 when runs were skipped for bad input (the others diagnosed and written), else 0.
int run_diagnose(const DiagnoseOptions& o, std::ostream& out);
// diagnose DIR... --summary FILE; returns the number of campaigns that failed.
int run_diagnose_many(const DiagnoseOptions& o, std::ostream& out);

struct BlindOptions {
  validation::BlindSettings settings;
  std::string out_dir = "out/blind";
  bool progress = true;  // on stderr
  // Then the next-run advice checked on the ambiguous and unexplained campaigns
  // (validation/diagnosis/advice_check.hpp): DIR/advice.txt, a rerun resumes.
  bool check_advice = false;
};
void run_blind(const BlindOptions& o, std::ostream& out);

// app/work_limit.cpp: a run's work estimated before it starts; InputError beyond the limits
// of rectification/simulation/work_estimate.hpp, naming the estimate, the key and
// --no-work-limit.
void check_shake_work(const io::Case& c);
void check_sweep_work(const io::Case& c);
void check_reproduce_work(const io::Case& c);
void check_frequency_work(const io::Case& c);
void check_identify_work(const io::Case& c, int monte_carlo);
void check_campaign_work(const io::Case& c);

}  // namespace vrelab::app
