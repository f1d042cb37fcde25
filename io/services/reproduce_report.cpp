#include "io/services/reproduce_report.hpp"

#include <algorithm>
#include <cmath>
#include <filesystem>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "io/formats/output.hpp"
#include "io/services/internal.hpp"
#include "io/services/results_json.hpp"
#include "rectification/prediction/eq3.hpp"
#include "vrelab_version.hpp"

namespace vrelab::io {
namespace {

using plant::kNumCoefficients;
using validation::ReproduceResult;
using validation::ReproduceSettings;
using validation::RunResult;
using internal::kArcsec;

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

std::string comment_line(const Case& c) {
  return fmt::format("# vrelab {} ({}) reproduce {} seed {}", kProgramVersion, kGitDescribe, c.path, c.seed);
}

std::string static_csv(const Case& c, const ReproduceResult& res) {
  const plant::Coefficients& truth = res.truth;
  std::string csv = comment_line(c) + "; units: see the unit column\nmethod,coefficient,unit,truth,estimate,error,sigma,assumed\n";
  for (const auto& m : res.static_test.methods)
    for (int i = 0; i < kNumCoefficients; ++i) {
      const bool avail = m.estimate.available[i], assumed = m.estimate.assumed[i];
      csv += fmt::format("{},{},{},{:.10e},{},{},{},{}\n", m.name, plant::coefficient_name(i), unit_of(i, c), truth[i],
                         avail ? fmt::format("{:.10e}", m.estimate.value[i]) : "",
                         avail ? fmt::format("{:.10e}", m.estimate.value[i] - truth[i]) : "",
                         avail && !assumed ? fmt::format("{:.4e}", m.first_order.sigma[i]) : "",
                         assumed ? "true" : "false");
    }
  return csv;
}

std::string confirmation_csv(const Case& c, const ReproduceResult& res) {
  const validation::ConfirmationRecord& cf = res.confirmation;
  std::string csv = comment_line(c) + "; t in s, output in " + c.output_unit + ", deviation in g, integrals in g*s\n" +
                    "t_s,output,deviation_g,integral_g_s,integral_without_oscillation_g_s\n";
  for (std::size_t i = 0; i < cf.t_s.size(); ++i)
    csv += fmt::format("{:.8g},{:.10g},{:.10e},{:.10e},{:.10e}\n", cf.t_s[i], cf.output[i],
                       cf.output[i] / cf.K1 - cf.rest_mean_g, cf.integral_g_s[i], cf.integral_without_oscillation_g_s[i]);
  return csv;
}

std::string amplitude_csv(const Case& c, const ReproduceResult& res) {
  std::string csv = comment_line(c) + "; units: g (accelerations, errors), Hz\n" +
                    "orientation,direction,a_IA_g,a_PA_g,a_OA_g,d_IA,d_PA,d_OA,frequency_Hz,amplitude_g,measured_g,"
                    "sigma_measured_g,predicted_g,sigma_predicted_g,printed_g,at_frequency_g,residual_g,combined_sigma_g,z\n";
  for (const RunResult& r : res.amplitude_runs)
    csv += fmt::format("{},{},{:.8g},{:.8g},{:.8g},{:.8g},{:.8g},{:.8g},{:.8g},{:.8g},{:.8e},{:.4e},{:.8e},{:.4e},{:.8e},{:.8e},"
                       "{:.4e},{:.4e},{:.4f}\n",
                       csv_field(r.orientation), csv_field(r.direction), r.orientation_g[0], r.orientation_g[1], r.orientation_g[2],
                       r.direction_unit[0], r.direction_unit[1], r.direction_unit[2], r.frequency_Hz, r.amplitude_g,
                       r.measured_g, r.sigma_measured_g, r.predicted.value_g, r.predicted.sigma_g, r.printed_g,
                       r.at_frequency.value_g, r.residual_g(), r.combined_sigma_g(), r.z());
  return csv;
}

std::string amplitude_curves_csv(const Case& c, const ReproduceResult& res) {
  std::string csv = comment_line(c) + "; units: g\norientation,direction,amplitude_g,predicted_g,sigma_predicted_g,printed_g\n";
  for (const auto& p : res.amplitude_curves)
    csv += fmt::format("{},{},{:.6g},{:.8e},{:.4e},{:.8e}\n", csv_field(p.orientation), csv_field(p.direction), p.amplitude_g,
                       p.predicted.value_g, p.predicted.sigma_g, p.printed_g);
  return csv;
}

std::string frequency_csv(const Case& c, const ReproduceResult& res) {
  std::string csv = comment_line(c) + "; units: Hz, g; changes from the reference run at reference_Hz\n"
                                      "frequency_Hz,measured_g,sigma_measured_g,quasi_static_g,at_frequency_g,sigma_predicted_g,"
                                      "change_measured_g,sigma_change_measured_g,change_predicted_g,sigma_change_predicted_g,"
                                      "z_change,change_true_g\n";
  for (std::size_t i = 0; i < res.frequency_runs.size(); ++i) {
    const RunResult& r = res.frequency_runs[i];
    const validation::FrequencyChange& d = res.departure.changes[i];
    csv += fmt::format("{:.8g},{:.10e},{:.4e},{:.10e},{:.10e},{:.4e},{:.10e},{:.4e},{:.10e},{:.4e},{:.4f},{:.10e}\n",
                       r.frequency_Hz, r.measured_g, r.sigma_measured_g, r.predicted.value_g, r.at_frequency.value_g,
                       r.at_frequency.sigma_g, d.measured_g, d.sigma_measured_g, d.predicted.value_g, d.predicted.sigma_g,
                       d.z, d.true_g);
  }
  return csv;
}

std::string frequency_curves_csv(const Case& c, const ReproduceResult& res) {
  std::string csv = comment_line(c) + "; units: Hz, g\nfrequency_Hz,quasi_static_g,at_frequency_g,sigma_predicted_g\n";
  for (const RunResult& r : res.departure.curve)
    csv += fmt::format("{:.6g},{:.8e},{:.8e},{:.4e}\n", r.frequency_Hz, r.predicted.value_g, r.at_frequency.value_g,
                       r.at_frequency.sigma_g);
  return csv;
}

std::string invisible_csv(const Case& c, const ReproduceResult& res) {
  const validation::InvisibleResult& inv = res.invisible;
  std::string csv = comment_line(c) + "; units: g\ndirection,amplitude_g,measured_g,sigma_measured_g,predicted_g,"
                                      "sigma_predicted_g,expected_residual_g,residual_g\n";
  for (const auto& r : inv.runs)
    csv += fmt::format("{},{:.6g},{:.8e},{:.4e},{:.8e},{:.4e},{:.8e},{:.8e}\n", csv_field(r.direction), r.amplitude_g,
                       r.measured_g, r.sigma_measured_g, r.predicted.value_g, r.predicted.sigma_g,
                       -inv.c_per_g * r.amplitude_g * r.amplitude_g / 2, r.residual_g());
  return csv;
}

// ---- the report, a section each

void report_static_table(Report& rep, const Case& c, const ReproduceResult& res) {
  std::vector<std::vector<std::string>> rows;
  std::vector<std::string> head = {"coefficient", "unit", "truth"};
  for (const auto& m : res.static_test.methods) {
    head.push_back(m.name + " error");
    head.push_back("error/sigma");
  }
  rows.push_back(head);
  for (int i = 0; i < kNumCoefficients; ++i) {
    std::vector<std::string> row = {std::string(plant::coefficient_name(i)), unit_of(i, c), sci(res.truth[i])};
    for (const auto& m : res.static_test.methods) {
      if (!m.estimate.available[i]) {
        row.push_back("n/a");
        row.push_back("");
      } else if (m.estimate.assumed[i]) {
        row.push_back("(given)");
        row.push_back("");
      } else {
        const double err = m.estimate.value[i] - res.truth[i];
        row.push_back(sci(err));
        row.push_back(m.first_order.sigma[i] > 0 ? fmt::format("{:.2f}", err / m.first_order.sigma[i]) : "");
      }
    }
    rows.push_back(row);
  }
  rep.table(rows);
}

void report_static_notes(Report& rep, const ReproduceResult& res) {
  std::vector<std::string> items;
  for (const auto& m : res.static_test.methods) {
    double worst = 0;
    std::string which;
    for (int i = 0; i < kNumCoefficients; ++i)
      if (m.estimate.available[i] && !m.estimate.assumed[i] && m.first_order.sigma[i] > 0) {
        const double z = std::abs(m.estimate.value[i] - res.truth[i]) / m.first_order.sigma[i];
        if (z > worst) worst = z, which = plant::coefficient_name(i);
      }
    // Errors far beyond sigma that the initial orientation error explains (its first-order bias).
    std::vector<std::string> biased;
    for (int i = 0; i < kNumCoefficients; ++i) {
      const double err = m.estimate.value[i] - res.truth[i], sg = m.first_order.sigma[i], b = m.first_order.bias[i];
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

void report_static(Report& rep, const Case& c, const ReproduceSettings& s, const ReproduceResult& res,
                   const std::string& figures_missing) {
  const auto& e = s.errors;
  rep.heading("1. The static test and the identified coefficients");
  rep.paragraph(fmt::format(
      "{} readings ({}, {} visit(s) each) of the ODE plant settled in each position; errors: initial orientation {} arcsec, "
      "set-angle sigma {:g} arcsec, reading noise sigma {:g} ug. Error = estimate - truth; sigma = first-order standard "
      "uncertainty (set-angle errors and noise); '(given)': held at the value the method assumes.",
      res.static_test.readings.size(), c.dividing_head ? c.dividing_head->description : std::string(), e.repeats,
      vec_text(e.initial_error_rad / kArcsec), e.angle_sigma_rad / kArcsec, e.noise_sigma_g * 1e6));
  report_static_table(rep, c, res);
  report_static_notes(rep, res);
  std::string held;
  for (int i = 0; i < kNumCoefficients; ++i)
    if (s.fixed[i]) held += fmt::format("{}{} = {:g}", held.empty() ? "" : ", ", plant::coefficient_name(i), *s.fixed[i]);
  rep.paragraph(fmt::format(
      "The predictions below use the least-squares coefficients and their full covariance: eq. (3) is linear in the "
      "coefficients, so its standard uncertainty is sqrt(g^T Sigma g) with g its gradient (Sigma is in summary.json). "
      "Held at given values, with no uncertainty: {}. The static test cannot see a common shift of (k0, k2, k_PP, "
      "k_OO) (section 5).",
      held.empty() ? std::string("none") : held));
  rep.figure("fig1_static", "Identification error over standard uncertainty, per coefficient and method (symlog axis).",
             figures_missing.empty(), figures_missing);
}

void report_confirmation(Report& rep, const Case& c, const ReproduceSettings& s, const ReproduceResult& res,
                         const std::string& figures_missing) {
  const validation::ConfirmationRecord& cf = res.confirmation;
  const double K1 = res.truth[plant::K1];
  const Vec3 conf_dir = s.confirmation.direction.v.normalized();
  const double conf_diff = cf.shake.measured_g - cf.predicted.value_g;
  const double conf_comb = std::hypot(cf.shake.sigma_g, cf.predicted.sigma_g);
  rep.heading("2. The confirmation plot");
  // Every clause from the record itself.
  double u_lo = INFINITY, u_hi = -INFINITY;
  for (std::size_t i = 0; i < cf.t_s.size(); ++i)
    if (cf.t_s[i] >= cf.t_measure_start_s) u_lo = std::min(u_lo, cf.output[i]), u_hi = std::max(u_hi, cf.output[i]);
  const double swing = cf.t_s.empty() ? 0.0 : (u_hi - u_lo) / 2;
  const double noise_ug = s.shake.readout.noise_sigma_g * 1e6;
  const std::string acquisition =
      s.shake.readout.active()
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
      s.confirmation.amplitude_g, s.frequency_Hz, s.confirmation.direction.name, vec_text(conf_dir),
      s.confirmation.orientation.name, vec_text(s.confirmation.orientation.v), acquisition,
      cf.t_s.empty() ? 0.0 : -cf.t_s.front(), cf.t_measure_start_s, cf.t_end_s - cf.t_measure_start_s, swing,
      c.output_unit, ug(cf.shake.measured_g, 1), K1 * cf.shake.measured_g, c.output_unit,
      swing > 0 ? std::abs(K1 * cf.shake.measured_g) / swing : 0.0, cf.oscillation_amplitude_g_s * 1e3,
      ug(cf.integral_slope_g), ug(cf.shake.integral_slope_g),
      slope_biased ? ", biased by the swing (more than 3 sigma of the measurement away)" : "", ug(cf.shake.measured_g),
      ug(cf.shake.sigma_g), ug(cf.predicted.value_g), ug(cf.predicted.sigma_g), ug(conf_diff),
      conf_comb > 0 ? conf_diff / conf_comb : 0.0,
      cf.predicted.value_g != 0 ? fmt::format(", {:.2f} % of the prediction", 100 * conf_diff / cf.predicted.value_g)
                                : std::string("")));
  rep.figure("fig2_confirmation",
             "Top: the raw output. Bottom: its running integral, with the fitted slope and the slope eq. (3) predicts.",
             figures_missing.empty(), figures_missing);
}

std::string names(const std::vector<validation::NamedVector>& v) {
  std::string t;
  for (const auto& d : v) t += (t.empty() ? "" : ", ") + d.name;
  return t;
}

void report_amplitude(Report& rep, const ReproduceSettings& s, const ReproduceResult& res,
                      const std::string& figures_missing) {
  const validation::AmplitudeAnalysis& a = res.amplitude;
  const validation::Agreement &amp = a.all, &amp_nonzero = a.nonzero;
  std::vector<std::string> growth;
  for (std::size_t i : a.growth_runs) {
    const RunResult& r = res.amplitude_runs[i];
    growth.push_back(fmt::format("{}: {} +- {} ug", r.orientation, ug(r.predicted.value_g, 1), ug(r.predicted.sigma_g, 1)));
  }
  rep.heading("3. Measured vibration error against eq. (3), over amplitude");
  rep.paragraph(fmt::format(
      "{} shaker runs at {:g} Hz: amplitudes {} g peak x directions {} x static orientations {}. Agreement with the "
      "corrected eq. (3) from the identified coefficients: {} of {} runs within 2 combined sigma, {} within 3; largest "
      "|z| = {:.2f} ({}); rms residual {} ug, largest {} ug; median |residual|/|prediction| {:.2f} % over the runs whose "
      "prediction exceeds 3 of its sigma. {} runs have a non-zero prediction (the others are zero by symmetry: no "
      "rectifying term acts for that direction); of these, {} are within 2 combined sigma and {} within 3 (largest |z| "
      "{:.2f}). In {} of the {} runs the prediction's sigma exceeds the measurement's: the static test's uncertainty of "
      "k2 and k4 enters eq. (3) as w^2 and w^4; at {:g} g along {}: {}.",
      res.amplitude_runs.size(), s.frequency_Hz, fmt::format("{}", fmt::join(s.amplitudes_g, ", ")), names(s.directions),
      names(s.orientations), amp.within_2, amp.n, amp.within_3, amp.max_abs_z, amp.worst, ug(amp.rms_residual_g),
      ug(amp.max_abs_residual_g), 100 * amp.median_relative, amp_nonzero.n, amp_nonzero.within_2, amp_nonzero.within_3,
      amp_nonzero.max_abs_z, a.prediction_dominates, res.amplitude_runs.size(), a.max_amplitude_g,
      s.directions.front().name,
      growth.empty() ? std::string("no non-zero prediction") : fmt::format("{}", fmt::join(growth, "; "))));
  rep.paragraph(fmt::format(
      "Low frequency: at {:g} Hz the frequency-dependent eq. (3) (the plant's dynamics with the identified coefficients) "
      "differs from the quasi-static one by at most {} ug over these runs.",
      s.frequency_Hz, ug(a.frequency_departure_g, 3)));
  const std::string printed_why = fmt::format(
      "The printed form lacks the factor a_IA before arcsin in the asymmetry term, which acts where |a_IA| < |w_IA|, and "
      "omits the k_PP and k_OO terms (here k_PP = {:.3g}, k_OO = {:.3g} 1/g as identified; section 5 shows what the "
      "static test cannot tell about them); docs/prediction.md.",
      res.identified[plant::k_PP], res.identified[plant::k_OO]);
  if (a.printed_off_runs > 0)
    rep.paragraph(fmt::format(
        "Flagged: eq. (3) as printed departs from the measurement by more than 3 combined sigma in {} runs (largest {} "
        "ug), at: {}. {} The corrected form is the one drawn as the prediction.",
        a.printed_off_runs, ug(a.printed_worst_g, 1), fmt::format("{}", fmt::join(a.printed_off_where, "; ")),
        printed_why));
  else
    rep.paragraph(fmt::format(
        "Eq. (3) as printed agrees with the measurement within 3 combined sigma in every run here: it differs from the "
        "corrected form by at most {} ug ({}), where the combined sigma is {} ug. {}",
        ug(a.printed_gap_g, 3), a.printed_gap_where, ug(a.printed_gap_sigma_g, 3), printed_why));
  rep.figure("fig3_amplitude",
             "Measured vibration error (points, +-1 sigma) and eq. (3) from the identified coefficients (curve, +-1 sigma "
             "band; dashed: as printed), per static orientation (rows) and vibration direction (columns).",
             figures_missing.empty(), figures_missing);
  rep.figure("fig4_residuals", "Residuals, measured - predicted, in combined sigma and in ug.", figures_missing.empty(),
             figures_missing);
}

void report_frequency(Report& rep, const ReproduceSettings& s, const ReproduceResult& res,
                      const std::string& figures_missing) {
  const validation::DepartureAnalysis& d = res.departure;
  rep.heading("4. Where eq. (3) stops holding: frequency");
  const auto& fr = res.frequency_runs;
  const RunResult& ref = fr[d.reference];
  const RunResult& top = *std::max_element(fr.begin(), fr.end(), [](const RunResult& x, const RunResult& y) {
    return std::abs(x.measured_g) < std::abs(y.measured_g);
  });
  std::string departs;
  for (double f : d.departs_Hz) departs += fmt::format("{}{:g}", departs.empty() ? "" : ", ", f);
  rep.paragraph(fmt::format(
      "The confirmation condition ({:g} g along {} at {}) measured at {} frequencies, {:g} to {:g} Hz. Eq. (3) has no "
      "frequency in it. The measured error differs from its value at the reference {:g} Hz by more than 3 sigma of the "
      "two measurements at {}; the largest is {} ug at {:g} Hz against {} ug at {:g} Hz. The frequency-dependent "
      "eq. (3) (the identified coefficients behind the nominal dynamics: a term in the servo loop or at the output sees "
      "the rebalance current, whose amplitude follows the closed loop's response, docs/frequency.md) predicts the "
      "change from the reference run with its own uncertainty (the coefficient errors do not cancel: the terms scale "
      "differently with frequency); measured and predicted changes agree within {:.2f} combined sigma at worst ({:g} Hz). "
      "With the true coefficients the predicted change is within {:.2f} sigma of the measured one (measurement sigma only).",
      s.confirmation.amplitude_g, s.confirmation.direction.name, s.confirmation.orientation.name, fr.size(),
      fr.front().frequency_Hz, fr.back().frequency_Hz, d.reference_Hz,
      departs.empty() ? std::string("no frequency measured") : departs + " Hz", ug(top.measured_g), top.frequency_Hz,
      ug(ref.measured_g), d.reference_Hz, d.worst_z_change, d.worst_z_change_Hz, d.worst_z_true));
  std::vector<std::vector<std::string>> rows = {
      {"frequency (Hz)", "measured (ug)", "change measured (ug)", "change predicted (ug)", "eq. (3) quasi-static (ug)",
       "frequency-dependent (ug)"}};
  for (std::size_t i = 0; i < fr.size(); ++i) {
    const RunResult& r = fr[i];
    const bool is_ref = i == d.reference;
    const validation::Prediction& dp = d.changes[i].predicted;
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

void report_invisible(Report& rep, const ReproduceResult& res, const std::string& figures_missing) {
  const validation::InvisibleResult& inv = res.invisible;
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

// The summary: eq. (3) against the runs first, then each study's one line.
void report_summary(Report& rep, const Case& c, const ReproduceResult& res, double wall_s) {
  const validation::Agreement& amp = res.amplitude.all;
  const validation::ConfirmationRecord& cf = res.confirmation;
  const double conf_comb = std::hypot(cf.shake.sigma_g, cf.predicted.sigma_g);
  std::vector<std::string> lines = {
      fmt::format("Confirmation run: measured {} +- {} ug, eq. (3) predicts {} +- {} ug ({:.2f} combined sigma apart).",
                  ug(cf.shake.measured_g), ug(cf.shake.sigma_g), ug(cf.predicted.value_g), ug(cf.predicted.sigma_g),
                  conf_comb > 0 ? (cf.shake.measured_g - cf.predicted.value_g) / conf_comb : 0.0),
      fmt::format("Static test: {} readings identify the coefficients of model (1) ({} methods compared).",
                  res.static_test.readings.size(), res.static_test.methods.size())};
  if (!res.frequency_runs.empty())
    lines.push_back(fmt::format("Frequency: the measured error departs from its {:g} Hz value by more than 3 sigma at {} of {} "
                                "frequencies; the frequency-dependent eq. (3) predicts the change within {:.2f} sigma.",
                                res.departure.reference_Hz, res.departure.departs_Hz.size(), res.frequency_runs.size(),
                                res.departure.worst_z_change));
  if (res.invisible.c_per_g != 0)
    lines.push_back(fmt::format("No static test sees a common shift of (k0, k2, k_PP, k_OO): c = {} 1/g hidden, fitted from "
                                "shaker runs as {} +- {} 1/g.",
                                sci(res.invisible.c_per_g), sci(res.invisible.c_fit_per_g), sci(res.invisible.c_fit_sigma_per_g)));
  lines.push_back(fmt::format("vrelab {} ({}), case {}, seed {}, {:.1f} s wall.", kProgramVersion, kGitDescribe, c.path, c.seed,
                              wall_s));
  rep.summary(fmt::format("Eq. (3) from the identified coefficients matches the measured vibration error in {} of {} shaker "
                          "runs within 2 sigma, {} within 3 (largest |z| {:.2f}).",
                          amp.within_2, amp.n, amp.within_3, amp.max_abs_z),
              lines, amp.within_3 == amp.n ? Report::Tone::good : Report::Tone::bad);
}

}  // namespace

void write_reproduce_data(const Case& c, const ReproduceSettings& s, const ReproduceResult& res, double wall_s,
                          const std::string& dir) {
  begin_report_folder(dir);
  write_atomic(dir + "/static.csv", static_csv(c, res));
  write_atomic(dir + "/confirmation.csv", confirmation_csv(c, res));
  write_atomic(dir + "/confirmation.json", json_text(reproduce_confirmation_json(c, s, res)));
  write_atomic(dir + "/amplitude.csv", amplitude_csv(c, res));
  write_atomic(dir + "/amplitude_curves.csv", amplitude_curves_csv(c, res));
  if (!res.frequency_runs.empty()) {
    write_atomic(dir + "/frequency.csv", frequency_csv(c, res));
    write_atomic(dir + "/frequency_curves.csv", frequency_curves_csv(c, res));
  }
  if (res.invisible.c_per_g != 0) write_atomic(dir + "/invisible.csv", invisible_csv(c, res));
  // A section not run leaves no file from an earlier run in the folder (nor its figure).
  std::vector<std::string> stale;
  if (res.frequency_runs.empty()) stale = {"frequency.csv", "frequency_curves.csv", "fig5_frequency.png", "fig5_frequency.svg"};
  if (res.invisible.c_per_g == 0)
    for (const char* f : {"invisible.csv", "fig6_invisible.png", "fig6_invisible.svg"}) stale.push_back(f);
  for (const auto& f : stale) std::filesystem::remove(dir + "/" + f);
  write_atomic(dir + "/summary.json", json_text(reproduce_summary_json(c, s, res, wall_s)));
}

Report reproduce_full_report(const Case& c, const ReproduceSettings& s, const ReproduceResult& res, double wall_s,
                             const std::string& figures_missing) {
  Report rep("vrelab reproduce: " + c.path);
  report_summary(rep, c, res, wall_s);
  rep.paragraph(
      "The paper's experiment on the virtual instrument: a static test on the dividing head identifies the coefficients "
      "of model (1); shaker runs measure the vibration error; eq. (3) predicts it from the identified coefficients. Every "
      "number below is also in the CSV/JSON files beside this report (summary.json records the case, the seed, the "
      "solver settings and the program version).");
  report_static(rep, c, s, res, figures_missing);
  report_confirmation(rep, c, s, res, figures_missing);
  report_amplitude(rep, s, res, figures_missing);
  if (!res.frequency_runs.empty()) report_frequency(rep, s, res, figures_missing);
  if (res.invisible.c_per_g != 0) report_invisible(rep, res, figures_missing);
  rep.heading("Files");
  rep.list({"static.csv: the identification per method", "confirmation.csv, confirmation.json: the record and its numbers",
            "amplitude.csv, amplitude_curves.csv: the runs and the predicted curves",
            "frequency.csv, frequency_curves.csv: the frequency departure (when run)",
            "invisible.csv: the second instrument (when run)",
            "summary.json: every number above, with the case, seed, plant, solver settings and program version"});
  return rep;
}

std::string reproduce_brief_report(const ReproduceResult& res) {
  const auto& ls = res.static_test.methods.back();
  const validation::ConfirmationRecord& cf = res.confirmation;
  const double conf_diff = cf.shake.measured_g - cf.predicted.value_g;
  const double conf_comb = std::hypot(cf.shake.sigma_g, cf.predicted.sigma_g);
  const validation::Agreement& amp = res.amplitude.all;
  std::string out;
  out += fmt::format("Static test: {} readings; least-squares k2 = {} (truth {}), sigma {}\n", res.static_test.readings.size(),
                     sci(ls.estimate.value[plant::k2]), sci(res.truth[plant::k2]), sci(ls.first_order.sigma[plant::k2]));
  out += fmt::format("Confirmation: measured {} +- {} ug, integral slope {} ug, eq. (3) {} +- {} ug ({:.2f} sigma)\n",
                     ug(cf.shake.measured_g), ug(cf.shake.sigma_g), ug(cf.integral_slope_g), ug(cf.predicted.value_g),
                     ug(cf.predicted.sigma_g), conf_diff / conf_comb);
  out += fmt::format("Amplitude study: {}/{} runs within 2 sigma, {}/{} within 3, max |z| {:.2f}, rms residual {} ug\n",
                     amp.within_2, amp.n, amp.within_3, amp.n, amp.max_abs_z, ug(amp.rms_residual_g));
  if (!res.frequency_runs.empty())
    out += fmt::format("Frequency: the measured error departs from its {:g} Hz value by > 3 sigma at {} of {} frequencies; "
                       "the frequency-dependent eq. (3) predicts the change within {:.2f} sigma\n",
                       res.departure.reference_Hz, res.departure.departs_Hz.size(), res.frequency_runs.size(),
                       res.departure.worst_z_change);
  const validation::InvisibleResult& inv = res.invisible;
  if (inv.c_per_g != 0)
    out += fmt::format("Invisible shift: c = {}, fitted {} +- {} 1/g\n", sci(inv.c_per_g), sci(inv.c_fit_per_g),
                       sci(inv.c_fit_sigma_per_g));
  return out;
}

}  // namespace vrelab::io
