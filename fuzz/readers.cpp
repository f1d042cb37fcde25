#include "fuzz/readers.hpp"

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <string_view>
#include <vector>

#include <unistd.h>

#include "io/formats/case_file.hpp"
#include "io/formats/csv.hpp"
#include "io/formats/lab_data.hpp"
#include "plant/ode_solver.hpp"
#include "rectification/measurement/series.hpp"

namespace vrelab::fuzz {
namespace {

namespace fs = std::filesystem;

// One temporary folder per process, removed at exit.
const fs::path& scratch() {
  static const fs::path dir = [] {
    std::string tmpl = (fs::temp_directory_path() / "vrelab-fuzz-XXXXXX").string();
    if (::mkdtemp(tmpl.data()) == nullptr) std::abort();
    std::atexit([] { std::error_code ec; fs::remove_all(scratch(), ec); });
    return fs::path(tmpl);
  }();
  return dir;
}

void write(const fs::path& p, std::string_view text) {
  std::ofstream out(p, std::ios::binary | std::ios::trunc);
  out.write(text.data(), static_cast<std::streamsize>(text.size()));
}

// Runs `read`; a refusal as bad input returns, anything else escapes.
template <class F>
void refused_or_accepted(F&& read) {
  try {
    read();
  } catch (const io::InputError&) {
  } catch (const plant::SolverError&) {
  } catch (const std::invalid_argument&) {
  }
}

}  // namespace

void case_file(const std::uint8_t* data, std::size_t size) {
  const fs::path p = scratch() / "case.toml";
  write(p, std::string_view(reinterpret_cast<const char*>(data), size));
  refused_or_accepted([&] { (void)io::read_case(p.string()); });
}

void lab_data(const std::uint8_t* data, std::size_t size) {
  const std::string_view in(reinterpret_cast<const char*>(data), size);
  const fs::path dir = scratch() / "lab";
  std::error_code ec;
  fs::create_directories(dir, ec);
  std::vector<std::string_view> parts;
  std::size_t from = 0;
  while (parts.size() < 3) {
    const std::size_t at = in.find("\n%%\n", from);
    if (at == std::string_view::npos) break;
    parts.push_back(in.substr(from, at + 1 - from));
    from = at + 4;
  }
  parts.push_back(in.substr(from));
  const char* names[] = {"manifest.toml", "static.csv", "runs.csv", "rec.csv"};
  for (std::size_t k = 0; k < 4; ++k) {
    if (k < parts.size()) write(dir / names[k], parts[k]);
    else fs::remove(dir / names[k], ec);
  }
  refused_or_accepted([&] { (void)io::read_campaign(dir.string()); });
}

void series(const std::uint8_t* data, std::size_t size) {
  std::istringstream in(std::string(reinterpret_cast<const char*>(data), size));
  refused_or_accepted([&] {
    rectification::SeriesWindows w;
    w.baseline_from_s = 0, w.baseline_to_s = 1, w.on_from_s = 1, w.on_to_s = 2, w.blocks = 2;
    rectification::SeriesMeasurer m(w);
    io::read_series_csv(in, "series.csv", "", [&m](double t, double u) { m.add(t, u); });
    (void)m.finish();
  });
}

Target target(const std::string& name) {
  if (name == "case_file") return &case_file;
  if (name == "lab_data") return &lab_data;
  if (name == "series") return &series;
  return nullptr;
}

}  // namespace vrelab::fuzz
