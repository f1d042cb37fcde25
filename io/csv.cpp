#include "io/csv.hpp"

#include <algorithm>
#include <fstream>
#include <stdexcept>

#include <fmt/format.h>

#include "io/case_file.hpp"

namespace vrelab::io {

std::vector<std::string> split_csv_line(const std::string& line, const std::string& where) {
  std::vector<std::string> out;
  std::size_t i = 0;
  const auto blank = [](char c) { return c == ' ' || c == '\t' || c == '\r'; };
  while (true) {
    while (i < line.size() && blank(line[i])) ++i;
    std::string cell;
    if (i < line.size() && line[i] == '"') {
      for (++i;; ++i) {
        if (i >= line.size()) throw std::invalid_argument(where + ": a quoted cell is not closed");
        if (line[i] == '"') {
          if (i + 1 < line.size() && line[i + 1] == '"') cell += '"', ++i;
          else break;
        } else {
          cell += line[i];
        }
      }
      ++i;
      while (i < line.size() && blank(line[i])) ++i;
      if (i < line.size() && line[i] != ',') throw std::invalid_argument(where + ": text after a quoted cell");
    } else {
      const std::size_t end = std::min(line.find(',', i), line.size());
      cell = line.substr(i, end - i);
      while (!cell.empty() && blank(cell.back())) cell.pop_back();
      i = end;
    }
    out.push_back(std::move(cell));
    if (i >= line.size()) break;
    ++i;  // the comma
  }
  return out;
}

namespace {

bool is_number(const std::string& field) {
  std::size_t used = 0;
  try {
    std::stod(field, &used);
  } catch (const std::exception&) {
    used = 0;
  }
  return used == field.size() && used > 0;
}

// The output column of a header: `name`, or the last column.
int series_column(const std::vector<std::string>& header, const std::string& name, const std::string& where) {
  if (header.size() < 2) throw InputError(where + ": the header needs a time column and an output column");
  int column = -1;
  if (name.empty()) {
    column = static_cast<int>(header.size()) - 1;
  } else {
    for (std::size_t i = 0; i < header.size(); ++i)
      if (header[i] == name) column = static_cast<int>(i);
    if (column < 1) throw InputError(fmt::format("{}: no column named '{}'", where, name));
  }
  if (column == 0) throw InputError(where + ": the output column cannot be the time column");
  // A header names the columns: a first line of numbers means the header is missing.
  if (std::all_of(header.begin(), header.end(), is_number))
    throw InputError(where + ": expected a header line naming the columns (e.g. time_s,output), got numbers");
  return column;
}

}  // namespace

std::string read_series_csv(const std::string& path, const std::string& column_name,
                            const std::function<void(double, double)>& sample) {
  std::ifstream in(path);
  if (!in) throw InputError(path + ": cannot open the series (no such file?)");
  std::string line, name;
  long line_no = 0;
  std::size_t column = 0;
  std::vector<std::string> header;
  while (std::getline(in, line)) {
    ++line_no;
    if (!line.empty() && line.back() == '\r') line.pop_back();
    if (line.empty() || line[0] == '#') continue;
    const std::string where = fmt::format("{}:{}", path, line_no);
    std::vector<std::string> f;
    try {
      f = split_csv_line(line, where);
    } catch (const std::invalid_argument& e) {
      throw InputError(e.what());
    }
    if (header.empty()) {
      header = f;
      column = static_cast<std::size_t>(series_column(header, column_name, where));
      name = header[column];
      continue;
    }
    if (f.size() != header.size())
      throw InputError(fmt::format("{}: {} fields, the header has {}", where, f.size(), header.size()));
    if (!is_number(f[0]) || !is_number(f[column])) throw InputError(fmt::format("{}: not a number in '{}'", where, line));
    try {
      sample(std::stod(f[0]), std::stod(f[column]));
    } catch (const std::invalid_argument& e) {
      throw InputError(fmt::format("{}: {} (t = {}, {} = {})", where, e.what(), f[0], name, f[column]));
    }
  }
  if (header.empty()) throw InputError(path + ": no header line and no samples");
  return name;
}

}  // namespace vrelab::io
