#pragma once
// io/services/blind_report.hpp -- `blind --out DIR`'s report (io/formats/report.hpp).
//
// Takes: a blind run's result and why its confusion figure was not drawn ("" when it was:
//        DIR/confusion.png/svg from tools/plots/confusion.py).
// Gives: the report: the targets met in the summary box, how often diagnose was right per kind of
//        campaign (each rate with its 95 % interval, "n/a" for a kind with no campaign), the
//        targets, the confusion matrix (figure and table, the rows and columns of confusion.csv),
//        the shrinkage, every miss with why. Rendered by Report::html(DIR), which embeds the figure.
#include <string>

#include "io/formats/report.hpp"
#include "validation/diagnosis/blind.hpp"

namespace vrelab::io {

Report blind_report(const validation::BlindResult& r, const std::string& figure_missing);

}  // namespace vrelab::io
