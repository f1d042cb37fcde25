#include "validation/diagnosis/advice_check.hpp"

#include <algorithm>
#include <cstdio>
#include <map>
#include <random>
#include <sstream>
#include <stdexcept>
#include <utility>

#include <fmt/format.h>

namespace vrelab::validation {

std::string AdviceCheck::turned() const {
  if (outcome_after == "right" && outcome_before != "right") return "right";
  if (outcome_after == "wrong" && outcome_before != "wrong") return "wrong";
  return "left";
}

RunRecord simulate_advised_run(const BlindCampaign& k, const NextRun& advised, int runs_before, int which) {
  std::mt19937_64 rng(k.seed + 17);
  const plant::PlantConfig truth = blind_truth(rng);
  CampaignDesign one = blind_design(k);
  one.frequencies_Hz = {advised.frequency_Hz}, one.amplitudes_g = {advised.amplitude_g};
  one.directions = {advised.direction}, one.orientations_g = {advised.orientation_g};
  one.random_runs.clear();
  const std::uint64_t seed = k.seed * 1000003u + 7919u * static_cast<std::uint64_t>(which + 1);
  RunRecord r = simulate_campaign(truth, k.hidden, one, seed, 1).runs.at(0);
  // The lab's log as blind's: the run's time after the campaign's, its rest reading, the
  // drift and the extra scatter.
  std::mt19937_64 log_rng(seed + 29);
  std::normal_distribution<double> n01;
  r.id = fmt::format("advised{}", which + 1);
  log_run(r, k, static_cast<std::size_t>(runs_before), log_rng, n01);
  return r;
}

namespace {

// The two effects a separating run's `between` names ("A vs B"); empty without them.
std::pair<std::string, std::string> pair_of(const NextRun& x) {
  const std::size_t vs = x.between.find(" vs ");
  if (x.purpose != "separates" || vs == std::string::npos) return {};
  return {x.between.substr(0, vs), x.between.substr(vs + 4)};
}

const EffectFit* effect_named(const Diagnosis& d, const std::string& name) {
  for (const EffectFit& f : d.effects)
    if (f.name == name) return &f;
  return nullptr;
}

// sqrt |change of chi^2_B - chi^2_A| from `before` to `after` (A vs B as the run names them).
double obtained_separation(const NextRun& x, const Diagnosis& before, const Diagnosis& after) {
  const auto [a, b] = pair_of(x);
  if (a.empty()) return NAN;
  const EffectFit *a0 = effect_named(before, a), *b0 = effect_named(before, b), *a1 = effect_named(after, a), *b1 = effect_named(after, b);
  if (!a0 || !b0 || !a1 || !b1) return NAN;
  const double change = (b1->insample_chi2 - a1->insample_chi2) - (b0->insample_chi2 - a0->insample_chi2);
  return std::sqrt(std::abs(change));
}

// A separating run's promise when the truth is one of its pair (the rival's rise then), else
// the smaller side; a locating run's expected gap.
double promised_under_truth(const NextRun& x, const BlindCampaign& k) {
  const std::pair<std::string, std::string> names = pair_of(x);
  if (names.first.empty()) return x.separation_sigma;
  const auto hidden = [&k](const std::string& name) {
    return std::any_of(k.hidden.begin(), k.hidden.end(), [&](const HiddenEffect& h) { return h.name == name; });
  };
  const bool a = hidden(names.first), b = hidden(names.second);
  return a && !b ? x.if_first_sigma : b && !a ? x.if_second_sigma : x.separation_sigma;
}

}  // namespace

AdviceCheck check_advice(const BlindCampaign& key, const DiagnoseSettings& s) {
  AdviceCheck out;
  out.index = key.index, out.category = key.category;
  BlindCampaign k = key;
  try {
    Campaign camp = blind_lab_campaign(k);
    k.diagnosis = diagnose(camp, s);
    out.called_before = blind_called(k.diagnosis), out.outcome_before = blind_outcome(k);
    out.called_after = out.called_before, out.outcome_after = out.outcome_before;
    const Diagnosis before = k.diagnosis;
    const int n = static_cast<int>(camp.runs.size());
    Campaign all = camp;
    for (std::size_t i = 0; i < before.next_runs.size(); ++i) {
      AdvisedRunCheck rc;
      rc.advised = before.next_runs[i];
      const RunRecord run = simulate_advised_run(k, rc.advised, n + static_cast<int>(i), static_cast<int>(i));
      rc.measured_g = run.measured_g, rc.sigma_g = run.sigma_g;
      Campaign with = camp;
      with.runs.push_back(run);
      const Diagnosis d = diagnose(with, s);
      rc.called = blind_called(d);
      rc.promised_sigma = promised_under_truth(rc.advised, k);
      rc.obtained_sigma = rc.advised.purpose == "separates" ? obtained_separation(rc.advised, before, d) : std::abs(d.runs.back().z);
      out.runs.push_back(rc);
      all.runs.push_back(run);
    }
    if (!out.runs.empty()) {
      k.diagnosis = diagnose(all, s);
      out.called_after = blind_called(k.diagnosis), out.outcome_after = blind_outcome(k);
    }
  } catch (const std::exception& e) {
    out.error = e.what();
  }
  return out;
}

// Fields separated by '|', runs by ';' within the last field, a run's fields by ','; names
// and verdicts hold none of these (effect names are identifiers, " + " joins a pair).
std::string advice_check_text(const AdviceCheck& a) {
  std::string t = fmt::format("{}|{}|{}|{}|{}|{}|", a.index, a.category, a.called_before, a.called_after, a.outcome_before,
                              a.outcome_after);
  for (std::size_t i = 0; i < a.runs.size(); ++i) {
    const AdvisedRunCheck& r = a.runs[i];
    const NextRun& x = r.advised;
    t += fmt::format("{}{:.17g},{:.17g},{:.17g},{:.17g},{:.17g},{:.17g},{:.17g},{:.17g},{:.17g},{:.17g},{:.17g},{:.17g},{:.17g},{:.17g},{:.17g},{},{},{}",
                     i ? ";" : "", x.frequency_Hz, x.amplitude_g, x.direction[0], x.direction[1], x.direction[2],
                     x.orientation_g[0], x.orientation_g[1], x.orientation_g[2], x.separation_sigma, r.measured_g, r.sigma_g,
                     r.promised_sigma, r.obtained_sigma, x.if_first_sigma, x.if_second_sigma, x.purpose, x.between, r.called);
  }
  std::string err = a.error;
  std::replace_if(err.begin(), err.end(), [](char c) { return c == '|' || c == '\n' || c == '\t'; }, ' ');
  return t + "|" + err;
}

namespace {
std::vector<std::string> split(const std::string& s, char sep) {
  std::vector<std::string> out;
  std::string cur;
  std::istringstream in(s);
  while (std::getline(in, cur, sep)) out.push_back(cur);
  if (!s.empty() && s.back() == sep) out.emplace_back();
  return out;
}
}  // namespace

AdviceCheck read_advice_check(const std::string& text) {
  const std::vector<std::string> f = split(text, '|');
  if (f.size() != 8) throw std::invalid_argument("advice check: expected 8 fields separated by '|'");
  AdviceCheck a;
  try {
    a.index = std::stoi(f[0]);
    a.category = f[1], a.called_before = f[2], a.called_after = f[3], a.outcome_before = f[4], a.outcome_after = f[5];
    a.error = f[7];
    if (!f[6].empty())
      for (const std::string& run : split(f[6], ';')) {
        const std::vector<std::string> v = split(run, ',');
        if (v.size() != 18) throw std::invalid_argument("advice check: a run needs 18 fields");
        AdvisedRunCheck r;
        NextRun& x = r.advised;
        x.frequency_Hz = std::stod(v[0]), x.amplitude_g = std::stod(v[1]);
        x.direction = Vec3(std::stod(v[2]), std::stod(v[3]), std::stod(v[4]));
        x.orientation_g = Vec3(std::stod(v[5]), std::stod(v[6]), std::stod(v[7]));
        x.separation_sigma = std::stod(v[8]), r.measured_g = std::stod(v[9]), r.sigma_g = std::stod(v[10]);
        r.promised_sigma = std::stod(v[11]), r.obtained_sigma = std::stod(v[12]);
        x.if_first_sigma = std::stod(v[13]), x.if_second_sigma = std::stod(v[14]);
        x.purpose = v[15], x.between = v[16], r.called = v[17];
        a.runs.push_back(r);
      }
  } catch (const std::invalid_argument&) {
    throw;
  } catch (const std::exception& e) {
    throw std::invalid_argument(std::string("advice check: a number cannot be read: ") + e.what());
  }
  return a;
}

std::string advice_summary(const std::vector<AdviceCheck>& checks) {
  std::vector<double> ratio;
  std::vector<std::string> locate;
  std::map<std::string, std::map<std::string, int>> turned;  // verdict before -> right / wrong / left
  int errors = 0, advised = 0;
  for (const AdviceCheck& a : checks) {
    if (!a.error.empty()) {
      ++errors;
      continue;
    }
    if (a.runs.empty()) continue;
    ++advised;
    ++turned[a.called_before == "ambiguous" ? "ambiguous" : "unexplained"][a.turned()];
    for (const AdvisedRunCheck& r : a.runs) {
      if (r.advised.purpose == "separates" && r.promised_sigma > 0 && std::isfinite(r.obtained_sigma))
        ratio.push_back(r.obtained_sigma / r.promised_sigma);
      if (r.advised.purpose == "locates")
        locate.push_back(fmt::format("{} expected {} obtained {:.1f}", r.advised.between,
                                     std::isfinite(r.advised.separation_sigma) ? fmt::format("{:.1f}", r.advised.separation_sigma) : "-",
                                     r.obtained_sigma));
    }
  }
  std::sort(ratio.begin(), ratio.end());
  std::string t = fmt::format("advice checked on {} campaign(s) with advice ({} error(s))\n", advised, errors);
  if (!ratio.empty()) {
    const auto q = [&](double p) { return ratio[static_cast<std::size_t>(p * static_cast<double>(ratio.size() - 1) + 0.5)]; };
    t += fmt::format("  separating runs: {}; obtained / promised separation: median {:.2f} (quartiles {:.2f} - {:.2f}); within 0.5-2: {}\n",
                     ratio.size(), q(0.5), q(0.25), q(0.75),
                     std::count_if(ratio.begin(), ratio.end(), [](double r) { return r >= 0.5 && r <= 2; }));
  }
  for (const auto& entry : turned) {
    const std::map<std::string, int>& m = entry.second;
    const auto get = [&m](const char* w) { return m.count(w) ? m.at(w) : 0; };
    t += fmt::format("  {}: turned right {}, turned wrong {}, left {}\n", entry.first, get("right"), get("wrong"), get("left"));
  }
  for (const std::string& l : locate) t += "  locating run: " + l + "\n";
  return t;
}

}  // namespace vrelab::validation
