#include "io/services/diagnosis_json.hpp"
#include "io/services/results_json.hpp"

#include <cmath>
#include <numbers>

#include "io/formats/output.hpp"
#include "io/formats/settings_json.hpp"
#include "io/formats/validation_json.hpp"
#include "rectification/measurement/vrc.hpp"

namespace vrelab::io {

using nlohmann::json;
using plant::kNumCoefficients;
using validation::RunResult;

// The ODE solver every shaker run uses (recorded beside the settings, not among them: a settings
// record holds only fields, so that settings_from_json reads it back).
const char* const kSolverName = "CVODE BDF, dense direct linear solver";

json sweep_grid_json(const rectification::SweepGrid& g) {
  json d = json::array(), o = json::array();
  for (const auto& v : g.directions) d.push_back(vec_json(v));
  for (const auto& v : g.orientations_g) o.push_back(vec_json(v));
  return {{"frequencies_Hz", g.frequencies_Hz}, {"amplitudes_g", g.amplitudes_g}, {"directions", d}, {"orientations_g", o}};
}

json frequency_study_settings_json(const rectification::FrequencyStudySettings& s) { return settings_json(s); }

json series_windows_json(const rectification::SeriesWindows& w) {
  return {{"baseline_s", {w.baseline_from_s, w.baseline_to_s}},
          {"on_s", {w.on_from_s, w.on_to_s}},
          {"frequency_Hz", w.frequency_Hz > 0 ? json(w.frequency_Hz) : json(nullptr)},
          {"K1", w.K1},
          {"blocks", w.blocks}};
}

double vibration_input_rms_g(const VibrationSpec& v) {
  vibration::SineVibration sine = v.sine;
  if (v.swept) sine.amplitude_g = v.swept->amplitude_g;
  const double s2 = v.type == VibrationKind::random ? 0.0 : std::pow(rectification::input_rms_g(sine), 2);
  const double r2 = v.gaussian ? std::pow(rectification::input_rms_g(*v.gaussian), 2) : 0.0;
  return std::sqrt(s2 + r2);
}

json vrc_json(double error_g, double input_rms_g) {
  const double x = rectification::vrc_ug_per_g2(error_g, input_rms_g);
  return std::isfinite(x) ? json(x) : json(nullptr);
}

json vibration_json(const VibrationSpec& v) {
  json j = {{"type", rectification::to_string(v.type)}};
  if (v.type != VibrationKind::random) {
    j["amplitude_g"] = vec_json(v.sine.amplitude_g);
    j["phase_deg"] = vec_json(v.sine.phase_rad * 180 / std::numbers::pi);
    j["frequency_Hz"] = v.sine.frequency_Hz > 0 ? json(v.sine.frequency_Hz) : json(nullptr);
  }
  if (v.gaussian) {
    j["rms_g"] = vec_json(v.gaussian->rms_g);
    const Eigen::Matrix3d cov = v.gaussian->covariance_g2();
    json cj = json::array();
    for (int i = 0; i < 3; ++i) cj.push_back(vec_json(cov.row(i).transpose()));
    j["covariance_g2"] = cj;
  }
  if (v.psd || v.swept) j["duration_s"] = v.duration_s;
  return j;
}

namespace {

json array_json(const validation::CoefArray& a, const validation::CoefFlags& available) {
  plant::Coefficients k;
  k.v = a;
  return coefficients_json(k, &available);
}

void identify_methods_json(json& j, const plant::Coefficients& truth, const validation::StaticTestReport& r) {
  j["estimates"] = {{"paper_printed", nullptr}, {"paper_corrected", nullptr}, {"least_squares", nullptr}};
  j["errors"] = j["estimates"];
  j["sigma"] = j["estimates"];
  j["bias_first_order"] = j["estimates"];
  j["given"] = j["estimates"];
  for (const auto& m : r.methods) {
    j["estimates"][m.name] = coefficients_json(m.estimate.value, &m.estimate.available);
    validation::CoefArray err{}, sigma = m.first_order.sigma, bias = m.first_order.bias;
    json given = json::array();
    for (int i = 0; i < kNumCoefficients; ++i) {
      err[i] = m.estimate.value[i] - truth[i];
      if (m.estimate.assumed[i]) {
        sigma[i] = bias[i] = 0.0;
        given.push_back(std::string(plant::coefficient_name(i)));
      }
    }
    j["errors"][m.name] = array_json(err, m.estimate.available);
    j["sigma"][m.name] = array_json(sigma, m.estimate.available);
    j["bias_first_order"][m.name] = array_json(bias, m.estimate.available);
    j["given"][m.name] = given;
    if (m.monte_carlo) {
      j["monte_carlo"][m.name] = {{"trials", m.monte_carlo->n},
                                  {"std", array_json(m.monte_carlo->std, m.estimate.available)},
                                  {"mean_error", array_json(m.monte_carlo->mean_error, m.estimate.available)}};
    }
  }
}

json identifiability_json(const Case& c, const IdentifyStudy& s) {
  const auto& id = s.report.identifiability;
  json free = json::array(), identifiable = json::object();
  for (int i = 0; i < kNumCoefficients; ++i)
    if (id.free[i]) {
      free.push_back(std::string(plant::coefficient_name(i)));
      identifiable[std::string(plant::coefficient_name(i))] = static_cast<bool>(id.identifiable[i]);
    }
  json fixed = json::object();
  for (int i = 0; i < kNumCoefficients; ++i)
    if (c.fixed[i]) fixed[std::string(plant::coefficient_name(i))] = *c.fixed[i];
  return {{"parameters", id.parameters},
          {"rank", id.rank},
          {"condition_number", s.position_set.condition_number},
          {"condition_number_weighted", id.condition_number},
          {"free", free},
          {"fixed", fixed},
          {"identifiable", identifiable},
          {"confounded", id.confounded}};
}

}  // namespace

json identify_json(const Case& c, const IdentifyStudy& s) {
  const DividingHead& head = *c.dividing_head;
  const int mc = s.settings.monte_carlo_trials;
  json j = result_record("identify", c);
  j["settings"] = settings_json(s.settings);  // as described, and what the program fixes:
  j["settings"]["monte_carlo_seed"] = mc > 0 ? json(s.settings.seed + 1) : json(nullptr);
  j["settings"]["least_squares_weights"] = "1 / first-order variance of each reading";
  j["settings"]["rank_tolerance"] = 1e-10;
  json units = json::object();
  for (int i = 0; i < kNumCoefficients; ++i) units[std::string(plant::coefficient_name(i))] = unit_of(i, c);
  j["units"] = units;
  j["truth"] = coefficients_json(*c.coefficients);
  identify_methods_json(j, *c.coefficients, s.report);
  j["identifiability"] = identifiability_json(c, s);
  j["notes"] = s.report.notes;
  json readings = json::array();
  for (const auto& rd : s.report.readings) {
    const auto& p = head.positions[static_cast<std::size_t>(rd.position)];
    readings.push_back({{"position", rd.position},
                        {"series", p.series},
                        {"angle_deg", p.angle_rad * 180 / std::numbers::pi},
                        {"a_nominal_g", vec_json(p.nominal_g)},
                        {"output", rd.output}});
  }
  j["readings"] = readings;
  j["readings_unit"] = c.output_unit;
  j["readings_source"] = head.from_ode ? "ode" : "model";
  return j;
}

json predict_json(const Case& c, const PredictStudy& s) {
  const auto terms_json = [&](const rectification::Eq3Terms& terms) {
    json tj = json::object();
    for (int t = 0; t < rectification::kNumTerms; ++t) {
      if (t == rectification::t_clipping && !c.range_limit_g) continue;
      tj[std::string(rectification::term_name(t))] = terms.g[t];
    }
    return tj;
  };
  json j = result_record("predict", c);
  j["settings"] = {{"model", "eq3_corrected_quasi_static"},
                   {"frequency_dependent", s.at_frequency.has_value()},
                   {"range_limit_g", c.range_limit_g ? json(*c.range_limit_g) : json(nullptr)}};
  j["model"] = "eq3_corrected_quasi_static";
  j["orientation_g"] = vec_json(*c.orientation_g);
  j["vibration"] = vibration_json(*c.vibration);
  j["range_limit_g"] = c.range_limit_g ? json(*c.range_limit_g) : json(nullptr);
  j["total_g"] = s.terms.total_g();
  j["terms"] = terms_json(s.terms);
  j["omitted_by_paper_g"] = s.terms.omitted_by_paper_g();
  j["paper_printed_total_g"] = s.printed_g ? json(*s.printed_g) : json(nullptr);
  const double rms = vibration_input_rms_g(*c.vibration);
  j["input_rms_g"] = rms;
  j["vrc_ug_per_g2"] = vrc_json(s.terms.total_g(), rms);
  if (s.at_frequency) {
    const rectification::FrequencyPrediction& fp = *s.at_frequency;
    json ft = terms_json(fp.terms);
    ft["pickoff_nonlinearity"] = fp.pickoff_g;
    ft["pendulum_geometry"] = fp.pendulum_geometry_g;
    ft["pickoff_second_order"] = fp.second_order_g;
    const bool random = c.vibration->type == VibrationKind::random;
    j["frequency_dependent"] = {{"frequency_Hz", random ? json(nullptr) : json(c.vibration->sine.frequency_Hz)},
                                {"total_g", fp.total_g()},
                                {"vrc_ug_per_g2", vrc_json(fp.total_g(), rms)},
                                {"terms", ft},
                                {"current_amplitude_g", std::abs(fp.current_amplitude_g)},
                                {"angle_amplitude_rad", std::abs(fp.angle_amplitude_rad)},
                                {"second_order_share", fp.total_g() != 0 ? json(fp.second_order_g / fp.total_g()) : json(nullptr)},
                                {"second_order_left_out", fp.second_order_left_out},
                                {"second_order_error_g", fp.second_order_error_g},
                                {"plant", plant_json(c.plant, c.physical.has_value())}};
  }
  j["units"] = {{"total_g", "g"}, {"terms", "g"}, {"input_rms_g", "g"}, {"vrc_ug_per_g2", "ug/g^2"}};
  return j;
}

json shake_json(const Case& c, const ShakeStudy& s) {
  const rectification::ShakeResult& r = s.result;
  const vibration::ShakerDemand& demand = s.table.demand;
  json j = result_record("shake", c);
  j["measured_g"] = r.measured_g;
  j["sigma_g"] = r.sigma_g;
  j["predicted_eq3_g"] = s.predicted_g;
  j["predicted_frequency_dependent_g"] = s.frequency_dependent_g ? nlohmann::json(*s.frequency_dependent_g) : nlohmann::json();
  j["integral_slope_g"] = r.integral_slope_g;
  j["baseline_g"] = r.baseline_g;
  const double rms = vibration_input_rms_g(*c.vibration);  // the commanded motion's
  j["input_rms_g"] = rms;
  j["vrc_ug_per_g2"] = vrc_json(r.measured_g, rms);
  j["sigma_vrc_ug_per_g2"] = vrc_json(r.sigma_g, rms);
  j["predicted_eq3_vrc_ug_per_g2"] = vrc_json(s.predicted_g, rms);
  j["plant"] = plant_json(c.plant, c.physical.has_value());
  j["vibration"] = vibration_json(*c.vibration);
  j["vibration"]["description"] = s.table.motion->describe();
  j["shaker_demand"] = {{"acceleration_rms_g", vec_json(demand.acceleration_rms_g)},
                        {"acceleration_peak_g", vec_json(demand.acceleration_peak_g)},
                        {"velocity_peak_m_per_s", vec_json(demand.velocity_peak_m_per_s)},
                        {"displacement_peak_m", vec_json(demand.displacement_peak_m)},
                        {"stroke_peak_to_peak_m", demand.table_stroke_peak_to_peak_m()}};
  j["measurement"] = {{"method", r.method},
                      {"settle_s", r.settle_s},
                      {"slowest_time_constant_s", r.slowest_time_constant_s},
                      {"periods", r.periods},
                      {"samples", r.samples},
                      {"sample_rate_Hz", r.sample_rate_Hz}};
  j["settings"] = settings_json(c.shake);
  j["solver_stats"] = {{"solver", kSolverName},
                       {"steps", r.steps},
                       {"rhs_evaluations", r.rhs_evaluations},
                       {"wall_s", s.wall_s},
                       {"cpu_s", s.cpu_s},
                       {"path", r.path},
                       {"shooting_iterations", r.shooting_iterations},
                       {"simulated_s", r.simulated_s}};
  j["units"] = {{"measured_g", "g"}, {"sigma_g", "g"}, {"predicted_eq3_g", "g"}, {"predicted_frequency_dependent_g", "g"}, {"input_rms_g", "g"}, {"vrc_ug_per_g2", "ug/g^2"}};
  return j;
}

json measure_json(const MeasureStudy& s) {
  const rectification::SeriesWindows& w = s.windows;
  const rectification::SeriesResult& r = s.result;
  json j;
  j["program"] = program_record();
  j["command"] = "measure";
  j["settings"] = series_windows_json(w);
  j["series"] = {{"file", s.path}, {"column", s.column}, {"K1", w.K1}, {"K1_unit", s.K1_unit}, {"K1_source", s.K1_source}};
  j["windows"] = {{"baseline_s", {w.baseline_from_s, w.baseline_to_s}},
                  {"on_s", {w.on_from_s, r.on_to_used_s}},
                  {"frequency_Hz", w.frequency_Hz > 0 ? json(w.frequency_Hz) : json(nullptr)},
                  {"blocks", w.blocks}};
  j["measured_g"] = r.measured_g;
  j["sigma_g"] = r.sigma_g;
  j["integral_slope_g"] = r.integral_slope_g;
  j["baseline_g"] = r.baseline_g;
  // Given with --input-rms-g, else measured by the record's reference channels (ref_*_g or
  // input_*_g columns); else null (a record of the output alone does not know its input).
  const double rms = s.vrc_input_rms_g();
  j["input_rms_g"] = rms > 0 ? json(rms) : json(nullptr);
  j["input_rms_source"] = w.input_rms_g > 0 ? json("given") : rms > 0 ? json("reference_channels") : json(nullptr);
  j["vrc_ug_per_g2"] = vrc_json(r.measured_g, rms);
  j["sigma_vrc_ug_per_g2"] = vrc_json(r.sigma_g, rms);
  if (s.reference) {
    json axes = json::array();
    for (int i = 0; i < 3; ++i) axes.push_back(s.reference_axes[static_cast<std::size_t>(i)]);
    j["reference"] = {{"axes_present", axes}, {"rms_g", vec_json(s.reference_rms_g)}, {"input_rms_g", s.reference_input_rms_g}};
    // How the motion departs from one along its dominant axis (docs/data-format.md, "Reference channels").
    if (s.motion) j["reference"]["motion"] = to_json(*s.motion);
    else if (!s.motion_note.empty()) j["reference"]["motion_note"] = s.motion_note;
  }
  j["samples"] = {{"on", r.samples_on}, {"baseline", r.samples_baseline}};
  j["sample_rate_Hz"] = r.sample_rate_Hz;
  return j;
}

json frequency_json(const Case& c, const FrequencyStudy& s) {
  json table = json::array();
  for (const auto& m : s.curves)
    table.push_back({{"mechanism", m.name},
                     {"eq3_g", m.eq3_g},
                     {"off_1_percent_Hz", m.off_1_percent_Hz ? json(*m.off_1_percent_Hz) : json(nullptr)},
                     {"off_10_percent_Hz", m.off_10_percent_Hz ? json(*m.off_10_percent_Hz) : json(nullptr)},
                     {"worst_ode_deviation", m.worst_ode_deviation}});
  json j = result_record("frequency", c);
  j["plant"] = plant_json(c.plant, c.physical.has_value());
  j["settings"] = frequency_study_settings_json(s.settings);
  j["table"] = table;
  j["units"] = {{"eq3_g", "g"}, {"off_1_percent_Hz", "Hz"}};
  return j;
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
          // The run is a sine of peak amplitude_g along direction_unit: input rms amplitude_g / sqrt(2).
          {"input_rms_g", r.amplitude_g * r.direction_unit.norm() / std::numbers::sqrt2},
          {"measured_vrc_ug_per_g2", vrc_json(r.measured_g, r.amplitude_g * r.direction_unit.norm() / std::numbers::sqrt2)},
          {"predicted_vrc_ug_per_g2", vrc_json(r.predicted.value_g, r.amplitude_g * r.direction_unit.norm() / std::numbers::sqrt2)},
          {"at_frequency_vrc_ug_per_g2", vrc_json(r.at_frequency.value_g, r.amplitude_g * r.direction_unit.norm() / std::numbers::sqrt2)},
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

json agreement_json(const validation::Agreement& a) {
  return {{"runs", a.n},
          {"within_2_sigma", a.within_2},
          {"within_3_sigma", a.within_3},
          {"max_abs_z", a.max_abs_z},
          {"worst_run", a.worst},
          {"rms_residual_g", a.rms_residual_g},
          {"max_abs_residual_g", a.max_abs_residual_g},
          {"median_relative_residual", a.median_relative}};
}

json reproduce_confirmation_json(const Case& c, const validation::ReproduceSettings& s,
                                 const validation::ReproduceResult& res) {
  const validation::ConfirmationRecord& cf = res.confirmation;
  return {{"output_unit", c.output_unit},
          {"K1", res.truth[plant::K1]},
          {"frequency_Hz", s.frequency_Hz},
          {"amplitude_g", s.confirmation.amplitude_g},
          {"direction", vec_json(s.confirmation.direction.v.normalized())},
          {"direction_name", s.confirmation.direction.name},
          {"orientation_g", vec_json(s.confirmation.orientation.v)},
          {"orientation_name", s.confirmation.orientation.name},
          {"t_measure_start_s", cf.t_measure_start_s},
          {"t_end_s", cf.t_end_s},
          {"sample_rate_Hz", cf.shake.sample_rate_Hz},
          {"noise_sigma_g", s.shake.readout.noise_sigma_g},
          {"measured_g", cf.shake.measured_g},
          {"sigma_g", cf.shake.sigma_g},
          {"integral_slope_g", cf.integral_slope_g},
          {"integral_slope_straight_line_g", cf.shake.integral_slope_g},
          {"oscillation_amplitude_g_s", cf.oscillation_amplitude_g_s},
          {"predicted_g", cf.predicted.value_g},
          {"sigma_predicted_g", cf.predicted.sigma_g},
          // A sine of peak amplitude_g along the direction: input rms amplitude_g / sqrt(2).
          {"input_rms_g", s.confirmation.amplitude_g / std::numbers::sqrt2},
          {"measured_vrc_ug_per_g2", vrc_json(cf.shake.measured_g, s.confirmation.amplitude_g / std::numbers::sqrt2)},
          {"predicted_vrc_ug_per_g2", vrc_json(cf.predicted.value_g, s.confirmation.amplitude_g / std::numbers::sqrt2)}};
}

namespace {

json static_test_json(const validation::ReproduceResult& res) {
  json methods = json::array();
  for (const auto& m : res.static_test.methods) {
    json jm = {{"method", m.name}};
    jm["estimate"] = coefficients_json(m.estimate.value, &m.estimate.available);
    validation::CoefFlags has_sigma{};
    for (int i = 0; i < kNumCoefficients; ++i) has_sigma[i] = m.estimate.available[i] && !m.estimate.assumed[i];
    plant::Coefficients sk;
    sk.v = m.first_order.sigma;
    jm["sigma"] = coefficients_json(sk, &has_sigma);
    methods.push_back(jm);
  }
  json cov = json::array(), names = json::array();
  for (const auto& row : res.identified_uncertainty.covariance) cov.push_back(row);
  for (int i = 0; i < kNumCoefficients; ++i) names.push_back(std::string(plant::coefficient_name(i)));
  return {{"readings", res.static_test.readings.size()},
          {"methods", methods},
          {"identified_with", "least_squares"},
          {"identified_covariance", cov},
          {"covariance_order", names},
          {"truth", coefficients_json(res.truth)}};
}

json runs_json(const std::vector<RunResult>& runs) {
  json j = json::array();
  for (const auto& r : runs) j.push_back(run_json(r));
  return j;
}

}  // namespace

json reproduce_summary_json(const Case& c, const validation::ReproduceSettings& s, const validation::ReproduceResult& res,
                            double wall_s) {
  const validation::AmplitudeAnalysis& a = res.amplitude;
  json summary = result_record("reproduce", c);
  summary["settings"] = settings_json(s);  // validation_json.hpp: its positions and named vectors
  summary["solver"] = kSolverName;
  summary["plant"] = plant_json(c.plant, false);
  summary["wall_s"] = wall_s;
  summary["units"] = {{"errors", "g"}, {"frequency", "Hz"}, {"amplitude", "g peak"}, {"coefficients", "see docs/case-files.md"}};
  summary["static_test"] = static_test_json(res);
  summary["confirmation"] = reproduce_confirmation_json(c, s, res);
  summary["amplitude_study"] = {{"frequency_Hz", s.frequency_Hz},
                                {"agreement", agreement_json(a.all)},
                                {"agreement_nonzero_predictions", agreement_json(a.nonzero)},
                                {"prediction_sigma_exceeds_measurement_sigma", a.prediction_dominates},
                                {"printed_eq3_off_by_3_sigma", a.printed_off_runs},
                                {"printed_eq3_off_where", a.printed_off_where},
                                {"max_frequency_departure_g", a.frequency_departure_g},
                                {"max_printed_minus_corrected_g", a.printed_gap_g},
                                {"runs", runs_json(res.amplitude_runs)}};
  if (!res.frequency_runs.empty()) {
    const validation::DepartureAnalysis& d = res.departure;
    summary["frequency_departure"] = {{"reference_Hz", d.reference_Hz},
                                      {"departs_by_3_sigma_at_Hz", d.departs_Hz},
                                      {"max_abs_z_change", d.worst_z_change},
                                      {"max_abs_z_change_Hz", d.worst_z_change_Hz},
                                      {"max_abs_z_change_true_coefficients", d.worst_z_true},
                                      {"runs", runs_json(res.frequency_runs)}};
  }
  const validation::InvisibleResult& inv = res.invisible;
  if (inv.c_per_g != 0)
    summary["invisible"] = {{"c_per_g", inv.c_per_g},
                            {"c_fit_per_g", inv.c_fit_per_g},
                            {"c_fit_sigma_per_g", inv.c_fit_sigma_per_g},
                            {"max_static_difference_g", inv.max_static_difference_g},
                            {"runs", runs_json(inv.runs)}};
  return summary;
}

}  // namespace vrelab::io
