// Half-open windows read the same way by `measure` and by the lab data's raw records
// (diagnose): a record whose last sample is at the vibration window's end minus one sample
// interval covers [from, to). `measure` and `diagnose` decide with the same
// rectification::record_covers_window_end, so neither accepts a record the other skips ("the
// record ends at 0.799 s, before on_to_s = 0.8 s"), and both refuse a record one sample shorter.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <regex>
#include <sstream>

#include <nlohmann/json.hpp>

#include "app/commands.hpp"
#include "io/formats/lab_data.hpp"
#include "support/files.hpp"

namespace test_lab_windows {

using namespace vrelab;
namespace fs = std::filesystem;
using nlohmann::json;
using vrelab::test::read_file;
using vrelab::test::TempDir;

namespace {

// Rest [-0.5, 0), vibration [0, 0.8) at 1 kHz: the output steps by 1e-4 mA under vibration,
// with a small ripple so the batch means have a spread.
void write_record(const fs::path& p, int last_sample_ms) {
  std::ofstream f(p);
  f << "time_s,output_mA\n";
  for (int k = -500; k <= last_sample_ms; ++k) {
    const double t = k * 1e-3;
    f << t << "," << 0.88 + (k >= 0 ? 1e-4 : 0.0) + 1e-6 * std::sin(2 * std::numbers::pi * 37 * t) << "\n";
  }
}

void edit(const fs::path& file, const std::string& pattern, const std::string& with) {
  const std::string text = read_file(file), edited = std::regex_replace(text, std::regex(pattern), with);
  ASSERT_NE(edited, text) << pattern;
  std::ofstream(file) << edited;
}

}  // namespace

TEST(LabWindows, MeasureAndDiagnoseReadAHalfOpenWindowAlike) {
  TempDir t;
  const fs::path dir = t.path / "c";
  fs::copy(std::string(VRELAB_CASES_DIR) + "/lab-example", dir);
  // ia-40Hz-4g becomes a raw record at 10 Hz: 8 whole periods in [0, 0.8), 8 blocks (diagnose's choice).
  edit(dir / "runs.csv", "id,frequency_Hz,amplitude_g,d_IA,d_PA,d_OA,a_IA_g,a_PA_g,a_OA_g,measured_ug,sigma_ug",
       "id,frequency_Hz,amplitude_g,d_IA,d_PA,d_OA,a_IA_g,a_PA_g,a_OA_g,measured_ug,sigma_ug,series,rest_from_s,rest_to_s,on_from_s,on_to_s");
  edit(dir / "runs.csv", "ia-40Hz-4g,40,([^\\n]*)", "ia-40Hz-4g,10,$1,rec.csv,-0.5,0,0,0.8");
  write_record(dir / "rec.csv", 799);  // last sample at 0.799 s = 0.8 s - dt
  const validation::Campaign c = io::read_campaign(dir.string());
  ASSERT_TRUE(c.skipped.empty()) << c.skipped.front();
  double diagnosed_g = 0;
  for (const auto& r : c.runs)
    if (r.id == "ia-40Hz-4g") diagnosed_g = r.measured_g;

  app::MeasureOptions mo;
  mo.series_path = (dir / "rec.csv").string();
  mo.json_path = (t.path / "m.json").string();
  mo.on_s = {0.0, 0.8};
  mo.baseline_s = {-0.5, 0.0};
  mo.frequency_Hz = 10;
  mo.blocks = 8;
  mo.K1 = 1.0;  // the record's output_mA read as it stands
  std::ostringstream text;
  app::run_measure(mo, text);
  const json m = json::parse(read_file(mo.json_path));
  EXPECT_EQ(m["samples"]["on"].get<long>(), 800);
  EXPECT_EQ(m["samples"]["baseline"].get<long>(), 500);
  // The same samples: diagnose divides by the identified K1 (1.25 within its static test's
  // scatter, < 1e-3), measure here by 1.
  EXPECT_NEAR(diagnosed_g * 1.25, m["measured_g"].get<double>(), 1e-3 * 1e-4);

  // One sample shorter: both refuse it, saying where the record ends.
  write_record(dir / "rec.csv", 798);
  const validation::Campaign c2 = io::read_campaign(dir.string());
  ASSERT_EQ(c2.skipped.size(), 1u);
  EXPECT_TRUE(std::regex_search(c2.skipped[0], std::regex(R"(the record ends at 0\.798 s)"))) << c2.skipped[0];
  try {
    app::run_measure(mo, text);
    ADD_FAILURE() << "measure accepted a record that ends before its window";
  } catch (const std::exception& e) {
    EXPECT_TRUE(std::regex_search(e.what(), std::regex(R"(the record ends at 0\.798 s, before the vibration interval \[0, 0\.8\) s)")))
        << e.what();
  }
}

}  // namespace test_lab_windows
