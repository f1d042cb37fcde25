// Raw records in HDF5 (io/formats/raw_hdf5.hpp, docs/data-format.md "Raw records in HDF5") in
// the commands: a campaign and its HDF5 copy diagnose number for number alike, `measure` reads
// either, and a bad HDF5 record skips its run naming the file and the dataset. All in seconds.
// The reader against the CSV reader and the writer alone: tests/io/test_raw_hdf5.cpp.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>
#include <numbers>
#include <regex>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include <unistd.h>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "app/commands.hpp"
#include "io/formats/case_file.hpp"
#include "io/services/diagnosis.hpp"
#include "io/services/diagnosis_json.hpp"
#include "io/formats/lab_data.hpp"
#include "io/formats/raw_hdf5.hpp"
#include "io/formats/series.hpp"
#include "support/files.hpp"
#include "support/hdf5_file.hpp"
#include "support/lcg.hpp"

namespace vrelab::test_raw_hdf5 {
namespace {

namespace fs = std::filesystem;
using test::read_file;
using test::Lcg;
using test::write_h5;
using test::TempDir;

// cases/lab-example with three runs (or those named) given as raw records (records/<id>.csv):
// 10 kHz, 0.3 s at rest then the vibration window; the output carries the summary's measured
// value (x K1) on a sine, with 10 uA of pseudo-random noise. The record of ia-100Hz-2g is 8 s
// long (80000 samples: more than one 64 Ki block) and has reference channels.
struct RawCampaign {
  std::string dir;
  std::vector<std::string> ids;
  explicit RawCampaign(const fs::path& where, std::vector<std::string> raw_ids = {"ia-100Hz-2g", "ia-400Hz-4g", "diag-100Hz-2g"})
      : dir(where.string()), ids(std::move(raw_ids)) {
    fs::copy(std::string(VRELAB_CASES_DIR) + "/lab-example", dir);
    fs::create_directories(dir + "/records");
    std::istringstream runs(read_file(dir + "/runs.csv"));
    std::string line, text;
    Lcg rng;
    while (std::getline(runs, line)) {
      if (line.empty() || line[0] == '#') {
        text += line + "\n";
        continue;
      }
      if (line.rfind("id,", 0) == 0) {
        text += line + ",series,rest_from_s,rest_to_s,on_from_s,on_to_s\n";
        continue;
      }
      const std::string id = line.substr(0, line.find(','));
      const auto it = std::find(ids.begin(), ids.end(), id);
      if (it == ids.end()) {
        text += line + ",,,,,\n";
        continue;
      }
      const bool long_one = id == "ia-100Hz-2g";
      const double on_s = long_one ? 7.7 : 0.2, f = id.find("400Hz") != std::string::npos ? 400.0 : 100.0;
      const double measured_ug = std::stod(line.substr(line.rfind(',', line.rfind(',') - 1) + 1));
      std::ofstream rec(dir + "/records/" + id + ".csv");
      rec << (long_one ? "time_s,output_mA,ref_IA_g\n" : "time_s,output_mA\n");
      for (int i = 0;; ++i) {
        const double t = -0.3 + i * 1e-4;
        if (t > on_s + 1e-3) break;
        const double u = 0.88 + 1e-5 * rng.next() + (t >= 0 ? std::sin(2 * std::numbers::pi * f * t) + 1.25 * measured_ug * 1e-6 : 0.0);
        rec << fmt::format("{},{}", t, u);
        if (long_one) rec << fmt::format(",{}", t >= 0 ? 2 * std::sin(2 * std::numbers::pi * f * t) : 0.0);
        rec << "\n";
      }
      text += line + fmt::format(",records/{}.csv,-0.3,0,0,{}\n", id, on_s);
    }
    std::ofstream(dir + "/runs.csv") << text;
  }
  // Each record converted to HDF5 as a lab's converter would (the CSV's numbers as float64),
  // runs.csv pointed at the copies.
  void to_hdf5() const {
    for (const auto& id : ids) {
      const std::string csv = dir + "/records/" + id + ".csv";
      const bool ref = read_file(csv).rfind("time_s,output_mA,ref_IA_g", 0) == 0;
      io::Hdf5SeriesWriter w(dir + "/records/" + id + ".h5", "mA", {ref, false, false}, id);
      std::vector<double> t, u;
      io::read_series(csv, "output_mA", [&](double x, double y) { t.push_back(x), u.push_back(y); });
      std::vector<std::array<double, 3>> g;
      if (ref)
        io::read_series(csv, "output_mA", [](double, double) {},
                        [&](double, const std::array<double, 3>& r, const std::array<bool, 3>&) { g.push_back(r); });
      for (std::size_t i = 0; i < t.size(); ++i) w.add(t[i], u[i], ref ? g[i] : std::array<double, 3>{});
      w.commit();
      fs::remove(csv);
    }
    std::string text = read_file(dir + "/runs.csv");
    for (const auto& id : ids) {
      const std::string from = "records/" + id + ".csv";
      text.replace(text.find(from), from.size(), "records/" + id + ".h5");
    }
    std::ofstream(dir + "/runs.csv") << text;
  }
};

// The diagnosis' JSON without its timings.
nlohmann::json diagnosis_json(const std::string& dir) {
  io::DiagnoseOverrides o;
  o.set(&validation::DiagnoseSettings::resimulate_runs, 0);  // the ODE re-simulation is the same code either way; seconds saved
  nlohmann::json j = io::to_json(io::diagnose_folder(dir, o));
  j.erase("wall_s");
  return j;
}

TEST(RawHdf5Campaign, ACampaignAndItsHdf5CopyDiagnoseIdentically) {
  TempDir t;
  const RawCampaign c(t.path / "lab");
  const validation::Campaign a = io::read_campaign(c.dir);
  ASSERT_EQ(a.runs.size(), 10u) << (a.skipped.empty() ? "" : a.skipped.front());
  const nlohmann::json csv = diagnosis_json(c.dir);
  c.to_hdf5();
  ASSERT_TRUE(fs::exists(c.dir + "/records/ia-100Hz-2g.h5"));
  const validation::Campaign b = io::read_campaign(c.dir);
  ASSERT_EQ(b.runs.size(), 10u) << (b.skipped.empty() ? "" : b.skipped.front());
  for (std::size_t k = 0; k < a.runs.size(); ++k) {
    EXPECT_EQ(b.runs[k].measured_g, a.runs[k].measured_g) << a.runs[k].id;  // bit for bit: the same doubles, the same sums
    EXPECT_EQ(b.runs[k].sigma_g, a.runs[k].sigma_g) << a.runs[k].id;
  }
  // The synthetic records carry the summaries' values: the measurement gives them back
  // (10 uA noise / 1.25 over ~1000+ samples per block: well under 0.5 ug).
  EXPECT_NEAR(a.runs[1].measured_g, 234.167e-6, 0.5e-6);
  const nlohmann::json h5 = diagnosis_json(c.dir);
  EXPECT_EQ(h5, csv) << "the HDF5 copy's diagnosis differs";
}

TEST(RawHdf5, BadRecordsSkipTheRunNamingTheFileAndTheDataset) {
  TempDir t;
  // One raw record, the one made bad: each of the ten reads below reads it alone (the 8 s record
  // read ten times took 25 s of CPU under the sanitizers).
  const RawCampaign c(t.path / "lab", {"ia-400Hz-4g"});
  c.to_hdf5();
  const std::string rec = c.dir + "/records/ia-400Hz-4g.h5";
  const std::string good = read_file(rec);
  std::vector<double> time, out;
  for (int i = 0; i <= 5000; ++i) time.push_back(-0.3 + i * 1e-4), out.push_back(0.88);
  std::vector<double> back = time, nan = out, shorter = out;
  back[4000] = back[3999];
  nan[4100] = std::numeric_limits<double>::quiet_NaN();
  shorter.pop_back();
  const std::vector<double> early_t(time.begin(), time.begin() + 4001), early_u(out.begin(), out.begin() + 4001);
  struct Bad {
    std::vector<std::pair<std::string, std::vector<double>>> datasets;
    std::string expect;
  };
  const std::vector<Bad> cases{
      {{{"time_s", time}}, R"(ia-400Hz-4g\.h5: no dataset 'output_mA' .*the file has: time_s)"},
      {{{"t", time}, {"output_mA", out}}, R"(ia-400Hz-4g\.h5: no dataset 'time_s' .*the file has: output_mA, t)"},
      {{{"time_s", time}, {"output_V", out}}, R"(no dataset 'output_mA'.*did you mean)"},
      {{{"time_s", time}, {"output_mA", shorter}}, R"(ia-400Hz-4g\.h5: dataset output_mA has 5000 samples, time_s has 5001)"},
      {{{"time_s", time}, {"output_mA", out}, {"ref_PA_g", shorter}},
       R"(ia-400Hz-4g\.h5: dataset ref_PA_g has 5000 samples, time_s has 5001)"},
      {{{"time_s", back}, {"output_mA", out}}, R"(ia-400Hz-4g\.h5: dataset time_s\[4000\]: time does not increase)"},
      {{{"time_s", time}, {"output_mA", nan}}, R"(ia-400Hz-4g\.h5: dataset output_mA\[4100\]: a sample is not a finite number)"},
      {{{"time_s", early_t}, {"output_mA", early_u}}, R"(ia-400Hz-4g\.h5: the record ends at 0\.1 s)"},  // before on_to_s
  };
  for (const Bad& b : cases) {
    write_h5(rec, b.datasets);
    const validation::Campaign camp = io::read_campaign(c.dir);
    EXPECT_EQ(camp.runs.size(), 9u) << b.expect;  // the other runs read
    ASSERT_EQ(camp.skipped.size(), 1u) << b.expect;
    EXPECT_TRUE(std::regex_search(camp.skipped[0], std::regex(R"(runs\.csv:\d+ \(run 'ia-400Hz-4g'\): .*)" + b.expect)))
        << camp.skipped[0];
  }
  // Not an HDF5 file (a CSV saved under .h5), and no file at all.
  std::ofstream(rec) << "time_s,output_mA\n0,1\n";
  validation::Campaign camp = io::read_campaign(c.dir);
  ASSERT_EQ(camp.skipped.size(), 1u);
  EXPECT_TRUE(std::regex_search(camp.skipped[0], std::regex(R"(ia-400Hz-4g\.h5: not an HDF5 file)"))) << camp.skipped[0];
  fs::remove(rec);
  camp = io::read_campaign(c.dir);
  ASSERT_EQ(camp.skipped.size(), 1u);
  EXPECT_TRUE(std::regex_search(camp.skipped[0], std::regex(R"(ia-400Hz-4g\.h5: cannot open the series)"))) << camp.skipped[0];
  // `vrelab diagnose --check` on it: the run listed as skipped, exit 2 (the others diagnosed
  // by `diagnose` itself: tests/cli/cli_bad_input.sh, a bad CSV record).
  std::ostringstream text;
  app::DiagnoseOptions o;
  o.dir = c.dir;
  o.check = true;
  EXPECT_EQ(app::run_diagnose(o, text), 2);
  EXPECT_TRUE(std::regex_search(text.str(), std::regex(R"(ia-400Hz-4g\.h5: cannot open the series)"))) << text.str();
  EXPECT_TRUE(std::regex_search(text.str(), std::regex(R"(9 shaker runs \(1 skipped\))"))) << text.str();
}

TEST(RawHdf5, MeasureReadsAnHdf5SeriesAsItsCsv) {
  TempDir t;
  const RawCampaign c(t.path / "lab", {"ia-100Hz-2g"});
  const std::string csv = c.dir + "/records/ia-100Hz-2g.csv";
  app::MeasureOptions o;
  o.series_path = csv, o.json_path = (t.path / "csv.json").string();
  o.on_s = {0.0, 7.7}, o.baseline_s = {-0.3, 0.0}, o.frequency_Hz = 100, o.K1 = 1.25, o.blocks = 7;
  std::ostringstream text;
  app::run_measure(o, text);
  c.to_hdf5();
  o.series_path = c.dir + "/records/ia-100Hz-2g.h5", o.json_path = (t.path / "h5.json").string();
  app::run_measure(o, text);
  nlohmann::json a = nlohmann::json::parse(read_file(t.path / "csv.json")), b = nlohmann::json::parse(read_file(t.path / "h5.json"));
  for (auto* j : {&a, &b}) (*j)["series"].erase("file"), j->erase("program"), j->erase("wall_s");
  EXPECT_EQ(a, b);
  EXPECT_NEAR(b["measured_g"].get<double>(), 234.167e-6, 0.5e-6);
  // A bad HDF5 series: InputError (exit 2) naming the file and the dataset.
  write_h5(o.series_path, {{"time_s", {0.0, 0.1, 0.1}}, {"output_mA", {1.0, 1.0, 1.0}}});
  try {
    app::run_measure(o, text);
    ADD_FAILURE() << "accepted time that does not increase";
  } catch (const io::InputError& e) {
    EXPECT_TRUE(std::regex_search(std::string(e.what()), std::regex(R"(ia-100Hz-2g\.h5: dataset time_s\[2\]: time does not increase)")))
        << e.what();
  }
}

TEST(RawHdf5, CampaignWritesHdf5RecordsWhenAsked) {
  TempDir t;
  const fs::path case_path = t.path / "raw.toml";
  std::ofstream(case_path) << R"(g_m_per_s2 = 9.81
[coefficients]
K1 = 1.25
k0 = 1.5e-3
k1_asym = 2.0e-5
k2 = 1.5e-5
k3 = 1.0e-6
k4 = 2.0e-7
delta_OA = 1.0e-4
delta_PA = -5.0e-5
k_IP = 8.0e-6
k_IO = -5.0e-6
k_PO = 3.0e-6
k_PP = 0.0
k_OO = 0.0
[campaign]
hidden = [ { name = "pickoff_nonlinearity", parameter = 30.0 } ]
frequencies_Hz = [100.0]
amplitudes_g = [2.0]
directions = [[1.0, 0.0, 0.0]]
orientations_g = [[0.7071067811865476, 0.0, 0.7071067811865476]]
raw_series = true
raw_sample_rate_Hz = 2000.0
raw_record_s = 0.2
[run]
seed = 43
)";
  std::ostringstream text;
  app::CampaignOptions o;
  o.case_path = case_path.string(), o.progress = false;
  o.out_dir = (t.path / "csv").string();
  app::run_campaign(o, text);
  o.out_dir = (t.path / "h5").string(), o.raw_format = "hdf5";
  app::run_campaign(o, text);
  ASSERT_TRUE(fs::exists(t.path / "h5" / "records" / "run1.h5"));
  EXPECT_FALSE(fs::exists(t.path / "h5" / "records" / "run1.csv"));
  const validation::Campaign a = io::read_campaign((t.path / "csv").string()), b = io::read_campaign((t.path / "h5").string());
  ASSERT_EQ(a.runs.size(), 1u);
  ASSERT_EQ(b.runs.size(), 1u) << (b.skipped.empty() ? "" : b.skipped.front());
  // The same simulated samples; the CSV keeps 12 significant digits of the output (~1 mA:
  // 1e-12 mA, / K1 = 1.25 -> < 1e-12 g per sample, so in the means) and 9 of the time (the
  // grid points 0.5 ms apart, no sample within 1e-9 s of a window's end), HDF5 all 17.
  EXPECT_NEAR(b.runs[0].measured_g, a.runs[0].measured_g, 1e-11);
  EXPECT_NEAR(b.runs[0].sigma_g, a.runs[0].sigma_g, 1e-11);
  // hdf5 for a case without raw records: refused before any simulation.
  std::ofstream(t.path / "summary.toml") << std::regex_replace(read_file(case_path), std::regex("raw_series = true"), "raw_series = false");
  o.case_path = (t.path / "summary.toml").string(), o.out_dir = (t.path / "s").string();
  EXPECT_THROW(app::run_campaign(o, text), io::InputError);
  EXPECT_FALSE(fs::exists(t.path / "s"));
}

}  // namespace
}  // namespace vrelab::test_raw_hdf5
