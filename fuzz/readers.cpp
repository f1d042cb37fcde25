#include "fuzz/readers.hpp"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <regex>
#include <sstream>
#include <stdexcept>
#include <string_view>
#include <vector>

#include <hdf5.h>
#include <unistd.h>

#include "io/formats/case_file.hpp"
#include "io/formats/csv.hpp"
#include "io/formats/lab_data.hpp"
#include "io/formats/ranges.hpp"
#include "io/services/studies.hpp"
#include "plant/ode_solver.hpp"
#include "rectification/measurement/series.hpp"
#include "vibration/psd.hpp"
#include "vibration/random.hpp"

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

void write_lab_data(const std::uint8_t* data, std::size_t size, const std::string& dir_name) {
  const std::string_view in(reinterpret_cast<const char*>(data), size);
  const fs::path dir(dir_name);
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
}

void lab_data(const std::uint8_t* data, std::size_t size) {
  const fs::path dir = scratch() / "lab";
  write_lab_data(data, size, dir.string());
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

void psd_table(const std::uint8_t* data, std::size_t size) {
  const fs::path p = scratch() / "psd.csv";
  write(p, std::string_view(reinterpret_cast<const char*>(data), size));
  refused_or_accepted([&] {
    const vibration::RandomProfile prof = io::read_psd_file(p.string());
    // An accepted table is within the physical ranges, its rms finite and bounded.
    for (const auto& t : prof.psd) {
      if (!t) continue;
      for (const auto& row : t->rows)
        if (!io::range_problem(io::kFrequencyRange, row.frequency_Hz).empty() ||
            !io::range_problem(io::kPsdLevelRange, row.psd_g2_per_Hz.value_or(0)).empty())
          throw std::logic_error("psd_table: a row outside the physical ranges was accepted");
      if (!(vibration::rms_g(*t) <= io::kPsdMaxRms_g)) throw std::logic_error("psd_table: an rms out of range was accepted");
    }
  });
}

namespace {

// A printed report whose numbers include nan or inf (past its first two lines, which name the
// file and the column: a user's words).
bool prints_non_finite(const std::string& report) {
  static const std::regex word(R"((^|[^A-Za-z_])-?(nan|inf)([^A-Za-z_]|$))");
  std::istringstream lines(report);
  std::string line;
  for (int n = 1; std::getline(lines, line); ++n)
    if (n > 2 && std::regex_search(line, word)) return true;
  return false;
}

// `vrelab measure` on the record at `path`: as a 10 Hz sine run, then as a random run with
// the input's rms given; an accepted record's report prints finite numbers only.
void measure_record(const std::string& path) {
  for (const bool sine : {true, false})
    refused_or_accepted([&] {
      rectification::SeriesWindows w;
      w.baseline_from_s = 0, w.baseline_to_s = 1, w.on_from_s = 1, w.on_to_s = 2, w.blocks = 2;
      w.frequency_Hz = sine ? 10 : 0;
      w.input_rms_g = sine ? 0 : 1;
      const io::MeasureStudy s = io::measure(path, "", w);
      if (prints_non_finite(io::measure_report(s))) throw std::logic_error("measure printed nan or inf:\n" + io::measure_report(s));
    });
}

// Bytes read in order; zero past the end.
struct Bytes {
  const std::uint8_t* p;
  std::size_t n, at = 0;
  unsigned next() { return at < n ? p[at++] : 0u; }
  double next_double() {
    std::uint8_t b[8];
    for (auto& x : b) x = static_cast<std::uint8_t>(next());
    double d = 0;
    std::memcpy(&d, b, sizeof d);
    return d;
  }
};

// One dataset of write_hdf5_record.
void write_dataset(hid_t file, Bytes& b) {
  static const char* const names[] = {"time_s", "output_mA", "output_V", "ref_IA_g", "ref_PA_g", "ref_OA_g", "input_PA_g", ""};
  static const char* const units_of[] = {"s", "mA", "V", "g", "g", "g", "g", ""};
  const unsigned which = b.next() % 8, type = b.next() % 6, units = b.next() % 4;
  const unsigned low = b.next(), high = b.next();  // (sequenced: the order of a | b's operands is not)
  const std::size_t length = (low | (high << 8)) % 8193;
  const unsigned storage = b.next() % 3, fill = b.next() % 4, param = b.next();
  const char* name = which == 7 ? "output_mA" : names[which];
  if (H5Lexists(file, name, H5P_DEFAULT) > 0) return;
  if (which == 7) {  // a group where a dataset is expected
    const hid_t g = H5Gcreate2(file, name, H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT);
    if (g >= 0) H5Gclose(g);
    return;
  }
  std::vector<double> x(length);
  const double dt = (param + 1) / 2000.0, constant = fill == 2 ? b.next_double() : 0.0;
  for (std::size_t i = 0; i < length; ++i) {
    const double t = -0.5 + static_cast<double>(i) * dt;
    x[i] = fill == 0 ? t : fill == 1 ? 0.5 + (param / 16.0) * std::sin(2 * 3.141592653589793 * 10 * t) : fill == 2 ? constant : b.next_double();
  }
  const hid_t file_type = type == 1 ? H5T_IEEE_F32LE : type == 2 ? H5T_STD_I32LE : type == 3 ? H5T_STD_U8LE : H5T_IEEE_F64LE;
  hid_t string_type = -1;
  if (type == 4) {
    string_type = H5Tcopy(H5T_C_S1);
    H5Tset_size(string_type, 8);
  }
  const hsize_t dims1[1] = {length}, dims2[2] = {length / 2, 2};
  const hid_t space = type == 5 ? H5Screate_simple(2, dims2, nullptr) : H5Screate_simple(1, dims1, nullptr);
  const hid_t dcpl = H5Pcreate(H5P_DATASET_CREATE);
  if (storage > 0 && length > 0) {
    const hsize_t chunk1[1] = {std::min<hsize_t>(length, 64 * (1 + param))}, chunk2[2] = {std::max<hsize_t>(1, length / 2), 2};
    H5Pset_chunk(dcpl, type == 5 ? 2 : 1, type == 5 ? chunk2 : chunk1);
    if (storage == 2) H5Pset_deflate(dcpl, 1);
  }
  const hid_t d = H5Dcreate2(file, name, type == 4 ? string_type : file_type, space, H5P_DEFAULT, dcpl, H5P_DEFAULT);
  if (d >= 0) {
    if (type == 4) {
      std::vector<char> text(length * 8, 'x');
      H5Dwrite(d, string_type, H5S_ALL, H5S_ALL, H5P_DEFAULT, text.data());
    } else if (length > 0) {
      H5Dwrite(d, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, x.data());
    }
    if (units > 0) {
      const std::string u = units == 1 ? units_of[which] : units == 2 ? "V" : "s";
      const hid_t ut = H5Tcopy(H5T_C_S1);
      H5Tset_size(ut, u.size());
      const hid_t us = H5Screate(H5S_SCALAR);
      const hid_t a = H5Acreate2(d, "units", ut, us, H5P_DEFAULT, H5P_DEFAULT);
      if (a >= 0) {
        H5Awrite(a, ut, u.data());
        H5Aclose(a);
      }
      H5Sclose(us);
      H5Tclose(ut);
    }
    H5Dclose(d);
  }
  H5Pclose(dcpl);
  H5Sclose(space);
  if (string_type >= 0) H5Tclose(string_type);
}

}  // namespace

void raw_csv(const std::uint8_t* data, std::size_t size) {
  const fs::path p = scratch() / "rec.csv";
  write(p, std::string_view(reinterpret_cast<const char*>(data), size));
  measure_record(p.string());
}

void write_hdf5_record(const std::uint8_t* data, std::size_t size, const std::string& path) {
  H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr);
  const hid_t file = H5Fcreate(path.c_str(), H5F_ACC_TRUNC, H5P_DEFAULT, H5P_DEFAULT);
  if (file < 0) return;  // the reader then says the file is missing
  Bytes b{data, size};
  const unsigned datasets = 1 + b.next() % 6;
  for (unsigned k = 0; k < datasets; ++k) write_dataset(file, b);
  H5Fclose(file);
}

void raw_hdf5(const std::uint8_t* data, std::size_t size) {
  const fs::path p = scratch() / "rec.h5";
  write_hdf5_record(data, size, p.string());
  measure_record(p.string());
}

Target target(const std::string& name) {
  if (name == "case_file") return &case_file;
  if (name == "lab_data") return &lab_data;
  if (name == "series") return &series;
  if (name == "psd_table") return &psd_table;
  if (name == "raw_csv") return &raw_csv;
  if (name == "raw_hdf5") return &raw_hdf5;
  return nullptr;
}

}  // namespace vrelab::fuzz
