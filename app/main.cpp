// vrelab: the command-line interface. A thin layer: options in, library calls, results out.
// Exit codes: 0 success, 2 bad input (case file, options, parameters the physics rejects,
// solver failures), 1 anything else.
#include <iostream>
#include <stdexcept>
#include <string>

#include <CLI/CLI.hpp>

#include "io/case_file.hpp"
#include "app/commands.hpp"
#include "plant/ode_solver.hpp"
#include "vrelab_version.hpp"

int main(int argc, char** argv) {
  using namespace vrelab::app;
  using namespace vrelab::io;
  CLI::App app{"vrelab: a virtual shaker laboratory for the vibration rectification error of accelerometers"};
  app.set_version_flag("--version", std::string("vrelab ") + vrelab::kProgramVersion + " (" + vrelab::kGitDescribe + ")");
  app.require_subcommand(1);

  IdentifyOptions id;
  auto* identify = app.add_subcommand(
      "identify", "Virtual static test on a dividing head; identify the coefficients of model (1)");
  identify->add_option("case", id.case_path, "Case file (TOML)")->required();
  identify->add_option("--json", id.json_path, "Write the result as JSON to this file");
  identify->add_option("--monte-carlo", id.monte_carlo, "Also run N simulated tests for Monte Carlo uncertainty")
      ->check(CLI::NonNegativeNumber);
  identify->add_option("--seed", id.seed, "Override the case's [run] seed");

  PredictOptions pr;
  auto* predict = app.add_subcommand("predict", "Vibration error implied by model (1): eq. (3), corrected");
  predict->add_option("case", pr.case_path, "Case file (TOML)")->required();
  predict->add_option("--json", pr.json_path, "Write the result as JSON to this file");
  predict->add_flag("--frequency-dependent", pr.frequency_dependent,
                    "Also eq. (3) at [vibration] frequency_Hz through the plant's dynamics ([plant]; sine only)");

  ShakeOptions sh;
  auto* shake = app.add_subcommand("shake", "One run on the virtual shaker: measured vibration error vs eq. (3)");
  shake->add_option("case", sh.case_path, "Case file (TOML)")->required();
  shake->add_option("--json", sh.json_path, "Write the result as JSON to this file");
  shake->add_option("--series", sh.series_path, "Write the sampled record as CSV to this file");
  shake->add_option("--seed", sh.seed, "Override the case's [run] seed");

  MeasureOptions me;
  auto* measure = app.add_subcommand("measure", "Vibration error from a recorded output series (CSV)");
  measure->add_option("series", me.series_path, "CSV: time_s first, then output column(s); '#' lines are comments")
      ->required();
  measure->add_option("--on", me.on_s, "Vibration interval FROM,TO in s")->delimiter(',')->expected(2)->required();
  measure->add_option("--baseline", me.baseline_s, "Baseline (at rest) interval FROM,TO in s")
      ->delimiter(',')
      ->expected(2)
      ->required();
  measure->add_option("--frequency", me.frequency_Hz, "Sine frequency in Hz: measure over whole periods");
  measure->add_option("--K1", me.K1, "Scale factor, output units per g (default 1: output in g)");
  measure->add_option("--column", me.column, "Output column name (default: the last column)");
  measure->add_option("--blocks", me.blocks, "Blocks for the batch-means uncertainty (default 4)");
  measure->add_option("--json", me.json_path, "Write the result as JSON to this file");

  SweepOptions sw;
  auto* sweep = app.add_subcommand("sweep", "A grid of shaker runs on all cores; resumable");
  sweep->add_option("case", sw.case_path, "Case file (TOML) with a [sweep] table")->required();
  sweep->add_option("--out", sw.out_path, "Results CSV (resumed if it exists)")->required();
  sweep->add_flag("--restart", sw.restart, "Discard an existing results file");
  sweep->add_option("--threads", sw.threads, "Threads (default: the case's, 0 = all cores)");
  bool no_progress = false;
  sweep->add_flag("--no-progress", no_progress, "No progress bar");

  FrequencyOptions fr;
  auto* frequency = app.add_subcommand(
      "frequency", "Vibration error against frequency per term and place: eq. (3) through the dynamics vs the ODE");
  frequency->add_option("case", fr.case_path, "Case file (TOML): [coefficients], [orientation], [plant], [frequency_study]")
      ->required();
  frequency->add_option("--out", fr.out_dir, "Output folder (CSV, JSON, Markdown table, PNG/SVG figure)")->required();

  ReproduceOptions rp;
  auto* reproduce = app.add_subcommand(
      "reproduce", "The paper's experiment end to end: static test, confirmation plot, eq. (3) vs the shaker; report");
  reproduce->add_option("case", rp.case_path, "Case file (TOML) with [dividing_head] and [reproduce]")
      ->capture_default_str();
  reproduce->add_option("--out", rp.out_dir, "Output folder (report.html, report.md, figures, CSV/JSON)")
      ->capture_default_str();
  reproduce->add_option("--threads", rp.threads, "Threads (default: the case's, 0 = all cores)");
  bool no_plots = false;
  reproduce->add_flag("--no-plots", no_plots, "Write the data and the report without figures");

  CampaignOptions cp;
  auto* campaign = app.add_subcommand("campaign", "The virtual lab: a whole campaign from a truth with hidden effects, "
                                                  "in the lab data format, and its answer key");
  campaign->add_option("case", cp.case_path, "Case file (TOML) with [coefficients], [plant] and [campaign]")->required();
  campaign->add_option("--out", cp.out_dir, "Campaign folder (docs/data-format.md)")->required();
  campaign->add_option("--key", cp.key_path, "Answer key (JSON; default <out>.key.json); diagnose never reads it");
  campaign->add_option("--seed", cp.seed, "Seed (default: the case's [run] seed)");

  DiagnoseOptions dg;
  auto* diagnose = app.add_subcommand("diagnose", "The sim-to-real gap of a campaign: where, which effect, how far it shrinks");
  diagnose->add_option("dir", dg.dir, "Campaign folder (docs/data-format.md)")->required();
  diagnose->add_option("--json", dg.json_path, "Write the diagnosis as JSON");
  diagnose->add_option("--report", dg.report_dir, "Write report.md, report.html and diagnosis.json to this folder");
  // DiagnoseSettings over the manifest's [diagnose] (docs/data-format.md).
  diagnose->add_option("--significance-sigma", dg.settings.significance_sigma, "A gap is significant beyond this many sigma (5)");
  diagnose->add_option("--model-accuracy", dg.settings.model_accuracy, "The simulation's relative accuracy (0.002)");
  diagnose->add_option("--explained-shrinkage", dg.settings.explained_shrinkage,
                       "Held-out gap rms share an effect must remove to explain the gap (0.9)");
  diagnose->add_option("--resimulate-runs", dg.settings.resimulate_runs, "Runs re-simulated on the ODE plant (12; 0: none)");
  diagnose->add_flag_callback("--no-pairs", [&dg] { dg.settings.try_pairs = false; }, "Do not try two effects at once");

  BlindOptions bl;
  auto* blind = app.add_subcommand("blind", "Campaigns with random hidden effects, diagnosed without their keys, then scored");
  blind->add_option("--n", bl.settings.n, "Number of campaigns")->capture_default_str();
  blind->add_option("--seed", bl.settings.seed, "Seed of the draw")->capture_default_str();
  blind->add_option("--out", bl.out_dir, "Output folder (scores.json, confusion.csv)")->capture_default_str();
  blind->add_option("--threads", bl.settings.threads, "Threads (0: all cores)");
  blind->add_flag_callback("--no-progress", [&bl] { bl.progress = false; }, "No progress bar");

  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    const int rc = app.exit(e);
    return rc == 0 ? 0 : 2;
  }
  try {
    if (*identify) run_identify(id, std::cout);
    if (*predict) run_predict(pr, std::cout);
    if (*shake) run_shake(sh, std::cout);
    if (*measure) run_measure(me, std::cout);
    if (*frequency) run_frequency(fr, std::cout);
    if (*campaign) run_campaign(cp, std::cout);
    if (*diagnose) run_diagnose(dg, std::cout);
    if (*blind) run_blind(bl, std::cout);
    if (*reproduce) {
      rp.plots = !no_plots;
      run_reproduce(rp, std::cout);
    }
    if (*sweep) {
      sw.progress = !no_progress;
      if (run_sweep(sw, std::cout) > 0) return 2;
    }
  } catch (const InputError& e) {
    std::cerr << "vrelab: error: " << e.what() << "\n";
    return 2;
  } catch (const vrelab::plant::SolverError& e) {
    std::cerr << "vrelab: error: " << e.what() << "\n";
    return 2;
  } catch (const std::invalid_argument& e) {
    // The library rejects parameters it cannot work with (e.g. an unstable loop design):
    // input that passed the case reader's checks but not the physics.
    std::cerr << "vrelab: error: " << e.what() << "\n";
    return 2;
  } catch (const std::exception& e) {
    std::cerr << "vrelab: internal error: " << e.what() << "\n";
    return 1;
  }
  return 0;
}
