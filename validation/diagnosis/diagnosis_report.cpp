// validation/diagnosis/diagnosis_report.cpp -- a diagnosis in words (Diagnosis::BriefReport,
// FullReport).
#include "validation/diagnosis/diagnose.hpp"
#include "validation/diagnosis/diagnosis_text.hpp"

#include <cmath>

#include <fmt/format.h>

namespace vrelab::validation {
namespace {

std::string heldout_line(const Diagnosis& d, double wall_s) {
  const double above = d.shrinkage_above_floor();
  return fmt::format("Held-out gap rms: {:.4g} ug ({:.3g} sigma) before, {:.4g} ug ({:.3g} sigma) after {}; floor {:.4g} ug "
                     "({:.3g} sigma){}{}\n",
                     d.rms_before_g * 1e6, d.rms_before_sigma, d.rms_after_g * 1e6, d.rms_after_sigma, to_string(d.chosen),
                     d.rms_floor_g * 1e6, d.rms_floor_sigma,
                     std::isfinite(above) ? fmt::format(", {:.0f} % of the gap above it removed", 100 * above)
                                          : std::string(", the gap within it"),
                     wall_s >= 0 ? fmt::format(" ({:.1f} s wall)", wall_s) : "");
}

// The lab nuisances, one line each (not effects: estimated and removed or allowed for).
std::string nuisance_lines(const Diagnosis& d) {
  std::string t;
  for (const auto& x : d.nuisances) {
    if (!x.estimated) {
      t += fmt::format("Nuisance {}: {}\n", x.name, x.note);
      continue;
    }
    t += fmt::format("Nuisance {}: {:.4g} +- {:.2g} {}{}; {}\n", x.name, x.value, x.sigma, x.unit == "1" ? "" : x.unit,
                     x.significant ? " (significant)" : " (not flagged)", x.note);
  }
  return t;
}

// The runs that would tell the candidates apart best.
std::string next_run_lines(const Diagnosis& d) {
  if (d.next_runs.empty()) return "";
  const bool locates = d.next_runs.front().purpose == "locates";
  std::string t = locates ? "Next runs (where the gap lies; the gap the campaign's laws expect there):\n"
                          : "Next runs (what tells the candidates apart best; the rival's rise in -2 ln L as sigma):\n";
  for (const auto& r : d.next_runs)
    t += fmt::format("  {:g} Hz, {:g} g along [{:.2g}, {:.2g}, {:.2g}], static a = [{:.2g}, {:.2g}, {:.2g}] g: {} ({})\n",
                     r.frequency_Hz, r.amplitude_g, r.direction[0], r.direction[1], r.direction[2], r.orientation_g[0],
                     r.orientation_g[1], r.orientation_g[2],
                     std::isfinite(r.separation_sigma) ? fmt::format("{:.1f} sigma", r.separation_sigma) : "no expectation",
                     r.between);
  return t;
}

}  // namespace

std::string Diagnosis::BriefReport() const {
  const Diagnosis& d = *this;
  std::string t = "Verdict: " + verdict_text(d) + "\n" + heldout_line(d, -1);
  for (const auto& x : d.nuisances)
    if (x.significant)
      t += fmt::format("Nuisance {}: {:.4g} +- {:.2g} {}\n", x.name, x.value, x.sigma, x.unit == "1" ? "" : x.unit);
  return t + next_run_lines(d);
}

std::string Diagnosis::FullReport(double wall_s) const {
  const Diagnosis& d = *this;
  std::string t = "Gap: " + d.where + "\n";
  t += "Cross-validation: " + d.folds + "\n";
  t += "Verdict: " + verdict_text(d) + "\n";
  t += fmt::format("  {:<26}{:>16}{:>12}{:>12}{:>14}{:>12}\n", "effect", "parameter", "sigma", "evidence", "held-out chi2",
                   "all-run chi2");
  for (const auto& e : d.effects) {
    const std::optional<DatasheetValue> ds = datasheet_form(e.value, e.sigma, e.unit);
    t += fmt::format("  {:<26}{:>16.5g}{:>12.3g}{:>12.1f}{:>14.1f}{:>12.1f}  {} ({}{})\n", e.name, e.value, e.sigma, e.evidence,
                     e.heldout_chi2, e.insample_chi2, e.parameter, e.unit,
                     !ds ? ""
                     : std::isfinite(ds->sigma) ? fmt::format("; datasheet {:.4g} +- {:.2g} {}", ds->value, ds->sigma, ds->unit)
                                                : fmt::format("; datasheet {:.4g} {}, not pinned", ds->value, ds->unit));
    // The natural form's further parameters: fitted with sigma, chosen, or held at nominal.
    for (std::size_t j = 1; j < e.parameters.size(); ++j) {
      const auto& q = e.parameters[j];
      const char* magnitude = q.sign_identifiable ? "" : ", its magnitude: the sign is not identifiable";
      if (q.status == ParameterStatus::fitted)
        t += fmt::format("  {:<26}{:>16.5g}{:>12.3g}  fitted{}: {} ({}{})\n", "", q.value, q.sigma, q.at_bound ? " at its bound" : "",
                         q.name, q.unit, magnitude);
      else
        t += fmt::format("  {:<26}{:>16.5g}{:>12}  {}: {} ({}; range {:.3g} .. {:.3g}{})\n", "", q.value, "", to_string(q.status), q.name,
                         q.unit, q.lower, q.upper, magnitude);
    }
  }
  for (const auto& p : d.pairs)
    t += fmt::format("  pair {:<40}{:>12.5g},{:<12.5g}{:>12.1f}{:>14.1f}{:>12.1f}\n", p.a + " + " + p.b, p.pa, p.pb, p.evidence,
                     p.heldout_chi2, p.insample_chi2);
  for (const auto& e : d.effects)
    if (!e.not_ranked.empty()) t += fmt::format("  {} is not ranked: {}\n", e.name, e.not_ranked);
  t += heldout_line(d, wall_s);
  if (d.resimulated_runs > 0)
    t += fmt::format("Re-simulated on the ODE plant ({} runs with the largest gaps): rms {:.4g} ug without {}, {:.4g} ug "
                     "with it\n",
                     d.resimulated_runs, d.resimulated_rms_before_g * 1e6, to_string(d.chosen), d.resimulated_rms_after_g * 1e6);
  for (const auto& f : d.resimulation_failures) t += "  re-simulation failed: " + f + "\n";
  t += nuisance_lines(d) + next_run_lines(d);
  return t;
}

}  // namespace vrelab::validation
