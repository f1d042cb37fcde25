#include "vibration/demand.hpp"

#include "vibration/detail.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>

namespace vrelab::vibration {
namespace {

using detail::check_g;
using detail::kTwoPi;

// A number as the demand's messages and description print it: 4 significant digits.
std::string num_4_digits(double x) { return detail::num(x, 4); }

// Sine of peak amplitude amp_g (per axis) at f with harmonics (order, ratio); r_1 = 1.
ShakerDemand tone_demand(const Vec3& amp_g, double f, const std::vector<Harmonic>& hs, double g) {
  const double w = kTwoPi * f;
  double peak[3] = {1, 1 / w, 1 / (w * w)}, ms[3] = {1, 1 / (w * w), 1 / (w * w * w * w)};
  for (const Harmonic& h : hs) {
    const double hw = h.order * w;
    peak[0] += h.ratio;
    peak[1] += h.ratio / hw;
    peak[2] += h.ratio / (hw * hw);
    ms[0] += h.ratio * h.ratio;
    ms[1] += h.ratio * h.ratio / (hw * hw);
    ms[2] += h.ratio * h.ratio / (hw * hw * hw * hw);
  }
  ShakerDemand d;
  d.acceleration_peak_g = amp_g * peak[0];
  d.acceleration_rms_g = amp_g * std::sqrt(ms[0] / 2);
  d.velocity_peak_m_per_s = amp_g * g * peak[1];
  d.velocity_rms_m_per_s = amp_g * g * std::sqrt(ms[1] / 2);
  d.displacement_peak_m = amp_g * g * peak[2];
  d.displacement_rms_m = amp_g * g * std::sqrt(ms[2] / 2);
  return d;
}

double sine_frequency(const SineVibration& v) {
  validate(v);
  if (v.frequency_Hz <= 0)
    throw std::invalid_argument("frequency_Hz = " + num_4_digits(v.frequency_Hz) +
                                " (not given): velocity and displacement need the frequency");
  return v.frequency_Hz;
}

}  // namespace

ShakerDemand shaker_demand(const SineVibration& v, double g) {
  return tone_demand(v.amplitude_g, sine_frequency(v), {}, check_g(g));
}

ShakerDemand shaker_demand(const SineVibration& v, const std::vector<Harmonic>& hs, double g) {
  validate(hs);
  return tone_demand(v.amplitude_g, sine_frequency(v), hs, check_g(g));
}

ShakerDemand shaker_demand(const SweptSine& s, double g) {
  validate(s);
  return tone_demand(s.amplitude_g, std::min(s.start_frequency_Hz, s.end_frequency_Hz), {}, check_g(g));
}

ShakerDemand shaker_demand(const RandomProfile& p, double g) {
  validate(p);
  check_g(g);
  ShakerDemand d;
  for (int i = 0; i < 3; ++i) {
    if (!p.psd[i]) continue;
    d.acceleration_rms_g[i] = rms_g(*p.psd[i]);
    d.velocity_rms_m_per_s[i] = velocity_rms_m_per_s(*p.psd[i], g);
    d.displacement_rms_m[i] = displacement_rms_m(*p.psd[i], g);
  }
  d.acceleration_peak_g = kRandomPeakFactor * d.acceleration_rms_g;
  d.velocity_peak_m_per_s = kRandomPeakFactor * d.velocity_rms_m_per_s;
  d.displacement_peak_m = kRandomPeakFactor * d.displacement_rms_m;
  return d;
}

ShakerDemand combine(const ShakerDemand& a, const ShakerDemand& b) {
  auto rss = [](const Vec3& x, const Vec3& y) -> Vec3 { return (x.array().square() + y.array().square()).sqrt(); };
  ShakerDemand d;
  d.acceleration_rms_g = rss(a.acceleration_rms_g, b.acceleration_rms_g);
  d.velocity_rms_m_per_s = rss(a.velocity_rms_m_per_s, b.velocity_rms_m_per_s);
  d.displacement_rms_m = rss(a.displacement_rms_m, b.displacement_rms_m);
  d.acceleration_peak_g = a.acceleration_peak_g + b.acceleration_peak_g;
  d.velocity_peak_m_per_s = a.velocity_peak_m_per_s + b.velocity_peak_m_per_s;
  d.displacement_peak_m = a.displacement_peak_m + b.displacement_peak_m;
  return d;
}

std::string ShakerDemand::report() const {
  std::ostringstream o;
  auto v3 = [&](const Vec3& v, double scale) {
    std::ostringstream s;
    s.precision(4);
    s << '[' << v[0] * scale << ", " << v[1] * scale << ", " << v[2] * scale << ']';
    return s.str();
  };
  o << "acceleration rms " << v3(acceleration_rms_g, 1) << " g, peak " << v3(acceleration_peak_g, 1) << " g; "
    << "velocity rms " << v3(velocity_rms_m_per_s, 1) << " m/s, peak " << v3(velocity_peak_m_per_s, 1) << " m/s; "
    << "displacement rms " << v3(displacement_rms_m, 1e3) << " mm, peak " << v3(displacement_peak_m, 1e3)
    << " mm; table: stroke " << num_4_digits(table_stroke_peak_to_peak_m() * 1e3) << " mm peak-to-peak, velocity "
    << num_4_digits(table_velocity_peak_m_per_s()) << " m/s peak";
  return o.str();
}

void check_feasible(const ShakerDemand& d, const ShakerLimits& lim) {
  if (std::isnan(lim.stroke_peak_to_peak_m) || lim.stroke_peak_to_peak_m <= 0)
    throw std::invalid_argument("stroke_peak_to_peak_m = " + num_4_digits(lim.stroke_peak_to_peak_m) + " must be > 0");
  if (std::isnan(lim.velocity_peak_m_per_s) || lim.velocity_peak_m_per_s <= 0)
    throw std::invalid_argument("velocity_peak_m_per_s = " + num_4_digits(lim.velocity_peak_m_per_s) + " must be > 0");
  const double stroke = d.table_stroke_peak_to_peak_m();
  if (!(stroke <= lim.stroke_peak_to_peak_m))
    throw std::invalid_argument(
        "the profile needs a stroke of " + num_4_digits(stroke * 1e3) +
        " mm peak-to-peak, above the shaker's stroke_peak_to_peak_m = " +
        num_4_digits(lim.stroke_peak_to_peak_m * 1e3) + " mm");
  const double vel = d.table_velocity_peak_m_per_s();
  if (!(vel <= lim.velocity_peak_m_per_s))
    throw std::invalid_argument(
        "the profile needs a velocity of " + num_4_digits(vel) +
        " m/s peak, above the shaker's velocity_peak_m_per_s = " + num_4_digits(lim.velocity_peak_m_per_s) + " m/s");
}

}  // namespace vrelab::vibration
