// The diagnosis stage's settings and results on file: the manifest's [diagnose] table, the
// settings' checks, the confusion matrix's CSV (no campaign is simulated: fast).
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>

#include "io/case_file.hpp"
#include "io/diagnosis_json.hpp"
#include "io/lab_data.hpp"
#include "support/files.hpp"
#include "validation/diagnosis/blind.hpp"
#include "validation/diagnosis/diagnose.hpp"

using namespace vrelab;
namespace fs = std::filesystem;
using vrelab::test::TempDir;

namespace {

// The shipped hand-written campaign with `table` appended to its manifest.
fs::path lab_with(const TempDir& t, const std::string& table) {
  const fs::path dir = t.path / "lab";
  fs::copy(fs::path(VRELAB_CASES_DIR) / "lab-example", dir, fs::copy_options::recursive);
  std::ofstream(dir / "manifest.toml", std::ios::app) << "\n" << table;
  return dir;
}

std::string error_of(const fs::path& dir) {
  try {
    io::read_campaign(dir.string());
  } catch (const io::InputError& e) {
    return e.what();
  }
  return "";
}

}  // namespace

TEST(DiagnoseSettings, TheManifestsDiagnoseTableSetsThemByFieldName) {
  TempDir t;
  io::LabManifest m;
  io::read_campaign(lab_with(t, "[diagnose]\nsignificance_sigma = 4\nresimulate_runs = 0\ntry_pairs = false\n").string(), &m);
  EXPECT_TRUE(m.diagnose_given);
  EXPECT_EQ(m.diagnose.significance_sigma, 4.0);
  EXPECT_EQ(m.diagnose.resimulate_runs, 0);
  EXPECT_FALSE(m.diagnose.try_pairs);
  EXPECT_EQ(m.diagnose.model_accuracy, validation::DiagnoseSettings{}.model_accuracy);  // absent: the default
}

TEST(DiagnoseSettings, ABadKeyOrValueNamesTheFileTheKeyAndWhy) {
  {
    TempDir t;
    EXPECT_NE(error_of(lab_with(t, "[diagnose]\nsignificance = 4\n")).find("manifest.toml:"), std::string::npos);
  }
  {
    TempDir t;
    EXPECT_NE(error_of(lab_with(t, "[diagnose]\nsignificance = 4\n")).find("[diagnose] significance: unknown key"),
              std::string::npos);
  }
  {
    TempDir t;
    EXPECT_NE(error_of(lab_with(t, "[diagnose]\nresimulate_runs = 2.5\n")).find("resimulate_runs: expected a whole number"),
              std::string::npos);
  }
  {
    TempDir t;
    EXPECT_NE(error_of(lab_with(t, "[diagnose]\nmodel_accuracy = -0.1\n")).find("model_accuracy = -0.1"), std::string::npos);
  }
}

TEST(DiagnoseSettings, IsValidNamesTheField) {
  std::string why;
  EXPECT_TRUE(validation::DiagnoseSettings{}.IsValid(&why)) << why;
  validation::DiagnoseSettings s;
  s.explained_shrinkage = 0;
  EXPECT_FALSE(s.IsValid(&why));
  EXPECT_NE(why.find("explained_shrinkage"), std::string::npos);
  s = {};
  s.resimulate_runs = -1;
  EXPECT_FALSE(s.IsValid(&why));
  EXPECT_NE(why.find("resimulate_runs"), std::string::npos);
  const nlohmann::json j = io::to_json(validation::DiagnoseSettings{});
  EXPECT_EQ(j["significance_sigma"], 5.0);
  EXPECT_EQ(j["try_pairs"], true);
}

TEST(Blind, SettingsAreCheckedBeforeAnyCampaign) {
  validation::BlindSettings s;
  std::string why;
  EXPECT_TRUE(s.IsValid(&why)) << why;
  s.n = 0;
  EXPECT_FALSE(s.IsValid(&why));
  EXPECT_NE(why.find("n = 0"), std::string::npos);
  EXPECT_THROW(validation::run_blind(s), std::invalid_argument);
  s.n = 1, s.diagnose.significance_sigma = 0;
  EXPECT_FALSE(s.IsValid(&why));
  EXPECT_NE(why.find("diagnose.significance_sigma"), std::string::npos) << why;
}

// The confusion matrix: rows the truth, columns what was called; any "A + B" verdict counts
// under two_effects, and the scores JSON carries the settings.
TEST(Blind, ConfusionCsvCountsPairVerdictsAsTwoEffects) {
  validation::BlindResult r;
  r.library = {"a", "b"};
  r.confusion["two"]["a + b"] = 2;
  r.confusion["two"]["b"] = 1;
  r.confusion["a"]["a"] = 3;
  const std::string csv = io::confusion_csv(r);
  EXPECT_NE(csv.find("truth,clean,a,b,two_effects,unexplained\n"), std::string::npos) << csv;
  EXPECT_NE(csv.find("\na,0,3,0,0,0\n"), std::string::npos) << csv;
  EXPECT_NE(csv.find("\ntwo,0,0,1,2,0\n"), std::string::npos) << csv;
  r.settings.n = 3, r.settings.seed = 11;
  const nlohmann::json j = io::to_json(r);
  EXPECT_EQ(j["settings"]["n"], 3);
  EXPECT_EQ(j["settings"]["diagnose"]["significance_sigma"], 5.0);
  EXPECT_EQ(j["seed"], 11);
}
