#include "io/formats/csv.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <map>
#include <stdexcept>

#include <fmt/format.h>

#include "io/formats/error.hpp"
#include "io/formats/paths.hpp"
#include "io/formats/ranges.hpp"

namespace vrelab::io {

std::vector<std::string> split_csv_line(const std::string& line, const std::string& path, long line_no, char separator) {
  std::vector<std::string> out;
  std::size_t i = 0;
  const auto blank = [separator](char c) { return c != separator && (c == ' ' || c == '\t' || c == '\r'); };
  while (true) {
    while (i < line.size() && blank(line[i])) ++i;
    std::string cell;
    if (i < line.size() && line[i] == '"') {
      for (++i;; ++i) {
        if (i >= line.size()) throw FormatError({.file = path, .line = line_no}, "a quoted cell is not closed");
        if (line[i] == '"') {
          if (i + 1 < line.size() && line[i + 1] == '"') cell += '"', ++i;
          else break;
        } else {
          cell += line[i];
        }
      }
      ++i;
      while (i < line.size() && blank(line[i])) ++i;
      if (i < line.size() && line[i] != separator) throw FormatError({.file = path, .line = line_no}, "text after a quoted cell");
    } else {
      const std::size_t end = std::min(line.find(separator, i), line.size());
      cell = line.substr(i, end - i);
      while (!cell.empty() && blank(cell.back())) cell.pop_back();
      i = end;
    }
    out.push_back(std::move(cell));
    if (i >= line.size()) break;
    ++i;  // the separator
  }
  return out;
}

std::optional<double> parse_decimal(std::string_view s) {
  std::size_t i = 0;
  const auto digits = [&] {
    const std::size_t from = i;
    while (i < s.size() && s[i] >= '0' && s[i] <= '9') ++i;
    return i - from;
  };
  if (i < s.size() && (s[i] == '+' || s[i] == '-')) ++i;
  std::size_t mantissa = digits();
  if (i < s.size() && s[i] == '.') {
    ++i;
    mantissa += digits();
  }
  if (mantissa == 0) return std::nullopt;
  if (i < s.size() && (s[i] == 'e' || s[i] == 'E')) {
    ++i;
    if (i < s.size() && (s[i] == '+' || s[i] == '-')) ++i;
    if (digits() == 0) return std::nullopt;
  }
  if (i != s.size()) return std::nullopt;
  // The grammar is strtod's decimal subset, so strtod reads exactly what the grammar accepted
  // (the "C" locale: the program never sets another).
  const std::string text(s);
  const double x = std::strtod(text.c_str(), nullptr);
  if (!std::isfinite(x)) return std::nullopt;  // 1e999
  return x;
}

std::string why_not_decimal(std::string_view s) {
  std::string lower;
  for (char ch : s) lower += static_cast<char>(std::tolower(static_cast<unsigned char>(ch)));
  const std::string_view l = lower;
  const std::string_view body = !l.empty() && (l[0] == '+' || l[0] == '-') ? l.substr(1) : l;
  if (body.rfind("0x", 0) == 0) return "hexadecimal; write the decimal value";
  if (body.rfind("inf", 0) == 0 || body.rfind("nan", 0) == 0) return "not finite";
  if (s.find(',') != std::string_view::npos) return "a decimal comma; write a decimal point";
  if (!s.empty() && (std::isspace(static_cast<unsigned char>(s.front())) || std::isspace(static_cast<unsigned char>(s.back()))))
    return "blanks around the number";
  const std::string t(s);
  char* end = nullptr;
  const double x = std::strtod(t.c_str(), &end);
  if (!t.empty() && *end == '\0' && !std::isfinite(x)) return "beyond the range of a double";
  return "not a decimal number";
}

std::size_t first_non_utf8(std::string_view s) {
  std::size_t i = 0;
  while (i < s.size()) {
    const auto b = static_cast<unsigned char>(s[i]);
    if (b < 0x80) {
      ++i;
      continue;
    }
    std::size_t n = 0;
    unsigned cp = 0;
    if (b >= 0xC2 && b <= 0xDF) n = 1, cp = b & 0x1Fu;
    else if (b >= 0xE0 && b <= 0xEF) n = 2, cp = b & 0x0Fu;
    else if (b >= 0xF0 && b <= 0xF4) n = 3, cp = b & 0x07u;
    else return i;  // a continuation byte alone, 0xC0/0xC1 (overlong), 0xF5.. (past U+10FFFF)
    for (std::size_t k = 1; k <= n; ++k) {
      if (i + k >= s.size()) return i;
      const auto c = static_cast<unsigned char>(s[i + k]);
      if ((c & 0xC0u) != 0x80u) return i;
      cp = (cp << 6) | (c & 0x3Fu);
    }
    if ((n == 2 && cp < 0x800) || (n == 3 && (cp < 0x10000 || cp > 0x10FFFF)) || (cp >= 0xD800 && cp <= 0xDFFF)) return i;
    i += n + 1;
  }
  return std::string_view::npos;
}

void check_text_line(std::string& line, long line_no, const std::string& path) {
  if (line_no == 1 && line.rfind("\xEF\xBB\xBF", 0) == 0) line.erase(0, 3);
  if (!line.empty() && line.back() == '\r') line.pop_back();
  const std::size_t at = first_non_utf8(line);
  if (at != std::string::npos)
    throw FormatError({.file = path, .line = line_no, .column = static_cast<long>(at + 1)},
                      fmt::format("not UTF-8 at byte {} (0x{:02X}; a Latin-1 or Windows-1252 export?); save the file as UTF-8",
                                  at + 1, static_cast<unsigned>(static_cast<unsigned char>(line[at]))));
}

char header_separator(const std::string& header_line) {
  for (const char c : {',', ';', '\t'})
    if (header_line.find(c) != std::string::npos) return c;
  return ',';
}

std::string separator_name(char separator) { return separator == '\t' ? std::string("a tab") : fmt::format("'{}'", separator); }

void check_header_names(const std::vector<std::string>& header, const std::string& path, long line_no) {
  std::map<std::string_view, std::size_t> seen;  // name -> its first column (0-based)
  for (std::size_t i = 0; i < header.size(); ++i)
    if (const auto [it, fresh] = seen.emplace(header[i], i); !fresh)
      throw FormatError({.file = path, .line = line_no, .column = static_cast<long>(i + 1), .key = header[i]},
                        fmt::format("column '{}' appears twice in the header (columns {} and {})", header[i], it->second + 1, i + 1));
}

std::string closest_name(const std::string& name, const std::vector<std::string>& names) {
  const auto lower = [](std::string x) {
    for (char& ch : x) ch = static_cast<char>(std::tolower(static_cast<unsigned char>(ch)));
    return x;
  };
  for (const auto& n : names)
    if (lower(n) == lower(name)) return n;
  std::string best;
  std::size_t best_d = 4;
  for (const auto& n : names) {
    // Levenshtein distance, one row at a time.
    std::vector<std::size_t> row(n.size() + 1);
    for (std::size_t j = 0; j <= n.size(); ++j) row[j] = j;
    for (std::size_t i = 1; i <= name.size(); ++i) {
      std::size_t diag = row[0];
      row[0] = i;
      for (std::size_t j = 1; j <= n.size(); ++j) {
        const std::size_t up = row[j];
        row[j] = std::min({row[j] + 1, row[j - 1] + 1, diag + (name[i - 1] == n[j - 1] ? 0 : 1)});
        diag = up;
      }
    }
    if (row[n.size()] < best_d) best_d = row[n.size()], best = n;
  }
  return best;
}

namespace {

bool is_number(const std::string& field) { return parse_decimal(field).has_value(); }

// The output column of a header: `name`, or the last column.
int series_column(const std::vector<std::string>& header, const std::string& name, const FormatLocation& where) {
  if (header.size() < 2) throw FormatError(where, "the header needs a time column and an output column");
  int column = -1;
  if (name.empty()) {
    // The one output_<unit> column (as the HDF5 reader's one output_<unit> dataset), else the last.
    column = static_cast<int>(header.size()) - 1;
    if (std::count_if(header.begin(), header.end(), [](const std::string& h) { return h.rfind("output_", 0) == 0; }) == 1)
      column = static_cast<int>(std::find_if(header.begin(), header.end(),
                                             [](const std::string& h) { return h.rfind("output_", 0) == 0; }) -
                                header.begin());
  } else {
    for (std::size_t i = 0; i < header.size(); ++i)
      if (header[i] == name) column = static_cast<int>(i);
    if (column < 0) {
      std::string found;
      for (const auto& h : header) found += (found.empty() ? "" : ", ") + h;
      throw FormatError(where, fmt::format("no column named '{}' (the header has: {})", name, found));
    }
  }
  // The time column: time_s, else the first.
  if (column == 0 && std::find(header.begin(), header.end(), "time_s") == header.end())
    throw FormatError(where, "the output column cannot be the time column");
  // A header names the columns: a first line of numbers means the header is missing.
  if (std::all_of(header.begin(), header.end(), is_number))
    throw FormatError(where, "expected a header line naming the columns (e.g. time_s,output), got numbers");
  return column;
}

}  // namespace

std::string read_series_csv(const std::string& path, const std::string& column_name,
                            const std::function<void(double, double)>& sample) {
  return read_series_csv(path, column_name, sample, {});
}

std::string read_series_csv(const std::string& path, const std::string& column_name,
                            const std::function<void(double, double)>& sample, const ReferenceSink& reference,
                            const ChannelNames& names) {
  require_readable_file(path, "the series");
  std::ifstream in(path);
  if (!in) throw FormatError({.file = path}, "cannot open the series");
  return read_series_csv(in, path, column_name, sample, reference, names);
}

std::vector<std::string> with_vrelab_names(std::vector<std::string> header, const ChannelNames& names) {
  for (const auto& [ours, theirs] : names)
    for (std::string& h : header)
      if (h == theirs) h = ours;
  return header;
}

std::string read_series_csv(std::istream& in, const std::string& path, const std::string& column_name,
                            const std::function<void(double, double)>& sample, const ReferenceSink& reference,
                            const ChannelNames& names) {
  std::string line, name;
  long line_no = 0;
  std::size_t column = 0;
  std::vector<std::string> header;
  char separator = ',';
  std::size_t tcol = 0;  // the column time_s, else the first
  std::array<std::size_t, 3> ref_col{};
  std::array<bool, 3> ref_present{};
  bool any_ref = false;
  double last_t = -INFINITY;
  while (std::getline(in, line)) {
    ++line_no;
    check_text_line(line, line_no, path);
    if (line.empty() || line[0] == '#') continue;
    const FormatLocation where{.file = path, .line = line_no};
    if (header.empty()) separator = header_separator(line);
    const std::vector<std::string> f = split_csv_line(line, path, line_no, separator);
    if (header.empty()) {
      check_header_names(f, path, line_no);
      header = with_vrelab_names(f, names);
      check_header_names(header, path, line_no);  // (a lab's name mapped onto a column vrelab's name already has)
      column = static_cast<std::size_t>(series_column(header, column_name, where));
      name = header[column];
      if (const auto it = std::find(header.begin(), header.end(), "time_s"); it != header.end())
        tcol = static_cast<std::size_t>(it - header.begin());
      if (tcol == column) throw FormatError(where, "the output column cannot be the time column");
      static const std::array<const char*, 3> axes{"IA", "PA", "OA"};
      for (std::size_t i = 0; i < 3 && reference; ++i)
        for (const std::string prefix : {"ref_", "input_"}) {
          const auto it = std::find(header.begin(), header.end(), prefix + axes[i] + "_g");
          if (it != header.end() && !ref_present[i]) ref_col[i] = static_cast<std::size_t>(it - header.begin()), ref_present[i] = true;
        }
      any_ref = ref_present[0] || ref_present[1] || ref_present[2];
      continue;
    }
    if (f.size() != header.size())
      throw FormatError(where, fmt::format("{} fields, the header has {}", f.size(), header.size()));
    double value[2] = {0, 0};
    for (int k = 0; k < 2; ++k) {
      const std::size_t col = k == 0 ? tcol : column;
      const auto x = parse_decimal(f[col]);
      if (!x) {
        const std::string why = why_not_decimal(f[col]);
        if (why == "not finite")
          throw FormatError(where, fmt::format("a sample is not a finite number (column {}, '{}')", col + 1, f[col]));
        throw FormatError(where, fmt::format("not a number in '{}' (column {}, '{}': {})", line, col + 1, f[col], why));
      }
      value[k] = *x;
      if (const std::string out = range_problem(k == 0 ? kTimeRange : kOutputRange, *x); !out.empty())
        throw FormatError({.file = path, .line = line_no, .column = static_cast<long>(col + 1), .key = header[col],
                           .kind = KeyKind::csv_column},
                          out);
    }
    // The reader's own check (read_series_hdf5 makes the same): time strictly increasing.
    if (!(value[0] > last_t))
      throw FormatError(where, fmt::format("time does not increase ({} s after {} s)", f[tcol], last_t));
    last_t = value[0];
    try {
      sample(value[0], value[1]);
    } catch (const std::invalid_argument& e) {
      throw FormatError(where, fmt::format("{} (t = {}, {} = {})", e.what(), f[tcol], name, f[column]));
    }
    if (any_ref) {
      std::array<double, 3> ref{};
      for (std::size_t i = 0; i < 3; ++i) {
        if (!ref_present[i]) continue;
        const auto x = parse_decimal(f[ref_col[i]]);
        if (!x)
          throw FormatError({.file = path, .line = line_no, .column = static_cast<long>(ref_col[i] + 1)},
                            fmt::format("reference column {}: {} (a reference channel must have a sample on every row: "
                                        "the same length and rate as the output)",
                                        header[ref_col[i]],
                                        f[ref_col[i]].empty() ? std::string("missing value")
                                                              : "'" + f[ref_col[i]] + "' is " + why_not_decimal(f[ref_col[i]])));
        ref[i] = *x;
        if (const std::string out = range_problem(kReferenceRange, *x); !out.empty())
          throw FormatError({.file = path, .line = line_no, .column = static_cast<long>(ref_col[i] + 1), .key = header[ref_col[i]],
                             .kind = KeyKind::csv_column},
                            out);
      }
      try {
        reference(value[0], ref, ref_present);
      } catch (const std::invalid_argument& e) {
        throw FormatError(where, e.what());
      }
    }
  }
  if (header.empty()) throw FormatError({.file = path}, "no header line and no samples");
  return name;
}

}  // namespace vrelab::io
