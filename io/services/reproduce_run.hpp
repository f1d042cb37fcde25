#pragma once
// io/services/reproduce_run.hpp -- `vrelab reproduce` as one library call: the paper's experiment on a
// case file, its data, figures and report written to a folder (docs/reproduce.md).
//
// Takes: a Case with [coefficients], [dividing_head] and [reproduce] (a plant built from the
//        coefficients), the output folder, a thread count over the case's and whether to draw
//        the figures.
// Gives: the result (validation::reproduce), the settings it ran with, the wall time, and why
//        figures are missing ("" when drawn). Writes the data (io/services/reproduce_report.hpp), the
//        figures (tools/plots/reproduce.py) and report.{md,html} in `out_dir`. Progress lines
//        go to `log` when given, the shaker runs' progress bars to `progress` when given.
//        Bad input is InputError naming the case file (exit code 2 in the CLI).
#include <functional>
#include <ostream>
#include <string>

#include "io/formats/case_file.hpp"
#include "validation/reproduce/reproduce.hpp"

namespace vrelab::io {

struct ReproduceRun {
  validation::ReproduceSettings settings;  // used
  validation::ReproduceResult result;
  std::string out_dir;
  std::string figures_missing;  // "" when the figures were drawn, else why not
  double wall_s = 0;
};

// threads < 0: the case's [reproduce] threads (0: all cores).
ReproduceRun reproduce_to_folder(const Case& c, const std::string& out_dir, int threads, bool plots,
                                 const std::function<void(const std::string&)>& log = {},
                                 std::ostream* progress = nullptr);

}  // namespace vrelab::io
