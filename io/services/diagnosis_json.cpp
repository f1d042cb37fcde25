#include "io/services/diagnosis_json.hpp"

#include <algorithm>
#include <cmath>
#include <map>
#include <string>
#include <utility>

#include <fmt/format.h>

#include "io/formats/output.hpp"
#include "io/formats/settings_json.hpp"
#include "rectification/measurement/vrc.hpp"
#include "validation/diagnosis/diagnosis_text.hpp"

namespace vrelab::io {

using nlohmann::json;

json nuisances_json(const validation::Diagnosis& d);

namespace {

json finite_or_null(double x) { return std::isfinite(x) ? json(x) : json(nullptr); }

// Every parameter of an effect: fitted (value, sigma), chosen (a discrete one) or held at its
// nominal (sigma null), with its unit and prior range.
json parameters_json(const validation::EffectFit& e) {
  json ps = json::array();
  for (const auto& q : e.parameters) {
    json p = {{"name", q.name},
              {"unit", q.unit},
              {"value", q.value},
              {"sigma", finite_or_null(q.sigma)},
              {"status", validation::to_string(q.status)},
              {"at_bound", q.at_bound},
              {"range", json::array({finite_or_null(q.lower), finite_or_null(q.upper)})}};
    if (!q.sign_identifiable) p["sign_identifiable"] = false;  // the value is a magnitude
    if (const auto ds = validation::datasheet_form(q.value, q.sigma, q.unit))  // IEEE Std 1293's units beside the model's
      p["datasheet"] = {{"value", ds->value}, {"sigma", finite_or_null(ds->sigma)}, {"unit", ds->unit}};
    ps.push_back(std::move(p));
  }
  return ps;
}

json effects_json(const validation::Diagnosis& d) {
  json effects = json::array();
  for (const auto& e : d.effects) {
    effects.push_back({{"name", e.name},
                       {"parameter", e.value},
                       {"parameter_name", e.parameter},
                       {"unit", e.unit},
                       {"sigma", finite_or_null(e.sigma)},
                       {"evidence", e.evidence},
                       {"heldout_chi2", e.heldout_chi2},
                       {"insample_chi2", finite_or_null(e.insample_chi2)},
                       {"insample_dof", e.insample_dof},
                       {"at_bound", e.at_bound},
                       {"parameters", parameters_json(e)}});
    if (!e.not_ranked.empty()) effects.back()["not_ranked"] = e.not_ranked;  // why it is no candidate
  }
  return effects;
}

// The run's input rms for the VRC (rectification/measurement/vrc.hpp): the sine's, the random
// part's, or both added.
double run_input_rms_g(const validation::RunRecord& r) {
  double s2 = r.sine_part ? std::pow(rectification::input_rms_g(r.vibration()), 2) : 0.0;
  if (r.random)
    for (const auto& t : r.random->psd)
      if (t) s2 += std::pow(vibration::rms_g(*t), 2);
  return std::sqrt(s2);
}

// Each run as read; with its diagnosis (prediction, gap, z, held-out gaps) when d has one per run.
json diagnosed_runs_json(const validation::Diagnosis& d, const validation::Campaign& c) {
  json runs = json::array();
  const bool diagnosed = d.runs.size() == c.runs.size();
  for (std::size_t k = 0; k < c.runs.size(); ++k) {
    const auto& r = c.runs[k];
    const VibrationKind kind =
        !r.random ? VibrationKind::sine : r.sine_part ? VibrationKind::sine_on_random : VibrationKind::random;
    runs.push_back({{"id", r.id},
                    {"kind", rectification::to_string(kind)},
                    {"frequency_Hz", r.frequency_Hz},
                    {"amplitude_g", r.amplitude_g},
                    {"direction", vec_json(r.direction)},
                    {"orientation_g", vec_json(r.orientation_g)},
                    {"measured_g", r.measured_g},
                    {"sigma_measured_g", r.sigma_g},
                    {"input_rms_g", run_input_rms_g(r)},
                    {"measured_vrc_ug_per_g2", rectification::vrc_ug_per_g2(r.measured_g, run_input_rms_g(r))}});
    if (diagnosed) {
      const auto& x = d.runs[k];
      runs.back().update({{"predicted_g", x.predicted_g},
                          {"sigma_predicted_g", x.sigma_predicted_g},
                          {"predicted_vrc_ug_per_g2", rectification::vrc_ug_per_g2(x.predicted_g, run_input_rms_g(r))},
                          {"gap_g", x.gap_g},
                          {"adjusted_gap_g", x.adjusted_gap_g},
                          {"z", x.z},
                          {"sigma_simulation_g", x.sigma_simulation_g},
                          {"heldout_before_g", x.heldout_before_g},
                          {"heldout_after_g", x.heldout_after_g},
                          {"heldout_floor_g", x.heldout_floor_g}});
    }
    if (r.motion) {
      runs.back()["motion"] = to_json(r.motion->departure);
      runs.back()["motion"]["used_by_prediction"] = r.motion->used();
    }
  }
  return runs;
}

json pairs_json(const validation::Diagnosis& d) {
  json pairs = json::array();
  for (const auto& p : d.pairs)
    pairs.push_back({{"names", {p.a, p.b}},
                     {"parameters", {p.pa, p.pb}},
                     {"evidence", p.evidence},
                     {"heldout_chi2", p.heldout_chi2},
                     {"insample_chi2", finite_or_null(p.insample_chi2)}});
  return pairs;
}

json campaign_row(const validation::BlindCampaign& k) {
  json h = json::array();
  for (const auto& x : k.hidden) {
    h.push_back({{"name", x.name}, {"parameter", x.parameter}});
    if (!x.form.empty()) h.back()["form"] = x.form;  // the natural form's further parameters
  }
  json row = {{"index", k.index}, {"seed", k.seed},           {"category", k.category}, {"hidden", h},
              {"called", k.called}, {"simulate_s", k.simulate_s}, {"wall_s", k.wall_s}};
  if (k.mixed) {  // its design (validation::blind_design): the runs of each kind
    const validation::CampaignDesign d = validation::blind_design(k);
    std::size_t sine_on = 0;
    for (const auto& r : d.random_runs) sine_on += r.sine_part;
    row["design"] = {{"sine_runs", d.sine_runs()},
                     {"random_runs", d.random_runs.size() - sine_on},
                     {"sine_on_random_runs", sine_on}};
  }
  if (k.category == "single" || k.category == "natural") {
    row["effect_gap_sigma"] = finite_or_null(k.effect_gap_sigma);  // the scored size
    row["effect_max_sigma"] = k.effect_max_sigma;                   // the largest run's size, beside
  }
  row["gap_rms_before_g"] = finite_or_null(k.gap_rms_before_g);  // held out, the lab's noise removed
  row["gap_rms_after_g"] = finite_or_null(k.gap_rms_after_g);
  if (k.category == "sigma_understated") row["noise_scale"] = k.noise_scale;
  if (k.category == "drift") row["drift_ug_per_h"] = k.drift_g_per_h * 1e6;
  if (k.category == "dynamics_off")
    row["manifest_dynamics_off"] = {{"crossover_ratio", k.manifest_crossover_ratio},
                                    {"pendulum_frequency_ratio", k.manifest_pendulum_ratio},
                                    {"phase_margin_offset_deg", k.manifest_margin_offset_deg}};
  if (k.error.empty()) {
    row["top"] = k.top;
    row["top_parameter"] = k.diagnosis.effects.front().value;
    json tp = json::array();
    for (const auto& q : k.diagnosis.effects.front().parameters)
      tp.push_back({{"name", q.name}, {"value", q.value}, {"sigma", std::isfinite(q.sigma) ? json(q.sigma) : json()}, {"status", validation::to_string(q.status)}});
    row["top_parameters"] = tp;
    row["rms_before_g"] = k.diagnosis.rms_before_g, row["rms_after_g"] = k.diagnosis.rms_after_g;
    row["where"] = k.diagnosis.where;
    row["verdict"] = validation::verdict_text(k.diagnosis);
    row["nuisances"] = nuisances_json(k.diagnosis);
    row["ambiguous_with"] = k.diagnosis.ambiguous_with;
  } else {
    row["error"] = k.error;
  }
  return row;
}

json families_json(const std::map<std::string, validation::FamilyScore>& families) {
  json j = json::object();
  for (const auto& [name, f] : families)
    j[name] = {{"n", f.n},         {"right", f.right},         {"right_physics", f.family}, {"unexplained", f.unexplained},
               {"no_gap", f.no_gap}, {"confidently_wrong", f.wrong}, {"ambiguous", f.ambiguous},   {"ambiguous_right_among", f.right_among},
               {"error", f.error}, {"right_effect_parameters_off", f.parameters_off}};
  return j;
}

json criteria_json(const std::vector<validation::BlindCriterion>& criteria) {
  json j = json::array();
  for (const auto& c : criteria)
    j.push_back({{"name", c.name},
                 {"k", c.k},
                 {"n", c.n},
                 {"rate", c.rate()},
                 {"ci95", {c.ci95.lo, c.ci95.hi}},
                 {"ci95_method", "Clopper-Pearson (exact binomial)"},
                 {"target", c.target},
                 {"target_is", c.at_least ? "at_least" : "at_most"},
                 {"met", c.met()}});
  return j;
}

}  // namespace

json to_json(const validation::DiagnoseSettings& s) { return settings_json(s); }

json to_json(const validation::BlindSettings& s) { return settings_json(s); }

json to_json(const plant::Dynamics& d) {
  return {{"pendulum_frequency_Hz", d.pendulum_frequency_Hz},
          {"pendulum_damping_ratio", d.pendulum_damping_ratio},
          {"angle_gain_rad_per_s2_per_g", d.angle_gain_rad_per_s2_per_g},
          {"loop_bandwidth_Hz", d.loop_bandwidth_Hz},
          {"phase_margin_deg", d.phase_margin_deg},
          {"integrator", d.integrator},
          {"integrator_zero_ratio", d.integrator_zero_ratio}};
}

json nuisances_json(const validation::Diagnosis& d) {
  json a = json::array();
  for (const auto& x : d.nuisances)
    a.push_back({{"name", x.name},
                 {"value", x.estimated ? json(x.value) : json(nullptr)},
                 {"sigma", finite_or_null(x.sigma)},
                 {"unit", x.unit},
                 {"estimated", x.estimated},
                 {"applied", x.applied},
                 {"significant", x.significant},
                 {"note", x.note}});
  return a;
}

json next_runs_json(const validation::Diagnosis& d) {
  json a = json::array();
  for (const auto& x : d.next_runs)
    a.push_back({{"frequency_Hz", x.frequency_Hz},
                 {"amplitude_g", x.amplitude_g},
                 {"direction", {x.direction[0], x.direction[1], x.direction[2]}},
                 {"orientation_g", {x.orientation_g[0], x.orientation_g[1], x.orientation_g[2]}},
                 {"separation_sigma", std::isfinite(x.separation_sigma) ? json(x.separation_sigma) : json(nullptr)},
                 {"between", x.between},
                 {"purpose", x.purpose},
                 {"if_first_sigma", std::isfinite(x.if_first_sigma) ? json(x.if_first_sigma) : json(nullptr)},
                 {"if_second_sigma", std::isfinite(x.if_second_sigma) ? json(x.if_second_sigma) : json(nullptr)}});
  return a;
}

json to_json(const validation::Diagnosis& d, const validation::Campaign& c) {
  json rms_z = json::object();
  for (const auto& [dir, z] : d.rms_z_by_direction) rms_z[dir] = z;
  return {{"gap_significant", d.gap_significant},
          {"verdict", validation::verdict_text(d)},
          {"chosen", validation::to_string(d.chosen)},
          {"pairs", pairs_json(d)},
          {"explained", d.explained()},
          {"where", d.where},
          {"folds", d.folds},
          {"significant_runs", d.significant_runs},
          {"chi2_nominal", d.chi2_nominal},
          {"amplitude_power", d.amplitude_power},
          {"frequency_power", d.frequency_power},
          {"peak", d.peak},
          {"rms_z_by_direction", rms_z},
          {"odd_in_a_IA_fraction", finite_or_null(d.odd_in_a_IA_fraction)},
          {"effects", effects_json(d)},
          {"nuisances", nuisances_json(d)},
          {"ambiguous_with", d.ambiguous_with},
          {"next_runs", next_runs_json(d)},
          {"shrinkage",
           {{"rms_before_g", d.rms_before_g},
            {"rms_after_g", d.rms_after_g},
            {"rms_before_sigma", d.rms_before_sigma},
            {"rms_after_sigma", d.rms_after_sigma},
            {"fraction_removed", d.rms_before_g > 0 ? 1 - d.rms_after_g / d.rms_before_g : 0.0},
            {"rms_floor_g", d.rms_floor_g},
            {"rms_floor_sigma", d.rms_floor_sigma},
            {"fraction_above_floor_removed", finite_or_null(d.shrinkage_above_floor())},
            {"on", "held-out runs (leave one amplitude out), gap the static test's coefficient errors cannot take up"}}},
          {"resimulated",
           {{"runs", d.resimulated_runs},
            {"rms_without_effect_g", d.resimulated_rms_before_g},
            {"rms_with_effect_g", d.resimulated_rms_after_g},
            {"failures", d.resimulation_failures},
            {"what", "measured - ODE plant (coefficients corrected by all runs under the chosen effect), runs with the "
                     "largest gaps"}}},
          {"identified", coefficients_json(d.identified)},
          {"skipped_runs", c.skipped},
          {"runs", diagnosed_runs_json(d, c)}};
}

json to_json(const rectification::MotionDeparture& m) {
  json j = {{"kind", rectification::to_string(m.kind)},
            {"axes", m.axes},
            {"sample_rate_Hz", m.sample_rate_Hz},
            {"samples", m.samples},
            {"commanded_rms_g", m.commanded_rms_g},
            {"measured_rms_g", m.measured_rms_g},
            {"measured_rms_axis_g", vec_json(m.measured_rms_axis_g)},
            {"rms_ratio", finite_or_null(m.rms_ratio)},
            {"transverse_ratio", finite_or_null(m.transverse_ratio)},
            {"transverse_sigma", finite_or_null(m.transverse_sigma)},
            {"transverse_axis_ratio",
             {finite_or_null(m.transverse_axis_ratio[0]), finite_or_null(m.transverse_axis_ratio[1]),
              finite_or_null(m.transverse_axis_ratio[2])}}};
  if (m.kind == VibrationKind::sine) {
    j["fundamental_ratio"] = finite_or_null(m.fundamental_ratio);
    j["harmonic2_ratio"] = finite_or_null(m.harmonic2_ratio);
    j["harmonic2_sigma"] = finite_or_null(m.harmonic2_sigma);
    j["harmonic3_ratio"] = finite_or_null(m.harmonic3_ratio);
    j["harmonic3_sigma"] = finite_or_null(m.harmonic3_sigma);
  } else {
    j["welch"] = {{"resolution_Hz", m.resolution_Hz}, {"segments", m.segments}, {"dof", m.dof}};
  }
  return j;
}

namespace {

// The run with the largest finite value of `field`, or null.
const validation::RunRecord* largest(const validation::Campaign& c, double rectification::MotionDeparture::*field) {
  const validation::RunRecord* best = nullptr;
  for (const auto& r : c.runs)
    if (r.motion && std::isfinite(r.motion->departure.*field) &&
        (!best || r.motion->departure.*field > best->motion->departure.*field))
      best = &r;
  return best;
}

}  // namespace

json motion_summary_json(const validation::Diagnosis& d, const validation::Campaign& c) {
  int sine = 0, sine_measured = 0;
  double rmin = INFINITY, rmax = -INFINITY;
  for (const auto& r : c.runs) {
    if (!r.random) ++sine, sine_measured += r.motion && r.motion->used() ? 1 : 0;
    if (r.motion && std::isfinite(r.motion->departure.rms_ratio))
      rmin = std::min(rmin, r.motion->departure.rms_ratio), rmax = std::max(rmax, r.motion->departure.rms_ratio);
  }
  const auto peak = [&](double rectification::MotionDeparture::*field, double rectification::MotionDeparture::*sigma) {
    const validation::RunRecord* r = largest(c, field);
    if (!r) return json(nullptr);
    return json{{"run", r->id}, {"value", r->motion->departure.*field}, {"sigma", finite_or_null(r->motion->departure.*sigma)}};
  };
  using MD = rectification::MotionDeparture;
  return {{"runs_with_reference", d.runs_with_measured_motion},
          {"sine_runs", sine},
          {"sine_runs_with_reference", sine_measured},
          {"rms_ratio_range", {finite_or_null(rmin), finite_or_null(rmax)}},
          {"largest_transverse_ratio", peak(&MD::transverse_ratio, &MD::transverse_sigma)},
          {"largest_harmonic2_ratio", peak(&MD::harmonic2_ratio, &MD::harmonic2_sigma)},
          {"largest_harmonic3_ratio", peak(&MD::harmonic3_ratio, &MD::harmonic3_sigma)},
          {"measured_not_fitted", d.measured_effects},
          {"policy",
           d.measured_effects.empty()
               ? "some sine runs have no reference: the table-motion effects stay candidates, their hypotheses applied to "
                 "the runs without one only"
               : "every sine run's motion is measured: the table-motion effects are measured, not fitted"}};
}

std::string motion_summary_text(const validation::Diagnosis& d, const validation::Campaign& c) {
  if (d.runs_with_measured_motion == 0) return "";
  const json j = motion_summary_json(d, c);
  std::string t = fmt::format("Reference channels: {} of {} runs measure the table's motion", d.runs_with_measured_motion,
                              c.runs.size());
  if (j["rms_ratio_range"][0].is_number())
    t += fmt::format("; rms / commanded {:.4g} to {:.4g}", j["rms_ratio_range"][0].get<double>(),
                     j["rms_ratio_range"][1].get<double>());
  for (const auto& [key, what] : {std::pair<const char*, const char*>{"largest_transverse_ratio", "transverse"},
                                  {"largest_harmonic2_ratio", "2nd harmonic"},
                                  {"largest_harmonic3_ratio", "3rd harmonic"}})
    if (!j[key].is_null())
      t += fmt::format("; {} up to {:.4g}{} ({})", what, j[key]["value"].get<double>(),
                       j[key]["sigma"].is_number() ? fmt::format(" +- {:.2g}", j[key]["sigma"].get<double>()) : std::string(),
                       j[key]["run"].get<std::string>());
  t += "\n";
  if (!d.measured_effects.empty()) {
    std::string names;
    for (const auto& n : d.measured_effects) names += (names.empty() ? "" : ", ") + n;
    t += "  measured, not fitted: " + names + "\n";
  } else {
    t += "  some sine runs have no reference: the table-motion effects are fitted on those runs only\n";
  }
  return t;
}

json to_json(const FolderDiagnosis& f) {
  const validation::Campaign& c = f.campaign;
  json j = {{"program", program_record()}, {"command", "diagnose"}, {"data", f.dir}, {"campaign", c.name}};
  j["nominal_dynamics"] = to_json(c.dynamics);
  j["nominal_dynamics"]["from"] =
      f.manifest.dynamics_given ? "the manifest's [dynamics]" : "defaults (the manifest has no [dynamics])";
  j["settings"] = to_json(f.settings);
  j["settings"]["from"] = f.settings_from;
  j["wall_s"] = f.wall_s;
  j["threads"] = f.threads;
  if (f.diagnosed) {
    j.update(to_json(f.diagnosis, c));
    if (f.diagnosis.runs_with_measured_motion > 0) j["motion"] = motion_summary_json(f.diagnosis, c);
  } else {  // read and checked only: the campaign as read, nothing judged
    j["diagnosed"] = false;
    j["skipped_runs"] = c.skipped;
    j["runs"] = diagnosed_runs_json(f.diagnosis, c);
  }
  j["units"] = {{"gap", "g"}, {"parameter", "see each effect's unit"}};
  return j;
}

json to_json(const validation::BlindResult& r) {
  const validation::BlindScores& s = r.scores;
  using validation::BlindScores;
  json rows = json::array();
  for (const auto& k : r.campaigns) rows.push_back(campaign_row(k));
  return {{"program", program_record()},
          {"command", "blind"},
          {"settings", to_json(r.settings)},
          {"n", r.settings.n},
          {"seed", r.settings.seed},
          {"wall_s", r.wall_s},
          {"threads", r.threads},
          {"ranks", r.ranks},
          {"top1_accuracy", BlindScores::rate(s.single_right, s.single)},
          {"single_effect_campaigns", s.single},
          {"single_effect_campaigns_below_5_sigma", s.small},
          {"single_below_5_sigma_explained_right", s.small_right},
          {"top_ranked_right_whatever_the_verdict", BlindScores::rate(s.single_top_right, s.single)},
          {"false_alarm_rate", BlindScores::rate(s.false_alarms, s.clean)},
          {"clean_campaigns", s.clean},
          {"unexplained_recognition", BlindScores::rate(s.out_of_library_unexplained, s.out_of_library)},
          {"out_of_library_campaigns", s.out_of_library},
          {"out_of_library_below_5_sigma", s.out_of_library_small},
          {"two_effect_explained_by_one_of_them", BlindScores::rate(s.two_by_one, s.two)},
          {"two_effect_explained_by_both", BlindScores::rate(s.two_by_both, s.two)},
          {"two_effect_campaigns", s.two},
          {"at_limit_campaigns", s.at_limit},
          {"at_limit_gap_found", BlindScores::rate(s.at_limit_found, s.at_limit)},
          {"family_size", "effect_gap_sigma: sqrt(g^T V^-1 g), the effect's gap as the nominal model sees it against the "
                          "diagnosis' covariance (static-test coefficient uncertainty included); scored when >= 5; a pair's: the "
                          "smaller of each effect's gap over the other's alone"},
          {"median_gap_shrinkage_noise_removed", s.median_gap_shrinkage},
          {"gap_shrinkage_campaigns", s.gap_shrinkage_campaigns},
          {"median_shrinkage", s.median_shrinkage},
          {"median_shrinkage_in_sigma", s.median_shrinkage_in_sigma},
          {"median_shrinkage_above_floor", s.median_shrinkage_above_floor},
          {"above_floor_campaigns", s.above_floor_campaigns},
          {"families", families_json(s.families)},
          {"criteria", criteria_json(r.Criteria())},
          {"family_size_max_run_sigma",
           {{"family_size", "effect_max_sigma: the largest |with - without| of any run over its sigma; scored when >= 5"},
            {"top1_accuracy", BlindScores::rate(s.by_max_run_sigma.single_right, s.by_max_run_sigma.single)},
            {"single_effect_campaigns", s.by_max_run_sigma.single},
            {"single_effect_campaigns_below_5_sigma", s.by_max_run_sigma.small},
            {"single_below_5_sigma_explained_right", s.by_max_run_sigma.small_right},
            {"median_shrinkage", s.by_max_run_sigma.median_shrinkage},
            {"median_shrinkage_in_sigma", s.by_max_run_sigma.median_shrinkage_in_sigma},
            {"families", families_json(s.by_max_run_sigma.families)}}},
          {"wrong", r.wrong},
          {"confusion", r.confusion},
          {"campaigns", rows}};
}

ConfusionMatrix confusion_matrix(const validation::BlindResult& r) {
  // Columns: every verdict blind can call (ambiguous and error too); rows: clean, the library,
  // two, then every other truth the run met (natural forms, out-of-library effects by name,
  // the nuisance and dynamics families), so that no campaign is left out.
  ConfusionMatrix m;
  m.called = {"clean"};
  for (const auto& n : r.library) m.called.push_back(n);
  for (const char* n : {"two_effects", "ambiguous", "unexplained", "error"}) m.called.push_back(n);  // two_effects: any "A + B"
  m.truths = {"clean"};
  for (const auto& n : r.library) m.truths.push_back(n);
  m.truths.push_back("two");
  for (const auto& [t, row] : r.confusion)
    if (std::find(m.truths.begin(), m.truths.end(), t) == m.truths.end()) m.truths.push_back(t);
  for (const auto& t : m.truths) {
    std::vector<int> counts(m.called.size(), 0);
    if (const auto row = r.confusion.find(t); row != r.confusion.end())
      for (const auto& [called, k] : row->second)
        for (std::size_t j = 0; j < m.called.size(); ++j)
          if (called == m.called[j] || (m.called[j] == "two_effects" && called.find(" + ") != std::string::npos)) counts[j] += k;
    m.counts.push_back(counts);
  }
  return m;
}

std::string confusion_csv(const validation::BlindResult& r) {
  const ConfusionMatrix m = confusion_matrix(r);
  std::string csv = "# rows: the hidden truth; columns: what diagnose called it (without the key)\ntruth";
  for (const auto& n : m.called) csv += "," + n;
  csv += "\n";
  for (std::size_t i = 0; i < m.truths.size(); ++i) {
    csv += m.truths[i];
    for (int k : m.counts[i]) csv += fmt::format(",{}", k);
    csv += "\n";
  }
  return csv;
}

}  // namespace vrelab::io
