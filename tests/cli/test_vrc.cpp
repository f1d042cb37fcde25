// The vibration rectification coefficient, VRC = error / (input rms)^2 in ug/g^2, in the JSON of
// predict, shake and measure, checked by hand: with k2 alone at the input the error is k2 times
// the IA variance, and the input rms is the rms of the motion's magnitude over the axes.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <regex>
#include <sstream>

#include <nlohmann/json.hpp>

#include "app/commands.hpp"
#include "support/files.hpp"

namespace test_vrc {

using namespace vrelab::app;
namespace fs = std::filesystem;
using nlohmann::json;
using vrelab::test::read_file;
using vrelab::test::TempDir;

namespace {

json predict(const TempDir& d, const std::string& vibration, bool frequency_dependent = false) {
  const fs::path c = d.path / "vrc.toml";
  std::ofstream(c) << "[coefficients]\nK1 = 1.25\nk0 = 0.0\nk1_asym = 0.0\nk2 = 2.0e-5\nk3 = 0.0\nk4 = 0.0\ndelta_OA = 0.0\n"
                      "delta_PA = 0.0\nk_IP = 0.0\nk_IO = 0.0\nk_PO = 0.0\nk_PP = 0.0\nk_OO = 0.0\n\n[orientation]\na_g = [1.0, 0.0, 0.0]\n\n[vibration]\n"
                   << vibration << "\n";
  PredictOptions o;
  o.case_path = c.string();
  o.json_path = (d.path / "predict.json").string();
  o.frequency_dependent = frequency_dependent;
  std::ostringstream text;
  run_predict(o, text);
  return json::parse(read_file(o.json_path));
}

}  // namespace

TEST(Vrc, PredictGivesErrorOverInputRmsSquaredInMicroGPerG2) {
  TempDir d;
  // Sine of peak [2, 1, 0] g: rms^2 = (4 + 1)/2 = 2.5 g^2; k2 w_IA^2/2 = 2e-5 * 2 = 40 ug; VRC 16.
  json j = predict(d, "type = \"sine\"\namplitude_g = [2.0, 1.0, 0.0]\nfrequency_Hz = 50.0");
  EXPECT_NEAR(j["input_rms_g"].get<double>(), std::sqrt(2.5), 1e-12);
  EXPECT_NEAR(j["vrc_ug_per_g2"].get<double>(), 16.0, 1e-9);
  // Random of rms [2, 1, 0] g: rms^2 = 5; k2 sigma_IA^2 = 80 ug; VRC 16.
  j = predict(d, "type = \"random\"\nrms_g = [2.0, 1.0, 0.0]\ncorrelation = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]]");
  EXPECT_NEAR(j["input_rms_g"].get<double>(), std::sqrt(5.0), 1e-12);
  EXPECT_NEAR(j["vrc_ug_per_g2"].get<double>(), 16.0, 1e-9);
  // Sine [2, 0, 0] on random [1, 0, 0]: rms^2 = 2 + 1 = 3; k2 (2 + 1) = 60 ug; VRC 20 = 1e6 k2.
  j = predict(d, "type = \"sine_on_random\"\namplitude_g = [2.0, 0.0, 0.0]\nfrequency_Hz = 50.0\nrms_g = [1.0, 0.0, 0.0]");
  EXPECT_NEAR(j["input_rms_g"].get<double>(), std::sqrt(3.0), 1e-12);
  EXPECT_NEAR(j["vrc_ug_per_g2"].get<double>(), 20.0, 1e-9);
  // Through the dynamics: a flat 1e-3 g^2/Hz from 1 to 10 Hz on IA (rms^2 = 9e-3 g^2), far
  // below the loop: VRC = 1e6 k2 within the loop's (f/f_c)^2 ~ 4e-4.
  j = predict(d, "type = \"random\"\npsd_IA = [[1.0, 1e-3], [10.0, 1e-3]]", true);
  EXPECT_NEAR(j["input_rms_g"].get<double>(), std::sqrt(9e-3), 1e-9);
  EXPECT_NEAR(j["vrc_ug_per_g2"].get<double>(), 20.0, 1e-6);
  EXPECT_NEAR(j["frequency_dependent"]["vrc_ug_per_g2"].get<double>(), 20.0, 20.0 * 1e-3);
}

TEST(Vrc, ShakeAndMeasureReportTheSameCoefficientAsTheirErrors) {
  TempDir d;
  ShakeOptions so;
  so.case_path = std::string(VRELAB_CASES_DIR) + "/shake-sine.toml";
  so.json_path = (d.path / "shake.json").string();
  std::ostringstream text;
  run_shake(so, text);
  const json s = json::parse(read_file(so.json_path));
  const double rms = s["input_rms_g"].get<double>();
  // By hand from the case: a sine of peak [3, 1, 0] g has rms^2 = (9 + 1) / 2 = 5 g^2.
  EXPECT_NEAR(rms, std::sqrt(5.0), 1e-12);
  EXPECT_NEAR(s["vrc_ug_per_g2"].get<double>(), 1e6 * s["measured_g"].get<double>() / (rms * rms), 1e-9);
  EXPECT_NEAR(s["predicted_eq3_vrc_ug_per_g2"].get<double>(), 1e6 * s["predicted_eq3_g"].get<double>() / (rms * rms), 1e-9);
  // measure: a hand-made record, output 1 g + 50 ug while vibrating; input rms 2 g -> 12.5 ug/g^2.
  const fs::path series = d.path / "series.csv";
  {
    std::ofstream f(series);
    f << "time_s,output_g\n";
    for (int k = -100; k < 100; ++k) f << k * 0.01 << "," << (k >= 0 ? 1.0 + 50e-6 : 1.0) << "\n";
  }
  MeasureOptions mo;
  mo.series_path = series.string();
  mo.json_path = (d.path / "measure.json").string();
  mo.on_s = {0.0, 1.0};
  mo.baseline_s = {-1.0, 0.0};
  mo.input_rms_g = 2.0;
  run_measure(mo, text);
  const json m = json::parse(read_file(mo.json_path));
  EXPECT_NEAR(m["measured_g"].get<double>(), 50e-6, 1e-12);
  EXPECT_NEAR(m["vrc_ug_per_g2"].get<double>(), 12.5, 1e-6);
  mo.input_rms_g = 0;  // not given: null
  run_measure(mo, text);
  EXPECT_TRUE(json::parse(read_file(mo.json_path))["vrc_ug_per_g2"].is_null());
}

// Reference channels: `vrelab shake --series` writes the table's motion (input_*_g); measure
// reads it over the vibration window and takes its rms for the VRC. The shipped lab case is an
// 80 Hz sine of peak amplitude_g: over whole periods sampled at 80 points a period the rms is
// the exact amplitude / sqrt(2) (the discrete mean of sin^2 over whole periods is 1/2), so the
// measured VRC equals shake's (same record, same error) to rounding.
TEST(Vrc, MeasureTakesTheInputRmsFromTheRecordsReferenceChannels) {
  TempDir d;
  const std::string text0 = read_file(fs::path(VRELAB_CASES_DIR) / "shake-sine-lab.toml");
  const fs::path c = d.path / "lab.toml";
  std::ofstream(c) << std::regex_replace(text0, std::regex("min_measure_s = 2.0"), "min_measure_s = 0.5");
  ShakeOptions so;
  so.case_path = c.string();
  so.json_path = (d.path / "shake.json").string();
  so.series_path = (d.path / "ts.csv").string();
  std::ostringstream text;
  run_shake(so, text);
  const json shake = json::parse(read_file(so.json_path));
  const double settle = shake["measurement"]["settle_s"].get<double>();
  const double span = shake["measurement"]["periods"].get<double>() / 80.0;
  MeasureOptions mo;
  mo.series_path = so.series_path;
  mo.json_path = (d.path / "measure.json").string();
  mo.on_s = {settle, settle + span};
  mo.baseline_s = {-span, 0.0};
  mo.frequency_Hz = 80;
  mo.K1 = 1.25;
  run_measure(mo, text);
  const json m = json::parse(read_file(mo.json_path));
  EXPECT_EQ(m["input_rms_source"], "reference_channels");
  // By hand from the case: peak [3, 1, 0] g, so rms = sqrt((9 + 1) / 2) = sqrt(5) g exactly
  // over whole periods; 1e-9 relative: the series file's 10 significant digits.
  EXPECT_NEAR(m["input_rms_g"].get<double>(), std::sqrt(5.0), 1e-9 * std::sqrt(5.0));
  EXPECT_NEAR(shake["input_rms_g"].get<double>(), std::sqrt(5.0), 1e-12 * std::sqrt(5.0));
  EXPECT_NEAR(m["vrc_ug_per_g2"].get<double>(), 1e6 * m["measured_g"].get<double>() / std::pow(m["input_rms_g"].get<double>(), 2), 1e-9);
}

}  // namespace test_vrc
