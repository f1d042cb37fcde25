// The commands as the CLI runs them, in-process: JSON schema and values on the shipped
// cases, and bad input (a clear message naming the key and line, no partial output).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <regex>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

#include "support/files.hpp"
#include "io/formats/case_file.hpp"
#include "app/commands.hpp"
#include "rectification/simulation/work_estimate.hpp"

namespace test_cli {

using namespace vrelab::app;
using namespace vrelab::io;
namespace fs = std::filesystem;
using vrelab::test::read_file;
using vrelab::test::TempDir;
using nlohmann::json;

namespace {

// A copy of a shipped case with one regex replacement applied.
fs::path edited_case(const TempDir& d, const std::string& name, const std::string& pattern, const std::string& with) {
  const std::string text = read_file(fs::path(VRELAB_CASES_DIR) / name);
  const std::string edited = std::regex_replace(text, std::regex(pattern), with);
  EXPECT_NE(edited, text) << "pattern " << pattern << " did not match";
  const fs::path out = d.path / ("edited-" + name);
  std::ofstream(out) << edited;
  return out;
}

json identify_json(const fs::path& case_path, const TempDir& d, int mc = 0) {
  IdentifyOptions o;
  o.case_path = case_path.string();
  o.json_path = (d.path / "out" / "identify.json").string();
  o.monte_carlo = mc;
  std::ostringstream text;
  run_identify(o, text);
  return json::parse(read_file(o.json_path));
}

}  // namespace

TEST(CliIdentify, IdealCaseRecoversTheTruthAndWritesTheDocumentedSchema) {
  TempDir d;
  const json j = identify_json(fs::path(VRELAB_CASES_DIR) / "ideal-static.toml", d);
  for (const char* key : {"program", "case", "seed", "truth", "estimates", "errors", "sigma", "identifiability", "readings"})
    EXPECT_TRUE(j.contains(key)) << key;
  EXPECT_EQ(j["identifiability"]["rank"], 10);
  EXPECT_EQ(j["readings"].size(), 24u);
  ASSERT_EQ(j["truth"].size(), 13u);  // the 13 coefficients of model (1)
  for (const char* m : {"paper_corrected", "least_squares"})
    for (auto& [name, truth] : j["truth"].items()) {
      const double t = truth.get<double>();
      EXPECT_NEAR(j["estimates"][m][name].get<double>(), t, 1e-9 * std::abs(t) + 1e-15) << m << " " << name;
    }
  EXPECT_TRUE(j["estimates"]["paper_printed"]["delta_OA"].is_null());
  EXPECT_NEAR(j["estimates"]["paper_printed"]["k3"].get<double>(), -j["truth"]["k3"].get<double>() / 3, 1e-9);
  EXPECT_EQ(j["case"]["content"]["dividing_head"]["positions_per_series"], 8);
}

TEST(CliIdentify, OtherPositionSetsRunLeastSquaresOnlyAndSaySo) {
  TempDir d;
  const fs::path c = edited_case(d, "ideal-static.toml", "positions_per_series = 8", "positions_per_series = 24");
  const json j = identify_json(c, d);
  EXPECT_TRUE(j["estimates"]["paper_corrected"].is_null());
  EXPECT_FALSE(j["estimates"]["least_squares"].is_null());
  EXPECT_NE(j["notes"][0].get<std::string>().find("3 x 8"), std::string::npos);
}

// The datasheet form: least squares' estimates times 1e6 in ug, ug/g^2, ug/g^3, urad (read
// back from the text against the JSON's 1/g values); the printed method's k2 (the sum over
// the wrong positions, docs/identification.md: about 1 instead of 1.5e-5) flagged, the
// corrected method's estimates (within a few sigma of least squares') not.
TEST(CliIdentify, TheDatasheetFormIsInMicroGAndThePrintedK2IsFlagged) {
  TempDir d;
  IdentifyOptions o;
  o.case_path = std::string(VRELAB_CASES_DIR) + "/paper-static.toml";
  o.json_path = (d.path / "identify.json").string();
  std::ostringstream text;
  run_identify(o, text);
  const std::string t = text.str();
  const json j = json::parse(read_file(o.json_path));
  const json& ls = j["estimates"]["least_squares"];
  std::smatch m;
  ASSERT_TRUE(std::regex_search(t, m, std::regex(R"(\n  k2 +(-?[0-9.e+-]+) ug/g\^2 +\+- ([0-9.e+-]+)\n)"))) << t;
  const double k2 = ls["k2"].get<double>();
  EXPECT_NEAR(std::stod(m[1]), k2 * 1e6, 1e-5 * std::abs(k2 * 1e6));  // printed to 6 digits
  ASSERT_TRUE(std::regex_search(t, m, std::regex(R"(\n  delta_OA +(-?[0-9.e+-]+) urad )"))) << t;
  EXPECT_NEAR(std::stod(m[1]), ls["delta_OA"].get<double>() * 1e6, 1e-3);
  EXPECT_TRUE(std::regex_search(t, std::regex(R"(warning: paper_printed's k2 = 1\.00[0-9]*e\+06 ug/g\^2 departs)"))) << t;
  EXPECT_EQ(t.find("warning: paper_corrected"), std::string::npos) << t;
}

TEST(CliPredict, WritesTotalAndTermsThatAddUp) {
  TempDir d;
  PredictOptions o;
  o.case_path = std::string(VRELAB_CASES_DIR) + "/paper-predict.toml";
  o.json_path = (d.path / "predict.json").string();
  std::ostringstream text;
  run_predict(o, text);
  const json j = json::parse(read_file(o.json_path));
  double sum = 0;
  for (auto& [k, v] : j["terms"].items()) sum += v.get<double>();
  EXPECT_NEAR(j["total_g"].get<double>(), sum, 1e-18);
  // k2 w^2/2 by hand: 1.5e-5 * 9 / 2.
  EXPECT_NEAR(j["terms"]["k2"].get<double>(), 1.5e-5 * 9 / 2, 1e-18);
  EXPECT_NEAR(j["omitted_by_paper_g"].get<double>(), 4e-6 * 1 / 2, 1e-18);
  EXPECT_TRUE(j.contains("paper_printed_total_g"));
}

namespace {

// Runs identify on an edited case and expects InputError whose message matches `expect`,
// and no output file.
void expect_identify_rejects(const std::string& pattern, const std::string& with, const std::string& expect,
                             const std::string& base = "ideal-static.toml") {
  TempDir d;
  const fs::path c = edited_case(d, base, pattern, with);
  IdentifyOptions o;
  o.case_path = c.string();
  o.json_path = (d.path / "out" / "identify.json").string();
  std::ostringstream text;
  try {
    run_identify(o, text);
    ADD_FAILURE() << "accepted: " << pattern << " -> " << with;
  } catch (const InputError& e) {
    EXPECT_TRUE(std::regex_search(std::string(e.what()), std::regex(expect))) << e.what();
    EXPECT_NE(std::string(e.what()).find(c.string()), std::string::npos) << "names the file: " << e.what();
  }
  EXPECT_FALSE(fs::exists(o.json_path));
}

}  // namespace

TEST(CliBadInput, TypoIsAnUnknownKeyWithLineAndSuggestion) {
  expect_identify_rejects("angle_sigma_arcsec", "angle_sigma_arcsex",
                          R"(:\d+: \[dividing_head\] angle_sigma_arcsex: unknown key \(did you mean 'angle_sigma_arcsec'\?\))");
  expect_identify_rejects("\\[coefficients\\]", "[coeficients]", R"(coeficients: unknown key \(did you mean 'coefficients'\?\))");
}

TEST(CliBadInput, MissingCoefficientIsNamed) {
  expect_identify_rejects("\nk4 = [^\n]*", "", R"(\[coefficients\] k4: missing)");
}

TEST(CliBadInput, NanIsRejected) {
  expect_identify_rejects("\nk2 = [^\n#]*", "\nk2 = nan ", R"(:\d+: \[coefficients\] k2: must be a finite number)");
}

TEST(CliBadInput, NegativeSigmaIsRejected) {
  expect_identify_rejects("noise_sigma_ug = 0.0", "noise_sigma_ug = -1.0",
                          R"(:\d+: \[dividing_head\] noise_sigma_ug: must not be negative)");
}

TEST(CliBadInput, EmptyPositionSetIsRejected) {
  expect_identify_rejects("positions_per_series = 8", "positions = []", R"(\[dividing_head\] positions: the position set is empty)");
  expect_identify_rejects("positions_per_series = 8", "positions_per_series = 0",
                          R"(positions_per_series: must be at least 1)");
}

TEST(CliBadInput, RankDeficientSetIsReportedInWords) {
  expect_identify_rejects("fixed = \\{[^}]*\\}", "fixed = { }",
                          R"(rank 11 of 13[\s\S]*k0 and a common shift of k2, k_PP, k_OO[\s\S]*k1_asym)");
}

TEST(CliBadInput, SyntaxErrorNamesTheLine) {
  // The edited line's number, counted here in the shipped file (the one line that starts "k3 = ").
  std::istringstream text(read_file(fs::path(VRELAB_CASES_DIR) / "ideal-static.toml"));
  int line = 0, k3_line = 0;
  for (std::string l; std::getline(text, l);) {
    ++line;
    if (l.rfind("k3 = ", 0) == 0) {
      EXPECT_EQ(k3_line, 0) << "two lines start with k3 =";
      k3_line = line;
    }
  }
  ASSERT_GT(k3_line, 0);
  expect_identify_rejects("k3 = ", "k3 = = ", "ideal-static\\.toml:" + std::to_string(k3_line) + ": ");
}

TEST(CliBadInput, PredictRejectsNegativeAmplitude) {
  TempDir d;
  const fs::path c = edited_case(d, "paper-predict.toml", "amplitude_g = \\[3.0", "amplitude_g = [-3.0");
  PredictOptions o;
  o.case_path = c.string();
  o.json_path = (d.path / "p.json").string();
  std::ostringstream text;
  EXPECT_THROW(run_predict(o, text), InputError);
  EXPECT_FALSE(fs::exists(o.json_path));
}

TEST(CliIdentify, SameSeedSameResultOtherSeedOtherResult) {
  TempDir d;
  const fs::path c = fs::path(VRELAB_CASES_DIR) / "paper-static.toml";
  auto run = [&](std::optional<std::uint64_t> seed) {
    IdentifyOptions o;
    o.case_path = c.string();
    o.json_path = (d.path / "r.json").string();
    o.seed = seed;
    std::ostringstream text;
    run_identify(o, text);
    return json::parse(read_file(o.json_path));
  };
  const json a = run(std::nullopt), b = run(std::nullopt), other = run(99);
  EXPECT_EQ(a["estimates"], b["estimates"]);
  EXPECT_EQ(a["readings"], b["readings"]);
  EXPECT_NE(a["estimates"]["least_squares"], other["estimates"]["least_squares"]);
  EXPECT_EQ(other["seed"], 99);
}

// A random run's shake sets the ODE beside both predictions: the quasi-static eq. (3) is 25 %
// high on GEVS at 14 g rms (the loop filters k4's 3 sigma^4 above its crossover), the
// frequency-dependent one -- what `predict --frequency-dependent` prints for the same case --
// within 3 of the ODE's sigma (measured: -0.84).
// (A 4 s ODE record: 0.05 s in Release, 14 s under the sanitizers: label campaign.)
TEST(CliShakeCampaign, ARandomRunIsJudgedAgainstTheFrequencyDependentPredictionToo) {
  TempDir d;
  ShakeOptions so;
  so.case_path = std::string(VRELAB_CASES_DIR) + "/shake-random-gevs.toml";
  so.json_path = (d.path / "shake.json").string();
  std::ostringstream text;
  run_shake(so, text);
  PredictOptions po;
  po.case_path = so.case_path;
  po.json_path = (d.path / "predict.json").string();
  po.frequency_dependent = true;
  run_predict(po, text);
  const json shake = json::parse(read_file(so.json_path)), predict = json::parse(read_file(po.json_path));
  const double measured = shake["measured_g"].get<double>(), sigma = shake["sigma_g"].get<double>();
  const double through = shake["predicted_frequency_dependent_g"].get<double>();
  EXPECT_EQ(through, predict["frequency_dependent"]["total_g"].get<double>());
  EXPECT_LT(std::abs(measured - through), 3 * sigma) << measured << " against " << through;
  EXPECT_GT(std::abs(measured - shake["predicted_eq3_g"].get<double>()), 5 * sigma);  // the quasi-static one is off
  EXPECT_NE(text.str().find("eq. (3) through the loop"), std::string::npos) << text.str();
}

TEST(CliMeasure, ReproducesShakeFromItsOwnRecordAndRejectsBadSeries) {
  TempDir d;
  // A noisy sampled run; its record (rest for t < 0, vibration from 0) measured again.
  const fs::path c = edited_case(d, "shake-sine-lab.toml", "min_measure_s = 2.0", "min_measure_s = 0.5");
  ShakeOptions so;
  so.case_path = c.string();
  so.json_path = (d.path / "shake.json").string();
  so.series_path = (d.path / "ts.csv").string();
  std::ostringstream text;
  run_shake(so, text);
  const json shake = json::parse(read_file(so.json_path));
  const double settle = shake["measurement"]["settle_s"].get<double>();
  const double measured_span = shake["measurement"]["periods"].get<double>() / 80.0;
  MeasureOptions mo;
  mo.series_path = so.series_path;
  mo.json_path = (d.path / "measure.json").string();
  mo.on_s = {settle, settle + measured_span};
  mo.baseline_s = {-measured_span, 0.0};
  mo.frequency_Hz = 80;
  mo.K1 = 1.25;
  run_measure(mo, text);
  const json m = json::parse(read_file(mo.json_path));
  // Same samples, same windows, same arithmetic up to summation order: 1e-12 g.
  EXPECT_NEAR(m["measured_g"].get<double>(), shake["measured_g"].get<double>(), 1e-12);
  EXPECT_NEAR(m["sigma_g"].get<double>(), shake["sigma_g"].get<double>(), 1e-12);

  // Bad series: a NaN sample, time going backwards, a record shorter than the interval.
  auto rejects = [&](const std::string& body, const std::string& expect) {
    const fs::path p = d.path / "bad.csv";
    std::ofstream(p) << "time_s,output\n" << body;
    MeasureOptions b = mo;
    b.series_path = p.string();
    b.json_path = (d.path / "bad.json").string();
    b.frequency_Hz = 0;
    b.on_s = {1.0, 2.0};
    b.baseline_s = {0.0, 1.0};
    try {
      run_measure(b, text);
      ADD_FAILURE() << "accepted: " << expect;
    } catch (const InputError& e) {
      EXPECT_TRUE(std::regex_search(std::string(e.what()), std::regex(expect))) << e.what();
    }
    EXPECT_FALSE(fs::exists(b.json_path));
  };
  std::string short_record;  // 0 .. 1.5 s: ends inside the vibration interval [1, 2)
  for (int k = 0; k < 300; ++k) short_record += std::to_string(k * 0.005) + ",1.0\n";
  rejects("0.0,1.0\n0.1,nan\n", R"(bad\.csv:3: a sample is not a finite number)");
  rejects("0.0,1.0\n0.2,1.0\n0.1,1.0\n", R"(bad\.csv:4: time does not increase)");
  rejects("0.0,1.0\n0.1,abc\n", R"(bad\.csv:3: not a number)");
  rejects(short_record, R"(too few samples.*shorter than the interval)");
  rejects("0.0,1.0\n0.1", R"(bad\.csv:3: 1 fields, the header has 2)");  // a truncated last line
  {
    const fs::path p = d.path / "noheader.csv";
    std::ofstream(p) << "0.0,1.0\n0.1,1.0\n";
    MeasureOptions b = mo;
    b.series_path = p.string();
    EXPECT_THROW(run_measure(b, text), InputError);  // numbers where the header should be
    b = mo;
    b.on_s = {-1.0, 1.0};  // overlaps the baseline
    EXPECT_THROW(run_measure(b, text), InputError);
  }
}

TEST(CliShake, WritesTheDocumentedJsonAndRejectsWhatTheShakerCannotDo) {
  TempDir d;
  ShakeOptions o;
  o.case_path = std::string(VRELAB_CASES_DIR) + "/shake-sine.toml";
  o.json_path = (d.path / "shake.json").string();
  std::ostringstream text;
  run_shake(o, text);
  const json j = json::parse(read_file(o.json_path));
  for (const char* key : {"measured_g", "sigma_g", "predicted_eq3_g", "case", "plant", "settings", "program", "seed"})
    EXPECT_TRUE(j.contains(key)) << key;
  // 5 Hz is 1 % of the loop: measured within 0.5 % of eq. (3) (the issue's low-frequency bound).
  EXPECT_NEAR(j["measured_g"].get<double>() / j["predicted_eq3_g"].get<double>(), 1.0, 5e-3);

  auto rejects = [&](const std::string& pattern, const std::string& with, const std::string& expect) {
    const fs::path c = edited_case(d, "shake-sine.toml", pattern, with);
    ShakeOptions b = o;
    b.case_path = c.string();
    b.json_path = (d.path / "bad.json").string();
    try {
      run_shake(b, text);
      ADD_FAILURE() << "accepted: " << with;
    } catch (const InputError& e) {
      EXPECT_TRUE(std::regex_search(std::string(e.what()), std::regex(expect))) << e.what();
    }
    EXPECT_FALSE(fs::exists(b.json_path));
  };
  rejects("\\[run\\]", "[shaker]\nstroke_limit_m = 0.001\n\n[run]", R"(\[shaker\] the profile is beyond the shaker: .*stroke)");
  rejects("\\[run\\]", "[readout]\nsample_rate_Hz = 8.0\n\n[run]", R"(Nyquist)");
  rejects("frequency_Hz = 5.0", "frequency_Hz = -5.0", R"(frequency_Hz)");
}

// Shaker imperfections act on tones: on a random run they are refused as the [shaker] table's
// (its line, its first imperfection key), not the [vibration] table's. The place is data.
TEST(CliShake, ImperfectionsOnARandomRunAreTheShakerTablesFault) {
  TempDir d;
  const fs::path c = edited_case(d, "shake-random-gevs.toml", "\\[run\\]",
                                 "[shaker]\ntransverse = {from_axis = \"IA\", to_axis = \"PA\", ratio = 0.05}\n\n[run]");
  const std::string text = read_file(c);
  long shaker_line = 1;  // the line of "[shaker]" in the text written, counted here
  for (std::size_t i = 0; i < text.find("[shaker]"); ++i) shaker_line += text[i] == '\n';
  ShakeOptions o;
  o.case_path = c.string();
  o.json_path = (d.path / "bad.json").string();
  std::ostringstream out;
  try {
    run_shake(o, out);
    ADD_FAILURE() << "accepted transverse motion on a random run";
  } catch (const InputError& e) {
    EXPECT_EQ(e.where().table, "shaker") << e.what();
    EXPECT_EQ(e.where().key, "transverse") << e.what();
    EXPECT_EQ(e.where().line, shaker_line) << e.what();
    EXPECT_EQ(e.reason(), "transverse motion, harmonics and rocking apply to sine and swept-sine runs");
  }
  EXPECT_FALSE(fs::exists(o.json_path));
}

TEST(CliSweep, ResumesAfterAnInterruptionWithIdenticalRowsAndRefusesAnotherCase) {
  TempDir d;
  const fs::path c = edited_case(d, "sweep-frequency.toml", "frequency_points = 40", "frequency_points = 6");
  SweepOptions o;
  o.case_path = c.string();
  o.out_path = (d.path / "sweep.csv").string();
  o.threads = 2;
  o.progress = false;
  std::ostringstream text;
  EXPECT_EQ(run_sweep(o, text), 0);
  const std::string full = read_file(o.out_path);
  // Interrupt: keep the header lines and the first 5 rows, the 6th cut mid-line.
  std::istringstream lines(full);
  std::string line, cut;
  int data_rows = 0;
  while (std::getline(lines, line)) {
    const bool header = line.empty() || line[0] == '#' || line.rfind("index,", 0) == 0;
    if (!header && data_rows == 5) {
      cut += line.substr(0, line.size() / 2);
      break;
    }
    cut += line + "\n";
    if (!header) ++data_rows;
  }
  std::ofstream(o.out_path) << cut;
  std::ostringstream resumed;
  EXPECT_EQ(run_sweep(o, resumed), 0);
  EXPECT_NE(resumed.str().find("5 already in"), std::string::npos) << resumed.str();
  // Same rows (the wall-time column aside) as the uninterrupted run.
  auto rows_without_wall = [](const std::string& text_) {
    std::istringstream in(text_);
    std::string l, out;
    while (std::getline(in, l))
      if (!l.empty() && l[0] != '#') out += l.substr(0, l.rfind(',')) + "\n";
    return out;
  };
  EXPECT_EQ(rows_without_wall(read_file(o.out_path)), rows_without_wall(full));
  // A malformed row: refused, naming the line.
  {
    std::string text_ = read_file(o.out_path);
    std::ofstream(o.out_path) << text_ << "99,1,5,1,0,0,0.5,0.8,0,1e-5,1e-9,1e-5,1,10,0.1\n";
    std::ostringstream out_;
    try {
      run_sweep(o, out_);
      ADD_FAILURE() << "accepted a row outside the grid";
    } catch (const InputError& e) {
      EXPECT_TRUE(std::regex_search(std::string(e.what()), std::regex(R"(sweep\.csv:\d+: not a row of this sweep)"))) << e.what();
    }
    std::ofstream(o.out_path) << text_;
  }
  // Another case on the same file: refused, the file untouched.
  const fs::path other = edited_case(d, "sweep-frequency.toml", "amplitudes_g = \\[5.0\\]", "amplitudes_g = [2.0]");
  SweepOptions b = o;
  b.case_path = other.string();
  EXPECT_THROW(run_sweep(b, text), InputError);
}

TEST(CliSweep, PredictsFromTheImpliedCoefficientsOfAPhysicalPlant) {
  TempDir d;
  const fs::path c = edited_case(d, "shake-physical.toml", "\\[run\\]",
                                 "[sweep]\nfrequencies_Hz = [5.0]\namplitudes_g = [5.0]\ndirections = [[1.0, 0.0, 0.0]]\n\n[run]");
  SweepOptions o;
  o.case_path = c.string();
  o.out_path = (d.path / "sweep.csv").string();
  o.progress = false;
  std::ostringstream text;
  EXPECT_EQ(run_sweep(o, text), 0);
  ShakeOptions so;
  so.case_path = c.string();
  so.json_path = (d.path / "shake.json").string();
  run_shake(so, text);
  const double predicted = json::parse(read_file(so.json_path))["predicted_eq3_g"].get<double>();
  // By hand (the case's SI values): the torquer's c2 = n2 * P g / k_t = 1.2e-2 * 5e-6 * 9.81 /
  // 0.0392 = 15.0 ug/g implies k2 = -c2, and eq. (3) of a 5 g peak along IA is k2 A^2 / 2 =
  // -187.7 ug. What else eq. (3) holds here: k3 = 2 c2^2 = 4.5e-10 /g^2 at a_IA = 0.5 g gives
  // 3 a_IA k3 A^2 / 2 = 0.008 ug; k4 = -5 c2^3 is 1e-14. Bound 0.05 ug: six times the k3 term.
  const double c2 = 1.2e-2 * 5e-6 * 9.81 / 0.0392;
  EXPECT_NEAR(predicted, -c2 * 25 / 2, 0.05e-6);
  const std::string csv = read_file(o.out_path);
  const std::string row = csv.substr(csv.rfind('\n', csv.size() - 2) + 1);
  std::vector<std::string> f;
  std::stringstream ss(row);
  for (std::string x; std::getline(ss, x, ',');) f.push_back(x);
  ASSERT_EQ(f.size(), 16u);  // with the checksum column
  EXPECT_NEAR(std::stod(f[11]), predicted, 1e-12);
}

TEST(CliIdentify, ReadingsFromTheOdePlantIdentifyAsModel1Does) {
  TempDir d;
  const fs::path c = edited_case(d, "ideal-static.toml", "repeats = 1", "repeats = 1\nsource = \"ode\"");
  const json ode = identify_json(c, d);
  EXPECT_EQ(ode["readings_source"], "ode");
  const json model = identify_json(fs::path(VRELAB_CASES_DIR) / "ideal-static.toml", d);
  // The settled ODE output equals model (1) to 1e-9 relative (floor 1e-12 g): the
  // least-squares coefficients differ by a few 1e-12 at most.
  for (auto& [name, v] : model["estimates"]["least_squares"].items())
    EXPECT_NEAR(ode["estimates"]["least_squares"][name].get<double>(), v.get<double>(), 1e-10 * std::max(1.0, std::abs(v.get<double>())))
        << name;
}

TEST(CliFrequency, WritesTheStudyAndItsOdePointsAgreeWithThePrediction) {
  TempDir d;
  // A small grid: 13 frequencies 10 Hz - 2 kHz, the ODE at 4 of them (both log-spaced between
  // the same ends: 12 / 3 steps, so every ODE frequency is a grid frequency), the shipped
  // instrument.
  const fs::path c = edited_case(d, "frequency.toml", "from_Hz = 1.0\nto_Hz = 5000.0\npoints = 80\node_points = 10",
                                 "from_Hz = 10.0\nto_Hz = 2000.0\npoints = 13\node_points = 4");
  FrequencyOptions o;
  o.case_path = c.string();
  o.out_dir = (d.path / "freq").string();
  std::ostringstream text;
  run_frequency(o, text);
  const json j = json::parse(read_file(d.path / "freq" / "summary.json"));
  ASSERT_GE(j["table"].size(), 20u);  // 9 terms at their places + 2 effects
  int input_rows = 0, loop_k2_rows = 0;
  for (const auto& row : j["table"]) {
    const std::string m = row["mechanism"];
    if (m.find("(input)") != std::string::npos) {
      EXPECT_TRUE(row["off_1_percent_Hz"].is_null()) << m;  // frequency-independent
      ++input_rows;
    }
    if (m == "k2 (loop)") {
      // |H_i|^2 departs from 1 by 1 % somewhere between 10 and 200 Hz (the loop crosses at 500 Hz).
      EXPECT_GT(row["off_1_percent_Hz"].get<double>(), 10.0);
      EXPECT_LT(row["off_1_percent_Hz"].get<double>(), 200.0);
      ++loop_k2_rows;
    }
  }
  // Both branches ran: the case's nonlinear terms have rows at the input, and k2 one in the loop.
  EXPECT_GE(input_rows, 1);
  EXPECT_EQ(loop_k2_rows, 1);
  // The issue's bound, recomputed here from the files rather than read from the summary: at
  // each ODE point, |ODE - frequency-dependent eq. (3)| / max(|prediction|, |eq. (3)|, 1e-12 g)
  // below 1 %. The files hold 10 (prediction) and 10 (ODE) significant digits: far below 1 %.
  const auto rows = [](const fs::path& p) {
    std::vector<std::vector<std::string>> out;
    std::stringstream in(read_file(p));
    for (std::string line; std::getline(in, line);) {
      if (line.empty() || line[0] == '#' || line.rfind("mechanism,", 0) == 0) continue;
      std::vector<std::string> f;
      std::stringstream ls(line);
      for (std::string x; std::getline(ls, x, ',');) f.push_back(x);
      out.push_back(f);
    }
    return out;
  };
  std::map<std::pair<std::string, double>, std::pair<double, double>> predicted;  // (mechanism, Hz) -> (prediction, eq. 3)
  for (const auto& f : rows(d.path / "freq" / "frequency.csv")) predicted[{f.at(0), std::stod(f.at(1))}] = {std::stod(f.at(2)), std::stod(f.at(3))};
  std::map<std::string, double> worst;
  int compared = 0;
  for (const auto& f : rows(d.path / "freq" / "ode_points.csv")) {
    const std::string m = f.at(0);
    const double hz = std::stod(f.at(1)), ode = std::stod(f.at(2));
    // The grid frequency printed with 8 digits: the same to 1e-7 relative.
    const auto p = predicted.lower_bound({m, hz * (1 - 1e-7)});
    ASSERT_TRUE(p != predicted.end() && p->first.first == m && std::abs(p->first.second / hz - 1) < 1e-7) << m << " at " << hz << " Hz";
    const auto [pred, eq3] = p->second;
    const double dev = std::abs(ode - pred) / std::max({std::abs(pred), std::abs(eq3), 1e-12});
    worst[m] = std::max(worst[m], dev);
    EXPECT_LT(dev, 0.01) << m << " at " << hz << " Hz: ODE " << ode << " g, predicted " << pred << " g";
    ++compared;
  }
  EXPECT_EQ(compared, 4 * static_cast<int>(j["table"].size()));  // 4 ODE points per mechanism
  // The summary's number is the one recomputed here (both from the same unrounded values up to
  // the files' digits).
  for (const auto& row : j["table"])
    EXPECT_NEAR(row["worst_ode_deviation"].get<double>(), worst[row["mechanism"].get<std::string>()], 1e-6) << row["mechanism"];
  EXPECT_TRUE(fs::exists(d.path / "freq" / "summary.md"));
}

// Issue 13 item 5: the work estimate. A 100 Hz sine for 1 s on a plant whose fastest pole is
// at 1 kHz: 1 s x 20 steps per period x 1 kHz = 2e4 steps (the plant, not the drive, sets the
// step); the same at 1e9 Hz (a Hz/kHz slip taken far) is 2e10 steps, refused naming the key
// and the flag. The figures are the estimate's definition, hence exact.
TEST(WorkEstimate, StepsFollowTheHighestFrequencyAndTheLimitNamesTheKey) {
  using namespace vrelab::rectification;
  PlantTimescales plant;
  plant.fastest_pole_Hz = 1000;
  plant.slowest_time_constant_s = 0.01;
  WorkRequest r;
  r.simulated_s = 1;
  r.drive_Hz = 100;
  r.drive_key = "[vibration] frequency_Hz";
  WorkEstimate e = estimate_work(r, plant);
  EXPECT_DOUBLE_EQ(e.steps, 2e4);
  EXPECT_NO_THROW(check_work(e));
  r.sample_rate_Hz = 1e5;  // sampled: one step per sample at least; 16 bytes each
  e = estimate_work(r, plant);
  EXPECT_DOUBLE_EQ(e.steps, 1e6);
  EXPECT_DOUBLE_EQ(e.bytes, 1.6e6);
  r.sample_rate_Hz = 0;
  r.drive_Hz = 1e9;
  e = estimate_work(r, plant);
  EXPECT_DOUBLE_EQ(e.steps, 2e10);
  try {
    check_work(e);
    FAIL() << "2e10 steps accepted";
  } catch (const std::invalid_argument& x) {
    EXPECT_NE(std::string(x.what()).find("from [vibration] frequency_Hz"), std::string::npos) << x.what();
    EXPECT_NE(std::string(x.what()).find("--no-work-limit"), std::string::npos) << x.what();
  }
}

}  // namespace test_cli
