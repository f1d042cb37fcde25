#pragma once
// io/csv.hpp -- the one CSV reader of the library: a line into cells, and an output series.
//
// Cells are trimmed of blanks; a cell may be quoted ("a, b"; "" is a quote inside), as
// spreadsheets write them. '#' lines are comments.
#include <functional>
#include <string>
#include <vector>

namespace vrelab::io {

// One CSV line into cells. An unclosed quote, or text after a quoted cell, is
// std::invalid_argument naming `where` (e.g. "file.csv:12").
std::vector<std::string> split_csv_line(const std::string& line, const std::string& where);

// A recorded output series: a header naming the columns, time (s) in the first column.
// Streams (t, value of `column`) to `sample` row by row (`column` empty: the last column) and
// returns the column's name. Anything wrong (no file, no header, a field count, not a
// number, `sample` rejecting a row with std::invalid_argument) is InputError naming the
// file and the line.
std::string read_series_csv(const std::string& path, const std::string& column,
                            const std::function<void(double t_s, double value)>& sample);

}  // namespace vrelab::io
