#include "validation/diagnosis/blind.hpp"

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <numbers>
#include <random>
#include <stdexcept>
#include <tuple>

#include <boost/math/distributions/binomial.hpp>
#include <fmt/format.h>

#include "core/dispatch.hpp"
#include "validation/diagnosis/diagnose.hpp"
#include "validation/diagnosis/diagnosis_text.hpp"
#include "validation/diagnosis/effects/common.hpp"

namespace vrelab::validation {
namespace {

using Clock = std::chrono::steady_clock;

double seconds_since(Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); }


// A hidden effect's parameter, drawn by the effect itself (its `draw`: where its gap is
// several sigma in the default design).
HiddenEffect draw_effect(const std::string& name, std::mt19937_64& rng) {
  const Effect* e = find_effect(name);
  if (!e) throw std::invalid_argument("blind: no effect named " + name);
  return draw_hidden(*e, rng);
}

// The library's effects with a natural form (Effect::draw_form), in the library's order.
std::vector<std::string> natural_form_effects() {
  std::vector<std::string> v;
  for (const Effect& e : effect_library())
    if (e.draw_form) v.push_back(e.name);
  return v;
}

// The out-of-library effects blind hides (the registry's, in its order: physically different
// from every library effect, each realised by a plant module or a shaker decorator).
std::vector<std::string> out_of_library_effects() {
  std::vector<std::string> v;
  for (const Effect& e : effect_registry())
    if (!e.in_library && e.draw) v.push_back(e.name);
  return v;
}

// Campaign i's key: its category and hidden effects, from its own seed. The mix, per 12:
// 2 clean, 2 out of library (1 in odd twelves, which have 1 dynamics_off instead), 1 pair,
// 1 sigma understated, 1 drift, 2 natural forms, 3 single.
BlindCampaign draw_campaign(int i, std::uint64_t seed, const std::vector<std::string>& library, bool mixed) {
  BlindCampaign k;
  k.index = i, k.seed = seed * 1000003u + static_cast<std::uint64_t>(i);
  k.mixed = mixed;
  std::mt19937_64 rng(k.seed);
  const int slot = i % 12;
  if (slot < 2) {
    k.category = "clean";
  } else if (slot == 8 && (i / 12) % 2 == 1) {
    // The manifest's nominal dynamics off the truth's by a few % (every other twelve, in the
    // second out-of-library slot): crossover and pendulum frequency 2-5 % either way, the
    // phase margin 1-4 deg either way; no effect hidden.
    k.category = "dynamics_off";
    const auto off = [&rng](double lo, double hi) {
      const double s = std::bernoulli_distribution(0.5)(rng) ? 1 : -1;
      return s * std::uniform_real_distribution<double>(lo, hi)(rng);
    };
    k.manifest_crossover_ratio = 1 + off(0.02, 0.05);
    k.manifest_pendulum_ratio = 1 + off(0.02, 0.05);
    k.manifest_margin_offset_deg = off(1, 4);
  } else if (slot == 2 || slot == 8) {
    k.category = "out_of_library";
    const std::vector<std::string> ool = out_of_library_effects();
    k.hidden.push_back(draw_effect(ool[std::uniform_int_distribution<std::size_t>(0, ool.size() - 1)(rng)], rng));
  } else if (slot == 4) {
    k.category = "sigma_understated";
    k.noise_scale = std::uniform_real_distribution<double>(1.8, 3.0)(rng);
  } else if (slot == 5) {
    k.category = "drift";
    const double s = std::bernoulli_distribution(0.5)(rng) ? 1 : -1;
    k.drift_g_per_h = s * std::exp(std::uniform_real_distribution<double>(std::log(0.2e-6), std::log(2e-6))(rng));
  } else if (slot == 3) {
    k.category = "two";
    std::vector<std::string> pick = library;
    std::shuffle(pick.begin(), pick.end(), rng);
    k.hidden = {draw_effect(pick[0], rng), draw_effect(pick[1], rng)};
  } else if (slot == 6 || slot == 7) {
    // A library effect in its natural form: its size as `draw`, its further parameters away
    // from the library's defaults (`draw_form`: damping, axis, phase, a second angle).
    k.category = "natural";
    const std::vector<std::string> nat = natural_form_effects();
    const Effect* e = find_effect(nat[std::uniform_int_distribution<std::size_t>(0, nat.size() - 1)(rng)]);
    k.hidden.push_back(draw_hidden_natural(*e, rng));
  } else {
    k.category = "single";
    k.hidden.push_back(draw_effect(library[std::uniform_int_distribution<std::size_t>(0, library.size() - 1)(rng)], rng));
  }
  return k;
}

// The lab's log of campaign k: each run's time (3 min a run, in the design's order) and a rest
// reading before it (sigma 0.3 ug); the drift in both; the scatter beyond the stated sigma.
// Returns what it added to each run's measured_g (g): the drift and the extra scatter, exactly
// 0 in a campaign with neither (drift_g_per_h 0, noise_scale 1: single, natural, clean, ...).
std::vector<double> apply_lab_log(Campaign& camp, const BlindCampaign& k) {
  std::mt19937_64 rng(k.seed + 29);
  std::normal_distribution<double> n01;
  std::vector<double> added(camp.runs.size());
  for (std::size_t j = 0; j < camp.runs.size(); ++j) added[j] = log_run(camp.runs[j], k, j, rng, n01);
  return added;
}

// The lab's log applied (apply_lab_log) and the manifest's dynamics the lab's estimate, not
// the truth's. Returns what the log added to each run's measured_g (g).
std::vector<double> hand_to_lab(Campaign& camp, const BlindCampaign& k) {
  std::vector<double> lab_g = apply_lab_log(camp, k);
  camp.dynamics.loop_bandwidth_Hz *= k.manifest_crossover_ratio;
  camp.dynamics.pendulum_frequency_Hz *= k.manifest_pendulum_ratio;
  camp.dynamics.phase_margin_deg += k.manifest_margin_offset_deg;
  return lab_g;
}

// Simulates campaign k from its truth and hidden effects, diagnoses it without the key.
void simulate_and_diagnose(BlindCampaign& k, const DiagnoseSettings& settings) {
  const auto t0 = Clock::now();
  try {
    std::mt19937_64 rng(k.seed + 17);
    const plant::PlantConfig truth = blind_truth(rng);
    std::vector<double> noise_g;  // each run's noise draw (the virtual lab's own)
    const CampaignDesign design = blind_design(k);
    Campaign camp = simulate_campaign(truth, k.hidden, design, k.seed, 1, {}, &noise_g);
    if (k.category == "single" || k.category == "natural" || k.category == "out_of_library") {
      // The effect's size through the ODE (the virtual lab without the effect, the same seed:
      // the same noise draws, so the difference is the effect's alone), not through the
      // hypothesis the diagnosis fits: which family a campaign is scored in must not depend on
      // the model under test. The scored size is the gap's significance as the nominal model
      // sees it (after what the static test's coefficient uncertainty absorbs; the nominal
      // model and the static test only); the largest run's size beside it.
      const Campaign clean = simulate_campaign(truth, {}, design, k.seed, 1);
      for (std::size_t j = 0; j < camp.runs.size(); ++j)
        k.effect_max_sigma =
            std::max(k.effect_max_sigma, std::abs(camp.runs[j].measured_g - clean.runs[j].measured_g) / camp.runs[j].sigma_g);
      k.effect_gap_sigma = nominal_gap_significance(camp, clean, settings);
    } else if (k.category == "two") {
      // Each effect's need: the gap the campaign with both shows over the campaign with the
      // other alone (the same noise draws), as the nominal model sees it; the smaller of the two
      // is the pair's size (scored as a pair when >= 5 sigma: both are then needed).
      double need = INFINITY;
      for (std::size_t e = 0; e < 2; ++e) {
        const Campaign other = simulate_campaign(truth, {k.hidden[1 - e]}, design, k.seed, 1);
        need = std::min(need, nominal_gap_significance(camp, other, settings));
      }
      k.effect_gap_sigma = need;
    }
    const std::vector<double> lab_g = hand_to_lab(camp, k);
    k.simulate_s = seconds_since(t0);
    k.diagnosis = diagnose(camp, settings);  // the key (k.hidden) is not passed
    // The gap's held-out rms without the lab's noise: a run's measured value is the ODE's plus
    // its noise draw plus what the lab log added (drift, extra scatter; 0 in single and
    // natural campaigns); diagnose removes the rest readings' line (fitted to their noise).
    // The campaign as diagnose saw it with the noise and the lab log's additions out and the
    // line back in (diagnose's removal takes it out again, the same line: the same rest
    // readings), with diagnose's sigma scaling when it applied one: its held-out nominal
    // residuals are the gap's own (gap_rms_without_lab_noise).
    const std::vector<double> line_g = drift_line_removed_g(camp);
    Campaign quiet = camp;
    for (std::size_t j = 0; j < quiet.runs.size(); ++j) quiet.runs[j].measured_g += line_g[j] - noise_g[j] - lab_g[j];
    const Nuisance* scale = k.diagnosis.nuisance("sigma_scale");
    const std::vector<double> gap_g = heldout_nominal_gap_g(quiet, settings, scale && scale->applied ? scale->value : 1.0);
    std::tie(k.gap_rms_before_g, k.gap_rms_after_g) = gap_rms_without_lab_noise(k.diagnosis, gap_g);
  } catch (const std::exception& e) {
    k.error = e.what();
  }
  k.wall_s = seconds_since(t0);
  const Diagnosis& d = k.diagnosis;
  k.called = !k.error.empty() ? "error" : blind_called(d);
  k.top = k.error.empty() && d.effects.front().not_ranked.empty() ? d.effects.front().name : "";
}

}  // namespace

double log_run(RunRecord& r, const BlindCampaign& k, std::size_t position, std::mt19937_64& rng,
               std::normal_distribution<double>& n01) {
  constexpr double kRunTime_h = 0.05, kRestSigma_g = 0.3e-6;
  r.time_h = kRunTime_h * static_cast<double>(position);
  const double drift = k.drift_g_per_h * r.time_h;
  r.rest_g = drift + kRestSigma_g * n01(rng);
  const double added = drift + std::sqrt(k.noise_scale * k.noise_scale - 1) * r.sigma_g * n01(rng);
  r.measured_g += added;
  return added;
}

Campaign blind_lab_campaign(const BlindCampaign& k) {
  std::mt19937_64 rng(k.seed + 17);
  const plant::PlantConfig truth = blind_truth(rng);
  Campaign camp = simulate_campaign(truth, k.hidden, blind_design(k), k.seed, 1);
  hand_to_lab(camp, k);
  return camp;
}

namespace {

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v.empty() ? 0.0 : v[v.size() / 2];
}

// The physics an effect belongs to (what it acts on); "" for none.
std::string physics_of(const std::string& name) {
  const Effect* e = find_effect(name);
  return e ? to_string(e->acts_on) : "";
}

// Whether the diagnosis' top effect (the one called) has every fitted parameter within 3 sigma
// of the hidden truth's (a phase's difference wrapped to [-pi, pi)) and every discrete one
// (chosen, or held at its nominal: either is a claim) equal to it; a held continuous parameter
// (the data do not pin it: reported at its nominal) is not judged; one whose sign is not
// identifiable (a magnitude) is judged against the truth's magnitude. `off` says which parameter failed, or lists the held ones.
bool match_parameters(const HiddenEffect& h, const Diagnosis& d, std::string* off) {
  const Effect* e = find_effect(h.name);
  if (!e || d.effects.empty() || d.effects.front().name != h.name) {
    *off = "no parameters reported";
    return false;
  }
  const std::vector<double> truth = h.values(*e);
  const std::vector<FittedParameter>& fit = d.effects.front().parameters;
  if (fit.size() != truth.size()) {
    *off = fmt::format("{} parameters reported for {}", fit.size(), truth.size());
    return false;
  }
  std::string held;
  for (std::size_t i = 0; i < fit.size(); ++i) {
    const FittedParameter& q = fit[i];
    double diff = q.value - truth[i];
    if (e->parameters[i].periodic) diff = std::remainder(diff, 2 * std::numbers::pi);
    if (!e->parameters[i].sign_identifiable) diff = std::abs(q.value) - std::abs(truth[i]);
    if (e->parameters[i].discrete) {  // held at its nominal or chosen, it is a claim (the mode's axis)
      if (diff != 0) {
        *off = fmt::format("{} {} {:.4g}, truth {:.4g}", q.name, to_string(q.status), q.value, truth[i]);
        return false;
      }
    } else if (q.status == ParameterStatus::held || (e->parameters[i].periodic && !(3 * q.sigma < std::numbers::pi))) {
      // A phase with 3 sigma over half the circle claims nothing: not judged, said (as held).
      held += q.status == ParameterStatus::held
                  ? fmt::format("{}{} held at {:.4g} (truth {:.4g})", held.empty() ? "" : ", ", q.name, q.value, truth[i])
                  : fmt::format("{}{} not pinned: {:.4g} +- {:.2g} (truth {:.4g})", held.empty() ? "" : ", ", q.name,
                                q.value, q.sigma, truth[i]);
    } else if (q.status == ParameterStatus::chosen) {
      if (diff != 0) {
        *off = fmt::format("{} chosen {:.4g}, truth {:.4g}", q.name, q.value, truth[i]);
        return false;
      }
    } else if (!(std::abs(diff) <= 3 * q.sigma)) {
      *off = fmt::format("{} = {:.4g} +- {:.2g}, truth {:.4g}{}: {:.1f} sigma", q.name, q.value, q.sigma, truth[i],
                         e->parameters[i].sign_identifiable ? "" : " (magnitudes compared)", std::abs(diff) / q.sigma);
      return false;
    }
  }
  *off = held;
  return true;
}

// The loop dynamics of a dynamics_off campaign as servo_dynamics' parameters would state them
// against the manifest: the truth's crossover and pendulum frequency over the manifest's (the
// manifest states the truth's x ratio), the truth's margin less the manifest's (-offset).
HiddenEffect loop_departure(const BlindCampaign& k) {
  return {"servo_dynamics", 1 / k.manifest_crossover_ratio, {-k.manifest_margin_offset_deg, 1 / k.manifest_pendulum_ratio}};
}

// Campaign k's outcome in its family (FamilyScore) sized by `size` (a single or natural
// effect's, in sigma), and why when not right (into `wrong` when given).
void score_family(const BlindCampaign& k, double size, std::map<std::string, FamilyScore>& families,
                  std::vector<std::string>* wrong) {
  const auto note = [wrong](const std::string& line) {
    if (wrong) wrong->push_back(line);
  };
  // Single effects below 5 sigma are a family apart (the issue scores >= 5 sigma); so are
  // out-of-library effects whose gap the design leaves below 5 sigma (no gap to call
  // unexplained: a proof mass's torsion without OA runs).
  const bool small = (k.category == "single" || k.category == "natural" || k.category == "out_of_library" || k.category == "two") &&
                     k.error.empty() && size < 5;
  FamilyScore& f = families[small ? k.category + "_below_5_sigma" : k.category];
  ++f.n;
  if (!k.error.empty()) {
    ++f.error;
    note(fmt::format("[{}] campaign {} (seed {}): error: {}", k.category, k.index, k.seed, k.error));
    return;
  }
  const Diagnosis& d = k.diagnosis;
  std::vector<std::string> truth;
  for (const auto& h : k.hidden) truth.push_back(h.name);
  if (k.category == "dynamics_off") truth.push_back(loop_departure(k).name);  // (an ambiguity naming it has the truth among)
  const auto is_truth = [&](const std::string& n) { return std::find(truth.begin(), truth.end(), n) != truth.end(); };
  std::string key = k.category;
  for (const auto& h : k.hidden) {
    key += fmt::format(" {} = {:.4g}", h.name, h.parameter);
    for (double x : h.form) key += fmt::format(", {:.4g}", x);
  }
  if (k.category == "single" || k.category == "natural" || k.category == "out_of_library")
    key += fmt::format(" (its gap {:.1f} sigma as the nominal model sees it, {:.1f} in the largest run)", k.effect_gap_sigma,
                       k.effect_max_sigma);
  if (k.category == "two") key += fmt::format(" (the weaker one's gap over the other's {:.1f} sigma as the nominal model sees it)", k.effect_gap_sigma);
  if (k.category == "sigma_understated") key += fmt::format(" (scatter x{:.2f})", k.noise_scale);
  if (k.category == "dynamics_off")
    key += fmt::format(" (manifest: crossover x{:.3f}, pendulum x{:.3f}, margin {:+.1f} deg)", k.manifest_crossover_ratio,
                       k.manifest_pendulum_ratio, k.manifest_margin_offset_deg);
  if (k.category == "drift") key += fmt::format(" ({:.3g} ug/h)", k.drift_g_per_h * 1e6);
  const std::string why = fmt::format("[{}] campaign {} (seed {}): {}; called \"{}\" (top {})", k.category, k.index, k.seed, key,
                                      verdict_text(d), k.top);
  if (!d.ambiguous_with.empty()) {
    ++f.ambiguous;
    // Among them: the truth's effect, or (an ambiguity between pairs, "A + B") a pair of the truth's.
    const auto names_truth = [&](const std::string& n) {
      const std::size_t plus = n.find(" + ");
      return plus == std::string::npos ? is_truth(n) : is_truth(n.substr(0, plus)) && is_truth(n.substr(plus + 3));
    };
    const bool among = std::any_of(d.ambiguous_with.begin(), d.ambiguous_with.end(), names_truth);
    f.right_among += among;
    if (!among) note(why + " (ambiguous, the truth not among them)");
    return;
  }
  // What was called: the effects of an "explained" verdict.
  const std::vector<std::string> called = d.explained() ? d.chosen.names : std::vector<std::string>{};
  const Nuisance* scale = d.nuisance("sigma_scale");
  const Nuisance* drift = d.nuisance("bias_drift");
  bool right = false, family = false;
  // A nuisance reported where there is none is a false alarm as much as a gap is.
  const bool scale_flagged = scale && scale->significant, drift_flagged = drift && drift->significant;
  if (k.category == "clean") right = !d.gap_significant && !scale_flagged && !drift_flagged;
  else if (k.category == "out_of_library") right = d.gap_significant && !d.explained();
  else if (k.category == "sigma_understated") right = !d.explained() && scale_flagged;
  else if (k.category == "drift")
    right = !d.explained() && drift_flagged &&
            std::abs(drift->value - k.drift_g_per_h * 1e6) < 3 * drift->sigma + 0.1 * std::abs(k.drift_g_per_h * 1e6);
  else if (k.category == "dynamics_off") {
    // The loop's dynamics found off the manifest: explained by servo_dynamics alone, every
    // parameter it fitted within 3 sigma of the truth's departure (below; a held one is not
    // judged). The manifest's crossover is the truth's x ratio, so the truth's is 1 / ratio of
    // the manifest's; likewise the pendulum frequency; its margin is the truth's + offset. A
    // pair with servo_dynamics found the loop and more: right physics.
    right = called.size() == 1 && is_truth(called[0]);
    family = !right && std::any_of(called.begin(), called.end(), is_truth);
  } else if (k.category == "two") {
    right = called.size() == 2 && is_truth(called[0]) && is_truth(called[1]);
    family = !right && std::any_of(called.begin(), called.end(), is_truth);
  } else {  // single, natural
    right = called.size() == 1 && is_truth(called[0]);
    family = !right && !called.empty() && std::all_of(called.begin(), called.end(), [&](const std::string& c) {
      return physics_of(c) == physics_of(truth.front());
    });
  }
  // A natural form is right when its fitted parameters are within 3 sigma of the truth too; so
  // are the loop dynamics of a manifest off the truth's.
  std::string off;
  if (right && k.category == "natural" && !match_parameters(k.hidden.front(), d, &off)) {
    ++f.parameters_off;
    note(why + " (the right effect, " + off + ")");
    return;
  }
  if (right && k.category == "dynamics_off" && !match_parameters(loop_departure(k), d, &off)) {
    ++f.parameters_off;
    note(why + " (the right effect, " + off + ")");
    return;
  }
  if (right) {
    ++f.right;
    return;
  }
  if (family) {
    ++f.family;
  } else if (d.explained()) {
    ++f.wrong;  // explained by an effect of another physics (or of none hidden)
  } else if (d.gap_significant) {
    ++f.unexplained;
  } else {
    ++f.no_gap;  // (a clean campaign here: no gap, but a nuisance flagged)
  }
  note(k.category == "clean" && !d.gap_significant ? why + " (a nuisance flagged on a clean campaign)" : why);
}

}  // namespace

std::string blind_called(const Diagnosis& d) {
  return !d.ambiguous_with.empty() ? "ambiguous"
         : !d.gap_significant      ? "clean"
         : d.explained()           ? to_string(d.chosen)
                                   : "unexplained";
}

std::string blind_outcome(const BlindCampaign& k) {
  std::map<std::string, FamilyScore> one;
  score_family(k, k.effect_gap_sigma, one, nullptr);
  const FamilyScore& f = one.begin()->second;
  return f.right ? "right" : f.family ? "family" : f.unexplained ? "unexplained" : f.no_gap ? "no_gap" : f.wrong ? "wrong"
         : f.ambiguous ? "ambiguous" : f.parameters_off ? "parameters_off" : "error";
}

namespace {

// Scores one campaign against its key into r (counts, confusion, the wrong ones).
// The held-out shrinkages 1 - after / before of the single campaigns: of the residuals' rms
// (with the runs' noise) in g and in each run's sigma, of the gap's rms (noise removed), and of
// the residuals above their floor (Diagnosis::shrinkage_above_floor, where the gap before
// exceeds it), over the scored single family; the first two over the single family by the
// largest run's size too.
struct Shrinkages {
  std::vector<double> residual_g, residual_sigma, gap, above_floor, largest_run_residual_g, largest_run_residual_sigma;
};

void score(const BlindCampaign& k, BlindResult& r, Shrinkages& sh) {
  BlindScores& s = r.scores;
  const Diagnosis& d = k.diagnosis;
  const std::string& called = k.called;
  score_family(k, k.effect_gap_sigma, s.families, &r.wrong);
  const CampaignDesign design = blind_design(k);  // (the expected chi^2 deviate is over its runs)
  if ((k.category == "single" || k.category == "natural") && k.error.empty() &&
      std::pow(k.effect_gap_sigma, 2) / std::sqrt(2.0 * static_cast<double>(design.sine_runs() + design.random_runs.size())) >= 5) {
    ++s.at_limit;
    s.at_limit_found += d.gap_significant;
  }
  score_family(k, k.effect_max_sigma, s.by_max_run_sigma.families, nullptr);
  if (k.category == "single" && k.error.empty()) {  // the single family by the largest run's size
    LargestRunSizeScores& o = s.by_max_run_sigma;
    if (k.effect_max_sigma < 5) {
      ++o.small, o.small_right += called == k.hidden[0].name;
    } else {
      ++o.single, o.single_right += called == k.hidden[0].name;
      if (d.rms_before_g > 0) sh.largest_run_residual_g.push_back(1 - d.rms_after_g / d.rms_before_g);
      if (d.rms_before_sigma > 0) sh.largest_run_residual_sigma.push_back(1 - d.rms_after_sigma / d.rms_before_sigma);
    }
  } else if (k.category == "single") {
    ++s.by_max_run_sigma.single;  // an error counts against it
  }
  if (k.category == "sigma_understated" || k.category == "drift" || k.category == "dynamics_off") {
    ++r.confusion[k.category][called];
    return;
  }
  if (k.category == "natural") {  // scored in its family only (parameters within 3 sigma)
    ++r.confusion[k.hidden[0].name + " (natural form)"][called];
    return;
  }
  ++r.confusion[k.category == "single"           ? k.hidden[0].name
                : k.category == "out_of_library" ? k.hidden[0].name + " (out of library)"
                                                 : k.category][called];
  const bool ool = k.category == "out_of_library";
  if ((k.category == "single" || ool) && k.error.empty() && k.effect_gap_sigma < 5) {
    // Below the "gap >= 5 sigma" (out of library: no gap to call unexplained in this
    // design): reported, not scored.
    if (ool) ++s.out_of_library_small;
    else ++s.small, s.small_right += called == k.hidden[0].name;
    r.wrong.push_back(fmt::format("campaign {} (seed {}): {} = {:.4g} hidden{}, its gap {:.1f} sigma as the nominal model sees "
                                  "it (largest run {:.1f} sigma; not scored); called {}",
                                  k.index, k.seed, k.hidden[0].name, k.hidden[0].parameter, ool ? " out of library" : "",
                                  k.effect_gap_sigma, k.effect_max_sigma, called));
  } else if (k.category == "single") {
    ++s.single;
    // Right: the gap found and attributed to the hidden effect (the verdict "explained by"
    // it); a right top rank with an "unexplained" verdict is counted apart.
    const bool right = called == k.hidden[0].name;
    s.single_right += right;
    s.single_top_right += k.error.empty() && d.gap_significant && k.top == k.hidden[0].name;
    if (k.error.empty() && k.gap_rms_before_g > 0) sh.gap.push_back(1 - k.gap_rms_after_g / k.gap_rms_before_g);
    if (k.error.empty() && d.rms_before_g > 0) sh.residual_g.push_back(1 - d.rms_after_g / d.rms_before_g);
    if (k.error.empty() && d.rms_before_sigma > 0) sh.residual_sigma.push_back(1 - d.rms_after_sigma / d.rms_before_sigma);
    if (k.error.empty() && std::isfinite(d.shrinkage_above_floor())) sh.above_floor.push_back(d.shrinkage_above_floor());

  } else if (k.category == "clean") {
    ++s.clean;
    const bool nuisance_flagged = std::any_of(d.nuisances.begin(), d.nuisances.end(), [](const Nuisance& x) { return x.significant; });
    s.false_alarms += called != "clean" || nuisance_flagged;

  } else if (ool) {
    ++s.out_of_library;
    s.out_of_library_unexplained += called == "unexplained";

  } else if (k.error.empty() && k.effect_gap_sigma < 5) {
    // A pair whose weaker effect adds less than 5 sigma to the other's gap: one of them needed
    // only; in its family apart (two_below_5_sigma), not in the pair rates. (A line without the
    // size, NaN, is scored as a pair: as blind scored it before it sized pairs.)
  } else {
    ++s.two;
    // The effects of an unambiguous "explained" verdict (what `called` names).
    std::vector<std::string> chosen;
    if (k.error.empty() && d.ambiguous_with.empty() && d.gap_significant && d.explained()) chosen = d.chosen.names;
    std::sort(chosen.begin(), chosen.end());
    const std::string& a = k.hidden[0].name;
    const std::string& b = k.hidden[1].name;
    s.two_by_one += chosen == std::vector<std::string>{a} || chosen == std::vector<std::string>{b};
    s.two_by_both += chosen == std::vector<std::string>{std::min(a, b), std::max(a, b)};
  }
}

}  // namespace

std::pair<double, double> gap_rms_without_lab_noise(const Diagnosis& d, const std::vector<double>& gap_before_g) {
  if (d.runs.empty() || d.runs.size() != gap_before_g.size())
    throw std::invalid_argument(fmt::format("gap_rms_without_lab_noise: {} runs diagnosed, {} runs' gaps", d.runs.size(),
                                            gap_before_g.size()));
  double sb = 0, sa = 0;
  for (std::size_t j = 0; j < d.runs.size(); ++j) {
    const double image = d.runs[j].heldout_before_g - gap_before_g[j];  // the noise's held-out image
    sb += gap_before_g[j] * gap_before_g[j];
    sa += std::pow(d.runs[j].heldout_after_g - image, 2);
  }
  const auto n = static_cast<double>(d.runs.size());
  return {std::sqrt(sb / n), std::sqrt(sa / n)};
}

bool parameters_match(const HiddenEffect& truth, const Diagnosis& d, std::string* why) {
  std::string w;
  const bool ok = match_parameters(truth, d, &w);
  if (why) *why = w;
  return ok;
}

BlindCampaign blind_key(int index, std::uint64_t seed, bool mixed) {
  std::vector<std::string> library;
  for (const auto& e : effect_library()) library.push_back(e.name);
  return draw_campaign(index, seed, library, mixed);
}

namespace {

// A PSD shape scaled to `rms_g`: GEVS (GSFC-STD-7000A), NAVMAT P-9492 or flat, 20 Hz - 2 kHz.
vibration::PsdTable shaped_psd(int shape, double rms_g) {
  using vibration::PsdRow;
  vibration::PsdTable t;
  if (shape == 0) t.rows = {PsdRow::level(20, 0.026), PsdRow::level(50, 0.16), PsdRow::level(800, 0.16), PsdRow::level(2000, 0.026)};
  else if (shape == 1) t.rows = {PsdRow::level(20, 0.01), PsdRow::level(80, 0.04), PsdRow::level(350, 0.04), PsdRow::level(2000, 0.007)};
  else t.rows = {PsdRow::level(20, 0.02), PsdRow::level(2000, 0.02)};
  const double k = std::pow(rms_g / vibration::rms_g(t), 2);
  for (PsdRow& r : t.rows) *r.psd_g2_per_Hz *= k;
  return t;
}

// A random part of `rms_g` in all (split evenly over its axes): a shape; one axis (IA twice as
// likely as PA or OA) or IA with PA or with OA; common or independent phases.
vibration::RandomProfile drawn_profile(std::mt19937_64& rng, double rms_g) {
  const int shape = std::uniform_int_distribution<int>(0, 2)(rng);
  const int axes = std::uniform_int_distribution<int>(0, 5)(rng);  // IA, IA, PA, OA, IA+PA, IA+OA
  vibration::RandomProfile p;
  if (axes <= 3) {
    p.psd[static_cast<std::size_t>(axes <= 1 ? 0 : axes - 1)] = shaped_psd(shape, rms_g);
  } else {
    p.psd[0] = shaped_psd(shape, rms_g / std::sqrt(2.0));
    p.psd[axes == 4 ? 1 : 2] = shaped_psd(shape, rms_g / std::sqrt(2.0));
  }
  p.coupling = effects::coin(rng) ? vibration::AxisCoupling::common : vibration::AxisCoupling::independent;
  return p;
}

}  // namespace

CampaignDesign blind_design(const BlindCampaign& k) {
  CampaignDesign d = default_design();
  if (!k.mixed) return d;
  std::mt19937_64 rng(k.seed + 31);
  std::vector<double> f = d.frequencies_Hz;
  std::shuffle(f.begin(), f.end(), rng);
  f.resize(3);
  std::sort(f.begin(), f.end());
  d.frequencies_Hz = f;
  d.directions = {Vec3::UnitX(), Vec3::UnitY()};
  const Vec3 up = d.orientations_g[0], down = d.orientations_g[1];
  const auto orientation = [&] { return effects::coin(rng) ? up : down; };
  const int n_random = std::uniform_int_distribution<int>(5, 8)(rng), n_sine_on = std::uniform_int_distribution<int>(1, 2)(rng);
  for (int i = 0; i < n_random; ++i) {
    RandomRunDesign r;
    r.profile = drawn_profile(rng, effects::log_uniform(rng, 2, 12));
    r.orientation_g = orientation();
    d.random_runs.push_back(r);
  }
  for (int i = 0; i < n_sine_on; ++i) {
    RandomRunDesign r;
    r.profile = drawn_profile(rng, effects::log_uniform(rng, 2, 6));
    r.orientation_g = orientation();
    r.sine_part = true;
    r.frequency_Hz = std::array{40.0, 100.0, 200.0, 400.0}[std::uniform_int_distribution<std::size_t>(0, 3)(rng)];
    r.amplitude_g = std::uniform_real_distribution<double>(1, 3)(rng);
    r.direction = effects::coin(rng) ? Vec3::UnitX() : Vec3::UnitY();
    d.random_runs.push_back(r);
  }
  d.random_record_s = 8;
  // The lab keeps the instrument's output within a navigation accelerometer's range (50 g) at 3
  // sigma, backing off a random run a hidden mode amplifies (the truth as simulate_and_diagnose
  // draws it).
  std::mt19937_64 truth_rng(k.seed + 17);
  return within_output_range(d, blind_truth(truth_rng), k.hidden, kBlindOutputRange_g);
}

plant::PlantConfig blind_truth(std::mt19937_64& rng) {
  std::uniform_real_distribution<double> u(0.7, 1.3);
  std::bernoulli_distribution sign(0.5);
  plant::PlantConfig p;
  auto& c = p.coefficients;
  c[plant::K1] = 1.25 * u(rng), c[plant::k0] = 1.5e-3 * u(rng), c[plant::k1_asym] = 2e-5 * u(rng);
  c[plant::k2] = 1.5e-5 * u(rng), c[plant::k3] = 1e-6 * u(rng), c[plant::k4] = 2e-7 * u(rng);
  c[plant::delta_OA] = 1e-4 * u(rng), c[plant::delta_PA] = -5e-5 * u(rng);
  for (int i : {plant::k_IP, plant::k_IO, plant::k_PO}) c[i] = (sign(rng) ? 1 : -1) * 5e-6 * u(rng);
  return p;
}

bool BlindSettings::IsValid(std::string* why) const { return core::validate(*this, why); }

BlindResult run_blind(const BlindSettings& settings, const BlindProgress& progress) {
  return run_blind(settings, progress, {}, {});
}

BlindResult run_blind(const BlindSettings& settings, const BlindProgress& progress,
                      const std::map<int, std::string>& done, const BlindCampaignDone& on_campaign) {
  std::string why;
  if (!settings.IsValid(&why)) throw std::invalid_argument("blind: " + why);
  BlindResult r;
  r.settings = settings;
  r.threads = core::threads_per_process(settings.threads);
  r.ranks = core::process_count();
  for (const auto& e : effect_library()) r.library.push_back(e.name);
  for (int i = 0; i < settings.n; ++i) r.campaigns.push_back(draw_campaign(i, settings.seed, r.library, settings.mixed));
  std::vector<std::size_t> todo;
  std::size_t finished = 0;
  for (int i = 0; i < settings.n; ++i) {
    const auto it = done.find(i);
    bool got = false;
    if (it != done.end()) {
      try {
        read_campaign_result(it->second, r.campaigns[static_cast<std::size_t>(i)]);
        got = true, ++finished;
      } catch (const OutdatedCampaignResult&) {  // diagnosed again (its key drawn afresh)
        r.campaigns[static_cast<std::size_t>(i)] = draw_campaign(i, settings.seed, r.library, settings.mixed);
      }
    }
    if (!got) todo.push_back(static_cast<std::size_t>(i));
  }
  r.resumed = static_cast<int>(finished);
  const auto start = Clock::now();
  const auto n = static_cast<std::size_t>(settings.n);
  // A campaign's result travels as its text (from another rank under MPI) and is read back
  // on rank 0: the same numbers whatever ran it.
  core::dispatch(
      todo, r.threads,
      [&](std::size_t i) {
        BlindCampaign k = r.campaigns[i];  // the key, drawn on every rank alike
        simulate_and_diagnose(k, settings.diagnose);
        return campaign_result_text(k);
      },
      [&](std::size_t i, const std::string& text) {
        read_campaign_result(text, r.campaigns[i]);
        if (on_campaign) on_campaign(static_cast<int>(i), text);
        if (progress) progress(++finished, n);
      });
  r.wall_s = seconds_since(start);
  if (!core::is_root_process()) return r;  // rank 0 holds the results
  Shrinkages sh;
  for (const BlindCampaign& k : r.campaigns) score(k, r, sh);
  r.scores.median_gap_shrinkage = median(sh.gap);
  r.scores.gap_shrinkage_campaigns = static_cast<int>(sh.gap.size());
  r.scores.median_shrinkage = median(sh.residual_g);
  r.scores.median_shrinkage_in_sigma = median(sh.residual_sigma);
  r.scores.median_shrinkage_above_floor = median(sh.above_floor);
  r.scores.above_floor_campaigns = static_cast<int>(sh.above_floor.size());
  r.scores.by_max_run_sigma.median_shrinkage = median(sh.largest_run_residual_g);
  r.scores.by_max_run_sigma.median_shrinkage_in_sigma = median(sh.largest_run_residual_sigma);
  return r;
}

RateInterval clopper_pearson(int k, int n, double confidence) {
  if (n < 0 || k < 0 || k > n || !(confidence > 0 && confidence < 1))
    throw std::invalid_argument(fmt::format("clopper_pearson: {} of {} at confidence {}", k, n, confidence));
  if (n == 0) return {};
  using B = boost::math::binomial_distribution<double>;
  const double tail = (1 - confidence) / 2;
  return {B::find_lower_bound_on_p(n, k, tail, B::clopper_pearson_exact_interval),
          B::find_upper_bound_on_p(n, k, tail, B::clopper_pearson_exact_interval)};
}

std::vector<BlindCriterion> BlindResult::Criteria() const {
  const auto right = [this](const std::string& family) {
    const auto it = scores.families.find(family);
    return it == scores.families.end() ? std::pair{0, 0} : std::pair{it->second.right, it->second.n};
  };
  std::vector<BlindCriterion> v;
  const auto add = [&v](std::string name, std::pair<int, int> kn, double target, bool at_least) {
    v.push_back({std::move(name), kn.first, kn.second, target, at_least, clopper_pearson(kn.first, kn.second)});
  };
  add("single, gap >= 5 sigma: right effect", right("single"), 0.95, true);
  add("natural form, gap >= 5 sigma: right effect, parameters within 3 sigma", right("natural"), 0.90, true);
  add("out of library: unexplained", right("out_of_library"), 0.90, true);
  add("sigma understated: flagged, no effect called", right("sigma_understated"), 0.90, true);
  add("drift: reported as drift", right("drift"), 0.90, true);
  add("two, each needed >= 5 sigma: both named", {scores.two_by_both, scores.two}, 0.60, true);
  add("two, each needed >= 5 sigma: one of them named at least", {scores.two_by_both + scores.two_by_one, scores.two}, 0.95, true);
  add("detection at the limit (expected chi^2 deviate >= 5): gap found", {scores.at_limit_found, scores.at_limit}, 0.95, true);
  add("clean: false alarm (a gap or a nuisance flagged)", {scores.false_alarms, scores.clean}, 0.02, false);
  int confidently_wrong = 0, all = 0;
  for (const auto& [name, f] : scores.families) confidently_wrong += f.wrong, all += f.n;
  add("all families: confidently wrong", {confidently_wrong, all}, 0.01, false);
  return v;
}

namespace {
std::string family_rows(const std::map<std::string, FamilyScore>& families, const std::vector<std::string>& order) {
  std::string t = fmt::format("  {:<22}{:>4}{:>7}{:>8}{:>8}{:>8}{:>8}{:>8}{:>11}{:>7}{:>8}\n", "family", "n", "right", "family", "unexpl",
                              "no gap", "WRONG", "ambig", "(right in)", "error", "par>3s");
  for (const auto& name : order) {
    const auto it = families.find(name);
    if (it == families.end()) continue;
    const FamilyScore& f = it->second;
    t += fmt::format("  {:<22}{:>4}{:>7}{:>8}{:>8}{:>8}{:>8}{:>8}{:>11}{:>7}{:>8}\n", name, f.n, f.right, f.family, f.unexplained, f.no_gap,
                     f.wrong, f.ambiguous, f.right_among, f.error, f.parameters_off);
  }
  return t;
}
}  // namespace

std::string BlindResult::BriefReport() const {
  const BlindScores& s = scores;
  std::string t = fmt::format("blind --n {} --seed {}{}: {:.1f} s wall on {} threads{}\n", settings.n, settings.seed,
                              settings.mixed ? " --mixed" : "", wall_s, threads, ranks > 1 ? fmt::format(" x {} MPI ranks", ranks) : "");
  if (settings.mixed)
    t += "  every campaign on a mixed design of its own: 36 sine runs, 5-8 random and 1-2 sine-on-random runs (blind_design)\n";
  const LargestRunSizeScores& o = s.by_max_run_sigma;
  t += "  a single or natural effect is scored when its gap is >= 5 sigma as the nominal model sees it (after the static "
       "test's coefficient uncertainty: effect_gap_sigma)\n";
  t += fmt::format("  top-1 attribution (single in-library effects, verdict 'explained by' the hidden one): {}/{} = {:.0f} %"
                   " (sized by the largest run, >= 5 sigma in some run: {}/{} = {:.0f} %)\n",
                   s.single_right, s.single, 100 * BlindScores::rate(s.single_right, s.single), o.single_right, o.single,
                   100 * BlindScores::rate(o.single_right, o.single));
  t += fmt::format("  hidden effect ranked first whatever the verdict: {}/{}\n", s.single_top_right, s.single);
  if (s.small > 0 || o.small > 0)
    t += fmt::format("  single effects with a gap below 5 sigma (not scored): {}, explained right anyway {} (sized by the "
                     "largest run, below 5 sigma in every run: {}, right {})\n",
                     s.small, s.small_right, o.small, o.small_right);
  t += fmt::format("  false alarms on clean campaigns: {}/{}\n", s.false_alarms, s.clean);
  t += fmt::format("  out-of-library called unexplained: {}/{} (gap >= 5 sigma; {} below, not scored)\n",
                   s.out_of_library_unexplained, s.out_of_library, s.out_of_library_small);
  t += fmt::format("  two effects, each needed >= 5 sigma (its gap over the other's): explained by both (a pair) {}/{}, by one of them {}/{}\n",
                   s.two_by_both, s.two, s.two_by_one, s.two);
  t += fmt::format("  median held-out shrinkage of the gap rms (the lab's noise removed; {} single campaigns): {:.0f} %\n",
                   s.gap_shrinkage_campaigns, 100 * s.median_gap_shrinkage);
  t += fmt::format("  median held-out shrinkage of the residual rms (with each run's noise): {:.0f} %, in each run's sigma "
                   "{:.0f} % (on the single family sized by the largest run: {:.0f} %, {:.0f} %)\n",
                   100 * s.median_shrinkage, 100 * s.median_shrinkage_in_sigma, 100 * o.median_shrinkage,
                   100 * o.median_shrinkage_in_sigma);
  t += fmt::format("  median held-out shrinkage above the floor (the residuals' rms beyond what no effect removes; {} single "
                   "campaigns): {:.0f} %\n",
                   s.above_floor_campaigns, 100 * s.median_shrinkage_above_floor);
  t += "Rates against their targets (the 95 % interval is Clopper-Pearson's: what a run of this size can tell):\n";
  for (const BlindCriterion& c : Criteria())
    t += c.n == 0 ? fmt::format("  {:<72} {:>4}/{:<4} {:>7}  {:>16}  target {} {:.0f} %: no campaigns\n", c.name, c.k, c.n, "-", "-",
                                c.at_least ? ">=" : "<=", 100 * c.target)
                  : fmt::format("  {:<72} {:>4}/{:<4} {:>5.1f} %  [{:5.1f}, {:5.1f}] %  target {} {:.0f} %: {}\n", c.name, c.k,
                                c.n, 100 * c.rate(), 100 * c.ci95.lo, 100 * c.ci95.hi, c.at_least ? ">=" : "<=", 100 * c.target,
                                c.met() ? "met" : "not met");
  t += "Per family (right; right physics, not the right effect; unexplained; no gap; WRONG: explained by another physics):\n";
  t += FamilyTable();
  t += "The single and natural families sized by the largest run (its gap in its sigma):\n";
  return t + family_rows(o.families, {"single", "single_below_5_sigma", "natural", "natural_below_5_sigma"});
}

std::string BlindResult::FamilyTable() const {
  return family_rows(scores.families, {"single", "single_below_5_sigma", "natural", "natural_below_5_sigma", "two", "two_below_5_sigma", "out_of_library", "out_of_library_below_5_sigma",
                                       "dynamics_off", "sigma_understated", "drift", "clean"});
}

std::string BlindResult::FullReport() const {
  std::string t = BriefReport();
  for (const auto& w : wrong) t += "  wrong: " + w + "\n";
  return t;
}

}  // namespace vrelab::validation
