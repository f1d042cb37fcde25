#include "io/services/studies.hpp"

#include <algorithm>
#include <array>
#include <chrono>
#include <ctime>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iostream>
#include <iterator>
#include <map>
#include <numbers>
#include <optional>
#include <sstream>

#include <fmt/format.h>
#include <unistd.h>

#include "core/dispatch.hpp"
#include "core/parallel.hpp"
#include "core/progress.hpp"
#include "io/formats/csv.hpp"
#include "io/formats/output.hpp"
#include "io/formats/paths.hpp"
#include "io/services/internal.hpp"
#include "io/services/results_json.hpp"
#include "io/formats/series.hpp"
#include "rectification/measurement/vrc.hpp"
#include "rectification/prediction/random.hpp"
#include "rectification/prediction/second_order.hpp"
#include "rectification/simulation/sweep.hpp"
#include "vrelab_version.hpp"

namespace vrelab::io {
namespace {

// A case table the reason is about: "<case>: [table] <reason>".
FormatLocation table_of(const Case& c, const std::string& table) {
  return {.file = c.path, .table = table, .kind = KeyKind::toml_table};
}

using plant::kNumCoefficients;
using internal::kArcsec;
using internal::seconds_since;

std::string cell(double x) { return fmt::format(" {:>10.3e}", x); }
std::string text_cell(const std::string& s) { return fmt::format(" {:>10}", s); }

// CPU seconds of the calling thread (not the process: other threads may run beside it).
double thread_cpu_s() {
  timespec ts{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
}

std::uint64_t fnv1a(const std::string& s) {
  std::uint64_t h = 1469598103934665603ull;
  for (unsigned char ch : s) h = (h ^ ch) * 1099511628211ull;
  return h;
}

}  // namespace

std::string header_line(const std::string& command, const Case& c, std::uint64_t seed) {
  return fmt::format("vrelab {} ({}) {} {}  [seed {}]\n", kProgramVersion, kGitDescribe, command, c.path, seed);
}

// ---------------------------------------------------------------- identify

IdentifyStudy identify(const Case& c, int monte_carlo_trials, const std::string& checkpoint) {
  require(c, c.coefficients.has_value(), "coefficients", "identify");
  require(c, c.dividing_head.has_value(), "dividing_head", "identify");
  const DividingHead& head = *c.dividing_head;
  IdentifyStudy s;
  s.settings.fixed = c.fixed;
  s.settings.seed = c.seed;
  s.settings.monte_carlo_trials = monte_carlo_trials;
  if (!checkpoint.empty()) {  // ties the file to the case's content (not its path) and the program
    s.settings.monte_carlo_checkpoint.path = checkpoint;
    s.settings.monte_carlo_checkpoint.fingerprint = fmt::format(
        "case+program {:016x}", fnv1a(c.content.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace) + kProgramVersion + kGitDescribe));
  }
  validation::OutputSource source;  // empty: model (1)
  if (head.from_ode) {
    const plant::PlantConfig plant = c.plant;
    source = [plant](const Vec3& a) { return plant.coefficients[plant::K1] * plant::settled_output_g(plant, a); };
  }
  if (std::string why; !s.settings.IsValid(&why)) throw InputError(c.path + ": --monte-carlo: " + why);
  // Identifiability first: a rank-deficient set is reported in words, not solved into noise.
  s.position_set = validation::identifiability(head.positions, c.fixed);
  if (!s.position_set.full_rank()) {
    std::string msg = fmt::format(
        "{}: [dividing_head] with [identification] fixed: the {} free coefficients are not all "
        "identifiable from this position set (rank {} of {}).",
        c.path, s.position_set.parameters, s.position_set.rank, s.position_set.parameters);
    for (const auto& g : s.position_set.confounded) msg += "\n  - " + g;
    msg += "\n  Fix one coefficient of each group in [identification] fixed (the paper takes k1_asym "
           "from another test and assumes k_PP = k_OO = 0), or add positions.";
    throw InputError(msg);
  }
  s.report = validation::run_static_test(*c.coefficients, head.positions, head.errors, s.settings, source);
  return s;
}

namespace {

std::string identify_table(const Case& c, const validation::StaticTestReport& r) {
  const plant::Coefficients& truth = *c.coefficients;
  std::string out;
  std::string line = fmt::format("{:<10}{:<7}{:>11}", "", "", "");
  for (const auto& m : r.methods) line += fmt::format("  {:<32}", m.name);
  out += line + "\n";
  line = fmt::format("{:<10}{:<7}{:>11}", "coef", "unit", "truth");
  for (std::size_t m = 0; m < r.methods.size(); ++m) line += "  " + text_cell("estimate") + text_cell("error") + text_cell("sigma");
  out += line + "\n";
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
    out += line + "\n";
  }
  out += "error = estimate - truth; sigma: first-order standard uncertainty from set-angle errors and noise;\n"
         "(given): held at a known or assumed value, not estimated.\n";
  return out;
}

// The datasheet form of a coefficient's unit (IEEE Std 1293 style): model (1)'s g-based
// units times 1e6 (k0 in ug, k2 in ug/g^2, k3 in ug/g^3, a misalignment in urad); the scale
// factor as it is. {unit, factor}.
std::pair<std::string, double> datasheet_unit(int i, const Case& c) {
  return plant::datasheet_unit(plant::coefficient_info()[i].unit).value_or(std::pair<std::string, double>{unit_of(i, c), 1.0});
}

// Least squares' estimates in datasheet units, and every other method's estimate that departs
// from it by more than 5 of that method's sigma (the same readings: a gap that size is the
// method's own error, e.g. the printed k2 formula's, not noise).
std::string identify_datasheet(const Case& c, const validation::StaticTestReport& r) {
  const validation::MethodResult* ls = nullptr;
  for (const auto& m : r.methods)
    if (m.name == "least_squares") ls = &m;
  if (!ls) return "";
  std::string out = "\nDatasheet form (least_squares, IEEE Std 1293 units), estimate +- sigma:\n";
  for (int i = 0; i < kNumCoefficients; ++i) {
    if (!ls->estimate.available[i]) continue;
    const auto [unit, f] = datasheet_unit(i, c);
    const std::string name(plant::coefficient_name(i));
    out += ls->estimate.assumed[i]
               ? fmt::format("  {:<10}{:>14.6g} {:<8} (given)\n", name, ls->estimate.value[i] * f, unit)
               : fmt::format("  {:<10}{:>14.6g} {:<8} +- {:.3g}\n", name, ls->estimate.value[i] * f, unit, ls->first_order.sigma[i] * f);
  }
  for (const auto& m : r.methods) {
    if (&m == ls) continue;
    for (int i = 0; i < kNumCoefficients; ++i) {
      if (!m.estimate.available[i] || m.estimate.assumed[i] || !ls->estimate.available[i]) continue;
      const double sigma = m.first_order.sigma[i], d = m.estimate.value[i] - ls->estimate.value[i];
      if (!(sigma > 0) || !(std::abs(d) > 5 * sigma)) continue;
      const auto [unit, f] = datasheet_unit(i, c);
      out += fmt::format("  warning: {}'s {} = {:.4g} {} departs from least squares' {:.4g} {} by {:.3g} of its sigma: "
                         "that method's own error, not the instrument (docs/identification.md)\n",
                         m.name, plant::coefficient_name(i), m.estimate.value[i] * f, unit, ls->estimate.value[i] * f, unit,
                         std::abs(d) / sigma);
    }
  }
  return out;
}

std::string identify_monte_carlo(const Case& c, const IdentifyStudy& s) {
  std::string out = fmt::format("\nUncertainty: first-order propagation vs Monte Carlo ({} trials, seed {})\n",
                                s.settings.monte_carlo_trials, c.seed + 1);
  for (const auto& m : s.report.methods) {
    out += fmt::format("  {}\n", m.name);
    out += fmt::format("  {:<10}{:>11}{:>11}{:>8}{:>11}{:>11}\n", "coef", "sigma_1st", "sigma_MC", "ratio", "bias_1st",
                       "bias_MC");
    for (int i = 0; i < kNumCoefficients; ++i) {
      if (!m.estimate.available[i] || m.estimate.assumed[i]) continue;
      const double s1 = m.first_order.sigma[i], smc = m.monte_carlo->std[i];
      out += fmt::format("  {:<10}{}{}{:>8.3f}{}{}\n", plant::coefficient_name(i), cell(s1), cell(smc),
                         s1 > 0 ? smc / s1 : 0.0, cell(m.first_order.bias[i]), cell(m.monte_carlo->mean_error[i]));
    }
  }
  out += "bias: effect of the initial orientation error (first-order) and the mean error over the trials (MC).\n";
  return out;
}

}  // namespace

std::string identify_report(const Case& c, const IdentifyStudy& s) {
  const DividingHead& head = *c.dividing_head;
  const validation::StaticTestReport& r = s.report;
  const auto& e = head.errors;
  std::string out = header_line("identify", c, c.seed);
  out += fmt::format("Static test on the virtual dividing head: {}, {} reading(s) each = {} readings, from {}\n",
                     head.description, e.repeats, r.readings.size(),
                     head.from_ode ? "the ODE plant (settled in each position)" : "model (1)");
  out += fmt::format(
      "  errors: initial orientation [{:g}, {:g}, {:g}] arcsec, set angle sigma {:g} arcsec, reading "
      "noise sigma {:g} ug\n",
      e.initial_error_rad[0] / kArcsec, e.initial_error_rad[1] / kArcsec, e.initial_error_rad[2] / kArcsec,
      e.angle_sigma_rad / kArcsec, e.noise_sigma_g * 1e6);
  out += fmt::format(
      "Identifiability (least squares): {} free coefficients, rank {}, condition number {:.3g} (position set), "
      "{:.3g} (weighted)\n",
      r.identifiability.parameters, r.identifiability.rank, s.position_set.condition_number,
      r.identifiability.condition_number);
  std::string fixed_list;
  for (int i = 0; i < kNumCoefficients; ++i)
    if (c.fixed[i]) fixed_list += fmt::format("{}{} = {:g}", fixed_list.empty() ? "" : ", ", plant::coefficient_name(i), *c.fixed[i]);
  if (!fixed_list.empty()) out += "  fixed at known values: " + fixed_list + "\n";
  for (const auto& n : r.notes) out += "  note: " + n + "\n";
  out += "\n" + identify_table(c, r);
  out += identify_datasheet(c, r);
  if (s.settings.monte_carlo_trials > 0) out += identify_monte_carlo(c, s);
  return out;
}

// ---------------------------------------------------------------- predict

rectification::Eq3Terms predict_terms(const Case& c) {
  const VibrationSpec& v = *c.vibration;
  const plant::Coefficients& k = *c.coefficients;
  const Vec3& a = *c.orientation_g;
  if (v.type == VibrationKind::random) return rectification::random_rectification(k, a, *v.gaussian, c.range_limit_g);
  if (v.type == VibrationKind::sine_on_random)
    return rectification::sine_on_random_rectification(k, a, v.sine, *v.gaussian, c.range_limit_g);
  return rectification::sine_rectification(k, a, v.sine, c.range_limit_g);  // sine, swept sine
}

namespace {

// A key of the case's [vibration] table (`line` 0: the message names no line).
FormatLocation vibration_key(const Case& c, long line, const std::string& key) {
  return {.file = c.path, .line = line, .table = "vibration", .key = key, .kind = KeyKind::toml_key};
}

}  // namespace

PredictStudy predict(const Case& c, bool frequency_dependent) {
  require(c, c.coefficients.has_value(), "coefficients", "predict");
  require(c, c.orientation_g.has_value(), "orientation", "predict");
  require(c, c.vibration.has_value(), "vibration", "predict");
  const VibrationSpec& vs = *c.vibration;
  const bool random_kind = rectification::has_random_part(vs.type);
  if (frequency_dependent && vs.type != VibrationKind::sine && !random_kind)
    throw FormatError(vibration_key(c, 0, "type"), "--frequency-dependent takes a \"sine\", \"random\" or \"sine_on_random\" vibration");
  if (frequency_dependent && random_kind && !vs.psd)
    throw FormatError(vibration_key(c, vs.line, "psd_IA"),
                      "--frequency-dependent needs the random part as PSD tables (psd_IA, psd_PA, psd_OA), not rms_g");
  if (frequency_dependent && vs.type != VibrationKind::random && !(vs.sine.frequency_Hz > 0))
    throw FormatError(vibration_key(c, 0, "frequency_Hz"), "--frequency-dependent needs a positive frequency");
  PredictStudy s;
  s.terms = predict_terms(c);
  s.description = rectification::to_string(vs.type);
  if (vs.type == VibrationKind::sine || vs.type == VibrationKind::swept_sine) {
    s.printed_g = rectification::sine_rectification_as_printed(*c.coefficients, *c.orientation_g, vs.sine);
    const Vec3 ph = vs.sine.phase_rad * 180 / std::numbers::pi;
    s.description += fmt::format(", peak [{:g}, {:g}, {:g}] g, phase [{:g}, {:g}, {:g}] deg", vs.sine.amplitude_g[0],
                                 vs.sine.amplitude_g[1], vs.sine.amplitude_g[2], ph[0], ph[1], ph[2]);
  }
  if (vs.gaussian)
    s.description += fmt::format("{}Gaussian rms [{:g}, {:g}, {:g}] g",
                                 vs.type == VibrationKind::sine_on_random ? " + " : ", ",
                                 vs.gaussian->rms_g[0], vs.gaussian->rms_g[1], vs.gaussian->rms_g[2]);
  if (frequency_dependent && vs.type == VibrationKind::random)
    s.at_frequency = rectification::random_rectification_at_frequency(c.plant, *c.orientation_g, *vs.psd, c.range_limit_g);
  else if (frequency_dependent && vs.type == VibrationKind::sine_on_random)
    s.at_frequency = rectification::sine_on_random_rectification_at_frequency(c.plant, *c.orientation_g, vs.sine, *vs.psd,
                                                                               c.range_limit_g);
  else if (frequency_dependent)
    s.at_frequency = rectification::sine_rectification_at_frequency(c.plant, *c.orientation_g, vs.sine, c.range_limit_g);
  return s;
}

namespace {

std::string predict_at_frequency_report(const Case& c, const PredictStudy& s) {
  const VibrationSpec& vs = *c.vibration;
  const rectification::FrequencyPrediction& fp = *s.at_frequency;
  std::string out;
  if (vs.type == VibrationKind::sine)
    out = fmt::format(
        "At {:g} Hz through the plant's dynamics ({}): current amplitude |I| = {:.6g} g per {:g} g on IA, "
        "pendulum angle |Theta| = {:.4g} rad\n",
        vs.sine.frequency_Hz, c.physical ? "physical parameters" : "from coefficients", std::abs(fp.current_amplitude_g),
        vs.sine.amplitude_g[IA], std::abs(fp.angle_amplitude_rad));
  else
    out = fmt::format("Through the plant's dynamics ({}): the {} motion's PSD filtered by the loop, each term's Gaussian "
                      "expectation (docs/frequency.md, random motion)\n",
                      c.physical ? "physical parameters" : "from coefficients",
                      vs.type == VibrationKind::random ? "random" : "sine-on-random");
  out += fmt::format("  {:<20}{:>14}{:>16}\n", "term", "quasi-static", "at frequency");
  for (int t = 0; t < rectification::kNumTerms; ++t) {
    if (t == rectification::t_clipping && !c.range_limit_g) continue;
    out += fmt::format("  {:<20}{:>11.6f} ug{:>13.6f} ug\n", rectification::term_name(t), s.terms.g[t] * 1e6,
                       fp.terms.g[t] * 1e6);
  }
  out += fmt::format("  {:<20}{:>14}{:>13.6f} ug\n", "pickoff_nonlinearity", "-", fp.pickoff_g * 1e6);
  out += fmt::format("  {:<20}{:>14}{:>13.6f} ug\n", "pendulum_geometry", "-", fp.pendulum_geometry_g * 1e6);
  const bool pickoff = rectification::pickoff_p2_per_rad(c.plant) != 0;
  if (pickoff) out += fmt::format("  {:<20}{:>14}{:>13.6f} ug\n", "pickoff_2nd_order", "-", fp.second_order_g * 1e6);
  out += fmt::format("  {:<20}{:>11.6f} ug{:>13.6f} ug\n", "total", s.terms.total_g() * 1e6, fp.total_g() * 1e6);
  if (fp.second_order_left_out)
    out += "  The pickoff nonlinearity's second order is not computed for this motion (sine on random): first order only.\n";
  else if (pickoff)
    out += fmt::format("  pickoff_2nd_order: the pickoff's error through the loop and its IA terms beyond first order "
                       "(docs/frequency.md), {:.2f} % of the total; {}\n",
                       100 * fp.second_order_g / fp.total_g(),
                       vs.type == VibrationKind::sine
                           ? std::string("a harmonic balance, exact")
                           : fmt::format("second order in the pickoff's error, uncertain by about {:.3g} ug ({:.2f} % of the total){}",
                                         fp.second_order_error_g * 1e6, 100 * fp.second_order_error_g / std::abs(fp.total_g()),
                                         fp.second_order_error_g > 0.01 * std::abs(fp.total_g()) ? " -- large: check with `vrelab shake`" : ""));
  return out;
}

}  // namespace

std::string predict_report(const Case& c, const PredictStudy& s) {
  const Vec3 a = *c.orientation_g;
  std::string out = header_line("predict", c, c.seed);
  out += fmt::format("Static acceleration a = [{:g}, {:g}, {:g}] g (|a| = {:.6g} g); vibration: {}\n", a[0], a[1], a[2],
                     a.norm(), s.description);
  if (c.range_limit_g) out += fmt::format("Range limit: +/-{:g} g (clipping term)\n", *c.range_limit_g);
  out += "Vibration error from model (1), quasi-static (eq. (3) corrected):\n";
  out += fmt::format("  {:<10}{:>14}{:>16}\n", "term", "error (ug)", "error (g)");
  for (int t = 0; t < rectification::kNumTerms; ++t) {
    if (t == rectification::t_clipping && !c.range_limit_g) continue;
    const double g = s.terms.g[t];
    const bool omitted = t == rectification::t_k_PP || t == rectification::t_k_OO;
    out += fmt::format("  {:<10}{:>14.6f}{:>16.6e}{}\n", rectification::term_name(t), g * 1e6, g,
                       omitted ? "   (omitted by the printed eq. (3))" : "");
  }
  const double total = s.terms.total_g();
  out += fmt::format("  {:<10}{:>14.6f}{:>16.6e}\n", "total", total * 1e6, total);
  out += fmt::format("  of which the printed eq. (3) omits (k_PP, k_OO): {:.6f} ug\n", s.terms.omitted_by_paper_g() * 1e6);
  if (s.printed_g)
    out += fmt::format("Eq. (3) as printed in the paper gives {:.6f} ug (differs by {:.6f} ug)\n", *s.printed_g * 1e6,
                       (*s.printed_g - total) * 1e6);
  if (s.at_frequency) out += predict_at_frequency_report(c, s);
  const double rms = vibration_input_rms_g(*c.vibration);
  if (rms > 0)
    out += fmt::format("VRC = error / (input rms)^2, input rms {:.6g} g: {:.6g} ug/g^2 quasi-static{}\n", rms,
                       rectification::vrc_ug_per_g2(total, rms),
                       s.at_frequency ? fmt::format(", {:.6g} ug/g^2 through the dynamics",
                                                    rectification::vrc_ug_per_g2(s.at_frequency->total_g(), rms))
                                      : std::string());
  return out;
}

// ---------------------------------------------------------------- shake

namespace {

// The table's motion and what the shaker and the readout can do with it.
rectification::ShakerMotion shake_motion(const Case& c) {
  const VibrationSpec& vs = *c.vibration;
  rectification::ShakerMotion t;
  // The request alone first: what it refuses is the [vibration] table's. What the request
  // accepts and the imperfections then refuse (e.g. imperfections on a random run) is the
  // [shaker] table's, at its first imperfection key.
  try {
    (void)rectification::shaker_motion(vs, {}, *c.orientation_g, c.g_m_per_s2, c.seed);
  } catch (const std::invalid_argument& e) {
    throw FormatError({.file = c.path, .line = vs.line, .table = "vibration", .kind = KeyKind::toml_key}, e.what());
  }
  try {
    t = rectification::shaker_motion(vs, c.shaker, *c.orientation_g, c.g_m_per_s2, c.seed);
  } catch (const std::invalid_argument& e) {
    const char* key = c.shaker.transverse ? "transverse" : !c.shaker.harmonics.empty() ? "harmonics" : "rocking";
    throw FormatError({.file = c.path, .line = c.shaker.line, .table = "shaker", .key = key, .kind = KeyKind::toml_key},
                      e.what());
  }
  try {
    vibration::check_feasible(t.demand, c.shaker.limits);
  } catch (const std::invalid_argument& e) {
    throw FormatError(table_of(c, "shaker"), std::string("the profile is beyond the shaker: ") + e.what());
  }
  const auto& ro = c.shake.readout;
  if (ro.active() && t.top_Hz >= ro.sample_rate_Hz / 2)
    throw FormatError(table_of(c, "vibration"),
                      fmt::format("content up to {:g} Hz is at or above the Nyquist frequency {:g} Hz of "
                                  "[readout] sample_rate_Hz = {:g}",
                                  t.top_Hz, ro.sample_rate_Hz / 2, ro.sample_rate_Hz));
  return t;
}

// The sampled record, streamed to a temporary file and renamed when the run succeeded.
class SeriesFile {
 public:
  SeriesFile(const Case& c, const std::string& path) : path_(path) {
    if (path.empty()) return;
    require_writable_file(path, "the series (--series)");
    const std::filesystem::path target(path);
    std::error_code ec;
    if (target.has_parent_path()) std::filesystem::create_directories(target.parent_path(), ec);
    if (ec) throw InputError(fmt::format("{}: cannot create its folder: {}", path_for_message(path), ec.message()));
    tmp_ = path + ".tmp." + std::to_string(::getpid());
    out_.open(tmp_);
    if (!out_) throw InputError("cannot write " + tmp_);
    const Vec3& a = *c.orientation_g;
    out_ << fmt::format("# vrelab {} ({}) shake {}  seed {}\n", kProgramVersion, kGitDescribe, c.path, c.seed);
    out_ << fmt::format("# output in {}; K1 = {:g} {}/g; static a_g = [{:g}, {:g}, {:g}]; at rest for t < 0, "
                        "vibration on from t = 0\n",
                        c.output_unit, (*c.coefficients)[plant::K1], c.output_unit, a[0], a[1], a[2]);
    out_ << fmt::format("time_s,input_IA_g,input_PA_g,input_OA_g,output_{}\n", c.output_unit);
  }
  ~SeriesFile() {
    if (out_.is_open()) {  // not committed: no partial record
      out_.close();
      std::filesystem::remove(tmp_);
    }
  }
  rectification::SampleSink sink() {
    if (!out_.is_open()) return {};
    return [this](double t, const Vec3& in, double u) {
      out_ << fmt::format("{:.9e},{:.9e},{:.9e},{:.9e},{:.12e}\n", t, in[0], in[1], in[2], u);
    };
  }
  void commit() {
    if (!out_.is_open()) return;
    out_.close();
    if (!out_) throw InputError("writing " + tmp_ + " failed");
    std::error_code ec;
    std::filesystem::rename(tmp_, path_, ec);
    if (ec) throw InputError(fmt::format("cannot write {}: {}", path_for_message(path_), ec.message()));
  }

 private:
  std::string path_, tmp_;
  std::ofstream out_;
};

}  // namespace

namespace {

ShakeStudy shake_with(const Case& c, const std::function<rectification::SampleSink()>& make_sink,
                      const std::function<void()>& done) {
  require(c, c.coefficients.has_value(), "coefficients", "shake");
  require(c, c.orientation_g.has_value(), "orientation", "shake");
  require(c, c.vibration.has_value(), "vibration", "shake");
  if (std::string why; !c.shake.IsValid(&why)) throw FormatError(table_of(c, "shake"), why);
  const VibrationSpec& vs = *c.vibration;
  ShakeStudy s;
  s.table = shake_motion(c);
  const rectification::SampleSink sink = make_sink();
  const auto start = std::chrono::steady_clock::now();
  const double cpu_start = thread_cpu_s();
  const Vec3& a = *c.orientation_g;
  s.result = s.table.periodic ? rectification::shake_sine(c.plant, a, vs.sine, c.shake, sink,
                                                          c.shaker.imperfect() ? s.table.motion.get() : nullptr)
                              : rectification::shake_excitation(c.plant, a, *s.table.motion, vs.duration_s, c.shake, sink);
  s.wall_s = seconds_since(start);
  s.cpu_s = thread_cpu_s() - cpu_start;
  s.predicted_g = predict_terms(c).total_g();
  const bool psd = rectification::has_random_part(vs.type) && vs.psd;
  if (vs.type == VibrationKind::sine && !c.shaker.imperfect())
    s.frequency_dependent_g = rectification::sine_rectification_at_frequency(c.plant, a, vs.sine, c.range_limit_g).total_g();
  else if (vs.type == VibrationKind::random && psd)
    s.frequency_dependent_g = rectification::random_rectification_at_frequency(c.plant, a, *vs.psd, c.range_limit_g).total_g();
  else if (vs.type == VibrationKind::sine_on_random && psd && !c.shaker.imperfect())
    s.frequency_dependent_g =
        rectification::sine_on_random_rectification_at_frequency(c.plant, a, vs.sine, *vs.psd, c.range_limit_g).total_g();
  done();
  return s;
}

}  // namespace

ShakeStudy shake(const Case& c, const std::string& series_path) {
  std::optional<SeriesFile> series;
  return shake_with(
      c,
      [&] {
        series.emplace(c, series_path);
        return series->sink();
      },
      [&] { series->commit(); });
}

ShakeStudy shake(const Case& c, const rectification::SampleSink& sink) {
  return shake_with(c, [&] { return sink; }, [] {});
}

std::string shake_report(const Case& c, const ShakeStudy& s) {
  const rectification::ShakeResult& r = s.result;
  const auto& d = c.plant.dynamics;
  const Vec3& a = *c.orientation_g;
  std::string out = header_line("shake", c, c.seed);
  if (c.physical)
    out += fmt::format("Plant: physical parameters, pendulum {:.4g} Hz, servo given{}{}\n", d.pendulum_frequency_Hz,
                       d.integrator ? " (PI)" : " (no integrator)", c.plant.effects.empty() ? "" : ", effects:");
  else
    out += fmt::format("Plant: from coefficients, pendulum {:g} Hz, loop crossover {:g} Hz, phase margin {:g} deg{}{}\n",
                       d.pendulum_frequency_Hz, d.loop_bandwidth_Hz, d.phase_margin_deg,
                       d.integrator ? ", PI" : ", no integrator", c.plant.effects.empty() ? "" : ", effects:");
  for (const auto& e : c.plant.effects) out += "  " + e->name() + "\n";
  out += fmt::format("Static a = [{:g}, {:g}, {:g}] g; vibration: {}\n", a[0], a[1], a[2], s.table.motion->describe());
  out += "Shaker demand: " + s.table.demand.report() + "\n";
  out += fmt::format("Measurement: {}; settled {:.4g} s ({:.3g} slowest time constants), {}{}\n", r.method, r.settle_s,
                     r.settle_s / r.slowest_time_constant_s,
                     s.table.periodic ? fmt::format("{} periods measured", r.periods)
                                      : fmt::format("{:g} s measured (linear companion subtracted)", c.vibration->duration_s),
                     r.samples ? fmt::format(", {} samples at {:g} Hz", r.samples, r.sample_rate_Hz) : "");
  const double p = s.predicted_g;
  out += fmt::format("  measured vibration error   {:>14.6f} ug  +/- {:.3g} ug (1 sigma)\n", r.measured_g * 1e6, r.sigma_g * 1e6);
  out += fmt::format("  eq. (3) corrected, truth   {:>14.6f} ug\n", p * 1e6);
  out += fmt::format("  measured - eq. (3)         {:>14.6f} ug ({:+.4g} %)\n", (r.measured_g - p) * 1e6,
                     p != 0 ? 100 * (r.measured_g / p - 1) : 0.0);
  if (const std::optional<double>& q = s.frequency_dependent_g) {
    out += fmt::format("  eq. (3) through the loop   {:>14.6f} ug  (frequency-dependent: each term filtered where it acts)\n", *q * 1e6);
    out += fmt::format("  measured - through loop    {:>14.6f} ug ({:+.4g} %, {:+.3g} sigma)\n", (r.measured_g - *q) * 1e6,
                       *q != 0 ? 100 * (r.measured_g / *q - 1) : 0.0, r.sigma_g > 0 ? (r.measured_g - *q) / r.sigma_g : 0.0);
  }
  if (const double rms = vibration_input_rms_g(*c.vibration); rms > 0)
    out += fmt::format("  VRC (input rms {:.6g} g)      {:>14.6f} ug/g^2 +/- {:.3g} (eq. (3): {:.6f})\n", rms,
                       rectification::vrc_ug_per_g2(r.measured_g, rms), rectification::vrc_ug_per_g2(r.sigma_g, rms),
                       rectification::vrc_ug_per_g2(p, rms));
  out += fmt::format("  solver: {} steps, {} right-hand sides, {:.3g} s wall, {:.3g} s CPU; path: {}\n", r.steps,
                     r.rhs_evaluations, s.wall_s, s.cpu_s, r.path);
  return out;
}

// ---------------------------------------------------------------- sweep

namespace {

// `checksum` is FNV-1a (32 bits, 8 hex digits) of the row's text before it ("index,...,steps"):
// a resumed sweep verifies it, so a row edited by hand is found. wall_s, a timing and not a
// result, stays last and outside the checksum.
constexpr const char* kSweepColumns =
    "index,frequency_Hz,amplitude_g,direction_IA,direction_PA,direction_OA,a_IA_g,a_PA_g,a_OA_g,measured_g,sigma_g,"
    "predicted_eq3_g,settle_s,steps,checksum,wall_s";
constexpr long kSweepCommas = 15;

std::string row_checksum(const std::string& text) {
  std::uint32_t h = 2166136261u;
  for (unsigned char ch : text) h = (h ^ ch) * 16777619u;
  return fmt::format("{:08x}", h);
}

std::string sweep_line(const rectification::SweepRow& r) {
  const auto& c = r.condition;
  const std::string body =
      fmt::format("{},{:.10g},{:.10g},{:.10g},{:.10g},{:.10g},{:.10g},{:.10g},{:.10g},{:.12e},{:.4e},{:.12e},{:.6g},{}", c.index,
                  c.frequency_Hz, c.amplitude_g, c.direction[0], c.direction[1], c.direction[2], c.orientation_g[0],
                  c.orientation_g[1], c.orientation_g[2], r.measured_g, r.sigma_g, r.predicted_eq3_g, r.settle_s, r.steps);
  return fmt::format("{},{},{:.4g}\n", body, row_checksum(body), r.wall_s);
}

// The file's header: the fingerprint ties a results file to the case and the program (a
// resumed sweep must not mix rows of different settings).
std::string sweep_header(const Case& c, const std::string& fingerprint, int threads) {
  const auto& ro = c.shake.readout;
  return fmt::format(
      "# vrelab {} ({}) sweep {}\n# fingerprint {} conditions {} seed {}\n"
      "# settings: CVODE BDF, relative_tolerance {:g}, settle_decay {:g}, blocks {}, min_measure_s {:g}, "
      "readout sample_rate_Hz {:g} noise_sigma_g {:g} quantisation_lsb_g {:g}; units: g, Hz, s\n"
      "# run: {} MPI rank(s) x {} thread(s) (the last run of this file; rows do not depend on it)\n{}\n",
      kProgramVersion, kGitDescribe, c.path, fingerprint, c.sweep->size(), c.seed, c.shake.relative_tolerance,
      c.shake.settle_decay, c.shake.blocks, c.shake.min_measure_s, ro.sample_rate_Hz, ro.noise_sigma_g,
      ro.quantisation_lsb_g, core::process_count(), threads, kSweepColumns);
}

// The rows of an earlier run of the same sweep (index -> line); a partial last line dropped.
// A line that is not a row of this sweep (its index or its cell count) stops the resume; a
// row whose checksum does not match its text (edited by hand) is dropped, so its condition
// is run again, and named in *dropped with its line: the condition's result is a function of
// the case alone (its noise seed included), so running it again loses nothing, while
// keeping an edited number would put into the results what the program did not compute.
std::map<std::size_t, std::string> resumed_rows(const std::string& path, const std::string& fingerprint,
                                                std::size_t conditions, std::vector<std::string>* dropped) {
  std::map<std::size_t, std::string> rows;
  std::ifstream in(path);
  std::string line, text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  if (text.find("# fingerprint " + fingerprint) == std::string::npos)
    throw InputError(path + ": exists with rows of another case or program version; use --restart to discard it");
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
    if (used != index_field.size() || used == 0 || std::count(line.begin(), line.end(), ',') != kSweepCommas ||
        index >= conditions)
      throw InputError(fmt::format("{}:{}: not a row of this sweep (index '{}', {} conditions); use --restart to "
                                   "discard the file",
                                   path, line_no, index_field, conditions));
    const std::size_t wall = line.rfind(','), sum = line.rfind(',', wall - 1);
    const std::string body = line.substr(0, sum), checksum = line.substr(sum + 1, wall - sum - 1);
    if (checksum != row_checksum(body)) {
      dropped->push_back(fmt::format("{}:{}: condition {}: the row does not match its checksum (edited by hand?); run again",
                                     path, line_no, index));
      rows.erase(index);
      continue;
    }
    rows[index] = line + "\n";
  }
  return rows;
}

std::string sweep_text(const std::string& header, const std::map<std::size_t, std::string>& rows) {
  std::string text = header;
  for (const auto& [i, l] : rows) text += l;
  return text;
}

}  // namespace

SweepStudy sweep(const Case& c, const std::string& out_path, bool restart, int threads, bool progress, std::ostream& out) {
  namespace fs = std::filesystem;
  require(c, c.coefficients.has_value(), "coefficients", "sweep");
  require(c, c.sweep.has_value(), "sweep", "sweep");
  const rectification::SweepGrid& grid = *c.sweep;
  if (std::string why; !grid.IsValid(&why)) throw FormatError(table_of(c, "sweep"), why);
  if (std::string why; !c.shake.IsValid(&why)) throw FormatError(table_of(c, "shake"), why);
  const std::string fingerprint = fmt::format("{:016x}", fnv1a(c.content.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace) + kProgramVersion + kGitDescribe));
  const int used = core::threads_per_process(threads >= 0 ? threads : c.sweep_threads);
  const std::string header = sweep_header(c, fingerprint, used);
  const fs::path path(out_path);
  // Under mpirun only rank 0 reads and writes the file; the others compute the conditions it
  // hands out (core/dispatch.hpp).
  const bool writer = core::is_root_process();
  if (writer) require_writable_file(out_path, "the sweep's results (--out)");
  std::error_code ec;
  if (writer && path.has_parent_path()) fs::create_directories(path.parent_path(), ec);
  if (ec) throw InputError(fmt::format("{}: cannot create its folder: {}", path_for_message(out_path), ec.message()));
  std::map<std::size_t, std::string> rows;
  SweepStudy s;
  if (writer && fs::exists(path) && !restart) rows = resumed_rows(out_path, fingerprint, grid.size(), &s.recomputed);
  if (writer) write_atomic(out_path, sweep_text(header, rows));  // the kept rows; then appended as conditions finish
  std::vector<std::size_t> skip;
  for (const auto& [i, l] : rows) skip.push_back(i);
  out << header_line("sweep", c, c.seed);
  out << fmt::format("Grid: {} frequencies x {} amplitudes x {} directions x {} orientations = {} conditions; "
                     "{} already in {}; {} thread(s){}\n",
                     grid.frequencies_Hz.size(), grid.amplitudes_g.size(), grid.directions.size(),
                     grid.orientations_g.size(), grid.size(), rows.size(), out_path, used,
                     core::process_count() > 1 ? fmt::format(" on each of {} MPI ranks", core::process_count()) : "");
  for (const auto& r : s.recomputed) out << "  " << r << "\n";
  out.flush();
  s.conditions = grid.size();
  s.ran = grid.size() - skip.size();
  std::ofstream append;
  if (writer) append.open(out_path, std::ios::app);
  core::Progress bar(std::cerr, "sweep", s.ran, progress && writer);
  const auto start = std::chrono::steady_clock::now();
  rectification::run_sweep(
      c.plant, *c.coefficients, c.shake, grid, skip, used,
      [&](const rectification::SweepRow& r) {
        bar.tick();
        if (!r.ok) {
          s.failures.push_back(fmt::format("condition {} ({:g} Hz, {:g} g): {}", r.condition.index,
                                           r.condition.frequency_Hz, r.condition.amplitude_g, r.error));
          return;
        }
        const std::string l = sweep_line(r);
        append << l << std::flush;  // one row per write: an interruption loses at most this row
        rows[r.condition.index] = l;
      });
  bar.finish();
  append.close();
  s.wall_s = seconds_since(start);
  if (writer) write_atomic(out_path, sweep_text(header, rows));  // every row, sorted by condition
  s.written = rows.size();
  return s;
}

std::string sweep_report(const SweepStudy& s, const std::string& out_path) {
  std::string out = fmt::format("Done: {} conditions in {:.3g} s wall ({} written, {} failed) -> {}\n", s.ran, s.wall_s,
                                s.written, s.failures.size(), out_path);
  for (const auto& f : s.failures) out += "  failed: " + f + "\n";
  for (const auto& r : s.recomputed) out += "  recomputed: " + r + "\n";
  return out;
}

// ---------------------------------------------------------------- frequency

FrequencyStudy frequency(const Case& c) {
  require(c, c.coefficients.has_value(), "coefficients", "frequency");
  require(c, c.orientation_g.has_value(), "orientation", "frequency");
  FrequencyStudy s;
  if (c.frequency_study) s.settings = *c.frequency_study;
  else rectification::FrequencyGrid{}.apply(s.settings);  // no table: the grid's defaults
  if (std::string why; !s.settings.IsValid(&why)) throw FormatError(table_of(c, "frequency_study"), why);
  const auto start = std::chrono::steady_clock::now();
  s.curves = rectification::frequency_study(c.plant, *c.orientation_g, s.settings);
  s.wall_s = seconds_since(start);
  return s;
}

namespace {

std::string off_text(const std::optional<double>& f) { return f ? fmt::format("{:.3g}", *f) : std::string("-"); }
std::string eq3_text(const rectification::MechanismCurve& m) {
  return m.eq3_g != 0 ? fmt::format("{:.4f}", m.eq3_g * 1e6) : std::string("not in eq.(3)");
}

}  // namespace

std::string frequency_report(const Case& c, const FrequencyStudy& s) {
  const auto& fs = s.settings;
  const Vec3& a = *c.orientation_g;
  std::string out = fmt::format("vrelab {} ({}) frequency {}\n", kProgramVersion, kGitDescribe, c.path);
  out += fmt::format("Static a = [{:g}, {:g}, {:g}] g; {:g} g peak along [{:.3g}, {:.3g}, {:.3g}]; {} frequencies "
                     "{:g}-{:g} Hz; ODE at {} of them\n",
                     a[0], a[1], a[2], fs.amplitude_g, fs.direction[0], fs.direction[1], fs.direction[2],
                     fs.frequencies_Hz.size(), fs.frequencies_Hz.front(), fs.frequencies_Hz.back(),
                     fs.ode_frequencies_Hz.size());
  out += fmt::format("  {:<24}{:>14}{:>16}{:>16}{:>14}\n", "mechanism", "eq.(3) (ug)", "off 1% (Hz)", "off 10% (Hz)", "ODE vs pred");
  for (const auto& m : s.curves)
    out += fmt::format("  {:<24}{:>14}{:>16}{:>16}{:>14.2e}\n", m.name, eq3_text(m), off_text(m.off_1_percent_Hz),
                       off_text(m.off_10_percent_Hz), m.worst_ode_deviation);
  out += fmt::format("Off by 1 %/10 %: the lowest grid frequency where |e(f)/e_eq3 - 1| exceeds it ('-': nowhere "
                     "on the grid). {:.3g} s wall.\n",
                     s.wall_s);
  return out;
}

void write_frequency_data(const Case& c, const FrequencyStudy& s, const std::string& dir) {
  const auto& fs = s.settings;
  std::string grid_csv = fmt::format("# vrelab {} ({}) frequency {}; units: Hz, g\nmechanism,frequency_Hz,predicted_g,eq3_g,ratio\n",
                                     kProgramVersion, kGitDescribe, c.path);
  std::string ode_csv = fmt::format("# vrelab {} ({}) frequency {}; units: Hz, g\nmechanism,frequency_Hz,measured_g,sigma_g\n",
                                    kProgramVersion, kGitDescribe, c.path);
  std::string md = "| mechanism | eq. (3), quasi-static (ug) | eq. (3) off by 1 % above (Hz) | off by 10 % above (Hz) | "
                   "worst ODE vs prediction |\n| --- | --- | --- | --- | --- |\n";
  for (const auto& m : s.curves) {
    for (std::size_t i = 0; i < fs.frequencies_Hz.size(); ++i)
      grid_csv += fmt::format("{},{:.8g},{:.10e},{:.10e},{}\n", m.name, fs.frequencies_Hz[i], m.predicted_g[i], m.eq3_g,
                              m.eq3_g != 0 ? fmt::format("{:.8g}", m.predicted_g[i] / m.eq3_g) : std::string(""));
    for (std::size_t i = 0; i < fs.ode_frequencies_Hz.size(); ++i)
      ode_csv += fmt::format("{},{:.8g},{:.10e},{:.3e}\n", m.name, fs.ode_frequencies_Hz[i], m.ode_g[i], m.ode_sigma_g[i]);
    md += fmt::format("| {} | {} | {} | {} | {:.2e} |\n", m.name, eq3_text(m), off_text(m.off_1_percent_Hz),
                      off_text(m.off_10_percent_Hz), m.worst_ode_deviation);
  }
  write_atomic(dir + "/frequency.csv", grid_csv);
  write_atomic(dir + "/ode_points.csv", ode_csv);
  write_atomic(dir + "/summary.md", md);
  write_atomic(dir + "/summary.json", json_text(frequency_json(c, s)));
}

}  // namespace vrelab::io
