// app/commands.cpp -- the CLI's commands: read the case, call the study (io/services/studies.hpp),
// print its report, write its JSON (io/services/results_json.hpp).
#include "app/commands.hpp"

#include <cmath>
#include <string>

#include "core/dispatch.hpp"
#include "io/formats/case_file.hpp"
#include "io/formats/output.hpp"
#include "io/services/results_json.hpp"
#include "io/services/studies.hpp"

namespace vrelab::app {
namespace {

// A result with inf or NaN is not written (nor printed as if it were one): exit 2, naming it.
void check_finite(const io::Case& c, const nlohmann::json& j) {
  io::require_finite(j, c.path, "a value of the case drives the computation out of range");
}

void write_json(const std::string& path, const nlohmann::json& j) {
  if (!path.empty()) io::write_atomic(path, io::json_text(j));
}

}  // namespace

void run_identify(const IdentifyOptions& o, std::ostream& out) {
  if (!o.checkpoint_path.empty() && o.monte_carlo == 0) throw io::InputError("--checkpoint needs --monte-carlo N");
  io::Case c = io::read_case(o.case_path);
  if (o.seed) c.seed = *o.seed;
  if (o.work_limit) check_identify_work(c, o.monte_carlo);
  const io::IdentifyStudy s = io::identify(c, o.monte_carlo, o.checkpoint_path);
  if (!core::is_root_process()) return;  // under mpirun the Monte Carlo's results are rank 0's
  nlohmann::json j = io::identify_json(c, s);
  if (o.monte_carlo > 0) {  // where the trials ran (they do not depend on it: blocks seeded by their index)
    j["settings"]["monte_carlo_ranks"] = core::process_count();
    j["settings"]["monte_carlo_threads_per_rank"] = core::threads_per_process(0);
  }
  check_finite(c, j);
  out << io::identify_report(c, s);
  write_json(o.json_path, j);
}

void run_predict(const PredictOptions& o, std::ostream& out) {
  const io::Case c = io::read_case(o.case_path);
  const io::PredictStudy s = io::predict(c, o.frequency_dependent);
  const nlohmann::json j = io::predict_json(c, s);
  check_finite(c, j);
  out << io::predict_report(c, s);
  write_json(o.json_path, j);
}

void run_shake(const ShakeOptions& o, std::ostream& out) {
  io::Case c = io::read_case(o.case_path);
  if (o.seed) c.seed = *o.seed, c.shake.readout.seed = *o.seed;
  if (o.work_limit) check_shake_work(c);
  const io::ShakeStudy s = io::shake(c, o.series_path);
  const nlohmann::json j = io::shake_json(c, s);
  check_finite(c, j);
  out << io::shake_report(c, s);
  write_json(o.json_path, j);
}

void run_measure(const MeasureOptions& o, std::ostream& out) {
  if (o.on_s.size() != 2 || o.baseline_s.size() != 2)
    throw io::InputError("--on and --baseline each take FROM,TO in seconds");
  rectification::SeriesWindows w;
  w.on_from_s = o.on_s[0], w.on_to_s = o.on_s[1];
  w.baseline_from_s = o.baseline_s[0], w.baseline_to_s = o.baseline_s[1];
  w.frequency_Hz = o.frequency_Hz, w.blocks = o.blocks, w.input_rms_g = o.input_rms_g;
  const io::MeasureStudy s = io::measure(o.series_path, o.column, w, o.K1);
  out << io::measure_report(s);
  write_json(o.json_path, io::measure_json(s));
}

int run_sweep(const SweepOptions& o, std::ostream& out) {
  const io::Case c = io::read_case(o.case_path);
  if (o.work_limit) check_sweep_work(c);
  const io::SweepStudy s = io::sweep(c, o.out_path, o.restart, o.threads, o.progress, out);
  out << io::sweep_report(s, o.out_path);
  return static_cast<int>(s.failures.size());
}

void run_frequency(const FrequencyOptions& o, std::ostream& out) {
  const io::Case c = io::read_case(o.case_path);
  if (o.work_limit) check_frequency_work(c);
  const io::FrequencyStudy s = io::frequency(c);
  out << io::frequency_report(c, s);
  io::write_frequency_data(c, s, o.out_dir);
  const std::string why = io::run_plot_script("frequency.py", o.out_dir);
  if (!why.empty())
    out << "Figures skipped: " << why << ". The data are in " << o.out_dir << "\n";
  else
    out << "Wrote " << o.out_dir << "/frequency.{csv,png,svg}, ode_points.csv, summary.{md,json}\n";
}

}  // namespace vrelab::app
