#include "io/services/diagnosis_report.hpp"

#include <cmath>

#include <fmt/format.h>

#include "io/services/diagnosis_json.hpp"
#include "io/formats/output.hpp"
#include "io/formats/report.hpp"
#include "validation/diagnosis/diagnosis_text.hpp"
#include "vrelab_version.hpp"

namespace vrelab::io {
namespace {

// A parameter's sigma in words: a number, or why there is none (the fit did not pin it:
// no curvature, or it ended on its range's edge).
std::string sigma_text(double sigma, bool at_bound) {
  if (std::isfinite(sigma)) return fmt::format("{:.3g}", sigma);
  return at_bound ? "not pinned (at its bound)" : "not pinned";
}

std::string percent_removed(const validation::Diagnosis& d) {
  return d.rms_before_g > 0 ? fmt::format("{:.0f} %", 100 * (1 - d.rms_after_g / d.rms_before_g)) : std::string("n/a");
}

// The summary: the verdict, how far the gap shrinks, what was read, a nuisance flagged, the run to add.
void summary(Report& rep, const FolderDiagnosis& f) {
  const validation::Diagnosis& d = f.diagnosis;
  const validation::Campaign& c = f.campaign;
  std::vector<std::string> lines;
  if (d.gap_significant)
    lines.push_back(fmt::format("Held-out gap rms {:.4g} ug with the nominal simulation, {:.4g} ug with {}: {} removed "
                                "(floor, what no effect can remove: {:.4g} ug).",
                                d.rms_before_g * 1e6, d.rms_after_g * 1e6, validation::to_string(d.chosen), percent_removed(d),
                                d.rms_floor_g * 1e6));
  lines.push_back(fmt::format("{} static readings, {} shaker runs read{}.", c.statics.size(), c.runs.size(),
                              c.skipped.empty() ? std::string() : fmt::format(", {} skipped for bad input", c.skipped.size())));
  for (const auto& x : d.nuisances)
    if (x.significant)
      lines.push_back(fmt::format("Lab nuisance flagged: {} = {:.4g} +- {:.2g}{}.", x.name, x.value, x.sigma,
                                  x.unit == "1" ? "" : " " + x.unit));
  if (!d.next_runs.empty()) {
    const auto& r = d.next_runs.front();
    lines.push_back(r.purpose == "locates"
                        ? fmt::format("Next run to locate the gap ({}): {:g} Hz, {:g} g.", r.between, r.frequency_Hz, r.amplitude_g)
                        : fmt::format("Next run to tell {} apart: {:g} Hz, {:g} g ({:.1f} sigma between them).", r.between,
                                      r.frequency_Hz, r.amplitude_g, r.separation_sigma));
  }
  const auto tone = d.verdict == validation::Verdict::explained || d.verdict == validation::Verdict::no_significant_gap
                        ? Report::Tone::good
                        : Report::Tone::bad;
  rep.summary("Verdict: " + validation::verdict_text(d) + ".", lines, tone);
}

// Where the gap lies: the diagnosis' clauses, one a line.
void where(Report& rep, const validation::Diagnosis& d) {
  rep.heading("Where the gap lies");
  std::vector<std::string> clauses;
  for (std::size_t at = 0;;) {
    const std::size_t end = d.where.find("; ", at);
    clauses.push_back(d.where.substr(at, end == std::string::npos ? end : end - at));
    if (end == std::string::npos) break;
    at = end + 2;
  }
  rep.list(clauses);
}

// Which effect: each candidate with its fitted parameter, and the pairs when they were tried.
void which_effect(Report& rep, const validation::Diagnosis& d) {
  rep.heading("Which effect explains it");
  rep.paragraph("Every effect of the library fitted to the runs, best first. Evidence: how much the effect lowers chi^2 on "
                "runs it was not fitted to (held out, summed over folds; larger is better). A sigma 'not pinned': the "
                "runs do not determine the parameter.");
  std::vector<std::vector<std::string>> rows = {
      {"effect", "parameter", "unit", "value", "sigma", "datasheet (IEEE Std 1293 units)", "evidence (held-out chi^2 drop)",
       "held-out chi^2", "all-run chi^2 (fitted on every run)"}};
  for (const auto& e : d.effects) {
    const auto ds = validation::datasheet_form(e.value, e.sigma, e.unit);
    rows.push_back({e.name, e.parameter, e.unit, fmt::format("{:.5g}", e.value), sigma_text(e.sigma, e.at_bound),
                    ds ? fmt::format("{:.4g} {} (sigma {})", ds->value, ds->unit,
                                     std::isfinite(ds->sigma) ? fmt::format("{:.2g}", ds->sigma) : "not pinned")
                       : "",
                    fmt::format("{:.1f}", e.evidence), fmt::format("{:.1f}", e.heldout_chi2),
                    fmt::format("{:.1f} for {}", e.insample_chi2, e.insample_dof)});
  }
  rep.table(rows);
  if (!d.pairs.empty()) {
    rep.paragraph(fmt::format("The best effect with the two most promising seconds (ranked on each fold's training "
                              "runs), fitted together (additive to first order), tried where the best leaves the gap "
                              "unexplained or a second still lowers -2 ln L by {0:.0f} on every run; a pair chosen only "
                              "when its evidence beats the best single effect's by {0:.0f} (docs/diagnose.md, step 8):",
                              d.pair_evidence_margin));
    std::vector<std::vector<std::string>> prow = {{"pair", "parameters (each effect's unit)", "evidence", "held-out chi^2", "all-run chi^2"}};
    for (const auto& p : d.pairs)
      prow.push_back({p.a + " + " + p.b, fmt::format("{:.5g}, {:.5g}", p.pa, p.pb), fmt::format("{:.1f}", p.evidence),
                      fmt::format("{:.1f}", p.heldout_chi2), fmt::format("{:.1f}", p.insample_chi2)});
    rep.table(prow);
  }
}

// How far the gap shrinks: held out, above the floor, and on the ODE plant.
void how_far(Report& rep, const validation::Diagnosis& d) {
  rep.heading("How far the gap shrinks");
  rep.paragraph("On the held-out runs (each amplitude predicted from the others): the gap the static test's coefficient "
                "errors cannot take up.");
  const double above = d.shrinkage_above_floor();
  std::vector<std::vector<std::string>> rows = {{"held-out gap", "rms (ug)", "rms (run sigma)"},
                                                {"nominal simulation", fmt::format("{:.4g}", d.rms_before_g * 1e6),
                                                 fmt::format("{:.3g}", d.rms_before_sigma)},
                                                {"with " + validation::to_string(d.chosen), fmt::format("{:.4g}", d.rms_after_g * 1e6),
                                                 fmt::format("{:.3g}", d.rms_after_sigma)},
                                                {"floor: no gap at all (noise, simulation accuracy)",
                                                 fmt::format("{:.4g}", d.rms_floor_g * 1e6), fmt::format("{:.3g}", d.rms_floor_sigma)}};
  if (d.resimulated_runs > 0) {
    rows.push_back({fmt::format("ODE plant, {} largest-gap runs, without the effect", d.resimulated_runs),
                    fmt::format("{:.4g}", d.resimulated_rms_before_g * 1e6), ""});
    rows.push_back({fmt::format("ODE plant, {} largest-gap runs, with {}", d.resimulated_runs, validation::to_string(d.chosen)),
                    fmt::format("{:.4g}", d.resimulated_rms_after_g * 1e6), ""});
  }
  rep.table(rows);
  rep.paragraph(fmt::format("{} of the gap removed; {}", percent_removed(d),
                            std::isfinite(above) ? fmt::format("{:.0f} % of the gap above the floor.", 100 * above)
                                                 : std::string("the gap before is within the floor: nothing to shrink.")));
  for (const auto& fail : d.resimulation_failures) rep.paragraph("Re-simulation failed: " + fail);
}

void nuisances(Report& rep, const validation::Diagnosis& d) {
  if (d.nuisances.empty()) return;
  rep.heading("Lab nuisances (estimated apart, not effects)");
  std::vector<std::vector<std::string>> rows = {{"nuisance", "value", "sigma", "unit", "flagged", "note"}};
  for (const auto& x : d.nuisances)
    rows.push_back({x.name, x.estimated ? fmt::format("{:.4g}", x.value) : "not estimated",
                    x.estimated ? sigma_text(x.sigma, false) : "", x.unit, x.significant ? "yes" : "no", x.note});
  rep.table(rows);
}

void next_runs(Report& rep, const validation::Diagnosis& d) {
  if (d.next_runs.empty()) return;
  const bool locates = d.next_runs.front().purpose == "locates";
  rep.heading(locates ? "Runs to add next (where the gap lies)" : "Runs to add next (what tells the candidates apart best)");
  std::vector<std::vector<std::string>> rows = {{locates ? "locates" : "between", "frequency (Hz)", "amplitude (g)",
                                                 "direction [IA, PA, OA]", "static a [IA, PA, OA] (g)",
                                                 locates ? "gap expected (sigma)" : "separation (sigma)"}};
  for (const auto& r : d.next_runs)
    rows.push_back({r.between, fmt::format("{:g}", r.frequency_Hz), fmt::format("{:g}", r.amplitude_g),
                    fmt::format("[{:.2g}, {:.2g}, {:.2g}]", r.direction[0], r.direction[1], r.direction[2]),
                    fmt::format("[{:.2g}, {:.2g}, {:.2g}]", r.orientation_g[0], r.orientation_g[1], r.orientation_g[2]),
                    std::isfinite(r.separation_sigma) ? fmt::format("{:.1f}", r.separation_sigma) : "-"});
  rep.table(rows);
}

}  // namespace

void write_diagnosis_report(const FolderDiagnosis& f, const std::string& dir) {
  const validation::Campaign& c = f.campaign;
  const validation::Diagnosis& d = f.diagnosis;
  Report rep("vrelab diagnose: " + f.dir);
  summary(rep, f);
  begin_report_folder(dir);
  write_atomic(dir + "/diagnosis.json", json_text(to_json(f)));
  const std::string why = run_plot_script("diagnose.py", dir);
  rep.figure("gap_map", "The gap per run, standardised against all the others (z), over frequency and amplitude, per direction.",
             why.empty(), why);
  where(rep, d);
  which_effect(rep, d);
  how_far(rep, d);
  rep.figure("residuals", "Held-out gap (what the coefficient errors cannot take up) before and after the chosen effect.",
             why.empty(), why);
  nuisances(rep, d);
  next_runs(rep, d);
  rep.heading("The data");
  rep.paragraph(fmt::format("vrelab {} ({}); campaign {}: {} static readings, {} shaker runs, {} skipped. Every number above "
                            "is in diagnosis.json beside this report.",
                            kProgramVersion, kGitDescribe, f.dir, c.statics.size(), c.runs.size(), c.skipped.size()));
  if (!c.skipped.empty()) rep.list(c.skipped);
  if (const std::string motion = motion_summary_text(d, c); !motion.empty()) rep.paragraph(motion);
  write_report_folder(dir, rep);
}

}  // namespace vrelab::io
