// The lab data format's reader (io/formats/lab_data.hpp, docs/data-format.md): bad runs
// skipped with file and line while bad files stop the reading, quoted cells, a raw record
// measured as its summary would be, the manifest's [diagnose] table read by field name and
// its bad keys named. Readers only, no diagnosis: fast.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <regex>
#include <sstream>
#include <string>
#include <utility>

#include <fmt/format.h>

#include "io/formats/error.hpp"
#include "io/formats/lab_data.hpp"
#include "support/files.hpp"
#include "support/lab_manifest.hpp"
#include "validation/diagnosis/campaign.hpp"

namespace test_lab_data {

using namespace vrelab;
using namespace vrelab::validation;
namespace fs = std::filesystem;
using vrelab::test::read_file;
using vrelab::test::TempDir;
using vrelab::test::error_of;
using vrelab::test::lab_with;

TEST(LabData, BadRunsAreSkippedWithFileAndLineAndBadFilesStop) {
  TempDir t;
  const std::string dir = (t.path / "c").string();
  fs::copy(std::string(VRELAB_CASES_DIR) + "/lab-example", dir);
  auto edit = [&](const std::string& file, const std::string& pattern, const std::string& with) {
    std::ifstream in(dir + "/" + file);
    std::stringstream s;
    s << in.rdbuf();
    const std::string text = s.str(), edited = std::regex_replace(text, std::regex(pattern), with);
    ASSERT_NE(edited, text) << pattern;
    std::ofstream(dir + "/" + file) << edited;
  };
  // A NaN in one run and a raw record shorter than its window in another: both skipped, the
  // other runs read.
  edit("runs.csv", "ia-10Hz-2g,10,2,1,0,0,0.7071,0,0.7071,[^,]*,", "ia-10Hz-2g,10,2,1,0,0,0.7071,0,0.7071,nan,");
  {
    std::ofstream s(dir + "/short.csv");
    s << "time_s,output_mA\n";
    for (int i = 0; i < 100; ++i) s << i * 1e-3 << "," << 0.88 << "\n";
  }
  edit("runs.csv", "id,frequency_Hz,amplitude_g,d_IA,d_PA,d_OA,a_IA_g,a_PA_g,a_OA_g,measured_ug,sigma_ug",
       "id,frequency_Hz,amplitude_g,d_IA,d_PA,d_OA,a_IA_g,a_PA_g,a_OA_g,measured_ug,sigma_ug,series,rest_from_s,rest_to_s,on_from_s,on_to_s");
  edit("runs.csv", "(ia-40Hz-4g,[^\\n]*)", "$1,short.csv,0,0.04,0.05,0.5");
  const Campaign c = io::read_campaign(dir);
  EXPECT_EQ(c.runs.size(), 8u);
  ASSERT_EQ(c.skipped.size(), 2u);
  EXPECT_TRUE(std::regex_search(c.skipped[0], std::regex(R"(run 'ia-10Hz-2g': .*runs\.csv:\d+:10: column measured_ug: nan is not a finite number)")))
      << c.skipped[0];
  EXPECT_TRUE(std::regex_search(c.skipped[1], std::regex(R"(short\.csv: the record ends at 0\.099 s, before on_to_s = 0\.5 s)")))
      << c.skipped[1];

  // Files that stop the diagnosis, each named.
  edit("static.csv", "output_mA,sigma_mA", "output_V,sigma_V");
  try {
    io::read_campaign(dir);
    ADD_FAILURE() << "accepted a unit mismatch";
  } catch (const io::InputError& e) {
    EXPECT_TRUE(std::regex_search(std::string(e.what()), std::regex(R"(static\.csv: column 'output_V' is in 'V', the manifest's output unit is 'mA')")))
        << e.what();
  }
  fs::remove(dir + "/static.csv");
  try {
    io::read_campaign(dir);
    ADD_FAILURE() << "accepted a missing static.csv";
  } catch (const io::InputError& e) {
    EXPECT_NE(std::string(e.what()).find("static.csv: cannot open"), std::string::npos) << e.what();
  }
}

// Spreadsheets quote cells: "a, b" is one cell, "" a quote inside; an unclosed quote stops
// the reading with file and line.
TEST(LabData, QuotedCsvCellsAreRead) {
  TempDir t;
  const std::string dir = (t.path / "c").string();
  fs::copy(std::string(VRELAB_CASES_DIR) + "/lab-example", dir);
  const Campaign plain = io::read_campaign(dir);
  std::string text = read_file(dir + "/runs.csv");
  text = std::regex_replace(text, std::regex("id,frequency_Hz,"), "\"id\", \"frequency_Hz\",");
  text = std::regex_replace(text, std::regex("\nia-100Hz-2g,100,"), "\n\"ia-100Hz-2g, \"\"quoted\"\"\" ,\"100\",");
  std::ofstream(dir + "/runs.csv") << text;
  const Campaign quoted = io::read_campaign(dir);
  ASSERT_EQ(quoted.runs.size(), plain.runs.size());
  EXPECT_EQ(quoted.runs[1].id, "ia-100Hz-2g, \"quoted\"");
  EXPECT_EQ(quoted.runs[1].frequency_Hz, 100.0);
  EXPECT_EQ(quoted.runs[1].measured_g, plain.runs[1].measured_g);
  std::ofstream(dir + "/runs.csv") << text << "\"unclosed,10,2,1,0,0,0.7071,0,0.7071,1,0.3\n";
  try {
    io::read_campaign(dir);
    ADD_FAILURE() << "accepted an unclosed quote";
  } catch (const io::InputError& e) {
    EXPECT_TRUE(std::regex_search(std::string(e.what()), std::regex(R"(runs\.csv:\d+: a quoted cell is not closed)"))) << e.what();
  }
}

// A campaign as a spreadsheet in a comma-decimal locale exports it (';'-separated tables; or
// tab-separated) reads as its comma twin: written back by the writer, file for file the same
// bytes. With decimal commas it is refused, naming the file, the line, the cell and why.
TEST(LabData, SemicolonAndTabTablesReadAsTheirCommaTwin) {
  TempDir t;
  const std::string comma = (t.path / "comma").string();
  fs::copy(std::string(VRELAB_CASES_DIR) + "/lab-example", comma);
  io::LabManifest m;
  const Campaign plain = io::read_campaign(comma, &m);
  const auto with_separator = [&](const std::string& name, const std::string& sep) {
    const std::string dir = (t.path / name).string();
    fs::copy(comma, dir);
    for (const char* table : {"/static.csv", "/runs.csv"}) {
      std::istringstream in(read_file(dir + table));
      std::string line, text;
      while (std::getline(in, line)) text += (line.empty() || line[0] == '#' ? line : std::regex_replace(line, std::regex(","), sep)) + "\n";
      std::ofstream(dir + table) << text;
    }
    EXPECT_NE(read_file(dir + "/runs.csv").find("id" + sep + "frequency_Hz" + sep), std::string::npos);
    return dir;
  };
  const auto written = [&](const Campaign& c, const std::string& name) {
    const std::string out = (t.path / ("written-" + name)).string();
    io::write_campaign(out, c, m);
    return read_file(out + "/static.csv") + read_file(out + "/runs.csv");
  };
  const std::string reference = written(plain, "comma");
  for (const auto& [name, sep] : {std::pair<std::string, std::string>{"semicolon", ";"}, {"tab", "\t"}}) {
    const Campaign c = io::read_campaign(with_separator(name, sep));
    ASSERT_EQ(c.runs.size(), plain.runs.size()) << name;
    ASSERT_EQ(c.statics.size(), plain.statics.size()) << name;
    EXPECT_EQ(written(c, name), reference) << name;
  }
  // Decimal commas (what such an export usually holds): refused at the first one.
  const std::string dir = with_separator("decimal-comma", ";");
  std::string runs = read_file(dir + "/runs.csv");
  runs = std::regex_replace(runs, std::regex(";53\\.443;"), ";53,443;");
  std::ofstream(dir + "/runs.csv") << runs;
  const Campaign c = io::read_campaign(dir);
  ASSERT_EQ(c.skipped.size(), 1u);
  EXPECT_TRUE(std::regex_search(c.skipped[0], std::regex(R"(runs\.csv:\d+:10: column measured_ug: '53,443' is not a number \(a decimal comma; write a decimal point\))")))
      << c.skipped[0];
}

// A shaker controller's PSD export names its columns its own way ("Frequency (Hz)",
// "Control IA (g^2/Hz)"): the manifest's [names] maps vrelab's names to them, and the campaign
// reads as its vrelab-named twin (written back by the writer: the same bytes; each random
// run's PSD rows equal). Without [names] those runs are skipped naming the missing column; a
// key that is no such name, or one lab name given twice, is refused naming the key.
TEST(LabData, ALabsOwnColumnNamesInTheManifestReadAsVrelabs) {
  TempDir t;
  const std::string plain_dir = (t.path / "plain").string(), lab_dir = (t.path / "lab").string();
  fs::copy(std::string(VRELAB_CASES_DIR) + "/lab-random", plain_dir);
  fs::copy(plain_dir, lab_dir);
  for (const auto& f : fs::directory_iterator(lab_dir)) {
    const std::string name = f.path().filename().string();
    if (name == "runs.csv" || name == "static.csv" || f.path().extension() != ".csv") continue;
    std::string text = read_file(f.path().string());
    text = std::regex_replace(text, std::regex("frequency_Hz"), "Frequency (Hz)");
    text = std::regex_replace(text, std::regex("psd_(IA|PA|OA)_g2_per_Hz"), "\"Control $1 (g^2/Hz)\"");
    std::ofstream(f.path()) << text;
  }
  EXPECT_NE(read_file(lab_dir + "/gevs.csv").find("Frequency (Hz),\"Control IA (g^2/Hz)\""), std::string::npos);
  io::LabManifest m;
  const Campaign plain = io::read_campaign(plain_dir, &m);
  ASSERT_TRUE(plain.skipped.empty());
  const Campaign unnamed = io::read_campaign(lab_dir);
  EXPECT_GE(unnamed.skipped.size(), 3u);
  EXPECT_NE(unnamed.skipped.at(0).find("frequency_Hz"), std::string::npos) << unnamed.skipped.at(0);
  const std::string manifest = read_file(lab_dir + "/manifest.toml");
  std::ofstream(lab_dir + "/manifest.toml")
      << manifest << "\n[names]\nfrequency_Hz = \"Frequency (Hz)\"\npsd_IA_g2_per_Hz = \"Control IA (g^2/Hz)\"\n"
      << "psd_PA_g2_per_Hz = \"Control PA (g^2/Hz)\"\n";
  io::LabManifest lm;
  const Campaign named = io::read_campaign(lab_dir, &lm);
  ASSERT_TRUE(named.skipped.empty()) << named.skipped.front();
  EXPECT_EQ(lm.names.at("frequency_Hz"), "Frequency (Hz)");
  ASSERT_EQ(named.runs.size(), plain.runs.size());
  int random = 0;
  for (std::size_t k = 0; k < plain.runs.size(); ++k) {
    ASSERT_EQ(named.runs[k].random.has_value(), plain.runs[k].random.has_value());
    if (!plain.runs[k].random) continue;
    ++random;
    for (std::size_t a = 0; a < 3; ++a) {
      const auto &x = named.runs[k].random->psd[a], &y = plain.runs[k].random->psd[a];
      ASSERT_EQ(x.has_value(), y.has_value());
      if (!x) continue;
      ASSERT_EQ(x->rows.size(), y->rows.size());
      for (std::size_t i = 0; i < x->rows.size(); ++i) {
        EXPECT_EQ(x->rows[i].frequency_Hz, y->rows[i].frequency_Hz);
        EXPECT_EQ(*x->rows[i].psd_g2_per_Hz, *y->rows[i].psd_g2_per_Hz);
      }
    }
  }
  EXPECT_GE(random, 3);
  const auto written = [&](const Campaign& c, const std::string& name) {
    const std::string out = (t.path / name).string();
    io::write_campaign(out, c, m);
    return read_file(out + "/runs.csv");
  };
  EXPECT_EQ(written(named, "w-named"), written(plain, "w-plain"));
  // Refused: an unknown key; one lab name twice.
  std::ofstream(lab_dir + "/manifest.toml") << manifest << "\n[names]\nfrequency = \"Frequency (Hz)\"\n";
  EXPECT_NE(error_of(lab_dir).find("[names] frequency: unknown key"), std::string::npos) << error_of(lab_dir);
  std::ofstream(lab_dir + "/manifest.toml") << manifest << "\n[names]\nfrequency_Hz = \"F\"\ntime_s = \"F\"\n";
  EXPECT_NE(error_of(lab_dir).find("already the lab's name of"), std::string::npos) << error_of(lab_dir);
}

TEST(LabData, RawRecordIsMeasuredAsTheSummaryWouldBe) {
  // A synthetic record: 0.88 mA at rest, then a 50 Hz sine of 1 mA with a 25 ug (x K1) offset.
  TempDir t;
  const std::string dir = (t.path / "c").string();
  fs::copy(std::string(VRELAB_CASES_DIR) + "/lab-example", dir);
  const double K1 = 1.25;  // the example instrument's (the reader uses the static test's, within 1e-5)
  {
    std::ofstream s(dir + "/rec.csv");
    s << "# time_s, output in mA\ntime_s,output_mA\n";
    for (int i = 0; i < 20000; ++i) {
      const double tt = -1.0 + i * 1e-4;
      const double u = 0.88 + (tt >= 0 ? std::sin(2 * std::numbers::pi * 50 * tt) + K1 * 25e-6 : 0.0);
      s << fmt::format("{:.6f},{:.12f}\n", tt, u);
    }
  }
  std::ofstream(dir + "/runs.csv") << "id,frequency_Hz,amplitude_g,d_IA,d_PA,d_OA,a_IA_g,a_PA_g,a_OA_g,series,rest_from_s,"
                                      "rest_to_s,on_from_s,on_to_s\n"
                                      "raw1,50,1,1,0,0,0.7071,0,0.7071,rec.csv,-1,0,0,0.9999\n";
  const Campaign c = io::read_campaign(dir);
  ASSERT_EQ(c.runs.size(), 1u) << (c.skipped.empty() ? "" : c.skipped[0]);
  // The offset in g through the identified K1 (within 0.1 % of 1.25): 25 ug to 0.05 ug.
  EXPECT_NEAR(c.runs[0].measured_g, 25e-6, 0.05e-6);
  EXPECT_GT(c.runs[0].sigma_g, 0.0);

  // A sample that is not a number, and time that goes back: the run is skipped, the line named.
  for (const auto& [bad, expect] : {std::pair<std::string, std::string>{"0.5,abc", R"(rec\.csv:\d+: not a number in .*0\.5,abc)"},
                                    {"0.1,0.88", R"(rec\.csv:\d+: time does not increase)"}}) {
    std::ifstream in(dir + "/rec.csv");
    std::stringstream all;
    all << in.rdbuf();
    std::string text = all.str();
    const auto pos = text.find("0.500000,");  // insert the bad line in the middle of the record
    ASSERT_NE(pos, std::string::npos);
    text.insert(pos, bad + "\n");
    std::ofstream(dir + "/rec.csv") << text;
    const Campaign b = io::read_campaign(dir);
    ASSERT_EQ(b.skipped.size(), 1u);
    EXPECT_TRUE(std::regex_search(b.skipped[0], std::regex(expect))) << b.skipped[0];
    text.erase(pos, bad.size() + 1);
    std::ofstream(dir + "/rec.csv") << text;
  }
}


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

}  // namespace test_lab_data
