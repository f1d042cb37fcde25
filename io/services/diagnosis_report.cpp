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

// Section 2: each effect, and the pairs when no one effect explained the gap.
void which_effect(Report& rep, const FolderDiagnosis& f) {
  const validation::Diagnosis& d = f.diagnosis;
  std::vector<std::vector<std::string>> rows = {
      {"effect", "parameter", "value", "sigma", "evidence (held-out -2 ln L)", "held-out chi2"}};
  for (const auto& e : d.effects)
    rows.push_back({e.name, e.parameter + " (" + e.unit + ")", fmt::format("{:.5g}", e.value), fmt::format("{:.3g}", e.sigma),
                    fmt::format("{:.1f}", e.evidence), fmt::format("{:.1f}", e.heldout_chi2)});
  rep.table(rows);
  if (!d.pairs.empty()) {
    rep.paragraph(fmt::format("No one effect explains the gap; the best with the two most promising seconds (ranked on "
                              "each fold's training runs), fitted together (additive to first order), a pair chosen "
                              "only when its evidence beats the best single effect's by {:.0f}:",
                              d.pair_evidence_margin));
    std::vector<std::vector<std::string>> prow = {{"pair", "parameters", "evidence", "held-out chi2"}};
    for (const auto& p : d.pairs)
      prow.push_back({p.a + " + " + p.b, fmt::format("{:.5g}, {:.5g}", p.pa, p.pb), fmt::format("{:.1f}", p.evidence),
                      fmt::format("{:.1f}", p.heldout_chi2)});
    rep.table(prow);
  }
  rep.paragraph("Verdict: " + validation::verdict_text(d) + ".");
}

// Section 3: the held-out shrinkage and the confirmation on the ODE plant.
void how_far(Report& rep, const validation::Diagnosis& d) {
  rep.paragraph(fmt::format(
      "On the held-out runs (each amplitude predicted from the others), the gap the static test's coefficient errors "
      "cannot take up has rms {:.4g} ug ({:.3g} sigma) with the nominal simulation and {:.4g} ug ({:.3g} sigma) with {} "
      "added: {:.0f} % removed.",
      d.rms_before_g * 1e6, d.rms_before_sigma, d.rms_after_g * 1e6, d.rms_after_sigma, validation::to_string(d.chosen),
      d.rms_before_g > 0 ? 100 * (1 - d.rms_after_g / d.rms_before_g) : 0.0));
  const double above = d.shrinkage_above_floor();
  rep.paragraph(fmt::format(
      "No effect can remove the floor: with no gap at all the held-out gap would have rms {:.4g} ug ({:.3g} sigma), the "
      "runs' noise and the simulation's accuracy with the coefficients' error the training runs leave, extrapolated. {}",
      d.rms_floor_g * 1e6, d.rms_floor_sigma,
      std::isfinite(above) ? fmt::format("Of the gap above it, {:.0f} % is removed.", 100 * above)
                           : std::string("The gap before is within it: nothing to shrink.")));
  if (d.resimulated_runs > 0)
    rep.paragraph(fmt::format(
        "Confirmed on the ODE plant: the {} runs with the largest gaps re-simulated with the coefficients corrected by "
        "all runs under {} and the effect added leave rms {:.4g} ug; without the effect, {:.4g} ug.",
        d.resimulated_runs, validation::to_string(d.chosen), d.resimulated_rms_after_g * 1e6, d.resimulated_rms_before_g * 1e6));
}

}  // namespace

void write_diagnosis_report(const FolderDiagnosis& f, const std::string& dir) {
  const validation::Campaign& c = f.campaign;
  Report rep("vrelab diagnose: " + f.dir);
  rep.paragraph(fmt::format("vrelab {} ({}). {} static readings, {} shaker runs, {} skipped.", kProgramVersion, kGitDescribe,
                            c.statics.size(), c.runs.size(), c.skipped.size()));
  if (!c.skipped.empty()) rep.list(c.skipped);
  if (const std::string motion = motion_summary_text(f.diagnosis, c); !motion.empty()) rep.paragraph(motion);
  rep.heading("1. Where the gap lies");
  rep.paragraph(f.diagnosis.where + ".");
  rep.heading("2. Which effect");
  which_effect(rep, f);
  rep.heading("3. How far it shrinks");
  how_far(rep, f.diagnosis);
  begin_report_folder(dir);
  write_atomic(dir + "/diagnosis.json", json_text(to_json(f)));
  const std::string why = run_plot_script("diagnose.py", dir);
  rep.figure("gap_map", "The gap per run, standardised against all the others (z), over frequency and amplitude, per direction.",
             why.empty(), why);
  rep.figure("residuals", "Held-out gap (what the coefficient errors cannot take up) before and after the chosen effect.",
             why.empty(), why);
  write_report_folder(dir, rep);
}

}  // namespace vrelab::io
