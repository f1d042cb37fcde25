#include "io/services/blind_report.hpp"

#include <map>
#include <utility>

#include <fmt/format.h>

#include "io/services/diagnosis_json.hpp"

namespace vrelab::io {
namespace {

using validation::BlindCriterion;
using validation::FamilyScore;

// The families in the order of blind's text report, each in the user's words.
const std::vector<std::pair<std::string, std::string>>& families() {
  static const std::vector<std::pair<std::string, std::string>> v = {
      {"single", "one library effect (gap >= 5 sigma)"},
      {"single_below_5_sigma", "one library effect, gap below 5 sigma (not scored)"},
      {"natural", "one library effect in its natural form (gap >= 5 sigma)"},
      {"natural_below_5_sigma", "natural form, gap below 5 sigma (not scored)"},
      {"two", "two library effects together (each needed >= 5 sigma)"},
      {"two_below_5_sigma", "two library effects, one adding below 5 sigma (not scored)"},
      {"out_of_library", "an effect outside the library (gap >= 5 sigma)"},
      {"out_of_library_below_5_sigma", "outside the library, gap below 5 sigma (not scored)"},
      {"dynamics_off", "the servo loop off its nominal"},
      {"sigma_understated", "the stated sigma too small"},
      {"drift", "a bias drift"},
      {"clean", "nothing hidden"}};
  return v;
}

std::string rate_text(int k, int n) { return n ? fmt::format("{:.0f} %", 100.0 * k / n) : std::string("n/a"); }

std::string interval_text(int k, int n) {
  if (n == 0) return "n/a";
  const validation::RateInterval ci = validation::clopper_pearson(k, n);
  return fmt::format("{:.0f} - {:.0f} %", 100 * ci.lo, 100 * ci.hi);
}

std::string target_text(const BlindCriterion& c) { return fmt::format("{} {:.0f} %", c.at_least ? ">=" : "<=", 100 * c.target); }

void summary(Report& rep, const validation::BlindResult& r) {
  int assessed = 0, met = 0, wrong = 0, all = 0;
  std::vector<std::string> missed;
  for (const BlindCriterion& c : r.Criteria()) {
    if (c.n == 0) continue;
    ++assessed, met += c.met();
    if (!c.met()) missed.push_back(c.name);
  }
  for (const auto& [name, f] : r.scores.families) wrong += f.wrong, all += f.n;
  std::vector<std::string> lines;
  for (const BlindCriterion& c : r.Criteria())
    if (c.n > 0)
      lines.push_back(fmt::format("{}: {}/{} = {} (95 % interval {}), target {}: {}.", c.name, c.k, c.n, rate_text(c.k, c.n),
                                  interval_text(c.k, c.n), target_text(c), c.met() ? "met" : "NOT met"));
  lines.push_back(fmt::format("{} simulated campaigns with hidden effects, seed {}{}, diagnosed without their keys in {:.1f} s{}.",
                              r.settings.n, r.settings.seed, r.settings.mixed ? " (mixed designs)" : "", r.wall_s,
                              r.resumed > 0 ? fmt::format(" ({} read back from an earlier run)", r.resumed) : ""));
  const std::size_t empty = r.Criteria().size() - static_cast<std::size_t>(assessed);
  rep.summary(fmt::format("{} of {} targets met{}; {} of {} campaigns confidently wrong.", met, assessed,
                          empty > 0 ? fmt::format(" ({} more have no campaign in this run)", empty) : "", wrong, all),
              lines, met == assessed ? Report::Tone::good : Report::Tone::bad);
}

void per_family(Report& rep, const validation::BlindResult& r) {
  rep.heading("How often diagnose was right, by what was hidden");
  rep.paragraph("Each campaign counts once: right (the hidden effect called; for a pair both; outside the library: "
                "'unexplained'; a nuisance: flagged with no effect called; nothing hidden: no gap), right physics but not "
                "the right effect, unexplained, no gap, or confidently wrong (explained by an effect of another physics). "
                "The 95 % interval is Clopper-Pearson's (exact binomial): what a run of this size can tell. n/a: no "
                "campaign of that kind in this run.");
  std::vector<std::vector<std::string>> rows = {{"hidden in the campaign", "campaigns", "right", "right (%)",
                                                 "95 % interval (%)", "right physics, wrong effect", "unexplained", "no gap",
                                                 "confidently wrong", "ambiguous (truth among)", "error",
                                                 "right effect, a parameter beyond 3 sigma"}};
  for (const auto& [key, words] : families()) {
    const auto it = r.scores.families.find(key);
    const FamilyScore f = it == r.scores.families.end() ? FamilyScore{} : it->second;
    if (f.n == 0) {
      rows.push_back({words, "0", "n/a", "n/a", "n/a", "", "", "", "", "", "", ""});
      continue;
    }
    rows.push_back({words, std::to_string(f.n), fmt::format("{}/{}", f.right, f.n), rate_text(f.right, f.n),
                    interval_text(f.right, f.n), std::to_string(f.family), std::to_string(f.unexplained), std::to_string(f.no_gap),
                    std::to_string(f.wrong), fmt::format("{} ({})", f.ambiguous, f.right_among), std::to_string(f.error),
                    std::to_string(f.parameters_off)});
  }
  rep.table(rows);
}

void targets(Report& rep, const validation::BlindResult& r) {
  rep.heading("Does diagnose meet its targets?");
  rep.paragraph("'met' compares the rate itself with the target; the interval says how sure a run of this size can be.");
  std::vector<std::vector<std::string>> rows = {{"what is measured", "campaigns (k/n)", "rate (%)", "95 % interval (%)", "target (%)", "result"}};
  for (const BlindCriterion& c : r.Criteria())
    rows.push_back({c.name, fmt::format("{}/{}", c.k, c.n), rate_text(c.k, c.n), interval_text(c.k, c.n), target_text(c),
                    c.n == 0 ? "n/a (no campaigns)" : c.met() ? "met" : "not met"});
  rep.table(rows);
}

void confusion(Report& rep, const validation::BlindResult& r, const std::string& figure_missing) {
  rep.heading("What was hidden, and what diagnose called it");
  rep.figure("confusion", "The confusion matrix: rows the hidden truth, columns diagnose's verdict without the key (confusion.csv).",
             figure_missing.empty(), figure_missing);
  const ConfusionMatrix m = confusion_matrix(r);
  std::vector<bool> used(m.called.size(), false);  // the table keeps the verdicts some campaign got
  for (const auto& row : m.counts)
    for (std::size_t j = 0; j < row.size(); ++j) used[j] = used[j] || row[j] > 0;
  std::vector<std::vector<std::string>> rows = {{"hidden \\ called (campaigns)"}};
  for (std::size_t j = 0; j < m.called.size(); ++j)
    if (used[j]) rows[0].push_back(m.called[j]);
  for (std::size_t i = 0; i < m.truths.size(); ++i) {
    std::vector<std::string> row = {m.truths[i]};
    int total = 0;
    for (std::size_t j = 0; j < m.called.size(); ++j) {
      total += m.counts[i][j];
      if (used[j]) row.push_back(m.counts[i][j] ? std::to_string(m.counts[i][j]) : "");
    }
    if (total > 0) rows.push_back(row);
  }
  rep.table(rows);
}

void shrinkage(Report& rep, const validation::BlindResult& r) {
  const validation::BlindScores& s = r.scores;
  rep.heading("How much of the gap the chosen effect removes");
  rep.paragraph("Held out (each amplitude predicted from the others), over the scored single-effect campaigns. A single or "
                "natural campaign is scored when the gap its effect makes is >= 5 sigma as the diagnosis' nominal model sees "
                "it (effect_gap_sigma); beside, sized by its largest run (effect_max_sigma).");
  std::vector<std::vector<std::string>> rows = {{"measure", "value", "campaigns"},
                                                {"median shrinkage of the gap, the lab's noise removed",
                                                 fmt::format("{:.0f} %", 100 * s.median_gap_shrinkage),
                                                 std::to_string(s.gap_shrinkage_campaigns)},
                                                {"median shrinkage of the residuals, with the noise",
                                                 fmt::format("{:.0f} %", 100 * s.median_shrinkage), std::to_string(s.single)},
                                                {"median shrinkage above the floor", fmt::format("{:.0f} %", 100 * s.median_shrinkage_above_floor),
                                                 std::to_string(s.above_floor_campaigns)},
                                                {"single, right effect, sized by the largest run",
                                                 fmt::format("{}/{} ({})", s.by_max_run_sigma.single_right, s.by_max_run_sigma.single,
                                                             rate_text(s.by_max_run_sigma.single_right, s.by_max_run_sigma.single)),
                                                 std::to_string(s.by_max_run_sigma.single)}};
  rep.table(rows);
}

}  // namespace

Report blind_report(const validation::BlindResult& r, const std::string& figure_missing) {
  Report rep(fmt::format("vrelab blind: {} campaigns, seed {}", r.settings.n, r.settings.seed));
  summary(rep, r);
  per_family(rep, r);
  confusion(rep, r, figure_missing);
  targets(rep, r);
  shrinkage(rep, r);
  rep.heading("Every miss, with why");
  rep.list(r.wrong.empty() ? std::vector<std::string>{"none"} : r.wrong);
  rep.heading("The run");
  rep.paragraph(fmt::format("{:.1f} s wall on {} threads{}. Beside this report: scores.json (every number, per campaign), "
                            "confusion.csv and its figure, campaigns.txt (what a rerun reads back).",
                            r.wall_s, r.threads, r.ranks > 1 ? fmt::format(" x {} MPI ranks", r.ranks) : ""));
  return rep;
}

}  // namespace vrelab::io
