// `vrelab reproduce`: the prediction's uncertainty against Monte Carlo, the whole
// reproduction on a small case (agreement at low frequency, the departure in frequency, the
// invisible shift recovered), the report written as Markdown and HTML, and bad input.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <cmath>
#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <numbers>
#include <random>
#include <regex>
#include <sstream>

#include <Eigen/Cholesky>
#include <nlohmann/json.hpp>

#include "support/files.hpp"
#include "io/formats/case_file.hpp"
#include "app/commands.hpp"
#include "io/formats/report.hpp"
#include "io/formats/settings_json.hpp"
#include "io/formats/validation_json.hpp"
#include "rectification/prediction/eq3.hpp"
#include "rectification/prediction/gradient.hpp"
#include "support/constants.hpp"
#include "support/instrument.hpp"
#include "support/random_coefficients.hpp"
#include "validation/reproduce/reproduce.hpp"
#include "validation/identification/static_test.hpp"

namespace test_reproduce {

using namespace vrelab;
using namespace vrelab::plant;
using namespace vrelab::validation;
using vrelab::test::paper_like_coefficients;
namespace fs = std::filesystem;
using vrelab::test::read_file;
using vrelab::test::TempDir;
using nlohmann::json;
using vrelab::test::kArcsec;

namespace {

using Cov = std::array<CoefArray, kNumCoefficients>;

}  // namespace

TEST(PredictionUncertainty, GradientIsExactAndSigmaMatchesMonteCarloOverTheCoefficients) {
  std::mt19937_64 rng(2024);
  std::normal_distribution<double> n01;
  for (int trial = 0; trial < 6; ++trial) {
    const Coefficients c = test::random_coefficients(rng, 1e-6, 1e-4);
    const Vec3 a = Vec3(n01(rng), n01(rng), n01(rng)).normalized();
    const vibration::SineVibration v{Vec3(3 * n01(rng), 2 * n01(rng), n01(rng)), Vec3(0, 0.3, -0.5), 10};
    const auto f = [&](const Coefficients& k) { return rectification::sine_rectification(k, a, v).total_g(); };
    // A random covariance: M M^T with M scaled to each coefficient's size.
    Eigen::MatrixXd M = Eigen::MatrixXd::Zero(kNumCoefficients, kNumCoefficients);
    for (int i = 0; i < kNumCoefficients; ++i)
      for (int j = 0; j < kNumCoefficients; ++j) M(i, j) = 0.1 * std::abs(c[i]) * n01(rng) / 3;
    const Eigen::MatrixXd S = M * M.transpose();
    Cov cov{};
    for (int i = 0; i < kNumCoefficients; ++i)
      for (int j = 0; j < kNumCoefficients; ++j) cov[i][j] = S(i, j);
    // Eq. (3) is linear in the rectifying coefficients: f(c) = f(c0) + g . c exactly.
    const CoefArray g = rectification::prediction_gradient(f, c);
    Coefficients c0 = c;
    double lin = 0;
    for (int i : {k1_asym, k2, k3, k4, k_IP, k_IO, k_PO, k_PP, k_OO}) lin += g[i] * c[i], c0[i] = 0;
    EXPECT_NEAR(f(c0) + lin, f(c), 1e-12 * (std::abs(f(c)) + 1e-9));
    // Monte Carlo over the coefficients: the sample standard deviation of f against
    // sqrt(g^T S g). 20000 draws: relative sd of the estimate 1/sqrt(2N) = 0.5 %; bound 3 %.
    const Prediction p = predict_with_uncertainty(f, c, cov);
    const Eigen::MatrixXd L = S.llt().matrixL();
    double s1 = 0, s2 = 0;
    const int N = 20000;
    for (int k = 0; k < N; ++k) {
      Eigen::VectorXd z(kNumCoefficients);
      for (int i = 0; i < kNumCoefficients; ++i) z(i) = n01(rng);
      const Eigen::VectorXd d = L * z;
      Coefficients ck = c;
      for (int i = 0; i < kNumCoefficients; ++i) ck[i] += d(i);
      const double x = f(ck) - p.value_g;
      s1 += x, s2 += x * x;
    }
    const double sd = std::sqrt((s2 - s1 * s1 / N) / (N - 1));
    EXPECT_NEAR(sd / p.sigma_g, 1.0, 0.03) << "trial " << trial;
  }
}

TEST(PredictionUncertaintyCampaign, TheStaticTestsCovarianceCarriesEq3sScatterOverRepeatedTests) {
  // The chain the report uses: static test -> least squares -> eq. (3), its sigma from the
  // first-order covariance, against the scatter of eq. (3) over 1000 simulated tests (same
  // initial orientation error, fresh set-angle errors and noise). Relative sd of the sample
  // sd: 1/sqrt(2000) = 2.2 %; first-order truncation is ~(angle error)^2, negligible. Bound 10 %.
  const Coefficients truth = paper_like_coefficients();
  const std::vector<Position> positions = equally_spaced_positions(8);
  StaticTestErrors e;
  e.initial_error_rad = Vec3(3, -2, 4) * kArcsec;
  e.angle_sigma_rad = 0.5 * kArcsec;
  e.noise_sigma_g = 0.5e-6;
  e.repeats = 4;
  FixedSet fixed{};
  fixed[k1_asym] = truth[k1_asym], fixed[k_PP] = 0.0, fixed[k_OO] = 0.0;
  StaticTestSettings st;
  st.fixed = fixed;
  st.seed = 5;
  const StaticTestReport r = run_static_test(truth, positions, e, st);
  const MethodResult& ls = r.methods.back();
  ASSERT_EQ(ls.name, "least_squares");
  struct Condition {
    Vec3 a, w;
  };
  const std::vector<Condition> conditions = {{Vec3(1, 0, 0), Vec3(3, 0, 0)},
                                             {Vec3(0.6, 0.8, 0), Vec3(1, 1, 1) * (2 / std::sqrt(3.0))},
                                             {Vec3(0, 0.6, 0.8), Vec3(0.5, 0, 0)}};
  // The same weights as run_static_test uses (first-order variances at an unweighted fit).
  const LeastSquaresResult first = least_squares(positions, r.readings, {}, fixed);
  const ReadingBudget budget = reading_budget(first.estimate.value, positions, r.readings, e);
  std::vector<double> weights;
  for (double v : budget.variance) weights.push_back(1 / v);
  std::mt19937_64 rng(77);
  std::vector<std::vector<double>> values(conditions.size());
  for (int t = 0; t < 1000; ++t) {
    const std::vector<Reading> readings = simulate_static_test(truth, positions, e, rng);
    const Coefficients est = least_squares(positions, readings, weights, fixed).estimate.value;
    for (std::size_t k = 0; k < conditions.size(); ++k)
      values[k].push_back(rectification::sine_rectification(est, conditions[k].a, {conditions[k].w, Vec3::Zero(), 10}).total_g());
  }
  for (std::size_t k = 0; k < conditions.size(); ++k) {
    const auto f = [&](const Coefficients& c) {
      return rectification::sine_rectification(c, conditions[k].a, {conditions[k].w, Vec3::Zero(), 10}).total_g();
    };
    const Prediction p = predict_with_uncertainty(f, ls.estimate.value, ls.first_order.covariance);
    double m = 0, s2 = 0;
    for (double x : values[k]) m += x;
    m /= static_cast<double>(values[k].size());
    for (double x : values[k]) s2 += (x - m) * (x - m);
    const double sd = std::sqrt(s2 / static_cast<double>(values[k].size() - 1));
    EXPECT_NEAR(sd / p.sigma_g, 1.0, 0.10) << "condition " << k << ": MC sd " << sd << " first-order " << p.sigma_g;
    // The diagonal of the covariance is the sigma the identify table shows.
    for (int i = 0; i < kNumCoefficients; ++i)
      EXPECT_DOUBLE_EQ(std::sqrt(ls.first_order.covariance[i][i]), ls.first_order.sigma[i]);
  }
}

namespace {

// A small reproduction: 2 amplitudes x 2 directions x 2 orientations at 20 Hz, two
// departure frequencies, the invisible shift; 1 s records.
const char* kSmallCase = R"(g_m_per_s2 = 9.81
[instrument]
output_unit = "mA"
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
[dividing_head]
positions_per_series = 8
initial_error_arcsec = [3.0, -2.0, 4.0]
angle_sigma_arcsec = 0.5
noise_sigma_ug = 0.5
repeats = 4
source = "ode"
[identification]
fixed = { k1_asym = 2.0e-5, k_PP = 0.0, k_OO = 0.0 }
[readout]
sample_rate_Hz = 5000.0
noise_sigma_ug = 20.0
[shake]
min_measure_s = 1.0
blocks = 10
[reproduce]
frequency_Hz = 20.0
amplitudes_g = [1.0, 3.0]
directions = [[1.0, 0.0, 0.0], [1.0, 1.0, 1.0]]
direction_names = ["IA", "oblique <1,1,1>"]
orientations_g = [[1.0, 0.0, 0.0], [0.0, 0.6, 0.8]]
orientation_names = ["IA vertical", "IA horizontal"]
departure_frequencies_Hz = [20.0, 300.0]
invisible_shift_per_g = 4.0e-6
threads = 2
[reproduce.confirmation]
orientation = 1
direction = 1
amplitude_g = 2.0
record_s = 1.0
[run]
seed = 11
)";

}  // namespace

TEST(ReproduceCampaign, SmallCaseAgreesAtLowFrequencyFlagsFrequencyAndRecoversTheInvisibleShift) {
  TempDir d;
  const fs::path case_path = d.path / "small.toml";
  std::ofstream(case_path) << kSmallCase;
  app::ReproduceOptions o;
  o.case_path = case_path.string();
  o.out_dir = (d.path / "out").string();
  // Figures when a Python with matplotlib is here (CI installs it), else the report says why not.
  const bool matplotlib = std::system("/usr/bin/python3 -c 'import matplotlib' >/dev/null 2>&1") == 0 ||
                          std::system("python3 -c 'import matplotlib' >/dev/null 2>&1") == 0;
  std::ostringstream text;
  app::run_reproduce(o, text);
  const json s = json::parse(read_file(d.path / "out" / "summary.json"));

  // The record of how the result was made.
  EXPECT_EQ(s["command"], "reproduce");
  EXPECT_EQ(s["seed"], 11);
  EXPECT_TRUE(s["program"].contains("version"));
  EXPECT_TRUE(s["case"]["content"].contains("reproduce"));
  // The settings record holds only settings: read back, it writes the same record, and the
  // case's [shake] blocks (10 in kSmallCase) came through it.
  ReproduceSettings back;
  ASSERT_NO_THROW(io::settings_from_json(s["settings"], back)) << s["settings"].dump();
  EXPECT_EQ(io::settings_json(back), s["settings"]);
  EXPECT_EQ(back.shake.blocks, 10);
  EXPECT_EQ(s["solver"], "CVODE BDF, dense direct linear solver");

  // Where the paper's assumptions hold (20 Hz, in range, k_PP = k_OO = 0), measured and
  // predicted agree within the combined uncertainty. z is a residual over its standard
  // uncertainty (batch-mean sigma with 9 degrees of freedom and a Gaussian prediction
  // sigma): |z| > 4 has a chance below 0.3 % per run for a correct implementation; a
  // missing term or a wrong sigma gives tens.
  const auto& runs = s["amplitude_study"]["runs"];
  ASSERT_EQ(runs.size(), 8u);
  // z recomputed here from the JSON's measured and predicted errors and their sigmas (the
  // program's own z must be that number). The prediction's sigma is bounded from above as
  // well as below, so an inflated sigma cannot make |z| small: each run's prediction must be a
  // claim, sigma below half its value (31 % is the largest seen here, on the 3 g runs where
  // k2's share of the static test's uncertainty weighs A^2 / 2 = 4.5 g^2), so a sigma inflated
  // by 1.6 times or more fails.
  for (const auto& r : runs) {
    const double measured = r["measured_g"].get<double>(), predicted = r["predicted_g"].get<double>();
    const double sigma = r["sigma_measured_g"].get<double>(), sigma_predicted = r["sigma_predicted_g"].get<double>();
    const double z = (measured - predicted) / std::hypot(sigma, sigma_predicted);
    std::printf("  run: measured %.4g g +- %.3g, predicted %.4g g +- %.3g, z %.3f\n", measured, sigma, predicted, sigma_predicted, z);
    EXPECT_LT(std::abs(z), 4.0) << r.dump();
    EXPECT_NEAR(r["z"].get<double>(), z, 1e-9 * std::max(1.0, std::abs(z))) << r.dump();
    EXPECT_GT(sigma, 0.0);
    EXPECT_GT(sigma_predicted, 0.0);
    EXPECT_LT(sigma_predicted, std::abs(predicted) / 2) << r.dump();
  }
  // The confirmation run: the measured error within 4 combined sigma of eq. (3).
  const auto& cf = s["confirmation"];
  EXPECT_LT(std::abs(cf["measured_g"].get<double>() - cf["predicted_g"].get<double>()),
            4 * std::hypot(cf["sigma_g"].get<double>(), cf["sigma_predicted_g"].get<double>()));
  // The VRC beside each error, recomputed here from the same JSON: a sine of peak a_i = A u_i
  // along the axes has input rms^2 = sum_i a_i^2 / 2; VRC = 1e6 error / rms^2 in ug/g^2. A peak
  // taken for the rms (2x) or the VRC in g/g^2 (1e-6x) fails by far more than the 1e-9 bound.
  const auto sine_mean_square = [](double amplitude, const json& unit) {
    double ms = 0;
    for (const auto& u : unit) ms += std::pow(amplitude * u.get<double>(), 2) / 2;
    return ms;
  };
  const auto expect_vrc = [](const json& j, const char* key, double error_g, double ms) {
    const double v = 1e6 * error_g / ms;
    EXPECT_NEAR(j[key].get<double>(), v, 1e-9 * std::abs(v)) << key << " " << j.dump();
  };
  for (const auto& r : runs) {
    const double ms = sine_mean_square(r["amplitude_g"], r["direction_unit"]);
    EXPECT_NEAR(r["input_rms_g"].get<double>(), std::sqrt(ms), 1e-12 * std::sqrt(ms));
    expect_vrc(r, "measured_vrc_ug_per_g2", r["measured_g"], ms);
    expect_vrc(r, "predicted_vrc_ug_per_g2", r["predicted_g"], ms);
    expect_vrc(r, "at_frequency_vrc_ug_per_g2", r["at_frequency_g"], ms);
  }
  {
    const double ms = sine_mean_square(cf["amplitude_g"], cf["direction"]);
    EXPECT_NEAR(cf["input_rms_g"].get<double>(), std::sqrt(ms), 1e-12 * std::sqrt(ms));
    expect_vrc(cf, "measured_vrc_ug_per_g2", cf["measured_g"], ms);
    expect_vrc(cf, "predicted_vrc_ug_per_g2", cf["predicted_g"], ms);
  }
  // Its record: the rest at t < 0 as long as the measuring interval, then the vibration.
  const std::string rec = read_file(d.path / "out" / "confirmation.csv");
  EXPECT_NE(rec.find("t_s,output,deviation_g,integral_g_s,integral_without_oscillation_g_s"), std::string::npos);
  // The paper's integral: its slope fitted with the vibration's swing estimates the same
  // error as the whole-period mean of the same record (5 sigma: the two estimators weigh
  // the noise differently, and the integral's noise is a random walk).
  EXPECT_NEAR(cf["integral_slope_g"].get<double>(), cf["measured_g"].get<double>(), 5 * cf["sigma_g"].get<double>());

  // The departure in frequency: a loop-placed k2 sees the rebalance current, whose
  // amplitude peaks near 300 Hz for this loop (docs/frequency.md), so the measured error
  // there is well above its 20 Hz value (1.87x in the shipped case; bound 1.5x). The change
  // from 20 Hz predicted by the frequency-dependent eq. (3) agrees with the measured change
  // within 4 combined sigma (identified coefficients, their sigma included), and within 4
  // measurement sigma with the true coefficients.
  const auto& fd = s["frequency_departure"];
  EXPECT_EQ(fd["reference_Hz"], 20.0);
  ASSERT_EQ(fd["departs_by_3_sigma_at_Hz"].size(), 1u);
  EXPECT_EQ(fd["departs_by_3_sigma_at_Hz"][0], 300.0);
  const auto& fr = fd["runs"];
  ASSERT_EQ(fr.size(), 2u);
  EXPECT_GT(fr[1]["measured_g"].get<double>() / fr[0]["measured_g"].get<double>(), 1.5);
  EXPECT_LT(fd["max_abs_z_change"].get<double>(), 4.0);
  EXPECT_LT(fd["max_abs_z_change_true_coefficients"].get<double>(), 4.0);

  // The invisible shift: the static outputs agree to the solver's precision, the residuals
  // give c back (GLS): within 4 sigma, and sigma small enough for the test to mean something.
  const auto& inv = s["invisible"];
  EXPECT_LT(inv["max_static_difference_g"].get<double>(), 1e-12);
  const double c = inv["c_per_g"], c_fit = inv["c_fit_per_g"], c_sigma = inv["c_fit_sigma_per_g"];
  EXPECT_LT(c_sigma, 0.05 * c);
  EXPECT_NEAR(c_fit, c, 4 * c_sigma);

  // The report: both renderings, every section, the case's names escaped in HTML.
  const std::string md = read_file(d.path / "out" / "report.md"), html = read_file(d.path / "out" / "report.html");
  for (const char* h : {"## 1. The static test", "## 2. The confirmation plot", "## 3. Measured vibration error",
                        "## 4. Where eq. (3) stops holding", "## 5. What no static test can see"})
    EXPECT_NE(md.find(h), std::string::npos) << h;
  EXPECT_NE(md.find("oblique <1,1,1>"), std::string::npos);
  EXPECT_NE(html.find("oblique &lt;1,1,1&gt;"), std::string::npos);
  EXPECT_EQ(html.find("oblique <1,1,1>"), std::string::npos);
  for (const char* f : {"static.csv", "confirmation.csv", "confirmation.json", "amplitude.csv", "amplitude_curves.csv",
                        "frequency.csv", "frequency_curves.csv", "invisible.csv"})
    EXPECT_TRUE(fs::exists(d.path / "out" / f)) << f;
  for (const char* f : {"fig1_static", "fig2_confirmation", "fig3_amplitude", "fig4_residuals", "fig5_frequency",
                        "fig6_invisible"}) {
    if (matplotlib) {
      EXPECT_TRUE(fs::exists(d.path / "out" / (std::string(f) + ".png"))) << f;
      EXPECT_TRUE(fs::exists(d.path / "out" / (std::string(f) + ".svg"))) << f;
      EXPECT_NE(md.find(std::string("](") + f + ".png)"), std::string::npos) << f;
    } else {
      EXPECT_NE(md.find(std::string("Figure ") + f + " not drawn"), std::string::npos) << f;
    }
  }
}

TEST(Reproduce, BadReproduceTableIsNamedWithFileLineAndKey) {
  TempDir d;
  auto expect_rejects = [&](const std::string& pattern, const std::string& with, const std::string& expect) {
    const std::string edited = std::regex_replace(std::string(kSmallCase), std::regex(pattern), with);
    ASSERT_NE(edited, kSmallCase) << pattern;
    const fs::path p = d.path / "bad.toml";
    std::ofstream(p) << edited;
    app::ReproduceOptions o;
    o.case_path = p.string();
    o.out_dir = (d.path / "bad-out").string();
    o.plots = false;
    std::ostringstream text;
    try {
      app::run_reproduce(o, text);
      ADD_FAILURE() << "accepted: " << with;
    } catch (const io::InputError& e) {
      EXPECT_TRUE(std::regex_search(std::string(e.what()), std::regex(expect))) << e.what();
      EXPECT_NE(std::string(e.what()).find(p.string()), std::string::npos) << e.what();
    }
    EXPECT_FALSE(fs::exists(d.path / "bad-out" / "summary.json"));
  };
  expect_rejects("orientation = 1\n", "orientation = 3\n", R"(:\d+: \[reproduce.confirmation\] orientation = 3: must be at most 2, the entries of orientations_g)");
  expect_rejects(R"(\[0\.0, 0\.6, 0\.8\])", "[0.0, 0.6, 0.9]", R"(\[reproduce\] orientations_g\[1\] = \[0, 0\.6, 0\.9\]: .*\|a\| = 1 g.*got \|a\| = 1\.08167 g)");
  expect_rejects(R"(direction_names = \[[^\]]*\])", R"(direction_names = ["IA"])", R"(\[reproduce\] direction_names: expected an array of 2)");
  expect_rejects(R"(departure_frequencies_Hz = \[20\.0, 300\.0\])", "departure_frequencies_Hz = [20.0, 800.0]",
                 R"(departure_frequencies_Hz: 800 Hz needs at least 10 samples per period)");
  expect_rejects("amplitude_g = 2.0\n", "amplitude_g = -2.0\n", R"(\[reproduce.confirmation\] amplitude_g = -2: must be in \(0, 1000\] g)");
  expect_rejects("frequency_Hz = 20.0\n", "frequency_Hz = 600.0\n",
                 R"(\[reproduce\] frequency_Hz: 600 Hz needs at least 10 samples per period)");
}

TEST(Report, MarkdownAndHtmlCarryTheSameContentAndHtmlIsEscaped) {
  TempDir d;
  std::ofstream(d.path / "drawn.png", std::ios::binary) << "\x89PNG";  // embedded, base64: iVBORw==
  io::Report r("title <x>");
  r.heading("Section & more");
  r.paragraph("|a_IA| < |w_IA|");
  r.table({{"h1", "h|2"}, {"1", "<2>"}});
  r.list({"one", "two & three"});
  r.figure("fig", "caption", false, "no matplotlib");
  r.figure("drawn", "drawn caption", true, "");
  r.figure("lost", "lost caption", true, "");
  r.summary("Verdict: <none>", {"a & b"}, io::Report::Tone::bad);  // shown first wherever it is given
  const std::string md = r.markdown(), html = r.html(d.path.string());
  EXPECT_NE(md.find("# title <x>\n\n> **Verdict: <none>**\n>\n> - a & b\n"), std::string::npos) << md;
  EXPECT_NE(md.find("| h1 | h\\|2 |\n| --- | --- |\n| 1 | <2> |"), std::string::npos) << md;
  EXPECT_NE(md.find("- two & three"), std::string::npos);
  EXPECT_NE(md.find("not drawn: no matplotlib"), std::string::npos);
  EXPECT_NE(html.find("<h1>title &lt;x&gt;</h1>\n<section class=\"summary bad\">\n<p class=\"headline\">Verdict: &lt;none&gt;</p>\n"
                      "<ul>\n<li>a &amp; b</li>"),
            std::string::npos) << html;
  EXPECT_NE(html.find("<h2>Section &amp; more</h2>"), std::string::npos);
  EXPECT_NE(html.find("<p>|a_IA| &lt; |w_IA|</p>"), std::string::npos);
  EXPECT_NE(html.find("<tr><td class=\"n\">1</td><td>&lt;2&gt;</td></tr>"), std::string::npos) << html;  // numbers right-aligned
  EXPECT_EQ(html.find("<x>"), std::string::npos);
  // Figures embedded: the page names no other file.
  EXPECT_NE(html.find("<img src=\"data:image/png;base64,iVBORw==\" alt=\"drawn caption\">"), std::string::npos) << html;
  EXPECT_NE(html.find("Figure lost not drawn: its file is missing."), std::string::npos) << html;
  EXPECT_NE(html.find("Figure fig not drawn: no matplotlib."), std::string::npos) << html;
  EXPECT_EQ(html.find("href="), std::string::npos);
  EXPECT_EQ(html.find(".png\""), std::string::npos);
  EXPECT_NE(html.find("</html>"), std::string::npos);
}

TEST(ReproduceSettings, IsValidNamesTheKeyAndRefusesARankDeficientPositionSet) {
  TempDir d;
  const fs::path case_path = d.path / "small.toml";
  std::ofstream(case_path) << kSmallCase;
  const io::Case c = io::read_case(case_path.string());
  ASSERT_TRUE(c.reproduce.has_value());
  validation::ReproduceSettings s = *c.reproduce;
  std::string why;
  EXPECT_TRUE(s.IsValid(&why)) << why;
  // The case reader fills the whole configuration: static test, seed, measurement.
  EXPECT_EQ(s.seed, 11u);
  EXPECT_EQ(s.positions.size(), c.dividing_head->positions.size());
  EXPECT_EQ(s.shake.blocks, 10);
  EXPECT_EQ(s.confirmation.direction.name, "IA");

  validation::ReproduceSettings bad = s;
  bad.amplitudes_g.clear();
  EXPECT_FALSE(bad.IsValid(&why));
  EXPECT_NE(why.find("amplitudes_g"), std::string::npos) << why;
  bad = s;
  bad.confirmation.record_s = 0;
  EXPECT_FALSE(bad.IsValid(&why));
  EXPECT_NE(why.find("record_s"), std::string::npos) << why;
  // Nothing fixed: k1_asym, k_PP and k_OO cannot all be told from the others by a static test.
  bad = s;
  bad.fixed = {};
  EXPECT_FALSE(bad.IsValid(&why));
  EXPECT_NE(why.find("rank"), std::string::npos) << why;
  EXPECT_THROW(validation::reproduce(c.plant, bad), std::invalid_argument);
}

TEST(ReproduceAnalysis, AgreementCountsRunsWithinTwoAndThreeCombinedSigma) {
  // Residuals of 1, 2.5 and 4 combined sigma (sigma 3 + 4 -> combined 5): one within 2,
  // two within 3, the worst at |z| = 4; rms of (5, 12.5, 20) ug.
  std::vector<validation::RunResult> runs(3);
  const double z[] = {1.0, -2.5, 4.0};
  for (int i = 0; i < 3; ++i) {
    auto& r = runs[static_cast<std::size_t>(i)];
    r.sigma_measured_g = 3e-6;
    r.predicted = {100e-6, 4e-6};
    r.measured_g = r.predicted.value_g + z[i] * 5e-6;
    r.orientation = "up", r.direction = "IA", r.amplitude_g = i + 1, r.frequency_Hz = 20;
  }
  const validation::Agreement a = validation::agreement(runs);
  EXPECT_EQ(a.n, 3u);
  EXPECT_EQ(a.within_2, 1u);
  EXPECT_EQ(a.within_3, 2u);
  EXPECT_NEAR(a.max_abs_z, 4.0, 1e-12);
  EXPECT_EQ(a.worst, "3 g along IA at up (20 Hz)");
  EXPECT_NEAR(a.rms_residual_g, std::sqrt((25.0 + 156.25 + 400.0) / 3) * 1e-6, 1e-15);
  EXPECT_NEAR(a.max_abs_residual_g, 20e-6, 1e-15);
  EXPECT_NEAR(a.median_relative, 0.125, 1e-12);  // |residual|/|prediction|: 0.05, 0.125, 0.2
}

}  // namespace test_reproduce
