#include "io/formats/series.hpp"

#include <cmath>
#include <filesystem>
#include <fstream>
#include <regex>

#include <fmt/format.h>

#include "io/formats/error.hpp"
#include "io/formats/raw_hdf5.hpp"

namespace vrelab::io {

std::string read_series(const std::string& path, const std::string& column,
                        const std::function<void(double t_s, double value)>& sample, const ReferenceSink& reference,
                        const ChannelNames& names) {
  if (is_hdf5_path(path)) return read_series_hdf5(path, column, sample, reference, names);
  return read_series_csv(path, column, sample, reference, names);
}

std::optional<StatedScaleFactor> stated_scale_factor(const std::string& path) {
  // Only a regular file is opened here (a FIFO would block, a device never end a line);
  // read_series refuses the others naming what they are.
  std::error_code ec;
  if (is_hdf5_path(path) || !std::filesystem::is_regular_file(path, ec)) return std::nullopt;
  std::ifstream in(path);
  if (!in) return std::nullopt;  // read_series names the file it cannot open
  static const std::regex k1(R"(K1\s*=\s*([^\s;,]+)\s*([A-Za-z]+)\s*/\s*g\b)");
  std::string line;
  for (long n = 1; std::getline(in, line); ++n) {
    const std::size_t first = line.find_first_not_of(" \t\xEF\xBB\xBF");  // a BOM or indent before '#'
    if (first == std::string::npos) continue;
    if (line[first] != '#') break;  // the header: comments are over
    std::smatch m;
    if (!std::regex_search(line, m, k1)) continue;
    double v = NAN;
    try {
      std::size_t used = 0;
      v = std::stod(m[1].str(), &used);
      if (used != m[1].str().size()) v = NAN;
    } catch (const std::exception&) {
    }
    if (!(v > 0) || !std::isfinite(v))
      throw FormatError(FormatLocation{.file = path, .line = n},
                        fmt::format("the comment states K1 = '{}': a scale factor is a positive number", m[1].str()));
    return StatedScaleFactor{v, m[2].str(), n};
  }
  return std::nullopt;
}

std::string output_unit_of(const std::string& column) {
  static const std::string prefix = "output_";
  return column.rfind(prefix, 0) == 0 ? column.substr(prefix.size()) : std::string();
}

}  // namespace vrelab::io
