// The diagnosis stage's settings and results on file: the manifest's [diagnose] table, the
// settings' checks, the confusion matrix's CSV (no campaign is simulated: fast).
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "io/formats/case_file.hpp"
#include "io/formats/csv.hpp"
#include "io/services/diagnosis_json.hpp"
#include "io/formats/lab_data.hpp"
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

// blind --out's report.html: each family's row with its counts, the confusion matrix's cells,
// every miss, the text escaped (a verdict or a note may hold < and &).
TEST(Blind, HtmlReportHasTheFamiliesTheConfusionAndEveryMissEscaped) {
  validation::BlindResult r;
  r.settings.n = 5, r.settings.seed = 8;
  validation::FamilyScore f;
  f.n = 4, f.right = 2, f.family = 1, f.wrong = 1;
  r.scores.families["single"] = f;
  r.confusion["mechanical_mode"]["mechanical_mode"] = 2;
  r.confusion["mechanical_mode"]["unexplained"] = 1;
  r.wrong = {"[single] campaign 3: mode <1 kHz & more"};
  const std::string h = io::blind_html(r);
  EXPECT_NE(h.find("<td class=\"l\">single</td><td>4</td><td class=\"ok\">2</td><td>1</td><td>0</td><td>0</td><td class=\"bad\">1</td>"),
            std::string::npos) << h;
  EXPECT_NE(h.find("<td class=\"l\">mechanical_mode</td><td class=\"ok\">2</td><td class=\"\">1</td>"), std::string::npos) << h;
  EXPECT_NE(h.find("<li>[single] campaign 3: mode &lt;1 kHz &amp; more</li>"), std::string::npos) << h;
  EXPECT_EQ(h.find("<1 kHz"), std::string::npos);
}

// Numbers as a lab writes them: finite decimals only. strtod alone reads "0x1E" as 30, "inf"
// and "nan" as themselves, and stops quietly at a decimal comma.
TEST(CsvText, OnlyFiniteDecimalNumbersAreNumbers) {
  EXPECT_EQ(io::parse_decimal("30").value(), 30.0);
  EXPECT_EQ(io::parse_decimal("-1.5e-3").value(), -1.5e-3);
  EXPECT_EQ(io::parse_decimal(".5").value(), 0.5);
  EXPECT_EQ(io::parse_decimal("5.").value(), 5.0);
  EXPECT_EQ(io::parse_decimal("+2E+2").value(), 200.0);
  for (const char* bad : {"0x1E", "0X1e", "inf", "-inf", "nan", "NaN", "1,5", " 1", "1 ", "", "-", ".", "e5", "1e", "1e+",
                          "1.2.3", "1e999", "12abc"})
    EXPECT_FALSE(io::parse_decimal(bad).has_value()) << bad;
  EXPECT_EQ(io::why_not_decimal("0x1E"), "hexadecimal; write the decimal value");
  EXPECT_EQ(io::why_not_decimal("nan"), "not finite");
  EXPECT_EQ(io::why_not_decimal("1,5"), "a decimal comma; write a decimal point");
}

// UTF-8 as RFC 3629 has it: a Latin-1 degree sign (0xB0) is not UTF-8, its UTF-8 form (C2 B0)
// is; overlong forms, surrogates and truncated sequences are not.
TEST(CsvText, Utf8IsCheckedByteByByte) {
  EXPECT_EQ(io::first_non_utf8("angle 30\xC2\xB0"), std::string::npos);
  EXPECT_EQ(io::first_non_utf8("\xE2\x82\xAC \xF0\x9F\x98\x80"), std::string::npos);  // euro, an emoji
  EXPECT_EQ(io::first_non_utf8("id\xB0"), 2u);
  EXPECT_EQ(io::first_non_utf8("\xC0\xAF"), 0u);          // overlong '/'
  EXPECT_EQ(io::first_non_utf8("a\xED\xA0\x80"), 1u);     // a surrogate
  EXPECT_EQ(io::first_non_utf8("ab\xE2\x82"), 2u);        // truncated at the end
  EXPECT_EQ(io::first_non_utf8("\xF4\x90\x80\x80"), 0u);  // past U+10FFFF
  std::string bom = "\xEF\xBB\xBFid,frequency_Hz\r";
  io::check_text_line(bom, 1, "runs.csv");
  EXPECT_EQ(bom, "id,frequency_Hz");
  std::string latin1 = "run\xB0,1";
  try {
    io::check_text_line(latin1, 7, "runs.csv");
    ADD_FAILURE() << "accepted a Latin-1 byte";
  } catch (const io::InputError& e) {
    EXPECT_NE(std::string(e.what()).find("runs.csv:7:4: not UTF-8 at byte 4 (0xB0"), std::string::npos) << e.what();
  }
}

TEST(CsvText, ClosestColumnNameIsSuggested) {
  const std::vector<std::string> names = {"id", "frequency_Hz", "amplitude_g"};
  EXPECT_EQ(io::closest_name("frequency_hz", names), "frequency_Hz");
  EXPECT_EQ(io::closest_name("amplitud_g", names), "amplitude_g");
  EXPECT_EQ(io::closest_name("temperature_C", names), "");
}

namespace {

// A lab CSV file's data rows (comment lines and the header dropped), split at commas.
std::vector<std::vector<std::string>> csv_rows(const fs::path& p) {
  std::vector<std::vector<std::string>> rows;
  std::istringstream in(vrelab::test::read_file(p));
  bool header = true;
  for (std::string line; std::getline(in, line);) {
    if (line.empty() || line[0] == '#') continue;
    if (header) {
      header = false;
      continue;
    }
    std::vector<std::string> cells;
    std::stringstream ls(line);
    for (std::string cell; std::getline(ls, cell, ',');) cells.push_back(cell);
    if (line.back() == ',') cells.emplace_back();
    rows.push_back(cells);
  }
  return rows;
}

// The mean square (g^2) of a PSD file, all its axis columns summed: between breakpoints the
// level is a straight line in log-log (a power law S1 (f/f1)^n), whose integral is closed-form.
double psd_mean_square_g2(const fs::path& p) {
  const auto rows = csv_rows(p);
  double s = 0;
  for (std::size_t k = 1; k < rows.size(); ++k)
    for (std::size_t col = 1; col < rows[k].size(); ++col) {
      const double f1 = std::stod(rows[k - 1][0]), f2 = std::stod(rows[k][0]);
      const double s1 = std::stod(rows[k - 1][col]), s2 = std::stod(rows[k][col]);
      const double n = std::log(s2 / s1) / std::log(f2 / f1);
      s += std::abs(n + 1) < 1e-12 ? s1 * f1 * std::log(f2 / f1) : s1 * f1 / (n + 1) * (std::pow(f2 / f1, n + 1) - 1);
    }
  return s;
}

}  // namespace

// diagnose --json's per-run VRC (measured and predicted) against one recomputed here from the
// same JSON's errors and the run's amplitudes: a sine's input rms^2 is sum_i a_i^2 / 2 (a_i the
// peak along axis i), a random part's the PSD's integral (read from its file, integrated in
// closed form here), a sine on random both added; VRC = 1e6 error / rms^2 in ug/g^2. A wrong
// rms (peak for rms, a missing part) or unit (g, mg) is off by >= 2x; the bound is 1e-9.
TEST(DiagnosisJson, RunVrcIsErrorOverTheSineAndRandomPartsMeanSquareInMicroGPerG2) {
  const fs::path dir = fs::path(VRELAB_CASES_DIR) / "lab-random";
  const validation::Campaign c = io::read_campaign(dir.string());
  validation::Diagnosis d;
  d.runs.resize(c.runs.size());
  for (std::size_t k = 0; k < c.runs.size(); ++k) d.runs[k].predicted_g = 0.9 * c.runs[k].measured_g + 1e-6;
  const nlohmann::json runs = io::to_json(d, c)["runs"];
  const auto rows = csv_rows(dir / "runs.csv");
  ASSERT_EQ(runs.size(), rows.size());
  int kinds[3] = {0, 0, 0};
  for (std::size_t k = 0; k < rows.size(); ++k) {
    const auto& row = rows[k];
    const auto& r = runs[k];
    ASSERT_EQ(r["id"], row[0]);
    const std::string kind = row[11];
    double ms = 0;
    if (kind != "random") {
      // The JSON's peak amplitude along its unit direction, per axis; the direction is the
      // file's normalised (d_* = 0.7071, 0.7071 is a unit vector to 1e-5 only).
      const double a = r["amplitude_g"];
      double n2 = 0;
      for (int i = 0; i < 3; ++i) n2 += std::pow(std::stod(row[3 + static_cast<std::size_t>(i)]), 2);
      for (int i = 0; i < 3; ++i) ms += std::pow(a * r["direction"][static_cast<std::size_t>(i)].get<double>(), 2) / 2;
      EXPECT_NEAR(ms, a * a / 2, 1e-12 * a * a) << row[0];
      EXPECT_NEAR(std::stod(row[2]), a, 1e-12) << row[0];
      EXPECT_GT(n2, 0.99) << row[0];
    }
    if (kind != "sine") ms += psd_mean_square_g2(dir / row[12]);
    ++kinds[kind == "sine" ? 0 : kind == "random" ? 1 : 2];
    EXPECT_NEAR(r["input_rms_g"].get<double>(), std::sqrt(ms), 1e-9 * std::sqrt(ms)) << row[0];
    const double measured = r["measured_g"], predicted = r["predicted_g"];
    EXPECT_NEAR(measured, std::stod(row[9]) * 1e-6, 1e-15) << row[0];  // the file's ug, in g
    const double vm = 1e6 * measured / ms, vp = 1e6 * predicted / ms;
    EXPECT_NEAR(r["measured_vrc_ug_per_g2"].get<double>(), vm, 1e-9 * std::abs(vm)) << row[0];
    EXPECT_NEAR(r["predicted_vrc_ug_per_g2"].get<double>(), vp, 1e-9 * std::abs(vp)) << row[0];
  }
  // The shipped case has all three kinds (the test means something for each).
  EXPECT_EQ(kinds[0], 10);
  EXPECT_GE(kinds[1], 4);
  EXPECT_GE(kinds[2], 1);
}
