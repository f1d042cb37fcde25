// Random and sine-on-random runs in the lab data format (docs/data-format.md, cases/lab-random):
// read with their PSD files, described for the grouping, predicted through the plant's dynamics
// as diagnose predicts one run (validation::predict_run_g) and checked against the virtual
// shaker's measurement written in the example; bad rows skipped with file, line and column.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <regex>

#include "io/formats/lab_data.hpp"
#include "plant/effects/effects.hpp"
#include "support/diagnosis_lookup.hpp"
#include "support/files.hpp"
#include "support/instrument.hpp"
#include "validation/diagnosis/diagnose.hpp"

namespace test_lab_random {

using namespace vrelab;
namespace fs = std::filesystem;
using vrelab::test::read_file;
using vrelab::test::run_with_id;
using vrelab::test::TempDir;

namespace {

// The example's truth (cases/campaign.toml with its hidden pickoff nonlinearity, p2 = 15/rad).
plant::PlantConfig truth() {
  plant::PlantConfig p = test::paper_like_plant();
  p.effects.push_back(std::make_shared<plant::PickoffNonlinearity>(15.0));
  return p;
}

}  // namespace

TEST(LabRandom, RunsAreReadDescribedAndPredictedAsTheShakerMeasuredThem) {
  const validation::Campaign c = io::read_campaign(std::string(VRELAB_CASES_DIR) + "/lab-random");
  ASSERT_TRUE(c.skipped.empty()) << c.skipped.front();
  EXPECT_EQ(c.runs.size(), 15u);
  const auto& nav = run_with_id(c, "navmat-ia-plus");
  ASSERT_TRUE(nav.random.has_value());
  EXPECT_FALSE(nav.sine_part);
  // NAVMAT P-9492: 6.06 g rms; described as sqrt(2) rms along IA.
  EXPECT_NEAR(nav.amplitude_g / std::sqrt(2.0), 6.06, 0.005);
  EXPECT_NEAR((nav.direction - Vec3::UnitX()).norm(), 0.0, 1e-12);
  EXPECT_GT(nav.frequency_Hz, 350);
  EXPECT_LT(nav.frequency_Hz, 1000);
  const auto& both = run_with_id(c, "navmat-ia-pa-plus");
  EXPECT_NEAR(both.direction[0], std::sqrt(0.5), 1e-12);
  const auto& sor = run_with_id(c, "sor-ia-100Hz-plus");
  EXPECT_TRUE(sor.sine_part);
  EXPECT_EQ(sor.frequency_Hz, 100.0);
  // Each random run predicted as diagnose predicts it (the truth's plant) within the virtual
  // shaker's 3 sigma (its 16 s record) plus the first-order model's 1 % (test_random_prediction.cpp).
  const plant::PlantConfig t = truth();
  int predicted_runs = 0;
  for (const auto& r : c.runs) {
    if (!r.random) continue;
    const double predicted = validation::predict_run_g(t, r);
    EXPECT_NEAR(r.measured_g, predicted, 3 * r.sigma_g + 0.01 * std::abs(predicted)) << r.id;
    ++predicted_runs;
  }
  // cases/lab-random/runs.csv: 5 of its 15 rows are random (4) or sine on random (1).
  EXPECT_EQ(predicted_runs, 5);
}

TEST(LabRandom, BadRandomRowsAreSkippedNamingFileLineAndColumn) {
  TempDir d;
  const fs::path dir = d.path / "c";
  fs::copy(std::string(VRELAB_CASES_DIR) + "/lab-random", dir);
  std::string runs = read_file(dir / "runs.csv");
  runs = std::regex_replace(runs, std::regex("random,navmat-ia-pa\\.csv,common"), "random,bad.csv,common");
  runs = std::regex_replace(runs, std::regex("(gevs-ia-plus,[^\\n]*),random,gevs\\.csv,common"), "$1,random,,common");
  runs = std::regex_replace(runs, std::regex("(sor-ia-100Hz-plus,[^\\n]*),sine_on_random,"), "$1,sinus,");
  std::ofstream(dir / "runs.csv") << runs;
  std::ofstream(dir / "bad.csv") << "frequency_Hz,psd_IA_g2_per_Hz\n20,0.01\n10,0.04\n";
  const validation::Campaign c = io::read_campaign(dir.string());
  EXPECT_EQ(c.runs.size(), 12u);
  ASSERT_EQ(c.skipped.size(), 3u);
  std::string all;
  for (const auto& s : c.skipped) all += s + "\n";
  EXPECT_TRUE(std::regex_search(all, std::regex(R"(bad\.csv:3: column frequency_Hz: 10 must be positive and above the previous row's)"))) << all;
  EXPECT_TRUE(std::regex_search(all, std::regex(R"(runs\.csv:\d+: column psd: a random run needs its PSD file)"))) << all;
  EXPECT_TRUE(std::regex_search(all, std::regex(R"(runs\.csv:\d+: column kind: must be sine, random or sine_on_random, got 'sinus')")))
      << all;
}

}  // namespace test_lab_random
