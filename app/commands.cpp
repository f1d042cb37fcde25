#include "app/commands.hpp"

#include <algorithm>
#include <chrono>
#include <cstdlib>
#include <iostream>
#include <iterator>
#include <map>
#include <sstream>
#include <thread>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <numbers>

#include <fmt/format.h>
#include <fmt/ostream.h>
#include <unistd.h>

#include "io/case_file.hpp"
#include "io/output.hpp"
#include "rectification/prediction/eq3.hpp"
#include "rectification/prediction/frequency.hpp"
#include "rectification/measurement/series.hpp"
#include "vibration/sampled.hpp"
#include "validation/identification/static_test.hpp"
#include "vrelab_version.hpp"

namespace vrelab::app {
using namespace vrelab::io;
namespace {

using nlohmann::json;
using plant::kNumCoefficients;
constexpr double kArcsec = std::numbers::pi / (180.0 * 3600.0);

json array_json(const validation::CoefArray& a, const validation::CoefFlags& available) {
  plant::Coefficients k;
  k.v = a;
  return coefficients_json(k, &available);
}

std::string cell(double x) { return fmt::format(" {:>10.3e}", x); }
std::string text_cell(const std::string& s) { return fmt::format(" {:>10}", s); }

std::string header_line(const std::string& command, const Case& c, std::uint64_t seed) {
  return fmt::format("vrelab {} ({}) {} {}  [seed {}]\n", kProgramVersion, kGitDescribe, command, c.path, seed);
}

}  // namespace

void run_identify(const IdentifyOptions& o, std::ostream& out) {
  Case c = read_case(o.case_path);
  require(c, c.coefficients.has_value(), "coefficients", "identify");
  require(c, c.dividing_head.has_value(), "dividing_head", "identify");
  if (o.seed) c.seed = *o.seed;
  if (o.monte_carlo == 1) throw InputError("--monte-carlo: needs at least 2 trials (or 0 for none)");
  const DividingHead& head = *c.dividing_head;
  const plant::Coefficients& truth = *c.coefficients;

  // Identifiability first: a rank-deficient set is reported in words, not solved into noise.
  const validation::Identifiability ident = validation::identifiability(head.positions, c.fixed);
  if (!ident.full_rank()) {
    std::string msg = fmt::format(
        "{}: [dividing_head] with [identification] fixed: the {} free coefficients are not all "
        "identifiable from this position set (rank {} of {}).",
        c.path, ident.parameters, ident.rank, ident.parameters);
    for (const auto& s : ident.confounded) msg += "\n  - " + s;
    msg += "\n  Fix one coefficient of each group in [identification] fixed (the paper takes k1_asym "
           "from another test and assumes k_PP = k_OO = 0), or add positions.";
    throw InputError(msg);
  }

  validation::StaticTestSettings settings;
  if (head.from_ode) {
    const plant::PlantConfig plant = c.plant;
    settings.source = [plant](const Vec3& a) { return plant.coefficients[plant::K1] * plant::settled_output_g(plant, a); };
  }
  settings.fixed = c.fixed;
  settings.seed = c.seed;
  settings.monte_carlo_trials = o.monte_carlo;
  const validation::StaticTestReport r = validation::run_static_test(truth, head.positions, head.errors, settings);

  // ---- text report
  const auto& e = head.errors;
  out << header_line("identify", c, c.seed);
  out << fmt::format("Static test on the virtual dividing head: {}, {} reading(s) each = {} readings, from {}\n",
                     head.description, e.repeats, r.readings.size(),
                     head.from_ode ? "the ODE plant (settled in each position)" : "model (1)");
  out << fmt::format(
      "  errors: initial orientation [{:g}, {:g}, {:g}] arcsec, set angle sigma {:g} arcsec, reading "
      "noise sigma {:g} ug\n",
      e.initial_error_rad[0] / kArcsec, e.initial_error_rad[1] / kArcsec, e.initial_error_rad[2] / kArcsec,
      e.angle_sigma_rad / kArcsec, e.noise_sigma_g * 1e6);
  out << fmt::format(
      "Identifiability (least squares): {} free coefficients, rank {}, condition number {:.3g} (position set), "
      "{:.3g} (weighted)\n",
      r.identifiability.parameters, r.identifiability.rank, ident.condition_number, r.identifiability.condition_number);
  std::string fixed_list;
  for (int i = 0; i < kNumCoefficients; ++i)
    if (c.fixed[i]) fixed_list += fmt::format("{}{} = {:g}", fixed_list.empty() ? "" : ", ", plant::coefficient_name(i), *c.fixed[i]);
  if (!fixed_list.empty()) out << "  fixed at known values: " << fixed_list << "\n";
  for (const auto& n : r.notes) out << "  note: " << n << "\n";
  out << "\n";

  std::string line = fmt::format("{:<10}{:<7}{:>11}", "", "", "");
  for (const auto& m : r.methods) line += fmt::format("  {:<32}", m.name);
  out << line << "\n";
  line = fmt::format("{:<10}{:<7}{:>11}", "coef", "unit", "truth");
  for (std::size_t m = 0; m < r.methods.size(); ++m) line += "  " + text_cell("estimate") + text_cell("error") + text_cell("sigma");
  out << line << "\n";
  for (int i = 0; i < kNumCoefficients; ++i) {
    line = fmt::format("{:<10}{:<7}", plant::coefficient_name(i), unit_of(i, c)) + cell(truth[i]);
    for (const auto& m : r.methods) {
      line += "  ";
      if (!m.estimate.available[i]) {
        line += text_cell("n/a") + text_cell("") + text_cell("");
      } else {
        line += cell(m.estimate.value[i]) + cell(m.estimate.value[i] - truth[i]) +
                (m.estimate.assumed[i] ? text_cell("(given)") : cell(m.first_order.sigma[i]));
      }
    }
    out << line << "\n";
  }
  out << "error = estimate - truth; sigma: first-order standard uncertainty from set-angle errors and noise;\n"
         "(given): held at a known or assumed value, not estimated.\n";

  if (o.monte_carlo > 0) {
    out << fmt::format("\nUncertainty: first-order propagation vs Monte Carlo ({} trials, seed {})\n", o.monte_carlo,
                       c.seed + 1);
    for (const auto& m : r.methods) {
      out << fmt::format("  {}\n", m.name);
      out << fmt::format("  {:<10}{:>11}{:>11}{:>8}{:>11}{:>11}\n", "coef", "sigma_1st", "sigma_MC", "ratio",
                         "bias_1st", "bias_MC");
      for (int i = 0; i < kNumCoefficients; ++i) {
        if (!m.estimate.available[i] || m.estimate.assumed[i]) continue;
        const double s1 = m.first_order.sigma[i], smc = m.monte_carlo->std[i];
        out << fmt::format("  {:<10}{}{}{:>8.3f}{}{}\n", plant::coefficient_name(i), cell(s1), cell(smc),
                           s1 > 0 ? smc / s1 : 0.0, cell(m.first_order.bias[i]), cell(m.monte_carlo->mean_error[i]));
      }
    }
    out << "bias: effect of the initial orientation error (first-order) and the mean error over the trials (MC).\n";
  }

  if (o.json_path.empty()) return;
  // ---- JSON
  json j = result_record("identify", c);
  j["settings"] = {{"monte_carlo_trials", o.monte_carlo},
                   {"monte_carlo_seed", o.monte_carlo > 0 ? json(c.seed + 1) : json(nullptr)},
                   {"least_squares_weights", "1 / first-order variance of each reading"},
                   {"rank_tolerance", 1e-10}};
  json units = json::object();
  for (int i = 0; i < kNumCoefficients; ++i) units[std::string(plant::coefficient_name(i))] = unit_of(i, c);
  j["units"] = units;
  j["truth"] = coefficients_json(truth);
  j["estimates"] = {{"paper_printed", nullptr}, {"paper_corrected", nullptr}, {"least_squares", nullptr}};
  j["errors"] = j["estimates"];
  j["sigma"] = j["estimates"];
  j["bias_first_order"] = j["estimates"];
  j["given"] = j["estimates"];
  for (const auto& m : r.methods) {
    j["estimates"][m.name] = coefficients_json(m.estimate.value, &m.estimate.available);
    validation::CoefArray err{}, sigma = m.first_order.sigma, bias = m.first_order.bias;
    json given = json::array();
    for (int i = 0; i < kNumCoefficients; ++i) {
      err[i] = m.estimate.value[i] - truth[i];
      if (m.estimate.assumed[i]) {
        sigma[i] = bias[i] = 0.0;
        given.push_back(std::string(plant::coefficient_name(i)));
      }
    }
    j["errors"][m.name] = array_json(err, m.estimate.available);
    j["sigma"][m.name] = array_json(sigma, m.estimate.available);
    j["bias_first_order"][m.name] = array_json(bias, m.estimate.available);
    j["given"][m.name] = given;
    if (m.monte_carlo) {
      j["monte_carlo"][m.name] = {{"trials", m.monte_carlo->n},
                                  {"std", array_json(m.monte_carlo->std, m.estimate.available)},
                                  {"mean_error", array_json(m.monte_carlo->mean_error, m.estimate.available)}};
    }
  }
  const auto& id = r.identifiability;
  json free = json::array(), identifiable = json::object();
  for (int i = 0; i < kNumCoefficients; ++i)
    if (id.free[i]) {
      free.push_back(std::string(plant::coefficient_name(i)));
      identifiable[std::string(plant::coefficient_name(i))] = static_cast<bool>(id.identifiable[i]);
    }
  json fixed = json::object();
  for (int i = 0; i < kNumCoefficients; ++i)
    if (c.fixed[i]) fixed[std::string(plant::coefficient_name(i))] = *c.fixed[i];
  j["identifiability"] = {{"parameters", id.parameters},
                          {"rank", id.rank},
                          {"condition_number", ident.condition_number},
                          {"condition_number_weighted", id.condition_number},
                          {"free", free},
                          {"fixed", fixed},
                          {"identifiable", identifiable},
                          {"confounded", id.confounded}};
  j["notes"] = r.notes;
  json readings = json::array();
  for (const auto& rd : r.readings) {
    const auto& p = head.positions[static_cast<std::size_t>(rd.position)];
    readings.push_back({{"position", rd.position},
                        {"series", p.series},
                        {"angle_deg", p.angle_rad * 180 / std::numbers::pi},
                        {"a_nominal_g", vec_json(p.nominal_g)},
                        {"output", rd.output}});
  }
  j["readings"] = readings;
  j["readings_unit"] = c.output_unit;
  j["readings_source"] = head.from_ode ? "ode" : "model";
  write_atomic(o.json_path, j.dump(2) + "\n");
}

namespace {

// Eq. (3) corrected for the case's vibration (quasi-static; frequency-independent).
rectification::Eq3Terms predict_terms(const Case& c) {
  const VibrationSpec& v = *c.vibration;
  const plant::Coefficients& k = *c.coefficients;
  const Vec3& a = *c.orientation_g;
  if (v.type == "random") return rectification::random_rectification(k, a, *v.gaussian, c.range_limit_g);
  if (v.type == "sine_on_random")
    return rectification::sine_on_random_rectification(k, a, v.sine, *v.gaussian, c.range_limit_g);
  return rectification::sine_rectification(k, a, v.sine, c.range_limit_g);  // sine, swept sine
}

json vibration_json(const VibrationSpec& v) {
  json j = {{"type", v.type}};
  if (v.type != "random") {
    j["amplitude_g"] = vec_json(v.sine.amplitude_g);
    j["phase_deg"] = vec_json(v.sine.phase_rad * 180 / std::numbers::pi);
    j["frequency_Hz"] = v.sine.frequency_Hz > 0 ? json(v.sine.frequency_Hz) : json(nullptr);
  }
  if (v.gaussian) {
    j["rms_g"] = vec_json(v.gaussian->rms_g);
    const Eigen::Matrix3d cov = v.gaussian->covariance_g2();
    json cj = json::array();
    for (int i = 0; i < 3; ++i) cj.push_back(vec_json(cov.row(i).transpose()));
    j["covariance_g2"] = cj;
  }
  if (v.psd || v.swept) j["duration_s"] = v.duration_s;
  return j;
}

}  // namespace

void run_predict(const PredictOptions& o, std::ostream& out) {
  const Case c = read_case(o.case_path);
  require(c, c.coefficients.has_value(), "coefficients", "predict");
  require(c, c.orientation_g.has_value(), "orientation", "predict");
  require(c, c.vibration.has_value(), "vibration", "predict");
  const plant::Coefficients& k = *c.coefficients;
  const Vec3 a = *c.orientation_g;

  const VibrationSpec& vs = *c.vibration;
  const rectification::Eq3Terms terms = predict_terms(c);
  std::optional<double> printed;
  json vib = vibration_json(vs);
  std::string description = vs.type;
  if (vs.type == "sine" || vs.type == "swept_sine") {
    printed = rectification::sine_rectification_as_printed(k, a, vs.sine);
    const Vec3 ph = vs.sine.phase_rad * 180 / std::numbers::pi;
    description += fmt::format(", peak [{:g}, {:g}, {:g}] g, phase [{:g}, {:g}, {:g}] deg", vs.sine.amplitude_g[0],
                               vs.sine.amplitude_g[1], vs.sine.amplitude_g[2], ph[0], ph[1], ph[2]);
  }
  if (vs.gaussian)
    description += fmt::format("{}Gaussian rms [{:g}, {:g}, {:g}] g", vs.type == "sine_on_random" ? " + " : ", ",
                               vs.gaussian->rms_g[0], vs.gaussian->rms_g[1], vs.gaussian->rms_g[2]);

  out << header_line("predict", c, c.seed);
  out << fmt::format("Static acceleration a = [{:g}, {:g}, {:g}] g (|a| = {:.6g} g); vibration: {}\n", a[0], a[1], a[2],
                     a.norm(), description);
  if (c.range_limit_g) out << fmt::format("Range limit: +/-{:g} g (clipping term)\n", *c.range_limit_g);
  out << "Vibration error from model (1), quasi-static (eq. (3) corrected):\n";
  out << fmt::format("  {:<10}{:>14}{:>16}\n", "term", "error (ug)", "error (g)");
  json tj = json::object();
  for (int t = 0; t < rectification::kNumTerms; ++t) {
    if (t == rectification::t_clipping && !c.range_limit_g) continue;
    const double g = terms.g[t];
    tj[std::string(rectification::term_name(t))] = g;
    const bool omitted = t == rectification::t_k_PP || t == rectification::t_k_OO;
    out << fmt::format("  {:<10}{:>14.6f}{:>16.6e}{}\n", rectification::term_name(t), g * 1e6, g,
                       omitted ? "   (omitted by the printed eq. (3))" : "");
  }
  const double total = terms.total_g();
  out << fmt::format("  {:<10}{:>14.6f}{:>16.6e}\n", "total", total * 1e6, total);
  out << fmt::format("  of which the printed eq. (3) omits (k_PP, k_OO): {:.6f} ug\n", terms.omitted_by_paper_g() * 1e6);
  if (printed)
    out << fmt::format("Eq. (3) as printed in the paper gives {:.6f} ug (differs by {:.6f} ug)\n", *printed * 1e6,
                       (*printed - total) * 1e6);

  std::optional<rectification::FrequencyPrediction> fp;
  if (o.frequency_dependent) {
    if (vs.type != "sine")
      throw InputError(c.path + ": [vibration] type: --frequency-dependent takes a \"sine\" vibration");
    if (!(vs.sine.frequency_Hz > 0))
      throw InputError(c.path + ": [vibration] frequency_Hz: --frequency-dependent needs a positive frequency");
    fp = rectification::sine_rectification_at_frequency(c.plant, a, vs.sine, c.range_limit_g);
    out << fmt::format("At {:g} Hz through the plant's dynamics ({}): current amplitude |I| = {:.6g} g per {:g} g on IA, "
                       "pendulum angle |Theta| = {:.4g} rad\n",
                       vs.sine.frequency_Hz, c.physical ? "physical parameters" : "from coefficients",
                       std::abs(fp->current_amplitude_g), vs.sine.amplitude_g[IA], std::abs(fp->angle_amplitude_rad));
    out << fmt::format("  {:<20}{:>14}{:>16}\n", "term", "quasi-static", "at frequency");
    for (int t = 0; t < rectification::kNumTerms; ++t) {
      if (t == rectification::t_clipping && !c.range_limit_g) continue;
      out << fmt::format("  {:<20}{:>11.6f} ug{:>13.6f} ug\n", rectification::term_name(t), terms.g[t] * 1e6,
                         fp->terms.g[t] * 1e6);
    }
    out << fmt::format("  {:<20}{:>14}{:>13.6f} ug\n", "pickoff_nonlinearity", "-", fp->pickoff_g * 1e6);
    out << fmt::format("  {:<20}{:>14}{:>13.6f} ug\n", "pendulum_geometry", "-", fp->pendulum_geometry_g * 1e6);
    out << fmt::format("  {:<20}{:>11.6f} ug{:>13.6f} ug\n", "total", terms.total_g() * 1e6, fp->total_g() * 1e6);
  }

  if (o.json_path.empty()) return;
  json j = result_record("predict", c);
  j["model"] = "eq3_corrected_quasi_static";
  j["orientation_g"] = vec_json(a);
  j["vibration"] = vib;
  j["range_limit_g"] = c.range_limit_g ? json(*c.range_limit_g) : json(nullptr);
  j["total_g"] = total;
  j["terms"] = tj;
  j["omitted_by_paper_g"] = terms.omitted_by_paper_g();
  j["paper_printed_total_g"] = printed ? json(*printed) : json(nullptr);
  if (fp) {
    json ft = json::object();
    for (int t = 0; t < rectification::kNumTerms; ++t) {
      if (t == rectification::t_clipping && !c.range_limit_g) continue;
      ft[std::string(rectification::term_name(t))] = fp->terms.g[t];
    }
    ft["pickoff_nonlinearity"] = fp->pickoff_g;
    ft["pendulum_geometry"] = fp->pendulum_geometry_g;
    j["frequency_dependent"] = {{"frequency_Hz", vs.sine.frequency_Hz},
                                {"total_g", fp->total_g()},
                                {"terms", ft},
                                {"current_amplitude_g", std::abs(fp->current_amplitude_g)},
                                {"angle_amplitude_rad", std::abs(fp->angle_amplitude_rad)},
                                {"plant", plant_json(c.plant, c.physical.has_value())}};
  }
  j["units"] = {{"total_g", "g"}, {"terms", "g"}};
  write_atomic(o.json_path, j.dump(2) + "\n");
}


void run_shake(const ShakeOptions& o, std::ostream& out) {
  Case c = read_case(o.case_path);
  require(c, c.coefficients.has_value(), "coefficients", "shake");
  require(c, c.orientation_g.has_value(), "orientation", "shake");
  require(c, c.vibration.has_value(), "vibration", "shake");
  if (o.seed) c.seed = *o.seed, c.shake.readout.seed = *o.seed;
  const VibrationSpec& vs = *c.vibration;
  const auto& ro = c.shake.readout;
  const Vec3 a_static = *c.orientation_g;
  // The table's motion, the shaker's demand and its limits.
  std::shared_ptr<const vibration::Excitation> motion;
  vibration::ShakerDemand demand;
  double top_Hz = 0;
  const bool periodic = vs.type == "sine";
  try {
    const std::string where = fmt::format("{}:{}: [vibration]", c.path, vs.line);
    if ((vs.type == "random" || vs.type == "sine_on_random") && !vs.psd)
      throw InputError(where + " rms_g: a shaken " + vs.type + " profile needs PSD tables psd_IA / psd_PA / psd_OA");
    if (periodic && !(vs.sine.frequency_Hz > 0))
      throw InputError(where + " frequency_Hz: a shaker run needs a positive frequency");
    std::shared_ptr<const vibration::ToneExcitation> tone;
    if (vs.type == "sine" || vs.type == "sine_on_random") tone = std::make_shared<vibration::SineExcitation>(vs.sine);
    if (vs.swept) tone = std::make_shared<vibration::SweptSineExcitation>(*vs.swept);
    std::shared_ptr<const vibration::Excitation> m = tone;
    if (tone && !c.shaker.harmonics.empty()) m = std::make_shared<vibration::HarmonicDistortion>(tone, c.shaker.harmonics);
    if (tone && c.shaker.transverse) {
      if (c.shaker.harmonics.empty())
        m = std::make_shared<vibration::TransverseMotion>(tone, *c.shaker.transverse);
      else
        m = std::make_shared<vibration::TransverseMotion>(m, *c.shaker.transverse, vs.sine.frequency_Hz);
    }
    if (tone && c.shaker.rocking) {
      vibration::RockingSpec r = *c.shaker.rocking;
      r.static_gravity_g = a_static;
      r.g_m_per_s2 = c.g_m_per_s2;
      m = std::make_shared<vibration::Rocking>(m, tone, r);
    }
    if (!tone && c.shaker.imperfect())
      throw InputError(c.path + ": [shaker] transverse motion, harmonics and rocking apply to sine and swept-sine runs");
    if (vs.psd) {
      top_Hz = vibration::max_frequency_Hz(*vs.psd);
      auto random = std::make_shared<vibration::RandomExcitation>(*vs.psd, 8 * top_Hz, c.seed);
      m = m ? std::shared_ptr<const vibration::Excitation>(std::make_shared<vibration::SumExcitation>(
                  std::vector<std::shared_ptr<const vibration::Excitation>>{m, random}))
            : random;
      demand = vibration::shaker_demand(*vs.psd, c.g_m_per_s2);
    }
    if (vs.swept) demand = vibration::shaker_demand(*vs.swept, c.g_m_per_s2);
    if (vs.type == "sine" || vs.type == "sine_on_random") {
      const auto d = vibration::shaker_demand(vs.sine, c.shaker.harmonics, c.g_m_per_s2);
      demand = vs.type == "sine" ? d : vibration::combine(d, demand);
    }
    top_Hz = std::max(top_Hz, m->max_frequency_Hz());
    motion = m;
  } catch (const std::invalid_argument& e) {
    throw InputError(c.path + ": [vibration]/[shaker]: " + e.what());
  }
  try {
    vibration::check_feasible(demand, c.shaker.limits);
  } catch (const std::invalid_argument& e) {
    throw InputError(c.path + ": [shaker] the profile is beyond the shaker: " + e.what());
  }
  if (ro.active() && top_Hz >= ro.sample_rate_Hz / 2)
    throw InputError(fmt::format("{}: [vibration] content up to {:g} Hz is at or above the Nyquist frequency {:g} Hz of "
                                 "[readout] sample_rate_Hz = {:g}",
                                 c.path, top_Hz, ro.sample_rate_Hz / 2, ro.sample_rate_Hz));
  const Vec3& a = a_static;

  // The sampled record, streamed to a temporary file and renamed at the end.
  std::ofstream series;
  std::string series_tmp;
  rectification::SampleSink sink;
  if (!o.series_path.empty()) {
    const std::filesystem::path target(o.series_path);
    if (target.has_parent_path()) std::filesystem::create_directories(target.parent_path());
    series_tmp = o.series_path + ".tmp." + std::to_string(::getpid());
    series.open(series_tmp);
    if (!series) throw InputError("cannot write " + series_tmp);
    series << fmt::format("# vrelab {} ({}) shake {}  seed {}\n", kProgramVersion, kGitDescribe, c.path, c.seed);
    series << fmt::format("# output in {}; K1 = {:g} {}/g; static a_g = [{:g}, {:g}, {:g}]; at rest for t < 0, "
                          "vibration on from t = 0\n",
                          c.output_unit, (*c.coefficients)[plant::K1], c.output_unit, a[0], a[1], a[2]);
    series << fmt::format("time_s,input_IA_g,input_PA_g,input_OA_g,output_{}\n", c.output_unit);
    sink = [&series](double t, const Vec3& in, double u) {
      series << fmt::format("{:.9e},{:.9e},{:.9e},{:.9e},{:.12e}\n", t, in[0], in[1], in[2], u);
    };
  }
  const auto start = std::chrono::steady_clock::now();
  rectification::ShakeResult r;
  try {
    r = periodic ? rectification::shake_sine(c.plant, a, vs.sine, c.shake, sink, c.shaker.imperfect() ? motion.get() : nullptr)
                 : rectification::shake_excitation(c.plant, a, *motion, vs.duration_s, c.shake, sink);
  } catch (...) {
    if (series.is_open()) {
      series.close();
      std::filesystem::remove(series_tmp);  // no partial record
    }
    throw;
  }
  const double wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  const double predicted = predict_terms(c).total_g();

  out << header_line("shake", c, c.seed);
  if (c.physical)
    out << fmt::format("Plant: physical parameters, pendulum {:.4g} Hz, servo given{}{}\n",
                       c.plant.dynamics.pendulum_frequency_Hz, c.plant.dynamics.integrator ? " (PI)" : " (no integrator)",
                       c.plant.effects.empty() ? "" : ", effects:");
  else
    out << fmt::format("Plant: from coefficients, pendulum {:g} Hz, loop crossover {:g} Hz, phase margin {:g} deg{}{}\n",
                       c.plant.dynamics.pendulum_frequency_Hz, c.plant.dynamics.loop_bandwidth_Hz,
                       c.plant.dynamics.phase_margin_deg, c.plant.dynamics.integrator ? ", PI" : ", no integrator",
                       c.plant.effects.empty() ? "" : ", effects:");
  for (const auto& e : c.plant.effects) out << "  " << e->name() << "\n";
  out << fmt::format("Static a = [{:g}, {:g}, {:g}] g; vibration: {}\n", a[0], a[1], a[2], motion->describe());
  out << "Shaker demand: " << demand.report() << "\n";
  out << fmt::format("Measurement: {}; settled {:.4g} s ({:.3g} slowest time constants), {}{}\n", r.method, r.settle_s,
                     r.settle_s / r.slowest_time_constant_s,
                     periodic ? fmt::format("{} periods measured", r.periods)
                              : fmt::format("{:g} s measured (linear companion subtracted)", vs.duration_s),
                     r.samples ? fmt::format(", {} samples at {:g} Hz", r.samples, r.sample_rate_Hz) : "");
  out << fmt::format("  measured vibration error   {:>14.6f} ug  +/- {:.3g} ug (1 sigma)\n", r.measured_g * 1e6, r.sigma_g * 1e6);
  out << fmt::format("  eq. (3) corrected, truth   {:>14.6f} ug\n", predicted * 1e6);
  out << fmt::format("  measured - eq. (3)         {:>14.6f} ug ({:+.4g} %)\n", (r.measured_g - predicted) * 1e6,
                     predicted != 0 ? 100 * (r.measured_g / predicted - 1) : 0.0);
  out << fmt::format("  solver: {} steps, {} right-hand sides, {:.3g} s wall\n", r.steps, r.rhs_evaluations, wall_s);

  if (series.is_open()) {
    series.close();
    if (!series) throw InputError("writing " + series_tmp + " failed");
    std::filesystem::rename(series_tmp, o.series_path);
  }
  if (o.json_path.empty()) return;
  json j = result_record("shake", c);
  j["measured_g"] = r.measured_g;
  j["sigma_g"] = r.sigma_g;
  j["predicted_eq3_g"] = predicted;
  j["integral_slope_g"] = r.integral_slope_g;
  j["baseline_g"] = r.baseline_g;
  j["plant"] = plant_json(c.plant, c.physical.has_value());
  j["vibration"] = vibration_json(vs);
  j["vibration"]["description"] = motion->describe();
  j["shaker_demand"] = {{"acceleration_rms_g", vec_json(demand.acceleration_rms_g)},
                        {"acceleration_peak_g", vec_json(demand.acceleration_peak_g)},
                        {"velocity_peak_m_per_s", vec_json(demand.velocity_peak_m_per_s)},
                        {"displacement_peak_m", vec_json(demand.displacement_peak_m)},
                        {"stroke_peak_to_peak_m", demand.table_stroke_peak_to_peak_m()}};
  j["measurement"] = {{"method", r.method},
                      {"settle_s", r.settle_s},
                      {"slowest_time_constant_s", r.slowest_time_constant_s},
                      {"periods", r.periods},
                      {"samples", r.samples},
                      {"sample_rate_Hz", r.sample_rate_Hz}};
  j["settings"] = {{"solver", "CVODE BDF, dense direct linear solver"},
                   {"relative_tolerance", c.shake.relative_tolerance},
                   {"settle_decay", c.shake.settle_decay},
                   {"blocks", c.shake.blocks},
                   {"min_measure_s", c.shake.min_measure_s},
                   {"readout",
                    {{"sample_rate_Hz", ro.sample_rate_Hz},
                     {"noise_sigma_g", ro.noise_sigma_g},
                     {"quantisation_lsb_g", ro.quantisation_lsb_g}}}};
  j["solver_stats"] = {{"steps", r.steps}, {"rhs_evaluations", r.rhs_evaluations}, {"wall_s", wall_s}};
  j["units"] = {{"measured_g", "g"}, {"sigma_g", "g"}, {"predicted_eq3_g", "g"}};
  write_atomic(o.json_path, j.dump(2) + "\n");
}

void run_measure(const MeasureOptions& o, std::ostream& out) {
  const std::string& path = o.series_path;
  if (o.on_s.size() != 2 || o.baseline_s.size() != 2) throw InputError("--on and --baseline each take FROM,TO in seconds");
  rectification::SeriesWindows w;
  w.on_from_s = o.on_s[0], w.on_to_s = o.on_s[1];
  w.baseline_from_s = o.baseline_s[0], w.baseline_to_s = o.baseline_s[1];
  w.frequency_Hz = o.frequency_Hz, w.K1 = o.K1, w.blocks = o.blocks;
  try {
    w.validate();
  } catch (const std::invalid_argument& e) {
    throw InputError(std::string("measure: ") + e.what());
  }
  std::ifstream in(path);
  if (!in) throw InputError(path + ": cannot open the series (no such file?)");
  rectification::SeriesMeasurer m(w);
  std::string line;
  long line_no = 0;
  int column = -1;
  std::string column_name;
  std::vector<std::string> header;
  auto split = [](const std::string& l) {
    std::vector<std::string> f;
    std::size_t start = 0;
    while (true) {
      const std::size_t comma = l.find(',', start);
      f.push_back(l.substr(start, comma == std::string::npos ? std::string::npos : comma - start));
      if (comma == std::string::npos) break;
      start = comma + 1;
    }
    return f;
  };
  while (std::getline(in, line)) {
    ++line_no;
    if (!line.empty() && line.back() == '\r') line.pop_back();
    if (line.empty() || line[0] == '#') continue;
    const std::vector<std::string> f = split(line);
    if (header.empty()) {
      header = f;
      if (header.size() < 2) throw InputError(fmt::format("{}:{}: the header needs a time column and an output column", path, line_no));
      if (o.column.empty()) {
        column = static_cast<int>(header.size()) - 1;
      } else {
        for (std::size_t i = 0; i < header.size(); ++i)
          if (header[i] == o.column) column = static_cast<int>(i);
        if (column < 1) throw InputError(fmt::format("{}:{}: no column named '{}'", path, line_no, o.column));
      }
      if (column == 0) throw InputError(fmt::format("{}:{}: the output column cannot be the time column", path, line_no));
      column_name = header[static_cast<std::size_t>(column)];
      // A header names the columns: a first line of numbers means the header is missing.
      bool all_numbers = true;
      for (const auto& field : header) {
        std::size_t used = 0;
        try {
          std::stod(field, &used);
        } catch (const std::exception&) {
          used = 0;
        }
        all_numbers = all_numbers && used == field.size() && used > 0;
      }
      if (all_numbers)
        throw InputError(fmt::format("{}:{}: expected a header line naming the columns (e.g. time_s,output), got numbers",
                                     path, line_no));
      continue;
    }
    if (f.size() != header.size())
      throw InputError(fmt::format("{}:{}: {} fields, the header has {}", path, line_no, f.size(), header.size()));
    double t = 0, u = 0;
    try {
      std::size_t used_t = 0, used_u = 0;
      t = std::stod(f[0], &used_t);
      u = std::stod(f[static_cast<std::size_t>(column)], &used_u);
      if (used_t != f[0].size() || used_u != f[static_cast<std::size_t>(column)].size()) throw std::invalid_argument("");
    } catch (const std::exception&) {
      throw InputError(fmt::format("{}:{}: not a number in '{}'", path, line_no, line));
    }
    try {
      m.add(t, u);
    } catch (const std::invalid_argument& e) {
      throw InputError(fmt::format("{}:{}: {} (t = {}, {} = {})", path, line_no, e.what(), f[0], column_name,
                                   f[static_cast<std::size_t>(column)]));
    }
  }
  if (header.empty()) throw InputError(path + ": no header line and no samples");
  rectification::SeriesResult r;
  try {
    r = m.finish();
  } catch (const std::invalid_argument& e) {
    throw InputError(path + ": " + e.what());
  }
  out << fmt::format("vrelab {} ({}) measure {}\n", kProgramVersion, kGitDescribe, path);
  out << fmt::format("Output column '{}', K1 = {:g} per g; sample rate {:.6g} Hz\n", column_name, o.K1, r.sample_rate_Hz);
  out << fmt::format("Baseline [{:g}, {:g}) s: {} samples, mean {:.9f} g\n", w.baseline_from_s, w.baseline_to_s,
                     r.samples_baseline, r.baseline_g);
  out << fmt::format("Vibration [{:g}, {:g}) s{}: {} samples\n", w.on_from_s, r.on_to_used_s,
                     o.frequency_Hz > 0 ? fmt::format(" (whole periods of {:g} Hz)", o.frequency_Hz) : "", r.samples_on);
  out << fmt::format("  vibration error          {:>14.6f} ug  +/- {:.3g} ug (1 sigma, batch means of {} blocks)\n",
                     r.measured_g * 1e6, r.sigma_g * 1e6, o.blocks);
  out << fmt::format("  running-integral slope   {:>14.6f} ug\n", r.integral_slope_g * 1e6);
  if (o.json_path.empty()) return;
  json j;
  j["program"] = program_record();
  j["command"] = "measure";
  j["series"] = {{"file", path}, {"column", column_name}, {"K1", o.K1}};
  j["windows"] = {{"baseline_s", {w.baseline_from_s, w.baseline_to_s}},
                  {"on_s", {w.on_from_s, r.on_to_used_s}},
                  {"frequency_Hz", o.frequency_Hz > 0 ? json(o.frequency_Hz) : json(nullptr)},
                  {"blocks", o.blocks}};
  j["measured_g"] = r.measured_g;
  j["sigma_g"] = r.sigma_g;
  j["integral_slope_g"] = r.integral_slope_g;
  j["baseline_g"] = r.baseline_g;
  j["samples"] = {{"on", r.samples_on}, {"baseline", r.samples_baseline}};
  j["sample_rate_Hz"] = r.sample_rate_Hz;
  write_atomic(o.json_path, j.dump(2) + "\n");
}

namespace {

std::uint64_t fnv1a(const std::string& s) {
  std::uint64_t h = 1469598103934665603ull;
  for (unsigned char ch : s) h = (h ^ ch) * 1099511628211ull;
  return h;
}

constexpr const char* kSweepColumns =
    "index,frequency_Hz,amplitude_g,direction_IA,direction_PA,direction_OA,a_IA_g,a_PA_g,a_OA_g,measured_g,sigma_g,"
    "predicted_eq3_g,settle_s,steps,wall_s";

std::string sweep_line(const rectification::SweepRow& r) {
  const auto& c = r.condition;
  return fmt::format("{},{:.10g},{:.10g},{:.10g},{:.10g},{:.10g},{:.10g},{:.10g},{:.10g},{:.12e},{:.4e},{:.12e},{:.6g},{},{:.4g}\n",
                     c.index, c.frequency_Hz, c.amplitude_g, c.direction[0], c.direction[1], c.direction[2],
                     c.orientation_g[0], c.orientation_g[1], c.orientation_g[2], r.measured_g, r.sigma_g,
                     r.predicted_eq3_g, r.settle_s, r.steps, r.wall_s);
}

}  // namespace

int run_sweep(const SweepOptions& o, std::ostream& out) {
  namespace fs = std::filesystem;
  const Case c = read_case(o.case_path);
  require(c, c.coefficients.has_value(), "coefficients", "sweep");
  require(c, c.sweep.has_value(), "sweep", "sweep");
  const rectification::SweepGrid& grid = *c.sweep;
  // The fingerprint ties a results file to the case and the program: a resumed sweep must
  // not mix rows of different settings.
  const std::string fingerprint = fmt::format("{:016x}", fnv1a(c.content.dump() + kProgramVersion + kGitDescribe));
  const auto& ro = c.shake.readout;
  const std::string header = fmt::format(
      "# vrelab {} ({}) sweep {}\n# fingerprint {} conditions {} seed {}\n"
      "# settings: CVODE BDF, relative_tolerance {:g}, settle_decay {:g}, blocks {}, min_measure_s {:g}, "
      "readout sample_rate_Hz {:g} noise_sigma_g {:g} quantisation_lsb_g {:g}; units: g, Hz, s\n{}\n",
      kProgramVersion, kGitDescribe, c.path, fingerprint, grid.size(), c.seed, c.shake.relative_tolerance,
      c.shake.settle_decay, c.shake.blocks, c.shake.min_measure_s, ro.sample_rate_Hz, ro.noise_sigma_g,
      ro.quantisation_lsb_g, kSweepColumns);
  std::map<std::size_t, std::string> rows;  // index -> line
  const fs::path path(o.out_path);
  if (path.has_parent_path()) fs::create_directories(path.parent_path());
  if (fs::exists(path) && !o.restart) {
    std::ifstream in(path);
    std::string line, text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    if (text.find("# fingerprint " + fingerprint) == std::string::npos)
      throw InputError(o.out_path + ": exists with rows of another case or program version; use --restart to discard it");
    // A run interrupted mid-write leaves an unterminated last line: drop it.
    if (!text.empty() && text.back() != '\n') text.erase(text.rfind('\n') + 1);
    std::istringstream lines(text);
    long line_no = 0;
    while (std::getline(lines, line)) {
      ++line_no;
      if (line.empty() || line[0] == '#' || line.rfind("index,", 0) == 0) continue;
      const std::string index_field = line.substr(0, line.find(','));
      std::size_t used = 0;
      unsigned long index = 0;
      try {
        index = std::stoul(index_field, &used);
      } catch (const std::exception&) {
        used = 0;
      }
      if (used != index_field.size() || used == 0 || std::count(line.begin(), line.end(), ',') != 14 ||
          index >= grid.size())
        throw InputError(fmt::format("{}:{}: not a row of this sweep (index '{}', {} conditions); use --restart to "
                                     "discard the file",
                                     o.out_path, line_no, index_field, grid.size()));
      rows[index] = line + "\n";
    }
  }
  // Rewrite the kept rows (dropping any partial line), then append as conditions finish.
  {
    std::string text = header;
    for (const auto& [i, l] : rows) text += l;
    write_atomic(o.out_path, text);
  }
  std::vector<std::size_t> skip;
  for (const auto& [i, l] : rows) skip.push_back(i);
  const int threads = o.threads >= 0 ? o.threads : c.sweep_threads;
  const int used = threads > 0 ? threads : static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));

  out << header_line("sweep", c, c.seed);
  out << fmt::format("Grid: {} frequencies x {} amplitudes x {} directions x {} orientations = {} conditions; "
                     "{} already in {}; {} thread(s)\n",
                     grid.frequencies_Hz.size(), grid.amplitudes_g.size(), grid.directions.size(),
                     grid.orientations_g.size(), grid.size(), rows.size(), o.out_path, used);
  out.flush();
  std::ofstream append(o.out_path, std::ios::app);
  std::vector<std::string> failures;
  const bool tty = ::isatty(2);
  std::size_t last_decile = 0;
  const auto start = std::chrono::steady_clock::now();
  rectification::run_sweep(
      c.plant, *c.coefficients, c.shake, grid, skip, used,
      [&](const rectification::SweepRow& r) {
        if (!r.ok) {
          failures.push_back(fmt::format("condition {} ({:g} Hz, {:g} g): {}", r.condition.index, r.condition.frequency_Hz,
                                         r.condition.amplitude_g, r.error));
          return;
        }
        const std::string l = sweep_line(r);
        append << l << std::flush;  // one row per write: an interruption loses at most this row
        rows[r.condition.index] = l;
      },
      [&](const rectification::SweepProgress& p) {
        if (!o.progress) return;
        const double eta = p.done ? p.elapsed_s / static_cast<double>(p.done) * static_cast<double>(p.total - p.done) : 0;
        if (tty) {
          const int width = 30, fill = static_cast<int>(width * p.done / std::max<std::size_t>(1, p.total));
          std::cerr << fmt::format("\r[{}{}] {}/{} conditions, {:.1f} s, ETA {:.0f} s ", std::string(fill, '#'),
                                   std::string(width - fill, '.'), p.done, p.total, p.elapsed_s, eta)
                    << std::flush;
        } else if (p.total && p.done * 10 / p.total > last_decile) {
          last_decile = p.done * 10 / p.total;
          std::cerr << fmt::format("sweep: {}/{} conditions, {:.1f} s\n", p.done, p.total, p.elapsed_s);
        }
      });
  if (o.progress && tty) std::cerr << "\n";
  append.close();
  const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  // Final file: every row, sorted by condition.
  std::string text = header;
  for (const auto& [i, l] : rows) text += l;
  write_atomic(o.out_path, text);
  out << fmt::format("Done: {} conditions in {:.3g} s wall ({} written, {} failed) -> {}\n", grid.size() - skip.size(),
                     wall, rows.size(), failures.size(), o.out_path);
  for (const auto& f : failures) out << "  failed: " << f << "\n";
  return static_cast<int>(failures.size());
}

void run_frequency(const FrequencyOptions& o, std::ostream& out) {
  const Case c = read_case(o.case_path);
  require(c, c.coefficients.has_value(), "coefficients", "frequency");
  require(c, c.orientation_g.has_value(), "orientation", "frequency");
  const rectification::FrequencyStudySettings fs = c.frequency_study.value_or(rectification::FrequencyStudySettings{
      rectification::spaced(1, 5000, 80, true), rectification::spaced(1, 5000, 10, true)});
  const auto start = std::chrono::steady_clock::now();
  const auto curves = rectification::frequency_study(c.plant, *c.orientation_g, fs);
  const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();

  std::string grid_csv = fmt::format("# vrelab {} ({}) frequency {}; units: Hz, g\nmechanism,frequency_Hz,predicted_g,eq3_g,ratio\n",
                                     kProgramVersion, kGitDescribe, c.path);
  std::string ode_csv = fmt::format("# vrelab {} ({}) frequency {}; units: Hz, g\nmechanism,frequency_Hz,measured_g,sigma_g\n",
                                    kProgramVersion, kGitDescribe, c.path);
  std::string md = "| mechanism | eq. (3), quasi-static (ug) | eq. (3) off by 1 % above (Hz) | off by 10 % above (Hz) | "
                   "worst ODE vs prediction |\n| --- | --- | --- | --- | --- |\n";
  json table = json::array();
  auto freq = [](const std::optional<double>& f) { return f ? fmt::format("{:.3g}", *f) : std::string("-"); };
  out << fmt::format("vrelab {} ({}) frequency {}\n", kProgramVersion, kGitDescribe, c.path);
  out << fmt::format("Static a = [{:g}, {:g}, {:g}] g; {:g} g peak along [{:.3g}, {:.3g}, {:.3g}]; {} frequencies "
                     "{:g}-{:g} Hz; ODE at {} of them\n",
                     (*c.orientation_g)[0], (*c.orientation_g)[1], (*c.orientation_g)[2], fs.amplitude_g, fs.direction[0],
                     fs.direction[1], fs.direction[2], fs.frequencies_Hz.size(), fs.frequencies_Hz.front(),
                     fs.frequencies_Hz.back(), fs.ode_frequencies_Hz.size());
  out << fmt::format("  {:<24}{:>14}{:>16}{:>16}{:>14}\n", "mechanism", "eq.(3) (ug)", "off 1% (Hz)", "off 10% (Hz)", "ODE vs pred");
  for (const auto& m : curves) {
    for (std::size_t i = 0; i < fs.frequencies_Hz.size(); ++i)
      grid_csv += fmt::format("{},{:.8g},{:.10e},{:.10e},{}\n", m.name, fs.frequencies_Hz[i], m.predicted_g[i], m.eq3_g,
                              m.eq3_g != 0 ? fmt::format("{:.8g}", m.predicted_g[i] / m.eq3_g) : std::string(""));
    for (std::size_t i = 0; i < fs.ode_frequencies_Hz.size(); ++i)
      ode_csv += fmt::format("{},{:.8g},{:.10e},{:.3e}\n", m.name, fs.ode_frequencies_Hz[i], m.ode_g[i], m.ode_sigma_g[i]);
    const std::string eq3 = m.eq3_g != 0 ? fmt::format("{:.4f}", m.eq3_g * 1e6) : std::string("not in eq.(3)");
    out << fmt::format("  {:<24}{:>14}{:>16}{:>16}{:>14.2e}\n", m.name, eq3, freq(m.off_1_percent_Hz),
                       freq(m.off_10_percent_Hz), m.worst_ode_deviation);
    md += fmt::format("| {} | {} | {} | {} | {:.2e} |\n", m.name, eq3, freq(m.off_1_percent_Hz), freq(m.off_10_percent_Hz),
                      m.worst_ode_deviation);
    table.push_back({{"mechanism", m.name},
                     {"eq3_g", m.eq3_g},
                     {"off_1_percent_Hz", m.off_1_percent_Hz ? json(*m.off_1_percent_Hz) : json(nullptr)},
                     {"off_10_percent_Hz", m.off_10_percent_Hz ? json(*m.off_10_percent_Hz) : json(nullptr)},
                     {"worst_ode_deviation", m.worst_ode_deviation}});
  }
  out << fmt::format("Off by 1 %/10 %: the lowest grid frequency where |e(f)/e_eq3 - 1| exceeds it ('-': nowhere "
                     "on the grid). {:.3g} s wall.\n",
                     wall);
  json j = result_record("frequency", c);
  j["plant"] = plant_json(c.plant, c.physical.has_value());
  j["settings"] = {{"amplitude_g", fs.amplitude_g},
                   {"direction", vec_json(fs.direction)},
                   {"frequencies_Hz", fs.frequencies_Hz},
                   {"ode_frequencies_Hz", fs.ode_frequencies_Hz},
                   {"pickoff_p2_per_rad", fs.pickoff_p2_per_rad}};
  j["table"] = table;
  j["units"] = {{"eq3_g", "g"}, {"off_1_percent_Hz", "Hz"}};
  const std::string dir = o.out_dir;
  write_atomic(dir + "/frequency.csv", grid_csv);
  write_atomic(dir + "/ode_points.csv", ode_csv);
  write_atomic(dir + "/summary.md", md);
  write_atomic(dir + "/summary.json", j.dump(2) + "\n");
  const std::string why = run_plot_script("frequency.py", dir);
  if (!why.empty())
    out << "Figures skipped: " << why << ". The data are in " << dir << "\n";
  else
    out << "Wrote " << dir << "/frequency.{csv,png,svg}, ode_points.csv, summary.{md,json}\n";
}

}  // namespace vrelab::app
