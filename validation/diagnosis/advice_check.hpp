#pragma once
// validation/diagnosis/advice_check.hpp -- the next-run advice checked against the truth
// (docs/blind.md, "The advice checked"): a blind campaign's advised runs simulated by the
// virtual lab under the campaign's truth (the ODE with its hidden effects), appended, and the
// campaign diagnosed again.
//
// Takes: a blind campaign's key (BlindCampaign from blind_key) and the diagnosis' settings.
// Gives: per advised run what it promised (NextRun::separation_sigma) and what it obtained:
//        for a run that separates A from B, sqrt|change of (chi^2_B - chi^2_A)| (EffectFit::
//        insample_chi2, every run, each effect refitted) when the run is appended; for a run
//        that locates the gap, |z| of the appended run; the verdict with it. Then all advised
//        runs appended together: the campaign's outcome in its blind family before and after
//        (blind_outcome) and whether the advice turned it right, wrong or left it.
#include <cmath>
#include <string>
#include <vector>

#include "validation/diagnosis/blind.hpp"

namespace vrelab::validation {

struct AdvisedRunCheck {
  NextRun advised;
  double measured_g = NAN, sigma_g = NAN;  // the virtual lab's measurement of it (the lab log applied)
  // What it promised under the truth: a separating run's if_first_sigma when the truth is its
  // first effect, if_second_sigma when the second, else its separation_sigma (the smaller);
  // a locating run's expected gap. And what it obtained (above).
  double promised_sigma = NAN, obtained_sigma = NAN;
  std::string called;                      // the verdict's call with it appended (blind's `called`)
};

struct AdviceCheck {
  int index = 0;
  std::string category, called_before, called_after;
  std::string outcome_before, outcome_after;  // blind_outcome
  std::vector<AdvisedRunCheck> runs;          // empty: no advice (the gap explained, or insignificant)
  std::string error;
  // right: not right before, right after; wrong: confidently wrong after, not before; left: otherwise.
  std::string turned() const;
};

// The virtual lab's measurement of one more sine run of campaign k (its truth, hidden effects
// and lab log: the run's time after the campaign's `runs_before` runs), seeded from k's seed
// and `which`.
RunRecord simulate_advised_run(const BlindCampaign& k, const NextRun& advised, int runs_before, int which);

// Campaign k (its key; the diagnosis is made here) checked as above.
AdviceCheck check_advice(const BlindCampaign& k, const DiagnoseSettings& s);

// One line of text (no tab, no newline) and back; read_advice_check throws
// std::invalid_argument for a line it cannot read.
std::string advice_check_text(const AdviceCheck& a);
AdviceCheck read_advice_check(const std::string& text);

// The checks summed up: the median of obtained / promised over the separating runs (with
// the count), the locating runs' expected and obtained |z|, and the verdicts turned right,
// wrong or left per verdict before (ambiguous, unexplained).
std::string advice_summary(const std::vector<AdviceCheck>& checks);

}  // namespace vrelab::validation
