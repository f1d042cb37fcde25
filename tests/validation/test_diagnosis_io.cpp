// The diagnosis stage's settings and results on file: the settings' checks and JSON, the
// confusion matrix's CSV, the blind report, the runs' VRC in diagnose --json (no campaign is
// simulated: fast). Reading the manifest's [diagnose] table: tests/io/test_lab_data.cpp.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "io/formats/case_file.hpp"
#include "io/services/blind_report.hpp"
#include "io/services/diagnosis_json.hpp"
#include "io/formats/lab_data.hpp"
#include "support/files.hpp"
#include "validation/diagnosis/blind.hpp"
#include "validation/diagnosis/diagnose.hpp"
#include "validation/diagnosis/diagnosis_text.hpp"

namespace test_diagnosis_io {

using namespace vrelab;
namespace fs = std::filesystem;
using vrelab::test::TempDir;

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
  // Truths beyond the library's rows (blind --n 4 once left its out-of-library campaign out)
  // and the verdicts beyond its columns.
  r.confusion["clipping (out of library)"]["unexplained"] = 1;
  r.confusion["a (natural form)"]["ambiguous"] = 1;
  r.confusion["sigma_understated"]["error"] = 1;
  const std::string csv = io::confusion_csv(r);
  EXPECT_NE(csv.find("truth,clean,a,b,two_effects,ambiguous,unexplained,error\n"), std::string::npos) << csv;
  EXPECT_NE(csv.find("\na,0,3,0,0,0,0,0\n"), std::string::npos) << csv;
  EXPECT_NE(csv.find("\ntwo,0,0,1,2,0,0,0\n"), std::string::npos) << csv;
  EXPECT_NE(csv.find("\nclipping (out of library),0,0,0,0,0,1,0\n"), std::string::npos) << csv;
  EXPECT_NE(csv.find("\na (natural form),0,0,0,0,1,0,0\n"), std::string::npos) << csv;
  EXPECT_NE(csv.find("\nsigma_understated,0,0,0,0,0,0,1\n"), std::string::npos) << csv;
  int counted = 0;  // every campaign (9) in the CSV's cells once
  std::istringstream lines(csv);
  std::string line;
  while (std::getline(lines, line)) {
    if (line.empty() || line[0] == '#' || line.rfind("truth,", 0) == 0) continue;
    std::istringstream cells(line.substr(line.find(',') + 1));
    for (std::string cell; std::getline(cells, cell, ',');) counted += std::stoi(cell);
  }
  EXPECT_EQ(counted, 9) << csv;
  r.settings.n = 3, r.settings.seed = 11;
  const nlohmann::json j = io::to_json(r);
  EXPECT_EQ(j["settings"]["n"], 3);
  EXPECT_EQ(j["settings"]["diagnose"]["significance_sigma"], 5.0);
  EXPECT_EQ(j["seed"], 11);
}

// blind --out's report.html: the targets in the summary box first, each family's row with its
// rate and interval ("n/a" for an empty one), the confusion figure embedded and the matrix's
// cells (every campaign, the out-of-library one too), every miss, the text escaped (a verdict
// or a note may hold < and &).
TEST(Blind, HtmlReportHasTheFamiliesTheConfusionAndEveryMissEscaped) {
  TempDir dir;
  std::ofstream(dir.path / "confusion.png", std::ios::binary) << "\x89PNG";
  validation::BlindResult r;
  r.settings.n = 5, r.settings.seed = 8;
  r.library = {"mechanical_mode"};
  validation::FamilyScore f;
  f.n = 4, f.right = 2, f.family = 1, f.wrong = 1;
  r.scores.families["single"] = f;
  r.scores.families["out_of_library"].n = 1;
  r.scores.families["out_of_library"].unexplained = 1;
  r.confusion["mechanical_mode"]["mechanical_mode"] = 2;
  r.confusion["mechanical_mode"]["unexplained"] = 1;
  r.confusion["mechanical_mode"]["ambiguous"] = 1;
  r.confusion["clipping (out of library)"]["mechanical_mode"] = 1;
  r.wrong = {"[single] campaign 3: mode <1 kHz & more"};
  const std::string h = io::blind_report(r, "").html(dir.path.string());
  EXPECT_LT(h.find("<section class=\"summary bad\">"), h.find("<h2>")) << h;
  EXPECT_NE(h.find("<p class=\"headline\">0 of 3 targets met (7 more have no campaign in this run); 1 of 5 campaigns confidently wrong.</p>"), std::string::npos) << h;
  EXPECT_NE(h.find("<tr><td>one library effect (gap &gt;= 5 sigma)</td><td class=\"n\">4</td><td class=\"n\">2/4</td><td class=\"n\">50 %</td>"
                   "<td class=\"n\">7 - 93 %</td><td class=\"n\">1</td><td class=\"n\">0</td><td class=\"n\">0</td>"
                   "<td class=\"n\">1</td><td class=\"n\">0 (0)</td><td class=\"n\">0</td><td class=\"n\">0</td></tr>"),
            std::string::npos) << h;
  EXPECT_NE(h.find("<tr><td>a bias drift</td><td class=\"n\">0</td><td class=\"n\">n/a</td><td class=\"n\">n/a</td><td class=\"n\">n/a</td>"), std::string::npos) << h;
  EXPECT_EQ(h.find("0/0 0.0 %"), std::string::npos);
  EXPECT_NE(h.find("<img src=\"data:image/png;base64,iVBORw==\""), std::string::npos) << h;
  EXPECT_NE(h.find("<tr><th>hidden \\ called (campaigns)</th><th class=\"n\">mechanical_mode</th><th class=\"n\">ambiguous</th>"
                   "<th class=\"n\">unexplained</th></tr>"),
            std::string::npos) << h;
  EXPECT_NE(h.find("<tr><td>mechanical_mode</td><td class=\"n\">2</td><td class=\"n\">1</td><td class=\"n\">1</td></tr>"), std::string::npos) << h;
  EXPECT_NE(h.find("<tr><td>clipping (out of library)</td><td class=\"n\">1</td><td class=\"n\"></td><td class=\"n\"></td></tr>"), std::string::npos) << h;
  EXPECT_NE(h.find("<li>[single] campaign 3: mode &lt;1 kHz &amp; more</li>"), std::string::npos) << h;
  EXPECT_EQ(h.find("<1 kHz"), std::string::npos);
  // Without the figure, the report says why.
  EXPECT_NE(io::blind_report(r, "no matplotlib").html(dir.path.string()).find("Figure confusion not drawn: no matplotlib."),
            std::string::npos);
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

// The datasheet form of a coefficient (IEEE Std 1293's units): the term it makes, in ug from the
// datasheet value, equals the model's in g x 1e6 at any amplitude: k5 = 3e-8 /g^4 at 2 g rectifies
// k5 a^5 = 9.6e-7 g, and 0.03 ug/g^5 x 2^5 g^5 = 0.96 ug; k_PP = 2e-6 /g: 2 ug/g^2; an angle per g
// 4e-7 rad/g: 0.4 urad/g. A ratio, a frequency, 1/rad or a phase has no datasheet form; a sigma
// the runs do not pin stays not a number.
TEST(DatasheetForm, ACoefficientsTermInUgIsTheModelsInGTimesAMillion) {
  const auto k5 = validation::datasheet_form(3e-8, 1e-9, "1/g^4");
  ASSERT_TRUE(k5.has_value());
  EXPECT_EQ(k5->unit, "ug/g^5");
  EXPECT_NEAR(k5->value * std::pow(2.0, 5), 0.96, 1e-12);
  EXPECT_NEAR(k5->sigma, 1e-3, 1e-15);
  const auto kpp = validation::datasheet_form(2e-6, INFINITY, "1/g");
  ASSERT_TRUE(kpp.has_value());
  EXPECT_EQ(kpp->unit, "ug/g^2");
  EXPECT_NEAR(kpp->value, 2.0, 1e-12);
  EXPECT_TRUE(std::isnan(kpp->sigma));
  const auto rocking = validation::datasheet_form(4e-7, 1e-8, "rad/g");
  ASSERT_TRUE(rocking.has_value());
  EXPECT_EQ(rocking->unit, "urad/g");
  EXPECT_NEAR(rocking->value, 0.4, 1e-12);
  for (const char* u : {"1", "Hz", "1/rad", "rad", "deg", "1/g^x", "1/g^"}) EXPECT_FALSE(validation::datasheet_form(1, 1, u)) << u;
}

}  // namespace test_diagnosis_io
