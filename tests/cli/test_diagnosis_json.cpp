// `diagnose --json` of a folder (io::to_json(FolderDiagnosis)) when there is no diagnosis: a
// folder read and checked only (io::read_folder, `diagnose --check`) is written as what there
// is (the program, the data, the settings, the runs as read), marked not diagnosed.
#include <gtest/gtest.h>

#include <string>

#include "io/services/diagnosis.hpp"
#include "io/services/diagnosis_json.hpp"

namespace test_diagnosis_json {

using namespace vrelab;

TEST(DiagnosisJson, AFolderReadButNotDiagnosedIsWrittenAsRead) {
  const io::FolderDiagnosis f = io::read_folder(std::string(VRELAB_CASES_DIR) + "/lab-example");
  ASSERT_FALSE(f.diagnosed);
  ASSERT_FALSE(f.campaign.runs.empty());
  const nlohmann::json j = io::to_json(f);
  EXPECT_EQ(j.at("command"), "diagnose");
  EXPECT_EQ(j.at("diagnosed"), false);
  EXPECT_TRUE(j.contains("settings"));
  EXPECT_FALSE(j.contains("verdict"));  // nothing judged
  ASSERT_EQ(j.at("runs").size(), f.campaign.runs.size());
  const nlohmann::json& run = j.at("runs").front();
  EXPECT_EQ(run.at("id"), f.campaign.runs.front().id);
  EXPECT_EQ(run.at("measured_g").get<double>(), f.campaign.runs.front().measured_g);
  EXPECT_FALSE(run.contains("predicted_g"));  // no prediction made
}

}  // namespace test_diagnosis_json
