#include "io/results_json.hpp"

#include "io/output.hpp"

namespace vrelab::io {

using nlohmann::json;
using plant::kNumCoefficients;
using validation::RunResult;

json shake_settings_json(const rectification::ShakeSettings& s) {
  return {{"solver", "CVODE BDF, dense direct linear solver"},
          {"relative_tolerance", s.relative_tolerance},
          {"settle_decay", s.settle_decay},
          {"blocks", s.blocks},
          {"min_measure_s", s.min_measure_s},
          {"readout",
           {{"sample_rate_Hz", s.readout.sample_rate_Hz},
            {"noise_sigma_g", s.readout.noise_sigma_g},
            {"quantisation_lsb_g", s.readout.quantisation_lsb_g}}}};
}

json sweep_grid_json(const rectification::SweepGrid& g) {
  json d = json::array(), o = json::array();
  for (const auto& v : g.directions) d.push_back(vec_json(v));
  for (const auto& v : g.orientations_g) o.push_back(vec_json(v));
  return {{"frequencies_Hz", g.frequencies_Hz}, {"amplitudes_g", g.amplitudes_g}, {"directions", d}, {"orientations_g", o}};
}

json frequency_study_settings_json(const rectification::FrequencyStudySettings& s) {
  return {{"amplitude_g", s.amplitude_g},
          {"direction", vec_json(s.direction)},
          {"frequencies_Hz", s.frequencies_Hz},
          {"ode_frequencies_Hz", s.ode_frequencies_Hz},
          {"pickoff_p2_per_rad", s.pickoff_p2_per_rad}};
}

json series_windows_json(const rectification::SeriesWindows& w) {
  return {{"baseline_s", {w.baseline_from_s, w.baseline_to_s}},
          {"on_s", {w.on_from_s, w.on_to_s}},
          {"frequency_Hz", w.frequency_Hz > 0 ? json(w.frequency_Hz) : json(nullptr)},
          {"K1", w.K1},
          {"blocks", w.blocks}};
}

namespace {
json named_json(const validation::NamedVector& v) { return {{"name", v.name}, {"vector", vec_json(v.v)}}; }
json named_list_json(const std::vector<validation::NamedVector>& v) {
  json j = json::array();
  for (const auto& x : v) j.push_back(named_json(x));
  return j;
}
}  // namespace

json reproduce_settings_json(const validation::ReproduceSettings& s) {
  json fixed = json::object();
  for (int i = 0; i < kNumCoefficients; ++i)
    if (s.fixed[i]) fixed[std::string(plant::coefficient_name(i))] = *s.fixed[i];
  return {{"static_test",
           {{"positions", s.positions.size()},
            {"initial_error_rad", vec_json(s.errors.initial_error_rad)},
            {"angle_sigma_rad", s.errors.angle_sigma_rad},
            {"noise_sigma_g", s.errors.noise_sigma_g},
            {"repeats", s.errors.repeats},
            {"fixed", fixed}}},
          {"seed", s.seed},
          {"shake", shake_settings_json(s.shake)},
          {"frequency_Hz", s.frequency_Hz},
          {"amplitudes_g", s.amplitudes_g},
          {"directions", named_list_json(s.directions)},
          {"orientations", named_list_json(s.orientations)},
          {"confirmation",
           {{"orientation", named_json(s.confirmation_orientation)},
            {"direction", named_json(s.confirmation_direction)},
            {"amplitude_g", s.confirmation_amplitude_g},
            {"record_s", s.confirmation_record_s}}},
          {"departure_frequencies_Hz", s.departure_frequencies_Hz},
          {"invisible_shift_per_g", s.invisible_shift_per_g},
          {"threads", s.threads}};
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
          {"amplitude_g", s.confirmation_amplitude_g},
          {"direction", vec_json(s.confirmation_direction.v.normalized())},
          {"direction_name", s.confirmation_direction.name},
          {"orientation_g", vec_json(s.confirmation_orientation.v)},
          {"orientation_name", s.confirmation_orientation.name},
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
          {"sigma_predicted_g", cf.predicted.sigma_g}};
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
  summary["settings"] = reproduce_settings_json(s);
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
