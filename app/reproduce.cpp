// app/reproduce.cpp -- `vrelab reproduce`: the paper's experiment, its report and its data.
// The run and its analysis are validation::reproduce; the files and the report io/reproduce_report.
#include <chrono>
#include <iostream>

#include <fmt/format.h>

#include "app/commands.hpp"
#include "io/case_file.hpp"
#include "io/output.hpp"
#include "io/reproduce_report.hpp"
#include "vrelab_version.hpp"

namespace vrelab::app {
using namespace vrelab::io;

void run_reproduce(const ReproduceOptions& o, std::ostream& out) {
  const Case c = read_case(o.case_path);
  require(c, c.coefficients.has_value(), "coefficients", "reproduce");
  require(c, c.dividing_head.has_value(), "dividing_head", "reproduce");
  require(c, c.reproduce.has_value(), "reproduce", "reproduce");
  if (c.physical) throw InputError(c.path + ": reproduce takes a plant built from coefficients ([plant] type = \"from_coefficients\")");
  validation::ReproduceSettings s = *c.reproduce;
  if (o.threads >= 0) s.threads = o.threads;
  if (std::string why; !s.IsValid(&why)) throw InputError(c.path + ": " + why);
  if (o.work_limit) check_reproduce_work(c);
  const std::string& dir = o.out_dir;
  const auto start = std::chrono::steady_clock::now();
  out << fmt::format("vrelab {} ({}) reproduce {}  [seed {}] -> {}\n", kProgramVersion, kGitDescribe, c.path, c.seed, dir);
  const validation::ReproduceResult res = validation::reproduce(
      c.plant, s, [&out](const std::string& m) { out << "  " << m << "\n" << std::flush; }, &std::cerr);
  const double wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();

  write_reproduce_data(c, s, res, wall_s, dir);
  const std::string figures_missing = o.plots ? run_plot_script("reproduce.py", dir) : std::string("--no-plots was given");
  const Report rep = reproduce_full_report(c, s, res, wall_s, figures_missing);
  write_atomic(dir + "/report.md", rep.markdown());
  write_atomic(dir + "/report.html", rep.html());

  out << reproduce_brief_report(res);
  if (!figures_missing.empty()) out << "Figures skipped: " << figures_missing << "\n";
  out << fmt::format("Wrote {}/report.html, report.md and the data ({:.1f} s wall)\n", dir, wall_s);
}

}  // namespace vrelab::app
