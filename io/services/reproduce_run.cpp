// io/services/reproduce_run.cpp -- the paper's experiment on a case file, written to a folder.
#include "io/services/reproduce_run.hpp"

#include <chrono>

#include "io/formats/output.hpp"
#include "io/services/reproduce_report.hpp"

namespace vrelab::io {

ReproduceRun reproduce_to_folder(const Case& c, const std::string& out_dir, int threads, bool plots,
                                 const std::function<void(const std::string&)>& log, std::ostream* progress) {
  require(c, c.coefficients.has_value(), "coefficients", "reproduce");
  require(c, c.dividing_head.has_value(), "dividing_head", "reproduce");
  require(c, c.reproduce.has_value(), "reproduce", "reproduce");
  if (c.physical) throw InputError(c.path + ": reproduce takes a plant built from coefficients ([plant] type = \"from_coefficients\")");
  ReproduceRun run;
  run.settings = *c.reproduce;
  if (threads >= 0) run.settings.threads = threads;
  if (std::string why; !run.settings.IsValid(&why)) throw InputError(c.path + ": " + why);
  run.out_dir = out_dir;
  const auto start = std::chrono::steady_clock::now();
  run.result = validation::reproduce(c.plant, run.settings, log, progress);
  run.wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();

  write_reproduce_data(c, run.settings, run.result, run.wall_s, out_dir);
  run.figures_missing = plots ? run_plot_script("reproduce.py", out_dir) : std::string("--no-plots was given");
  const Report rep = reproduce_full_report(c, run.settings, run.result, run.wall_s, run.figures_missing);
  write_report_folder(out_dir, rep);
  return run;
}

}  // namespace vrelab::io
