// app/reproduce.cpp -- `vrelab reproduce`: the paper's experiment, its report and its data
// (io::reproduce_to_folder, io/services/reproduce_run.hpp).
#include <iostream>

#include <fmt/format.h>

#include "app/commands.hpp"
#include "io/formats/case_file.hpp"
#include "io/services/reproduce_report.hpp"
#include "io/services/reproduce_run.hpp"
#include "vrelab_version.hpp"

namespace vrelab::app {

void run_reproduce(const ReproduceOptions& o, std::ostream& out) {
  const io::Case c = io::read_case(o.case_path);
  if (o.work_limit) check_reproduce_work(c);
  // The header line before the first progress line: after the checks, so bad input prints nothing.
  bool header = false;
  const auto print_header = [&] {
    if (!header)
      out << fmt::format("vrelab {} ({}) reproduce {}  [seed {}] -> {}\n", kProgramVersion, kGitDescribe, c.path,
                         c.seed, o.out_dir);
    header = true;
  };
  const io::ReproduceRun run = io::reproduce_to_folder(
      c, o.out_dir, o.threads, o.plots,
      [&](const std::string& m) {
        print_header();
        out << "  " << m << "\n" << std::flush;
      },
      &std::cerr);
  print_header();
  out << io::reproduce_brief_report(run.result);
  if (!run.figures_missing.empty()) out << "Figures skipped: " << run.figures_missing << "\n";
  out << fmt::format("Wrote {}/report.html, report.md and the data ({:.1f} s wall)\n", o.out_dir, run.wall_s);
}

}  // namespace vrelab::app
