// app/reproduce.cpp -- `vrelab reproduce`: the paper's experiment, its report and its data.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <numbers>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "io/case_file.hpp"
#include "app/commands.hpp"
#include "io/output.hpp"
#include "io/report.hpp"
#include "rectification/prediction/eq3.hpp"
#include "validation/reproduce/reproduce.hpp"
#include "vrelab_version.hpp"

namespace vrelab::app {
using namespace vrelab::io;
namespace {

using nlohmann::json;
using plant::kNumCoefficients;
using validation::RunResult;
constexpr double kArcsec = std::numbers::pi / (180.0 * 3600.0);

// A CSV field: quoted when it holds a comma, a quote or a line break (RFC 4180).
std::string csv_field(const std::string& x) {
  if (x.find_first_of(",\"\n") == std::string::npos) return x;
  std::string o = "\"";
  for (char ch : x) o += ch == '"' ? std::string("\"\"") : std::string(1, ch);
  return o + "\"";
}

std::string ug(double g, int decimals = 2) { return fmt::format("{:.{}f}", g * 1e6, decimals); }
std::string sci(double x) { return fmt::format("{:.3e}", x); }
std::string vec_text(const Vec3& v) { return fmt::format("[{:.3g}, {:.3g}, {:.3g}]", v[0], v[1], v[2]); }

// Agreement statistics of a set of runs against the corrected eq. (3).
struct Agreement {
  std::size_t n = 0, within_2 = 0, within_3 = 0;
  double max_abs_z = 0, rms_residual_g = 0, max_abs_residual_g = 0;
  double median_relative = 0;  // |residual| / |predicted| over runs with |predicted| > 3 sigma_pred
  std::string worst;           // the run with max |z|
};

std::string run_label(const RunResult& r) {
  return fmt::format("{} g along {} at {} ({} Hz)", fmt::format("{:g}", r.amplitude_g), r.direction, r.orientation,
                     fmt::format("{:g}", r.frequency_Hz));
}

Agreement agreement(const std::vector<RunResult>& runs) {
  Agreement a;
  std::vector<double> rel;
  double ss = 0;
  for (const RunResult& r : runs) {
    const double z = std::abs(r.z());
    ++a.n;
    if (z <= 2) ++a.within_2;
    if (z <= 3) ++a.within_3;
    if (z >= a.max_abs_z) a.max_abs_z = z, a.worst = run_label(r);
    ss += r.residual_g() * r.residual_g();
    a.max_abs_residual_g = std::max(a.max_abs_residual_g, std::abs(r.residual_g()));
    if (std::abs(r.predicted.value_g) > 3 * r.predicted.sigma_g && r.predicted.value_g != 0)
      rel.push_back(std::abs(r.residual_g() / r.predicted.value_g));
  }
  a.rms_residual_g = runs.empty() ? 0 : std::sqrt(ss / static_cast<double>(runs.size()));
  if (!rel.empty()) {
    std::sort(rel.begin(), rel.end());
    a.median_relative = rel[rel.size() / 2];
  }
  return a;
}

json run_json(const RunResult& r) {
  return {{"orientation", r.orientation},
          {"orientation_g", vec_json(r.orientation_g)},
          {"direction", r.direction},
          {"direction_unit", vec_json(r.direction_unit)},
          {"frequency_Hz", r.frequency_Hz},
          {"amplitude_g", r.amplitude_g},
          {"measured_g", r.measured_g},
          {"sigma_measured_g", r.sigma_measured_g},
          {"predicted_g", r.predicted.value_g},
          {"sigma_predicted_g", r.predicted.sigma_g},
          {"printed_g", r.printed_g},
          {"at_frequency_g", r.at_frequency.value_g},
          {"true_eq3_g", r.true_eq3_g},
          {"true_at_frequency_g", r.true_at_frequency_g},
          {"residual_g", r.residual_g()},
          {"combined_sigma_g", r.combined_sigma_g()},
          {"z", r.z()}};
}

json agreement_json(const Agreement& a) {
  return {{"runs", a.n},
          {"within_2_sigma", a.within_2},
          {"within_3_sigma", a.within_3},
          {"max_abs_z", a.max_abs_z},
          {"worst_run", a.worst},
          {"rms_residual_g", a.rms_residual_g},
          {"max_abs_residual_g", a.max_abs_residual_g},
          {"median_relative_residual", a.median_relative}};
}

validation::ReproduceSettings settings_of(const Case& c, const ReproduceOptions& o) {
  const ReproduceSpec& r = *c.reproduce;
  validation::ReproduceSettings s;
  s.positions = c.dividing_head->positions;
  s.errors = c.dividing_head->errors;
  s.fixed = c.fixed;
  s.seed = c.seed;
  s.shake = c.shake;
  s.frequency_Hz = r.frequency_Hz;
  s.amplitudes_g = r.amplitudes_g;
  s.directions = r.directions;
  s.orientations = r.orientations;
  s.confirmation_orientation = r.orientations[r.confirmation_orientation];
  s.confirmation_direction = r.directions[r.confirmation_direction];
  s.confirmation_amplitude_g = r.confirmation_amplitude_g;
  s.confirmation_record_s = r.confirmation_record_s;
  s.departure_frequencies_Hz = r.departure_frequencies_Hz;
  s.invisible_shift_per_g = r.invisible_shift_per_g;
  s.threads = o.threads >= 0 ? o.threads : r.threads;
  return s;
}

}  // namespace

void run_reproduce(const ReproduceOptions& o, std::ostream& out) {
  Case c = read_case(o.case_path);
  require(c, c.coefficients.has_value(), "coefficients", "reproduce");
  require(c, c.dividing_head.has_value(), "dividing_head", "reproduce");
  require(c, c.reproduce.has_value(), "reproduce", "reproduce");
  if (c.physical) throw InputError(c.path + ": reproduce takes a plant built from coefficients ([plant] type = \"from_coefficients\")");
  const validation::Identifiability ident = validation::identifiability(c.dividing_head->positions, c.fixed);
  if (!ident.full_rank())
    throw InputError(fmt::format("{}: [dividing_head] with [identification] fixed: rank {} of {}; fix more coefficients "
                                 "(the paper fixes k1_asym, k_PP and k_OO)",
                                 c.path, ident.rank, ident.parameters));
  const validation::ReproduceSettings s = settings_of(c, o);
  const std::string& dir = o.out_dir;
  const auto start = std::chrono::steady_clock::now();
  out << fmt::format("vrelab {} ({}) reproduce {}  [seed {}] -> {}\n", kProgramVersion, kGitDescribe, c.path, c.seed, dir);
  const validation::ReproduceResult res =
      validation::reproduce(c.plant, s, [&out](const std::string& m) { out << "  " << m << "\n" << std::flush; });
  const double wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  const plant::Coefficients& truth = c.plant.coefficients;
  const double K1 = truth[plant::K1];
  const std::string comment = fmt::format("# vrelab {} ({}) reproduce {} seed {}", kProgramVersion, kGitDescribe, c.path, c.seed);

  // ---- 1. the static test
  std::string static_csv = comment + "; units: see the unit column\nmethod,coefficient,unit,truth,estimate,error,sigma,assumed\n";
  json static_json = json::array();
  for (const auto& m : res.static_test.methods) {
    json jm = {{"method", m.name}};
    for (int i = 0; i < kNumCoefficients; ++i) {
      const bool avail = m.estimate.available[i], assumed = m.estimate.assumed[i];
      static_csv += fmt::format("{},{},{},{:.10e},{},{},{},{}\n", m.name, plant::coefficient_name(i), unit_of(i, c), truth[i],
                                avail ? fmt::format("{:.10e}", m.estimate.value[i]) : "",
                                avail ? fmt::format("{:.10e}", m.estimate.value[i] - truth[i]) : "",
                                avail && !assumed ? fmt::format("{:.4e}", m.first_order.sigma[i]) : "",
                                assumed ? "true" : "false");
    }
    jm["estimate"] = coefficients_json(m.estimate.value, &m.estimate.available);
    validation::CoefArray sig = m.first_order.sigma;
    validation::CoefFlags has_sigma{};
    for (int i = 0; i < kNumCoefficients; ++i) has_sigma[i] = m.estimate.available[i] && !m.estimate.assumed[i];
    plant::Coefficients sk;
    sk.v = sig;
    jm["sigma"] = coefficients_json(sk, &has_sigma);
    static_json.push_back(jm);
  }

  // ---- 2. the confirmation run
  const validation::ConfirmationRecord& cf = res.confirmation;
  std::string conf_csv = comment + "; t in s, output in " + c.output_unit + ", deviation in g, integrals in g*s\n" +
                         "t_s,output,deviation_g,integral_g_s,integral_without_oscillation_g_s\n";
  for (std::size_t i = 0; i < cf.t_s.size(); ++i)
    conf_csv += fmt::format("{:.8g},{:.10g},{:.10e},{:.10e},{:.10e}\n", cf.t_s[i], cf.output[i],
                            cf.output[i] / cf.K1 - cf.rest_mean_g, cf.integral_g_s[i], cf.integral_without_oscillation_g_s[i]);
  const Vec3 conf_dir = s.confirmation_direction.v.normalized();
  const json conf_json = {{"output_unit", c.output_unit},
                          {"K1", K1},
                          {"frequency_Hz", s.frequency_Hz},
                          {"amplitude_g", s.confirmation_amplitude_g},
                          {"direction", vec_json(conf_dir)},
                          {"direction_name", s.confirmation_direction.name},
                          {"orientation_g", vec_json(s.confirmation_orientation.v)},
                          {"orientation_name", s.confirmation_orientation.name},
                          {"t_measure_start_s", cf.t_measure_start_s},
                          {"t_end_s", cf.t_end_s},
                          {"sample_rate_Hz", cf.shake.sample_rate_Hz},
                          {"noise_sigma_g", c.shake.readout.noise_sigma_g},
                          {"measured_g", cf.shake.measured_g},
                          {"sigma_g", cf.shake.sigma_g},
                          {"integral_slope_g", cf.integral_slope_g},
                          {"integral_slope_straight_line_g", cf.shake.integral_slope_g},
                          {"oscillation_amplitude_g_s", cf.oscillation_amplitude_g_s},
                          {"predicted_g", cf.predicted.value_g},
                          {"sigma_predicted_g", cf.predicted.sigma_g}};

  // ---- 3. the amplitude study, and its curves
  const std::string run_header =
      "orientation,direction,a_IA_g,a_PA_g,a_OA_g,d_IA,d_PA,d_OA,frequency_Hz,amplitude_g,measured_g,sigma_measured_g,"
      "predicted_g,sigma_predicted_g,printed_g,at_frequency_g,residual_g,combined_sigma_g,z\n";
  auto run_row = [](const RunResult& r) {
    return fmt::format("{},{},{:.8g},{:.8g},{:.8g},{:.8g},{:.8g},{:.8g},{:.8g},{:.8g},{:.8e},{:.4e},{:.8e},{:.4e},{:.8e},{:.8e},"
                       "{:.4e},{:.4e},{:.4f}\n",
                       csv_field(r.orientation), csv_field(r.direction), r.orientation_g[0], r.orientation_g[1], r.orientation_g[2],
                       r.direction_unit[0], r.direction_unit[1], r.direction_unit[2], r.frequency_Hz, r.amplitude_g,
                       r.measured_g, r.sigma_measured_g, r.predicted.value_g, r.predicted.sigma_g, r.printed_g,
                       r.at_frequency.value_g, r.residual_g(), r.combined_sigma_g(), r.z());
  };
  std::string amp_csv = comment + "; units: g (accelerations, errors), Hz\n" + run_header;
  for (const auto& r : res.amplitude_runs) amp_csv += run_row(r);
  std::string curves_csv = comment + "; units: g\norientation,direction,amplitude_g,predicted_g,sigma_predicted_g,printed_g\n";
  const double a_max = *std::max_element(s.amplitudes_g.begin(), s.amplitudes_g.end());
  constexpr int kCurvePoints = 61;
  for (const auto& ori : s.orientations)
    for (const auto& d : s.directions)
      for (int k = 0; k < kCurvePoints; ++k) {
        RunResult r;
        r.orientation_g = ori.v, r.direction_unit = d.v.normalized(), r.frequency_Hz = s.frequency_Hz;
        r.amplitude_g = a_max * k / (kCurvePoints - 1);
        const vibration::SineVibration v{r.amplitude_g * r.direction_unit, Vec3::Zero(), s.frequency_Hz};
        const auto qs = [&](const plant::Coefficients& k3) { return rectification::sine_rectification(k3, ori.v, v).total_g(); };
        const validation::Prediction p = validation::predict_with_uncertainty(qs, res.identified, res.identified_uncertainty.covariance);
        curves_csv += fmt::format("{},{},{:.6g},{:.8e},{:.4e},{:.8e}\n", csv_field(ori.name), csv_field(d.name), r.amplitude_g, p.value_g, p.sigma_g,
                                  rectification::sine_rectification_as_printed(res.identified, ori.v, v));
      }
  const Agreement amp = agreement(res.amplitude_runs);
  // Where the printed eq. (3) departs from the measurement.
  std::vector<std::string> printed_off;
  std::size_t printed_off_n = 0;
  double printed_worst_g = 0;
  for (const auto& r : res.amplitude_runs) {
    const double d = r.measured_g - r.printed_g;
    if (std::abs(d) > 3 * r.combined_sigma_g()) {
      ++printed_off_n;
      if (std::abs(d) > std::abs(printed_worst_g)) printed_worst_g = d;
      const std::string where = fmt::format("{} along {}", r.orientation, r.direction);
      if (std::find(printed_off.begin(), printed_off.end(), where) == printed_off.end()) printed_off.push_back(where);
    }
  }
  // How far the printed form is from the corrected one, and the combined sigma there.
  double printed_gap_g = 0, printed_gap_sigma_g = 0;
  std::string printed_gap_where;
  for (const auto& r : res.amplitude_runs)
    if (std::abs(r.printed_g - r.predicted.value_g) > printed_gap_g)
      printed_gap_g = std::abs(r.printed_g - r.predicted.value_g), printed_gap_where = run_label(r),
      printed_gap_sigma_g = r.combined_sigma_g();
  // Runs whose prediction is not zero (by symmetry, e.g. along PA or OA with k_PP = k_OO = 0),
  // and where the prediction's sigma exceeds the measurement's.
  std::vector<RunResult> nonzero_runs;
  std::size_t prediction_dominates = 0;
  for (const auto& r : res.amplitude_runs) {
    if (r.predicted.value_g != 0) nonzero_runs.push_back(r);
    if (r.predicted.sigma_g > r.sigma_measured_g) ++prediction_dominates;
  }
  const Agreement amp_nonzero = agreement(nonzero_runs);
  // How far the main frequency is from the quasi-static limit, for the runs' own terms.
  double freq_departure = 0;
  for (const auto& r : res.amplitude_runs)
    if (r.predicted.value_g != 0) freq_departure = std::max(freq_departure, std::abs(r.at_frequency.value_g - r.predicted.value_g));
  // The prediction's relative uncertainty at the largest amplitude along IA, per orientation.
  std::vector<std::string> growth;
  for (const auto& r : res.amplitude_runs)
    if (r.amplitude_g == a_max && r.direction == s.directions.front().name && r.predicted.value_g != 0)
      growth.push_back(fmt::format("{}: {} +- {} ug", r.orientation, ug(r.predicted.value_g, 1), ug(r.predicted.sigma_g, 1)));

  // ---- 4. the departure in frequency: the change from the reference run (the study's
  // frequency, or the lowest), measured (sigma: the two runs') against the change the
  // frequency-dependent eq. (3) predicts (with its own sigma: the coefficient errors do not
  // cancel in it, the terms scale differently with frequency).
  std::string freq_csv = comment + "; units: Hz, g; changes from the reference run at reference_Hz\n"
                                   "frequency_Hz,measured_g,sigma_measured_g,quasi_static_g,at_frequency_g,sigma_predicted_g,"
                                   "change_measured_g,sigma_change_measured_g,change_predicted_g,sigma_change_predicted_g,"
                                   "z_change,change_true_g\n";
  std::string freq_curves_csv = comment + "; units: Hz, g\nfrequency_Hz,quasi_static_g,at_frequency_g,sigma_predicted_g\n";
  std::vector<double> departs_Hz;  // where the measured change exceeds 3 sigma
  double reference_Hz = 0, worst_z_change = 0, worst_z_change_Hz = 0, worst_z_true = 0;
  const RunResult* freq_ref = nullptr;
  if (!res.frequency_runs.empty()) {
    freq_ref = &res.frequency_runs.front();  // sorted: the lowest
    for (const auto& r : res.frequency_runs)
      if (r.frequency_Hz == s.frequency_Hz) freq_ref = &r;
    const RunResult& ref = *freq_ref;
    reference_Hz = ref.frequency_Hz;
    for (const auto& r : res.frequency_runs) {
      const bool is_ref = &r == freq_ref;
      const double dm = r.measured_g - ref.measured_g;
      const double sdm = is_ref ? 0.0 : std::hypot(r.sigma_measured_g, ref.sigma_measured_g);
      const validation::Prediction dp =
          is_ref ? validation::Prediction{} : validation::predicted_change(r, ref, res.nominal, res.identified_uncertainty.covariance);
      const double dt = r.true_at_frequency_g - ref.true_at_frequency_g;
      const double sz = std::hypot(sdm, dp.sigma_g);
      const double z = sz > 0 ? (dm - dp.value_g) / sz : 0.0;
      freq_csv += fmt::format("{:.8g},{:.10e},{:.4e},{:.10e},{:.10e},{:.4e},{:.10e},{:.4e},{:.10e},{:.4e},{:.4f},{:.10e}\n",
                              r.frequency_Hz, r.measured_g, r.sigma_measured_g, r.predicted.value_g, r.at_frequency.value_g,
                              r.at_frequency.sigma_g, dm, sdm, dp.value_g, dp.sigma_g, z, dt);
      if (sdm > 0 && std::abs(dm) > 3 * sdm) departs_Hz.push_back(r.frequency_Hz);
      if (std::abs(z) >= worst_z_change) worst_z_change = std::abs(z), worst_z_change_Hz = r.frequency_Hz;
      if (sdm > 0) worst_z_true = std::max(worst_z_true, std::abs(dm - dt) / sdm);
    }
  }
  if (!res.frequency_runs.empty()) {
    const auto& f = s.departure_frequencies_Hz;
    const double lo = *std::min_element(f.begin(), f.end()) / 1.5, hi = *std::max_element(f.begin(), f.end()) * 1.5;
    for (int k = 0; k < 80; ++k) {
      RunResult r = res.frequency_runs.front();
      r.frequency_Hz = lo * std::pow(hi / lo, k / 79.0);
      validation::predict_run(r, res.nominal, res.identified_uncertainty.covariance);
      freq_curves_csv += fmt::format("{:.6g},{:.8e},{:.8e},{:.4e}\n", r.frequency_Hz, r.predicted.value_g,
                                     r.at_frequency.value_g, r.at_frequency.sigma_g);
    }
  }

  // ---- 5. the invisible shift
  const validation::InvisibleResult& inv = res.invisible;
  std::string inv_csv = comment + "; units: g\ndirection,amplitude_g,measured_g,sigma_measured_g,predicted_g,sigma_predicted_g,"
                                  "expected_residual_g,residual_g\n";
  for (const auto& r : inv.runs)
    inv_csv += fmt::format("{},{:.6g},{:.8e},{:.4e},{:.8e},{:.4e},{:.8e},{:.8e}\n", csv_field(r.direction), r.amplitude_g, r.measured_g,
                           r.sigma_measured_g, r.predicted.value_g, r.predicted.sigma_g,
                           -inv.c_per_g * r.amplitude_g * r.amplitude_g / 2, r.residual_g());

  // ---- summary.json
  const auto& ls = res.static_test.methods.back();
  json summary = result_record("reproduce", c);
  summary["plant"] = plant_json(c.plant, false);
  summary["wall_s"] = wall_s;
  summary["units"] = {{"errors", "g"}, {"frequency", "Hz"}, {"amplitude", "g peak"}, {"coefficients", "see docs/case-files.md"}};
  summary["static_test"] = {{"readings", res.static_test.readings.size()},
                            {"methods", static_json},
                            {"identified_with", "least_squares"},
                            {"identified_covariance", [&] {
                               json m = json::array();
                               for (const auto& row : res.identified_uncertainty.covariance) m.push_back(row);
                               return m;
                             }()},
                            {"covariance_order", [] {
                               json names = json::array();
                               for (int i = 0; i < kNumCoefficients; ++i) names.push_back(std::string(plant::coefficient_name(i)));
                               return names;
                             }()},
                            {"truth", coefficients_json(truth)}};
  summary["confirmation"] = conf_json;
  summary["amplitude_study"] = {{"frequency_Hz", s.frequency_Hz},
                                {"agreement", agreement_json(amp)},
                                {"agreement_nonzero_predictions", agreement_json(amp_nonzero)},
                                {"prediction_sigma_exceeds_measurement_sigma", prediction_dominates},
                                {"printed_eq3_off_by_3_sigma", printed_off_n},
                                {"printed_eq3_off_where", printed_off},
                                {"max_frequency_departure_g", freq_departure},
                                {"max_printed_minus_corrected_g", printed_gap_g},
                                {"runs", json::array()}};
  for (const auto& r : res.amplitude_runs) summary["amplitude_study"]["runs"].push_back(run_json(r));
  if (!res.frequency_runs.empty()) {
    summary["frequency_departure"] = {{"reference_Hz", reference_Hz},
                                      {"departs_by_3_sigma_at_Hz", departs_Hz},
                                      {"max_abs_z_change", worst_z_change},
                                      {"max_abs_z_change_Hz", worst_z_change_Hz},
                                      {"max_abs_z_change_true_coefficients", worst_z_true},
                                      {"runs", json::array()}};
    for (const auto& r : res.frequency_runs) summary["frequency_departure"]["runs"].push_back(run_json(r));
  }
  if (inv.c_per_g != 0) {
    summary["invisible"] = {{"c_per_g", inv.c_per_g},
                            {"c_fit_per_g", inv.c_fit_per_g},
                            {"c_fit_sigma_per_g", inv.c_fit_sigma_per_g},
                            {"max_static_difference_g", inv.max_static_difference_g},
                            {"runs", json::array()}};
    for (const auto& r : inv.runs) summary["invisible"]["runs"].push_back(run_json(r));
  }

  write_atomic(dir + "/static.csv", static_csv);
  write_atomic(dir + "/confirmation.csv", conf_csv);
  write_atomic(dir + "/confirmation.json", conf_json.dump(2) + "\n");
  write_atomic(dir + "/amplitude.csv", amp_csv);
  write_atomic(dir + "/amplitude_curves.csv", curves_csv);
  if (!res.frequency_runs.empty()) {
    write_atomic(dir + "/frequency.csv", freq_csv);
    write_atomic(dir + "/frequency_curves.csv", freq_curves_csv);
  }
  if (inv.c_per_g != 0) write_atomic(dir + "/invisible.csv", inv_csv);
  // A section not run leaves no file from an earlier run in the folder (nor its figure).
  std::vector<std::string> stale;
  if (res.frequency_runs.empty()) stale = {"frequency.csv", "frequency_curves.csv", "fig5_frequency.png", "fig5_frequency.svg"};
  if (inv.c_per_g == 0)
    for (const char* f : {"invisible.csv", "fig6_invisible.png", "fig6_invisible.svg"}) stale.push_back(f);
  for (const auto& f : stale) std::filesystem::remove(dir + "/" + f);
  write_atomic(dir + "/summary.json", summary.dump(2) + "\n");

  // ---- figures
  const std::string figures_missing = o.plots ? run_plot_script("reproduce.py", dir) : std::string("--no-plots was given");

  // ---- the report
  const auto& e = c.dividing_head->errors;
  Report rep("vrelab reproduce: " + c.path);
  rep.paragraph(fmt::format(
      "vrelab {} ({}), case {}, seed {}, {:.1f} s wall. The paper's experiment on the virtual instrument: a static test on "
      "the dividing head identifies the coefficients of model (1); shaker runs measure the vibration error; eq. (3) "
      "predicts it from the identified coefficients. Every number below is also in the CSV/JSON files beside this report "
      "(summary.json records the case, the seed, the solver settings and the program version).",
      kProgramVersion, kGitDescribe, c.path, c.seed, wall_s));

  rep.heading("1. The static test and the identified coefficients");
  rep.paragraph(fmt::format(
      "{} readings ({}, {} visit(s) each) of the ODE plant settled in each position; errors: initial orientation {} arcsec, "
      "set-angle sigma {:g} arcsec, reading noise sigma {:g} ug. Error = estimate - truth; sigma = first-order standard "
      "uncertainty (set-angle errors and noise); '(given)': held at the value the method assumes.",
      res.static_test.readings.size(), c.dividing_head->description, e.repeats,
      vec_text(e.initial_error_rad / kArcsec), e.angle_sigma_rad / kArcsec, e.noise_sigma_g * 1e6));
  {
    std::vector<std::vector<std::string>> rows;
    std::vector<std::string> head = {"coefficient", "unit", "truth"};
    for (const auto& m : res.static_test.methods) {
      head.push_back(m.name + " error");
      head.push_back("error/sigma");
    }
    rows.push_back(head);
    for (int i = 0; i < kNumCoefficients; ++i) {
      std::vector<std::string> row = {std::string(plant::coefficient_name(i)), unit_of(i, c), sci(truth[i])};
      for (const auto& m : res.static_test.methods) {
        if (!m.estimate.available[i]) {
          row.push_back("n/a");
          row.push_back("");
        } else if (m.estimate.assumed[i]) {
          row.push_back("(given)");
          row.push_back("");
        } else {
          const double err = m.estimate.value[i] - truth[i];
          row.push_back(sci(err));
          row.push_back(m.first_order.sigma[i] > 0 ? fmt::format("{:.2f}", err / m.first_order.sigma[i]) : "");
        }
      }
      rows.push_back(row);
    }
    rep.table(rows);
  }
  {
    std::vector<std::string> items;
    for (const auto& m : res.static_test.methods) {
      double worst = 0;
      std::string which;
      for (int i = 0; i < kNumCoefficients; ++i)
        if (m.estimate.available[i] && !m.estimate.assumed[i] && m.first_order.sigma[i] > 0) {
          const double z = std::abs(m.estimate.value[i] - truth[i]) / m.first_order.sigma[i];
          if (z > worst) worst = z, which = plant::coefficient_name(i);
        }
      // Errors far beyond sigma that the initial orientation error explains (its first-order bias).
      std::vector<std::string> biased;
      for (int i = 0; i < kNumCoefficients; ++i) {
        const double err = m.estimate.value[i] - truth[i], sg = m.first_order.sigma[i], b = m.first_order.bias[i];
        if (m.estimate.available[i] && !m.estimate.assumed[i] && sg > 0 && std::abs(err) > 3 * sg &&
            std::abs(err - b) < 3 * sg)
          biased.push_back(fmt::format("{} (error {}, bias {})", plant::coefficient_name(i), sci(err), sci(b)));
      }
      if (!biased.empty())
        items.push_back(fmt::format(
            "{}: beyond 3 sigma but explained by the initial orientation error (its first-order bias; a static test "
            "measures misalignment relative to the head, so the mounting error is part of it): {}",
            m.name, fmt::format("{}", fmt::join(biased, "; "))));
      items.push_back(fmt::format("{}: largest |error|/sigma {:.3g} ({}){}", m.name, worst, which,
                                  m.name == "paper_printed" && worst > 5
                                      ? "; the printed formulas carry errata (k2 summed over the wrong positions, k3 from "
                                        "the slope that ignores k3, k4 with a wrong factor; docs/identification.md), so "
                                        "their errors are not noise"
                                      : ""));
    }
    rep.list(items);
  }
  {
    std::string held;
    for (int i = 0; i < kNumCoefficients; ++i)
      if (c.fixed[i]) held += fmt::format("{}{} = {:g}", held.empty() ? "" : ", ", plant::coefficient_name(i), *c.fixed[i]);
    rep.paragraph(fmt::format(
        "The predictions below use the least-squares coefficients and their full covariance: eq. (3) is linear in the "
        "coefficients, so its standard uncertainty is sqrt(g^T Sigma g) with g its gradient (Sigma is in summary.json). "
        "Held at given values, with no uncertainty: {}. The static test cannot see a common shift of (k0, k2, k_PP, "
        "k_OO) (section 5).",
        held.empty() ? std::string("none") : held));
  }
  rep.figure("fig1_static", "Identification error over standard uncertainty, per coefficient and method (symlog axis).",
             figures_missing.empty(), figures_missing);

  rep.heading("2. The confirmation plot");
  const double conf_diff = cf.shake.measured_g - cf.predicted.value_g;
  const double conf_comb = std::hypot(cf.shake.sigma_g, cf.predicted.sigma_g);
  {
    // Every clause from the record itself.
    double u_lo = INFINITY, u_hi = -INFINITY;
    for (std::size_t i = 0; i < cf.t_s.size(); ++i)
      if (cf.t_s[i] >= cf.t_measure_start_s) u_lo = std::min(u_lo, cf.output[i]), u_hi = std::max(u_hi, cf.output[i]);
    const double swing = cf.t_s.empty() ? 0.0 : (u_hi - u_lo) / 2;
    const double noise_ug = c.shake.readout.noise_sigma_g * 1e6;
    const std::string acquisition =
        c.shake.readout.active()
            ? fmt::format("sampled at {:g} Hz with {}", cf.shake.sample_rate_Hz,
                          noise_ug > 0 ? fmt::format("{:g} ug rms noise per sample", noise_ug) : std::string("no noise"))
            : fmt::format("sampled at {:g} Hz, no readout noise", cf.shake.sample_rate_Hz);
    const bool slope_biased = std::abs(cf.integral_slope_g - cf.shake.integral_slope_g) > 3 * cf.shake.sigma_g;
    rep.paragraph(fmt::format(
        "{:g} g peak at {:g} Hz along {} ({}), static orientation {} = {} g, {}; {:.3g} s at rest (t < 0), then the "
        "vibration: {:.3g} s of settling, {:.3g} s measured. Under vibration the raw output swings +-{:.3g} {} about its "
        "mean; the vibration error is {} ug, {:.2g} {} ({:.2g} of the swing). The running integral of the output minus its "
        "mean at rest is flat at rest and, under vibration, a straight line plus the vibration's own swing of +-{:.3g} "
        "mg*s. Fitted over the measured interval with that swing (a line plus three harmonics), its slope is {} ug; a "
        "straight line alone gives {} ug{}. The whole-period mean of the output is {} +- {} ug, and eq. (3) from the "
        "identified coefficients predicts {} +- {} ug: a difference of {} ug ({:.2f} combined sigma{}). The figure shows "
        "the integral with the fitted swing taken off.",
        s.confirmation_amplitude_g, s.frequency_Hz, s.confirmation_direction.name, vec_text(conf_dir),
        s.confirmation_orientation.name, vec_text(s.confirmation_orientation.v), acquisition,
        cf.t_s.empty() ? 0.0 : -cf.t_s.front(), cf.t_measure_start_s, cf.t_end_s - cf.t_measure_start_s, swing,
        c.output_unit, ug(cf.shake.measured_g, 1), K1 * cf.shake.measured_g, c.output_unit,
        swing > 0 ? std::abs(K1 * cf.shake.measured_g) / swing : 0.0, cf.oscillation_amplitude_g_s * 1e3,
        ug(cf.integral_slope_g), ug(cf.shake.integral_slope_g),
        slope_biased ? ", biased by the swing (more than 3 sigma of the measurement away)" : "", ug(cf.shake.measured_g),
        ug(cf.shake.sigma_g), ug(cf.predicted.value_g), ug(cf.predicted.sigma_g), ug(conf_diff),
        conf_comb > 0 ? conf_diff / conf_comb : 0.0,
        cf.predicted.value_g != 0 ? fmt::format(", {:.2f} % of the prediction", 100 * conf_diff / cf.predicted.value_g)
                                  : std::string("")));
  }
  rep.figure("fig2_confirmation",
             "Top: the raw output. Bottom: its running integral, with the fitted slope and the slope eq. (3) predicts.",
             figures_missing.empty(), figures_missing);

  rep.heading("3. Measured vibration error against eq. (3), over amplitude");
  rep.paragraph(fmt::format(
      "{} shaker runs at {:g} Hz: amplitudes {} g peak x directions {} x static orientations {}. Agreement with the "
      "corrected eq. (3) from the identified coefficients: {} of {} runs within 2 combined sigma, {} within 3; largest "
      "|z| = {:.2f} ({}); rms residual {} ug, largest {} ug; median |residual|/|prediction| {:.2f} % over the runs whose "
      "prediction exceeds 3 of its sigma. {} runs have a non-zero prediction (the others are zero by symmetry: no "
      "rectifying term acts for that direction); of these, {} are within 2 combined sigma and {} within 3 (largest |z| "
      "{:.2f}). In {} of the {} runs the prediction's sigma exceeds the measurement's: the static test's uncertainty of "
      "k2 and k4 enters eq. (3) as w^2 and w^4; at {:g} g along {}: {}.",
      res.amplitude_runs.size(), s.frequency_Hz, fmt::format("{}", fmt::join(s.amplitudes_g, ", ")),
      [&] { std::string t; for (const auto& d : s.directions) t += (t.empty() ? "" : ", ") + d.name; return t; }(),
      [&] { std::string t; for (const auto& d : s.orientations) t += (t.empty() ? "" : ", ") + d.name; return t; }(),
      amp.within_2, amp.n, amp.within_3, amp.max_abs_z, amp.worst, ug(amp.rms_residual_g), ug(amp.max_abs_residual_g),
      100 * amp.median_relative, amp_nonzero.n, amp_nonzero.within_2, amp_nonzero.within_3, amp_nonzero.max_abs_z,
      prediction_dominates, res.amplitude_runs.size(), a_max, s.directions.front().name,
      growth.empty() ? std::string("no non-zero prediction") : fmt::format("{}", fmt::join(growth, "; "))));
  rep.paragraph(fmt::format(
      "Low frequency: at {:g} Hz the frequency-dependent eq. (3) (the plant's dynamics with the identified coefficients) "
      "differs from the quasi-static one by at most {} ug over these runs.",
      s.frequency_Hz, ug(freq_departure, 3)));
  const std::string printed_why = fmt::format(
      "The printed form lacks the factor a_IA before arcsin in the asymmetry term, which acts where |a_IA| < |w_IA|, and "
      "omits the k_PP and k_OO terms (here k_PP = {:.3g}, k_OO = {:.3g} 1/g as identified; section 5 shows what the "
      "static test cannot tell about them); docs/prediction.md.",
      res.identified[plant::k_PP], res.identified[plant::k_OO]);
  if (printed_off_n > 0)
    rep.paragraph(fmt::format(
        "Flagged: eq. (3) as printed departs from the measurement by more than 3 combined sigma in {} runs (largest {} "
        "ug), at: {}. {} The corrected form is the one drawn as the prediction.",
        printed_off_n, ug(printed_worst_g, 1), fmt::format("{}", fmt::join(printed_off, "; ")), printed_why));
  else
    rep.paragraph(fmt::format(
        "Eq. (3) as printed agrees with the measurement within 3 combined sigma in every run here: it differs from the "
        "corrected form by at most {} ug ({}), where the combined sigma is {} ug. {}",
        ug(printed_gap_g, 3), printed_gap_where, ug(printed_gap_sigma_g, 3), printed_why));
  rep.figure("fig3_amplitude",
             "Measured vibration error (points, +-1 sigma) and eq. (3) from the identified coefficients (curve, +-1 sigma "
             "band; dashed: as printed), per static orientation (rows) and vibration direction (columns).",
             figures_missing.empty(), figures_missing);
  rep.figure("fig4_residuals", "Residuals, measured - predicted, in combined sigma and in ug.", figures_missing.empty(),
             figures_missing);

  if (!res.frequency_runs.empty()) {
    rep.heading("4. Where eq. (3) stops holding: frequency");
    const auto& fr = res.frequency_runs;
    const RunResult& ref = *freq_ref;
    const RunResult& top = *std::max_element(fr.begin(), fr.end(), [](const RunResult& x, const RunResult& y) {
      return std::abs(x.measured_g) < std::abs(y.measured_g);
    });
    std::string departs;
    for (double f : departs_Hz) departs += fmt::format("{}{:g}", departs.empty() ? "" : ", ", f);
    rep.paragraph(fmt::format(
        "The confirmation condition ({:g} g along {} at {}) measured at {} frequencies, {:g} to {:g} Hz. Eq. (3) has no "
        "frequency in it. The measured error differs from its value at the reference {:g} Hz by more than 3 sigma of the "
        "two measurements at {}; the largest is {} ug at {:g} Hz against {} ug at {:g} Hz. The frequency-dependent "
        "eq. (3) (the identified coefficients behind the nominal dynamics: a term in the servo loop or at the output sees "
        "the rebalance current, whose amplitude follows the closed loop's response, docs/frequency.md) predicts the "
        "change from the reference run with its own uncertainty (the coefficient errors do not cancel: the terms scale "
        "differently with frequency); measured and predicted changes agree within {:.2f} combined sigma at worst ({:g} Hz). "
        "With the true coefficients the predicted change is within {:.2f} sigma of the measured one (measurement sigma only).",
        s.confirmation_amplitude_g, s.confirmation_direction.name, s.confirmation_orientation.name, fr.size(),
        fr.front().frequency_Hz, fr.back().frequency_Hz, reference_Hz,
        departs.empty() ? std::string("no frequency measured") : departs + " Hz", ug(top.measured_g), top.frequency_Hz,
        ug(ref.measured_g), reference_Hz, worst_z_change, worst_z_change_Hz, worst_z_true));
    std::vector<std::vector<std::string>> rows = {
        {"frequency (Hz)", "measured (ug)", "change measured (ug)", "change predicted (ug)", "eq. (3) quasi-static (ug)",
         "frequency-dependent (ug)"}};
    for (const auto& r : fr) {
      const bool is_ref = &r == freq_ref;
      const validation::Prediction dp =
          is_ref ? validation::Prediction{} : validation::predicted_change(r, ref, res.nominal, res.identified_uncertainty.covariance);
      rows.push_back({fmt::format("{:g}", r.frequency_Hz), ug(r.measured_g) + " +- " + ug(r.sigma_measured_g),
                      is_ref ? std::string("(reference)") : ug(r.measured_g - ref.measured_g),
                      is_ref ? std::string("") : ug(dp.value_g) + " +- " + ug(dp.sigma_g),
                      ug(r.predicted.value_g) + " +- " + ug(r.predicted.sigma_g),
                      ug(r.at_frequency.value_g) + " +- " + ug(r.at_frequency.sigma_g)});
    }
    rep.table(rows);
    rep.figure("fig5_frequency", "Measured vibration error against frequency with the quasi-static and the frequency-dependent eq. (3).",
               figures_missing.empty(), figures_missing);
  }
  if (inv.c_per_g != 0) {
    rep.heading("5. What no static test can see: k_PP and k_OO");
    rep.paragraph(fmt::format(
        "A second instrument whose (k0, k2, k_PP, k_OO) differ from the first by c (1, -1, -1, -1), c = {} 1/g, reads the "
        "same in every static position (largest difference of the settled outputs over the test's positions: {:.2g} ug), "
        "so the static test identifies the same coefficients and eq. (3) predicts the same. Shaken along IA, PA and OA, "
        "it measures -c |w|^2 / 2 away from that prediction in every direction: the k_PP w_PA^2/2 and k_OO w_OA^2/2 terms "
        "the printed eq. (3) omits carry the part of the quadratic coefficients no 1 g test can separate from the bias. "
        "Fitted from the residuals (generalised least squares with the prediction's covariance): c = {} +- {} 1/g. A "
        "shaker run along PA or OA measures it; the paper's assumption k_PP = k_OO = 0 is an assumption, not a result.",
        sci(inv.c_per_g), inv.max_static_difference_g * 1e6, sci(inv.c_fit_per_g), sci(inv.c_fit_sigma_per_g)));
    rep.figure("fig6_invisible", "The second instrument: residual against amplitude per direction, and -c w^2/2.",
               figures_missing.empty(), figures_missing);
  }
  rep.heading("Files");
  rep.list({"static.csv: the identification per method", "confirmation.csv, confirmation.json: the record and its numbers",
            "amplitude.csv, amplitude_curves.csv: the runs and the predicted curves",
            "frequency.csv, frequency_curves.csv: the frequency departure (when run)",
            "invisible.csv: the second instrument (when run)",
            "summary.json: every number above, with the case, seed, plant, solver settings and program version"});
  write_atomic(dir + "/report.md", rep.markdown());
  write_atomic(dir + "/report.html", rep.html());

  // ---- console summary
  out << fmt::format("Static test: {} readings; least-squares k2 = {} (truth {}), sigma {}\n", res.static_test.readings.size(),
                     sci(ls.estimate.value[plant::k2]), sci(truth[plant::k2]), sci(ls.first_order.sigma[plant::k2]));
  out << fmt::format("Confirmation: measured {} +- {} ug, integral slope {} ug, eq. (3) {} +- {} ug ({:.2f} sigma)\n",
                     ug(cf.shake.measured_g), ug(cf.shake.sigma_g), ug(cf.integral_slope_g), ug(cf.predicted.value_g),
                     ug(cf.predicted.sigma_g), conf_diff / conf_comb);
  out << fmt::format("Amplitude study: {}/{} runs within 2 sigma, {}/{} within 3, max |z| {:.2f}, rms residual {} ug\n",
                     amp.within_2, amp.n, amp.within_3, amp.n, amp.max_abs_z, ug(amp.rms_residual_g));
  if (!res.frequency_runs.empty())
    out << fmt::format("Frequency: the measured error departs from its {:g} Hz value by > 3 sigma at {} of {} frequencies; "
                       "the frequency-dependent eq. (3) predicts the change within {:.2f} sigma\n",
                       reference_Hz, departs_Hz.size(), res.frequency_runs.size(), worst_z_change);
  if (inv.c_per_g != 0)
    out << fmt::format("Invisible shift: c = {}, fitted {} +- {} 1/g\n", sci(inv.c_per_g), sci(inv.c_fit_per_g),
                       sci(inv.c_fit_sigma_per_g));
  if (!figures_missing.empty()) out << "Figures skipped: " << figures_missing << "\n";
  out << fmt::format("Wrote {}/report.html, report.md and the data ({:.1f} s wall)\n", dir, wall_s);
}

}  // namespace vrelab::app
