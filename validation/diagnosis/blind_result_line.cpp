// A blind campaign's result line: what a thread or an MPI rank hands back and campaigns.txt
// keeps for resuming (docs/blind.md, "Result lines"), written and read back.
#include <cmath>
#include <stdexcept>
#include <string>
#include <vector>

#include <fmt/format.h>

#include "validation/diagnosis/blind.hpp"
#include "validation/diagnosis/diagnose.hpp"
#include "validation/diagnosis/diagnosis_text.hpp"

namespace vrelab::validation {

namespace {

// Strings in a result line: tab, newline and backslash escaped.
std::string escaped(const std::string& s) {
  std::string e;
  for (char ch : s) e += ch == '\t' ? "\\t" : ch == '\n' ? "\\n" : ch == '\\' ? "\\\\" : std::string(1, ch);
  return e;
}
std::string unescaped(const std::string& s) {
  std::string u;
  for (std::size_t i = 0; i < s.size(); ++i) {
    if (s[i] == '\\' && i + 1 < s.size()) {
      ++i;
      u += s[i] == 't' ? '\t' : s[i] == 'n' ? '\n' : s[i];
    } else {
      u += s[i];
    }
  }
  return u;
}

}  // namespace

// The fields: 17 fixed (times, scores' numbers, names), then the verdict, the ambiguous
// effects (their count, then each), the nuisances (their count, then 8 fields each): what the
// scoring reads. (Without the verdict, the nuisances and the ambiguity a nuisance campaign
// would score "no gap" whatever its diagnosis says.)
// Then the top effect's parameters (their count, then 6 fields each: name, unit, value,
// sigma, status, at_bound). Last, "gap" and the effect's gap significance, the gap's held-out
// rms before and after with the lab's noise removed, and the diagnosis' held-out floor in g and
// in sigma (a line without them, or without the floor, is outdated: OutdatedCampaignResult,
// and the campaign is diagnosed again).
constexpr std::size_t kFixedResultFields = 17, kNuisanceFields = 8, kParameterFields = 6, kGapFields = 6;

std::string campaign_result_text(const BlindCampaign& k) {
  const Diagnosis& d = k.diagnosis;
  const bool has_top = !d.effects.empty();
  std::string t = fmt::format("{:.17g}\t{:.17g}\t{:.17g}\t{:d}\t{:d}\t{:.17g}\t{:.17g}\t{:.17g}\t{:.17g}\t{:.17g}",
                              k.simulate_s, k.wall_s, k.effect_max_sigma, d.gap_significant ? 1 : 0, d.explained() ? 1 : 0,
                              d.rms_before_g, d.rms_after_g, d.rms_before_sigma, d.rms_after_sigma,
                              has_top ? d.effects.front().value : 0.0);
  for (const std::string& x : {k.error, k.called, k.top, to_string(d.chosen), d.where}) t.append("\t").append(escaped(x));
  t.append("\t").append(escaped(has_top ? d.effects.front().name : std::string()));
  t.append(has_top ? "\t1" : "\t0");
  t.append("\t").append(escaped(verdict_text(d)));
  t.append(fmt::format("\t{}", d.ambiguous_with.size()));
  for (const std::string& a : d.ambiguous_with) t.append("\t").append(escaped(a));
  t.append(fmt::format("\t{}", d.nuisances.size()));
  for (const Nuisance& x : d.nuisances)
    t.append(fmt::format("\t{}\t{}\t{:.17g}\t{:.17g}\t{:d}\t{:d}\t{:d}\t{}", escaped(x.name), escaped(x.unit), x.value, x.sigma,
                         x.estimated ? 1 : 0, x.applied ? 1 : 0, x.significant ? 1 : 0, escaped(x.note)));
  const std::vector<FittedParameter> none;
  const std::vector<FittedParameter>& ps = has_top ? d.effects.front().parameters : none;
  t.append(fmt::format("\t{}", ps.size()));
  for (const FittedParameter& q : ps)
    t.append(fmt::format("\t{}\t{}\t{:.17g}\t{:.17g}\t{}\t{:d}", escaped(q.name), escaped(q.unit), q.value, q.sigma, to_string(q.status),
                         q.at_bound ? 1 : 0));
  t.append(fmt::format("\tgap\t{:.17g}\t{:.17g}\t{:.17g}\t{:.17g}\t{:.17g}", k.effect_gap_sigma, k.gap_rms_before_g,
                       k.gap_rms_after_g, d.rms_floor_g, d.rms_floor_sigma));
  return t;
}

void read_campaign_result(const std::string& text, BlindCampaign& k) {
  std::vector<std::string> f;
  for (std::size_t at = 0;;) {
    const std::size_t tab = text.find('\t', at);
    f.push_back(text.substr(at, tab == std::string::npos ? std::string::npos : tab - at));
    if (tab == std::string::npos) break;
    at = tab + 1;
  }
  const auto bad = [&](const std::string& what) {
    return std::invalid_argument(fmt::format("blind: a campaign's result ({} fields): {}", f.size(), what));
  };
  auto num = [&](std::size_t i) {
    if (i >= f.size()) throw bad(fmt::format("field {} missing", i + 1));
    std::size_t used = 0;
    double x = 0;
    try {
      x = std::stod(f[i], &used);
    } catch (const std::exception&) {
      used = std::string::npos;
    }
    if (used != f[i].size()) throw bad("not a number: " + f[i]);
    return x;
  };
  auto count = [&](std::size_t i) {
    const double x = num(i);
    if (!(x >= 0 && x < 1e6 && x == std::floor(x))) throw bad("not a count: " + f[i]);
    return static_cast<std::size_t>(x);
  };
  if (f.size() < kFixedResultFields + 3) throw bad(fmt::format("at least {} expected", kFixedResultFields + 3));
  Diagnosis& d = k.diagnosis;
  k.simulate_s = num(0), k.wall_s = num(1), k.effect_max_sigma = num(2);
  d.gap_significant = f[3] == "1";
  const bool explained = f[4] == "1";
  d.rms_before_g = num(5), d.rms_after_g = num(6), d.rms_before_sigma = num(7), d.rms_after_sigma = num(8);
  k.error = unescaped(f[10]), k.called = unescaped(f[11]), k.top = unescaped(f[12]);
  try {
    d.chosen = chosen_from_text(unescaped(f[13]));
  } catch (const std::invalid_argument& e) {
    throw bad(e.what());
  }
  d.where = unescaped(f[14]);
  d.effects.clear();
  if (f[16] == "1") {
    EffectFit e;
    e.name = unescaped(f[15]);
    e.value = num(9);
    d.effects.push_back(e);
  }
  std::size_t at = kFixedResultFields;
  const std::string verdict_words = unescaped(f[at++]);  // (what the flags and the nuisances say: checked below)
  const bool diagnosed = !verdict_words.empty();
  const std::size_t n_ambiguous = count(at++);
  if (f.size() < at + n_ambiguous + 1) throw bad("the ambiguous effects cut short");
  d.ambiguous_with.clear();
  for (std::size_t i = 0; i < n_ambiguous; ++i) d.ambiguous_with.push_back(unescaped(f[at++]));
  d.verdict = !diagnosed                   ? Verdict::none
              : !d.gap_significant         ? Verdict::no_significant_gap
              : !d.ambiguous_with.empty()  ? Verdict::ambiguous
              : explained                  ? Verdict::explained
                                           : Verdict::not_explained;
  const std::size_t n_nuisances = count(at++);
  if (f.size() < at + kNuisanceFields * n_nuisances + 1) throw bad(fmt::format("{} nuisances of {} fields expected", n_nuisances, kNuisanceFields));
  d.nuisances.clear();
  for (std::size_t i = 0; i < n_nuisances; ++i) {
    Nuisance x;
    x.name = unescaped(f[at]), x.unit = unescaped(f[at + 1]);
    x.value = num(at + 2), x.sigma = num(at + 3);
    x.estimated = f[at + 4] == "1", x.applied = f[at + 5] == "1", x.significant = f[at + 6] == "1";
    x.note = unescaped(f[at + 7]);
    d.nuisances.push_back(x);
    at += kNuisanceFields;
  }
  if (verdict_text(d) != verdict_words) throw bad(fmt::format("the verdict \"{}\" is not what the fields say", verdict_words));
  // The top effect's parameters (the natural forms' scoring reads them).
  const std::size_t n_parameters = count(at++);
  const std::size_t gap_at = at + kParameterFields * n_parameters;
  if (f.size() == gap_at || (f.size() == gap_at + 4 && f[gap_at] == "gap"))
    throw OutdatedCampaignResult(fmt::format(
        "blind: a campaign's result ({} fields) written before blind kept the effect's gap significance, the gap's "
        "noise-free held-out rms and the held-out floor: diagnose it again",
        f.size()));
  if (f.size() != gap_at + kGapFields || f[gap_at] != "gap")
    throw bad(fmt::format("{} parameters of {} fields, then \"gap\" and 5 numbers expected", n_parameters, kParameterFields));
  k.effect_gap_sigma = num(gap_at + 1), k.gap_rms_before_g = num(gap_at + 2), k.gap_rms_after_g = num(gap_at + 3);
  d.rms_floor_g = num(gap_at + 4), d.rms_floor_sigma = num(gap_at + 5);
  if (n_parameters > 0 && d.effects.empty()) throw bad("parameters without a top effect");
  for (std::size_t i = 0; i < n_parameters; ++i) {
    FittedParameter q;
    q.name = unescaped(f[at]), q.unit = unescaped(f[at + 1]);
    q.value = num(at + 2), q.sigma = num(at + 3), q.at_bound = f[at + 5] == "1";
    try {
      q.status = parameter_status_from_text(f[at + 4]);
    } catch (const std::invalid_argument& e) {
      throw bad(e.what());
    }
    d.effects.front().parameters.push_back(q);
    at += kParameterFields;
  }
}

}  // namespace vrelab::validation
