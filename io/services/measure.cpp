// io/services/measure.cpp -- `vrelab measure`: the vibration error of a recorded series
// (io/formats/series.hpp), its scale factor, the reference channels' motion and VRC; the
// service and its report (declared in io/services/studies.hpp).
#include <array>
#include <cmath>
#include <optional>
#include <string>

#include <fmt/format.h>

#include "io/formats/output.hpp"
#include "io/formats/paths.hpp"
#include "io/formats/series.hpp"
#include "io/services/results_json.hpp"
#include "io/services/studies.hpp"
#include "rectification/measurement/reference.hpp"
#include "rectification/measurement/series.hpp"
#include "rectification/measurement/vrc.hpp"
#include "vrelab_version.hpp"

namespace vrelab::io {

namespace {

// The VRC's input rms from reference channels is the motion's magnitude over the axes with a
// channel: without the input axis IA's the reference does not measure the motion the VRC is of
// (a record with ref_PA_g alone of a run along IA would give the VRC of the transverse motion).
void require_input_axis_reference(const MeasureStudy& s) {
  if (!s.reference || s.windows.input_rms_g > 0 || s.reference_axes[0]) return;
  static const std::array<const char*, 3> axis{"IA", "PA", "OA"};
  std::string have, lack;
  for (std::size_t i = 0; i < 3; ++i) {
    std::string& list = s.reference_axes[i] ? have : lack;
    list += (list.empty() ? "" : ", ") + std::string(axis[i]);
  }
  throw FormatError({.file = path_for_message(s.path)},
                    fmt::format("the reference channels cover {} only (none for {}): without the input axis IA's channel "
                                "they do not measure the motion the VRC is of; give ref_IA_g (or all three channels) or "
                                "--input-rms-g",
                                have, lack));
}

// A number of the motion's departure, "-" where it is not defined (NaN: an axis without a
// reference channel, a ratio to a fundamental of zero).
std::string ratio(double x, int digits = 4) { return std::isfinite(x) ? fmt::format("{:.{}g}", x, digits) : std::string("-"); }

}  // namespace

MeasureStudy measure(const std::string& series_path, const std::string& column, rectification::SeriesWindows w,
                     std::optional<double> K1) {
  MeasureStudy s;
  // The scale factor: given, else the one the series states, else none (output in g).
  const std::optional<StatedScaleFactor> stated = stated_scale_factor(series_path);
  struct Scale {
    double K1;
    std::string unit, source, note;
  };
  const Scale k = [&]() -> Scale {
    if (!K1 && stated) return {stated->K1, stated->unit, fmt::format("stated by the series, line {}", stated->line), ""};
    if (!K1) return {1.0, "g", "none given: output in g", ""};
    if (!stated) return {*K1, "", "--K1", ""};
    const bool differs = std::abs(stated->K1 - *K1) > 1e-12 * std::abs(*K1);
    return {*K1, stated->unit, "--K1",
            differs ? fmt::format("the series states K1 = {:g} {}/g (line {}); --K1 {:g} used", stated->K1, stated->unit,
                                  stated->line, *K1)
                    : std::string()};
  }();
  w.K1 = k.K1, s.K1_unit = k.unit, s.K1_source = k.source, s.K1_note = k.note;
  if (std::string why; !w.IsValid(&why)) throw InputError("measure: " + why);
  s.path = series_path;
  s.windows = w;
  rectification::SeriesMeasurer m(w);
  // Reference channels: sums over the vibration window as the measurement reads it, [from, to).
  const double on_from = w.on_from_s, on_to = rectification::used_on_to_s(w);
  long n_ref = 0;
  Vec3 sum = Vec3::Zero(), sum2 = Vec3::Zero();
  rectification::ReferenceWindow rwin;
  rwin.from_s = on_from, rwin.to_s = on_to, rwin.frequency_Hz = w.frequency_Hz;
  std::optional<rectification::ReferenceAnalyzer> refan;
  const ReferenceSink ref = [&](double t, const std::array<double, 3>& g, const std::array<bool, 3>& present) {
    s.reference = true, s.reference_axes = present;
    if (!refan) refan.emplace(rwin);
    if (s.motion_note.empty()) {
      try {
        refan->add(t, g, present);
      } catch (const std::invalid_argument& e) {
        s.motion_note = fmt::format("at t = {:g} s: {}", t, e.what());
      }
    }
    if (t < on_from || t >= on_to) return;
    ++n_ref;
    for (int i = 0; i < 3; ++i) sum[i] += g[static_cast<std::size_t>(i)], sum2[i] += g[static_cast<std::size_t>(i)] * g[static_cast<std::size_t>(i)];
  };
  s.column = read_series(series_path, column, [&m](double t, double u) { m.add(t, u); }, ref);
  // An output in other units than g read as g would be off by K1 without a word.
  if (const std::string unit = output_unit_of(s.column); !unit.empty()) {
    if (!K1 && !stated && unit != "g")
      throw InputError(fmt::format("{}: the output column '{}' is in {}, not g, and no scale factor is given: give --K1 ({} per g) "
                                   "or a comment line '# K1 = <value> {}/g' before the header",
                                   series_path, s.column, unit, unit, unit));
    if (stated && unit != stated->unit)
      throw InputError(fmt::format("{}:{}: the comment states K1 in {}/g, the output column '{}' is in {}", series_path,
                                   stated->line, stated->unit, s.column, unit));
    if (s.K1_unit.empty()) s.K1_unit = unit;
  }
  if (n_ref > 1) {
    const double n = static_cast<double>(n_ref);
    for (int i = 0; i < 3; ++i) s.reference_rms_g[i] = std::sqrt(std::max(0.0, sum2[i] / n - (sum[i] / n) * (sum[i] / n)));
    s.reference_input_rms_g = s.reference_rms_g.norm();
  }
  if (refan && s.motion_note.empty()) {
    // No command is given to measure: the departure from a motion along the dominant axis.
    try {
      const rectification::ReferenceAnalysis a = refan->finish();
      int dom = 0;
      if (w.frequency_Hz > 0) {
        for (int i = 1; i < 3; ++i)
          if (std::abs(a.harmonic_g[1][i]) > std::abs(a.harmonic_g[1][dom])) dom = i;
        s.motion = rectification::sine_departure(a, Vec3::Unit(dom) * std::abs(a.harmonic_g[1][dom]));
      } else {
        a.rms_g.maxCoeff(&dom);
        Eigen::Matrix3d cmd = Eigen::Matrix3d::Zero();
        cmd(dom, dom) = a.rms_g[dom] * a.rms_g[dom];
        s.motion = rectification::random_departure(a, cmd);
      }
    } catch (const std::invalid_argument& e) {
      s.motion_note = e.what();
    }
  }
  try {
    s.result = m.finish();
  } catch (const std::invalid_argument& e) {
    throw FormatError({.file = series_path}, e.what());
  }
  require_input_axis_reference(s);
  require_finite(measure_json(s), series_path, "the record's samples or the options drive the measurement out of range");
  return s;
}

std::string measure_report(const MeasureStudy& s) {
  const rectification::SeriesWindows& w = s.windows;
  const rectification::SeriesResult& r = s.result;
  std::string out = fmt::format("vrelab {} ({}) measure {}\n", kProgramVersion, kGitDescribe, s.path);
  out += fmt::format("Output column '{}', K1 = {:g} {}/g ({}); sample rate {:.6g} Hz\n", s.column, w.K1,
                     s.K1_unit.empty() ? "output units" : s.K1_unit, s.K1_source, r.sample_rate_Hz);
  if (!s.K1_note.empty()) out += "  Note: " + s.K1_note + "\n";
  out += fmt::format("Baseline [{:g}, {:g}) s: {} samples, mean {:.9f} g\n", w.baseline_from_s, w.baseline_to_s,
                     r.samples_baseline, r.baseline_g);
  out += fmt::format("Vibration [{:g}, {:g}) s{}: {} samples\n", w.on_from_s, r.on_to_used_s,
                     w.frequency_Hz > 0 ? fmt::format(" (whole periods of {:g} Hz)", w.frequency_Hz) : "", r.samples_on);
  out += fmt::format("  vibration error          {:>14.6f} ug  +/- {:.3g} ug (1 sigma, batch means of {} blocks)\n",
                     r.measured_g * 1e6, r.sigma_g * 1e6, w.blocks);
  out += fmt::format("  running-integral slope   {:>14.6f} ug\n", r.integral_slope_g * 1e6);
  if (s.reference)
    out += fmt::format("Reference channels over the vibration window: rms [{:.6g}, {:.6g}, {:.6g}] g, magnitude {:.6g} g\n",
                       s.reference_rms_g[0], s.reference_rms_g[1], s.reference_rms_g[2], s.reference_input_rms_g);
  if (s.motion) {
    const rectification::MotionDeparture& m = *s.motion;
    static const char* axis[3] = {"IA", "PA", "OA"};
    int dom = 0;
    m.measured_rms_axis_g.maxCoeff(&dom);
    if (m.kind == VibrationKind::sine)
      out += fmt::format("  motion: transverse to {} {} +/- {} (per axis [{}, {}, {}]; -: no channel), 2nd harmonic {} +/- "
                         "{}, 3rd harmonic {} +/- {} (of the fundamental)\n",
                         axis[dom], ratio(m.transverse_ratio, 5), ratio(m.transverse_sigma, 2), ratio(m.transverse_axis_ratio[0]),
                         ratio(m.transverse_axis_ratio[1]), ratio(m.transverse_axis_ratio[2]), ratio(m.harmonic2_ratio, 5),
                         ratio(m.harmonic2_sigma, 2), ratio(m.harmonic3_ratio, 5), ratio(m.harmonic3_sigma, 2));
    else
      out += fmt::format("  motion: transverse to {} {} +/- {} (rms across / along; Welch {:.4g} Hz bins, {} segments, "
                         "{:.3g} dof per bin)\n",
                         axis[dom], ratio(m.transverse_ratio, 5), ratio(m.transverse_sigma, 2), m.resolution_Hz, m.segments, m.dof);
  } else if (!s.motion_note.empty()) {
    out += "  motion: not analysed: " + s.motion_note + "\n";
  }
  if (const double rms = s.vrc_input_rms_g(); rms > 0)
    out += fmt::format("  VRC (input rms {:g} g, {})   {:>14.6f} ug/g^2 +/- {:.3g}\n", rms,
                       w.input_rms_g > 0 ? "given" : "reference channels", rectification::vrc_ug_per_g2(r.measured_g, rms),
                       rectification::vrc_ug_per_g2(r.sigma_g, rms));
  return out;
}

}  // namespace vrelab::io
