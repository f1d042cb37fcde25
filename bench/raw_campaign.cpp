// vrelab_raw_campaign -- a big raw campaign for the memory check of raw-record reading
// (bench/raw_hdf5_1gb.sh): cases/lab-example with three of its runs given as long records
// sampled at 20 kHz, each with the output and three reference channels, written streaming
// (the generator's memory does not grow with the record either).
//
//   vrelab_raw_campaign CASES_DIR OUT_DIR SECONDS_PER_RECORD hdf5|csv|both
//
// `both` writes OUT_DIR/h5 and OUT_DIR/csv, the same samples: the CSV with round-trip digits
// (fmt's shortest form), so both folders hold the same doubles and must diagnose identically.
// Size: 3 records x 20000 Hz x 5 channels x 8 bytes = 2.4 MB per record-second in HDF5
// (420 s: 1.0 GB); about 2.5 times that as CSV.
#include <array>
#include <cmath>
#include <cstdlib>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <memory>
#include <numbers>
#include <sstream>
#include <string>
#include <vector>

#include <fmt/format.h>

#include "io/formats/raw_hdf5.hpp"

namespace fs = std::filesystem;

namespace {

struct Lcg {
  std::uint64_t s = 12345;
  double next() {  // [-1, 1)
    s = s * 6364136223846793005ull + 1442695040888963407ull;
    return static_cast<double>(s >> 11) / static_cast<double>(1ull << 52) - 1.0;
  }
};

std::string slurp(const fs::path& p) {
  std::ifstream in(p);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 5) {
    std::cerr << "usage: vrelab_raw_campaign CASES_DIR OUT_DIR SECONDS_PER_RECORD hdf5|csv|both\n";
    return 2;
  }
  const fs::path cases = argv[1], out = argv[2];
  const double seconds = std::stod(argv[3]);
  const std::string mode = argv[4];
  std::vector<std::pair<std::string, bool>> kinds;  // folder, hdf5?
  if (mode == "hdf5") kinds = {{out.string(), true}};
  else if (mode == "csv") kinds = {{out.string(), false}};
  else kinds = {{(out / "h5").string(), true}, {(out / "csv").string(), false}};
  const std::vector<std::string> ids{"ia-100Hz-2g", "ia-400Hz-4g", "diag-100Hz-2g"};
  const double rate_Hz = 20000, rest_s = 1.0, K1 = 1.25;
  for (const auto& [dir, hdf5] : kinds) {
    fs::create_directories(fs::path(dir) / "records");
    for (const char* f : {"manifest.toml", "static.csv"}) fs::copy_file(cases / "lab-example" / f, fs::path(dir) / f, fs::copy_options::overwrite_existing);
  }
  // runs.csv: the three runs as records, the others as their summaries.
  for (const auto& [dir, hdf5] : kinds) {
    std::istringstream runs(slurp(cases / "lab-example" / "runs.csv"));
    std::string line, text;
    while (std::getline(runs, line)) {
      if (line.empty() || line[0] == '#') text += line + "\n";
      else if (line.rfind("id,", 0) == 0) text += line + ",series,rest_from_s,rest_to_s,on_from_s,on_to_s\n";
      else {
        const std::string id = line.substr(0, line.find(','));
        bool raw = false;
        for (const auto& r : ids) raw = raw || r == id;
        text += raw ? line + fmt::format(",records/{}.{},{},0,0,{}\n", id, hdf5 ? "h5" : "csv", -rest_s, seconds) : line + ",,,,,\n";
      }
    }
    std::ofstream(fs::path(dir) / "runs.csv") << text;
  }
  std::istringstream runs(slurp(cases / "lab-example" / "runs.csv"));
  std::string line;
  while (std::getline(runs, line)) {
    const std::string id = line.substr(0, line.find(','));
    bool raw = false;
    for (const auto& r : ids) raw = raw || r == id;
    if (!raw) continue;
    // The run's row: id, frequency_Hz, amplitude_g, d_IA, d_PA, d_OA, ..., measured_ug, sigma_ug.
    std::vector<double> cell;
    for (std::size_t p = line.find(','); p != std::string::npos; p = line.find(',', p + 1)) cell.push_back(std::atof(line.c_str() + p + 1));
    const double f = cell.at(0), a = cell.at(1), measured_ug = cell.at(cell.size() - 2);
    // The reference channels carry the commanded motion, a d sin(w t) on each axis: the
    // diagnosis takes the motion as measured, so 2 g on IA alone for the diagonal run
    // diag-100Hz-2g would read as a table 41 % off the command on IA and still on PA, which
    // no effect explains.
    const std::array<double, 3> d{cell.at(2), cell.at(3), cell.at(4)};
    std::unique_ptr<vrelab::io::Hdf5SeriesWriter> h5;
    std::unique_ptr<std::FILE, int (*)(std::FILE*)> csv(nullptr, std::fclose);
    for (const auto& [dir, hdf5] : kinds) {
      if (hdf5) h5 = std::make_unique<vrelab::io::Hdf5SeriesWriter>(dir + "/records/" + id + ".h5", "mA",
                                                                    std::array<bool, 3>{true, true, true}, id, "generated");
      else {
        csv.reset(std::fopen((dir + "/records/" + id + ".csv").c_str(), "w"));
        std::fputs("time_s,output_mA,ref_IA_g,ref_PA_g,ref_OA_g\n", csv.get());
      }
    }
    Lcg rng;
    const long n = static_cast<long>(std::llround((rest_s + seconds) * rate_Hz)) + 2;
    for (long i = 0; i < n; ++i) {
      const double t = -rest_s + static_cast<double>(i) / rate_Hz;
      const bool on = t >= 0;
      const double s = std::sin(2 * std::numbers::pi * f * t);
      const double u = 0.88 + 1e-5 * rng.next() + (on ? s + K1 * measured_ug * 1e-6 : 0.0);
      std::array<double, 3> g{};
      for (std::size_t k = 0; k < 3; ++k) g[k] = (on ? a * d[k] * s : 0.0) + 1e-3 * rng.next();
      if (h5) h5->add(t, u, g);
      if (csv) fmt::print(csv.get(), "{},{},{},{},{}\n", t, u, g[0], g[1], g[2]);
    }
    if (h5) h5->commit();
    std::cout << "wrote " << id << ": " << n << " samples\n";
  }
  return 0;
}
