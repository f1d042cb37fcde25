// vrelab: the command-line interface. A thin layer: options in, library calls,
// results out. Exit codes: 0 success, 2 bad input (case file, options,
// parameters the physics rejects, solver failures), 1 anything else.
#include <CLI/CLI.hpp>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <functional>
#include <iostream>
#include <memory>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#ifdef __GLIBC__
#include <malloc.h>
#endif

#include "app/commands.hpp"
#include "app/settings_cli.hpp"
#include "core/dispatch.hpp"
#ifdef VRELAB_HAVE_MPI
#include "core/mpi.hpp"
#endif
#include "io/formats/case_file.hpp"
#include "io/formats/paths.hpp"
#include "plant/ode_solver.hpp"
#include "vrelab_version.hpp"

namespace {

using namespace vrelab::app;
using namespace vrelab::io;

// An option naming an output file: a regular file or a new name (io/formats/paths.hpp), refused
// with exit code 2 before the command starts (a folder, a FIFO, a path too long).
const CLI::Validator kOutputFile(
    [](std::string& p) {
      const std::string why = writable_file_problem(p);
      return why.empty() ? std::string() : "cannot write " + path_for_message(p) + ": " + why;
    },
    "FILE");

// A subcommand and what running it does (its exit code); each add_* registers
// one command's options on the CLI. `distributed`: the command hands its items to every rank
// under mpirun (core/dispatch.hpp); the other commands run on rank 0 alone.
struct Command {
  CLI::App* sub;
  std::function<int()> run;
  std::function<bool()> distributed = [] { return false; };
};

Command add_identify(CLI::App& app) {
  auto owned = std::make_shared<IdentifyOptions>();
  IdentifyOptions& o = *owned;
  CLI::App* cmd = app.add_subcommand("identify",
                                     "Virtual static test on a dividing head; "
                                     "identify the coefficients of model (1)");
  cmd->add_option("case", o.case_path, "Case file (TOML)")->required();
  cmd->add_option("--json", o.json_path, "Write the result as JSON to this file")->check(kOutputFile);
  cmd->add_option("--monte-carlo", o.monte_carlo, "Also run N simulated tests for Monte Carlo uncertainty")
      ->check(CLI::NonNegativeNumber);
  cmd->add_option("--checkpoint", o.checkpoint_path,
                  "With --monte-carlo: keep each block of trials in this file as it ends; a rerun with the "
                  "same file runs only the missing blocks (docs/mpi.md)")
      ->check(kOutputFile);
  cmd->add_option("--seed", o.seed, "Override the case's [run] seed");
  cmd->add_flag_callback(
      "--no-work-limit", [&o] { o.work_limit = false; },
      "Run even if the estimated work exceeds the limits (docs/case-files.md, Limits)");
  return {cmd,
          [owned] {
            run_identify(*owned, std::cout);
            return 0;
          },
          [owned] { return owned->monte_carlo > 0; }};
}

Command add_predict(CLI::App& app) {
  auto owned = std::make_shared<PredictOptions>();
  PredictOptions& o = *owned;
  CLI::App* cmd = app.add_subcommand("predict", "Vibration error implied by model (1): eq. (3), corrected");
  cmd->add_option("case", o.case_path, "Case file (TOML)")->required();
  cmd->add_option("--json", o.json_path, "Write the result as JSON to this file")->check(kOutputFile);
  cmd->add_flag("--frequency-dependent", o.frequency_dependent,
                "Also eq. (3) at [vibration] frequency_Hz through the plant's "
                "dynamics ([plant]; sine only)");
  return {cmd, [owned] {
            run_predict(*owned, std::cout);
            return 0;
          }};
}

Command add_shake(CLI::App& app) {
  auto owned = std::make_shared<ShakeOptions>();
  ShakeOptions& o = *owned;
  CLI::App* cmd = app.add_subcommand("shake", "One run on the virtual shaker: measured vibration error vs eq. (3)");
  cmd->add_option("case", o.case_path, "Case file (TOML)")->required();
  cmd->add_option("--json", o.json_path, "Write the result as JSON to this file")->check(kOutputFile);
  cmd->add_option("--series", o.series_path, "Write the sampled record as CSV to this file")->check(kOutputFile);
  cmd->add_option("--seed", o.seed, "Override the case's [run] seed");
  cmd->add_flag_callback(
      "--no-work-limit", [&o] { o.work_limit = false; },
      "Run even if the estimated work exceeds the limits (docs/case-files.md, Limits)");
  return {cmd, [owned] {
            run_shake(*owned, std::cout);
            return 0;
          }};
}

Command add_measure(CLI::App& app) {
  auto owned = std::make_shared<MeasureOptions>();
  MeasureOptions& o = *owned;
  CLI::App* cmd = app.add_subcommand("measure", "Vibration error from a recorded output series (CSV or HDF5)");
  cmd->add_option("series", o.series_path,
                  "CSV (time_s, else the first column, then output column(s); '#' lines are comments) or, named "
                  "*.h5 / *.hdf5, HDF5 (datasets time_s and output_<unit>; docs/data-format.md)")
      ->required();
  cmd->add_option("--on", o.on_s, "Vibration interval FROM,TO in s")->delimiter(',')->expected(2)->required();
  cmd->add_option("--baseline", o.baseline_s, "Baseline (at rest) interval FROM,TO in s")
      ->delimiter(',')
      ->expected(2)
      ->required();
  cmd->add_option("--frequency", o.frequency_Hz, "Sine frequency in Hz: measure over whole periods");
  cmd->add_option("--K1", o.K1,
                  "Scale factor, output units per g (default: the series' comment 'K1 = 1.25 mA/g' as shake --series "
                  "writes it, else 1: output in g; refused for an output_<unit> column other than g)");
  cmd->add_option("--column", o.column, "Output column name (default: the one output_* column or dataset, else the last column)");
  cmd->add_option("--blocks", o.blocks, "Blocks for the batch-means uncertainty (default 4)");
  cmd->add_option("--input-rms-g", o.input_rms_g,
                  "The input's rms in g (magnitude over the axes): the VRC, error / rms^2 in ug/g^2, is reported too");
  cmd->add_option("--json", o.json_path, "Write the result as JSON to this file")->check(kOutputFile);
  return {cmd, [owned] {
            run_measure(*owned, std::cout);
            return 0;
          }};
}

Command add_sweep(CLI::App& app) {
  auto owned = std::make_shared<SweepOptions>();
  SweepOptions& o = *owned;
  CLI::App* cmd = app.add_subcommand("sweep", "A grid of shaker runs on all cores; resumable");
  cmd->add_option("case", o.case_path, "Case file (TOML) with a [sweep] table")->required();
  cmd->add_option("--out", o.out_path, "Results CSV (resumed if it exists)")->required()->check(kOutputFile);
  cmd->add_flag("--restart", o.restart, "Discard an existing results file");
  cmd->add_option("--threads", o.threads, "Threads (default: the case's, 0 = all cores; under mpirun per rank, 0 = 1)");
  cmd->add_flag_callback(
      "--no-progress", [&o] { o.progress = false; }, "No progress bar");
  cmd->add_flag_callback(
      "--no-work-limit", [&o] { o.work_limit = false; },
      "Run even if the estimated work exceeds the limits (docs/case-files.md, Limits)");
  return {cmd, [owned] { return run_sweep(*owned, std::cout) > 0 ? 2 : 0; }, [] { return true; }};
}

Command add_frequency(CLI::App& app) {
  auto owned = std::make_shared<FrequencyOptions>();
  FrequencyOptions& o = *owned;
  CLI::App* cmd = app.add_subcommand("frequency",
                                     "Vibration error against frequency per term and place: eq. "
                                     "(3) through the dynamics vs the ODE");
  cmd->add_option("case", o.case_path,
                  "Case file (TOML): [coefficients], [orientation], [plant], "
                  "[frequency_study]")
      ->required();
  cmd->add_option("--out", o.out_dir, "Output folder (CSV, JSON, Markdown table, PNG/SVG figure)")->required();
  cmd->add_flag_callback(
      "--no-work-limit", [&o] { o.work_limit = false; },
      "Run even if the estimated work exceeds the limits (docs/case-files.md, Limits)");
  return {cmd, [owned] {
            run_frequency(*owned, std::cout);
            return 0;
          }};
}

Command add_reproduce(CLI::App& app) {
  auto owned = std::make_shared<ReproduceOptions>();
  ReproduceOptions& o = *owned;
  CLI::App* cmd = app.add_subcommand("reproduce",
                                     "The paper's experiment end to end: static test, "
                                     "confirmation plot, eq. (3) vs the shaker; report");
  cmd->add_option("case", o.case_path, "Case file (TOML) with [dividing_head] and [reproduce]")->capture_default_str();
  cmd->add_option("--out", o.out_dir, "Output folder (report.html, report.md, figures, CSV/JSON)")
      ->capture_default_str();
  cmd->add_option("--threads", o.threads, "Threads (default: the case's, 0 = all cores)");
  cmd->add_flag_callback(
      "--no-plots", [&o] { o.plots = false; }, "Write the data and the report without figures");
  cmd->add_flag_callback(
      "--no-work-limit", [&o] { o.work_limit = false; },
      "Run even if the estimated work exceeds the limits (docs/case-files.md, Limits)");
  return {cmd, [owned] {
            run_reproduce(*owned, std::cout);
            return 0;
          }};
}

Command add_campaign(CLI::App& app) {
  auto owned = std::make_shared<CampaignOptions>();
  CampaignOptions& o = *owned;
  CLI::App* cmd = app.add_subcommand("campaign",
                                     "The virtual lab: a whole campaign from a truth with hidden effects, "
                                     "in the lab data format, and its answer key");
  cmd->add_option("case", o.case_path, "Case file (TOML) with [coefficients], [plant] and [campaign]")->required();
  cmd->add_option("--out", o.out_dir, "Campaign folder (docs/data-format.md)")->required();
  cmd->add_option("--key", o.key_path, "Answer key (JSON; default <out>.key.json); diagnose never reads it")->check(kOutputFile);
  cmd->add_option("--seed", o.seed, "Seed (default: the case's [run] seed)");
  cmd->add_option("--raw-format", o.raw_format,
                  "Raw records (a case with [campaign] raw_series = true) as records/<id>.csv or records/<id>.h5 "
                  "(HDF5, docs/data-format.md)")
      ->check(CLI::IsMember({"csv", "hdf5"}))
      ->capture_default_str();
  cmd->add_flag_callback("--no-progress", [&o] { o.progress = false; }, "No progress bar");
  cmd->add_flag_callback(
      "--no-work-limit", [&o] { o.work_limit = false; },
      "Run even if the estimated work exceeds the limits (docs/case-files.md, Limits)");
  return {cmd, [owned] {
            run_campaign(*owned, std::cout);
            return 0;
          }};
}

Command add_diagnose(CLI::App& app) {
  auto owned = std::make_shared<DiagnoseOptions>();
  DiagnoseOptions& o = *owned;
  CLI::App* cmd = app.add_subcommand("diagnose",
                                     "The sim-to-real gap of a campaign: "
                                     "where, which effect, how far it shrinks");
  cmd->add_option("dir", o.dirs,
                  "Campaign folder (docs/data-format.md); with --summary: several, or folders of campaign folders")
      ->required();
  cmd->add_option("--summary", o.summary_path,
                  "Diagnose every campaign given and write one row per campaign to this CSV (resumed if it exists; "
                  "docs/mpi.md)")
      ->check(kOutputFile);
  cmd->add_option("--threads", o.threads,
                  "Threads (default 0: all cores): one campaign's effects fitted in parallel; with --summary, "
                  "campaigns in parallel, one thread each (under mpirun 1 per rank). The results do not depend on it");
  cmd->add_flag_callback("--no-progress", [&o] { o.progress = false; }, "No progress bar (of the effects' fits; with --summary, of the campaigns)");
  cmd->add_option("--json", o.json_path, "Write the diagnosis as JSON")->check(kOutputFile);
  cmd->add_option("--report", o.report_dir, "Write report.md, report.html and diagnosis.json to this folder");
  cmd->add_flag("--check", o.check,
                "Read and check the folder only (every file, run and setting; exit 2 naming what is bad); no diagnosis");
  // DiagnoseSettings over the manifest's [diagnose] (docs/data-format.md): a flag per field.
  add_override_flags(cmd, o.settings);
  return {cmd,
          [owned] {
            DiagnoseOptions& d = *owned;
            if (!d.summary_path.empty()) {
              if (d.check) throw InputError("diagnose --check: one campaign folder at a time (not with --summary)");
              return run_diagnose_many(d, std::cout) > 0 ? 2 : 0;
            }
            if (d.dirs.size() > 1)
              throw InputError("diagnose: several campaign folders need --summary FILE (one row per campaign)");
            d.dir = d.dirs.front();
            return run_diagnose(d, std::cout);
          },
          [owned] { return !owned->summary_path.empty(); }};
}

Command add_blind(CLI::App& app) {
  auto owned = std::make_shared<BlindOptions>();
  BlindOptions& o = *owned;
  CLI::App* cmd = app.add_subcommand("blind",
                                     "Campaigns with random hidden effects, "
                                     "diagnosed without their keys, then scored");
  add_settings_flags(cmd, o.settings);  // --n, --seed, --threads (BlindSettings' fields)
  cmd->add_option("--out", o.out_dir, "Output folder (scores.json, confusion.csv; campaigns.txt: a rerun resumes)")
      ->capture_default_str();
  cmd->add_flag_callback(
      "--no-progress", [&o] { o.progress = false; }, "No progress bar");
  cmd->add_flag("--check-advice", o.check_advice,
                "Then simulate each ambiguous or unexplained campaign's advised runs under its truth, append them and "
                "diagnose again (advice.txt; docs/blind.md)");
  return {cmd,
          [owned] {
            run_blind(*owned, std::cout);
            return 0;
          },
          [] { return true; }};
}

#ifdef VRELAB_HAVE_MPI
vrelab::core::MpiJob*& mpi_job() {
  static vrelab::core::MpiJob* job = nullptr;
  return job;
}
#endif

// A rank other than 0's error message, printed only if rank 0 has not ended the job first.
std::string& worker_error() {
  static std::string message;
  return message;
}

// Under mpirun (core/mpi.hpp) rank 0 prints and writes; the other ranks say nothing, and a
// rank that met an error (`raised`) ends the job: the others may wait in a dispatch it will
// not reach. A rank other than 0 first gives rank 0 3 s to report the same error (a bad
// case file is every rank's) and end the job itself. A command that ran to its end with
// failed items (exit 2) just returns: every rank has left the dispatch.
int exit_code(int code, bool raised, bool root) {
#ifdef VRELAB_HAVE_MPI
  if (raised && vrelab::core::process_count() > 1 && mpi_job()) {
    if (!root) {
      std::this_thread::sleep_for(std::chrono::seconds(3));
      std::fprintf(stderr, "%s\n", worker_error().c_str());
    }
    std::fflush(nullptr);
    mpi_job()->abort(code);
  }
#else
  (void)raised, (void)root;
#endif
  return code;
}

// The chosen command's exit code; errors printed (rank 0), or by another rank with its number.
int run_command(const std::vector<Command>& commands, bool root, bool* raised) {
  const int rank = vrelab::core::process_rank();
  auto report = [&](const char* kind, const char* what) {
    *raised = true;
    if (root) std::cerr << "vrelab: " << kind << what << "\n";
    else worker_error() = std::string("vrelab: rank ").append(std::to_string(rank)).append(": ").append(kind).append(what);
  };
  try {
    for (const Command& c : commands)
      if (*c.sub) {
        if (!root && !c.distributed()) return 0;  // rank 0 runs it alone
        return c.run();
      }
  } catch (const InputError& e) {
    report("error: ", e.what());
    return 2;
  } catch (const vrelab::plant::SolverError& e) {
    report("error: ", e.what());
    return 2;
  } catch (const std::invalid_argument& e) {
    // The library rejects parameters it cannot work with (e.g. an unstable loop
    // design): input that passed the case reader's checks but not the physics.
    report("error: ", e.what());
    return 2;
  } catch (const std::filesystem::filesystem_error& e) {
    // A path the system refuses (a reader's or writer's check above it missed it): the user's.
    report("error: ", (path_for_message(e.path1().string()) + ": " + e.code().message()).c_str());
    return 2;
  } catch (const std::exception& e) {
    report("internal error: ", e.what());
    return 1;
  }
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
#ifdef __GLIBC__
  // The diagnosis allocates and frees matrices of 100-250 kB thousands of times a second (a
  // 168-run campaign's covariance and its factorisation): with glibc's default thresholds each
  // is an mmap and munmap, and freed heap tops are trimmed and faulted in again (185 000 page
  // faults, ~10 % of a diagnosis in the kernel). Blocks up to 32 MiB come from the heap, and
  // up to 256 MiB of freed heap is kept.
  mallopt(M_MMAP_THRESHOLD, 32 << 20);
  mallopt(M_TRIM_THRESHOLD, 256 << 20);
#endif
#ifdef VRELAB_HAVE_MPI
  // Only under mpirun; without it the program runs on threads, as it does without MPI.
  std::unique_ptr<vrelab::core::MpiJob> mpi;
  try {
    mpi = vrelab::core::start_mpi(&argc, &argv);
  } catch (const std::exception& e) {
    std::cerr << "vrelab: internal error: " << e.what() << "\n";
    return 1;
  }
  mpi_job() = mpi.get();
  const bool root = vrelab::core::is_root_process();
#else
  // Built without MPI but started by mpirun: rank 0 runs the command on its threads, the
  // others leave at once (N copies would each write the same files).
  const char* rank_env = std::getenv("OMPI_COMM_WORLD_RANK") ? std::getenv("OMPI_COMM_WORLD_RANK") : std::getenv("PMI_RANK");
  if (rank_env && std::string(rank_env) != "0") return 0;
  if (rank_env)
    std::cerr << "vrelab: note: built without MPI (-DVRELAB_MPI=ON, docs/mpi.md): running on rank 0's threads alone\n";
  const bool root = true;
#endif
  if (!root) {  // no output, no progress from the other ranks
    std::cout.setstate(std::ios::badbit);
    std::cerr.setstate(std::ios::badbit);
  }
  CLI::App app{
      "vrelab: a virtual shaker laboratory for the vibration "
      "rectification error of accelerometers"};
  app.set_version_flag("--version",
                       std::string("vrelab ") + vrelab::kProgramVersion + " (" + vrelab::kGitDescribe + ")");
  app.require_subcommand(1);
  const std::vector<Command> commands = {add_identify(app), add_predict(app),   add_shake(app),     add_measure(app),
                                         add_sweep(app),    add_frequency(app), add_reproduce(app), add_campaign(app),
                                         add_diagnose(app), add_blind(app)};
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    const int rc = app.exit(e);
    return rc == 0 ? 0 : 2;
  }
  bool raised = false;
  const int code = run_command(commands, root, &raised);
  return exit_code(code, raised, root);
}
