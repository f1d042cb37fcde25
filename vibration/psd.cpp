#include "vibration/psd.hpp"

#include "vibration/detail.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <sstream>
#include <stdexcept>

namespace vrelab::vibration {
namespace {

using detail::check_g;
using detail::num;

[[noreturn]] void row_error(std::size_t i, const PsdRow& r, const std::string& what) {
  throw std::invalid_argument("PSD table row " + std::to_string(i + 1) + " (frequency_Hz = " + num(r.frequency_Hz) +
                              "): " + what);
}

// dB/octave -> exponent of f: 10 log10(P2/P1) = s log2(f2/f1)  =>  P ~ f^(s / (10 log10 2)).
double exponent_of_slope(double slope_dB_per_octave) { return slope_dB_per_octave / (10.0 * std::log10(2.0)); }

}  // namespace

void validate(const PsdTable& t) { (void)resolve(t); }

ResolvedPsd resolve(const PsdTable& t) {
  if (t.rows.size() < 2)
    throw std::invalid_argument("PSD table has " + std::to_string(t.rows.size()) +
                                " row(s); it needs at least 2 (frequency_Hz, psd_g2_per_Hz) rows");
  ResolvedPsd out;
  for (std::size_t i = 0; i < t.rows.size(); ++i) {
    const PsdRow& r = t.rows[i];
    if (!std::isfinite(r.frequency_Hz) || r.frequency_Hz <= 0)
      row_error(i, r, "frequency_Hz must be a finite number > 0");
    if (i > 0 && !(r.frequency_Hz > t.rows[i - 1].frequency_Hz))
      row_error(i, r,
                "frequency_Hz must be strictly above the previous row's (" + num(t.rows[i - 1].frequency_Hz) + ")");
    if (r.psd_g2_per_Hz.has_value() == r.slope_dB_per_octave.has_value())
      row_error(i, r, "give exactly one of psd_g2_per_Hz and slope_dB_per_octave");
    double level = 0;
    if (r.psd_g2_per_Hz) {
      level = *r.psd_g2_per_Hz;
      if (!std::isfinite(level) || level <= 0)
        row_error(i, r, "psd_g2_per_Hz = " + num(level) + " must be a finite number > 0");
    } else {
      if (i == 0) row_error(i, r, "the first row needs psd_g2_per_Hz (a slope needs a previous row)");
      const double s = *r.slope_dB_per_octave;
      if (!std::isfinite(s)) row_error(i, r, "slope_dB_per_octave must be a finite number");
      level = out.psd_g2_per_Hz.back() * std::pow(r.frequency_Hz / out.frequency_Hz.back(), exponent_of_slope(s));
      if (!std::isfinite(level) || level <= 0)
        row_error(
            i, r,
            "slope_dB_per_octave = " + num(s) + " gives psd_g2_per_Hz = " + num(level) + ", not a finite number > 0");
    }
    out.frequency_Hz.push_back(r.frequency_Hz);
    out.psd_g2_per_Hz.push_back(level);
  }
  return out;
}

double psd_g2_per_Hz(const ResolvedPsd& p, double f) {
  const auto& fs = p.frequency_Hz;
  if (!(f >= fs.front() && f <= fs.back())) return 0.0;
  // Segment k with fs[k] <= f <= fs[k+1].
  std::size_t k = static_cast<std::size_t>(std::upper_bound(fs.begin(), fs.end(), f) - fs.begin());
  k = std::min(k, fs.size() - 1) - 1;
  const double b = std::log(p.psd_g2_per_Hz[k + 1] / p.psd_g2_per_Hz[k]) / std::log(fs[k + 1] / fs[k]);
  return p.psd_g2_per_Hz[k] * std::pow(f / fs[k], b);
}

double psd_g2_per_Hz(const PsdTable& t, double f) { return psd_g2_per_Hz(resolve(t), f); }

double psd_moment(const ResolvedPsd& p, int m) {
  double sum = 0;
  for (std::size_t k = 0; k + 1 < p.frequency_Hz.size(); ++k) {
    const double f1 = p.frequency_Hz[k], x = std::log(p.frequency_Hz[k + 1] / f1);
    const double b = std::log(p.psd_g2_per_Hz[k + 1] / p.psd_g2_per_Hz[k]) / x;
    const double cx = (b + m + 1) * x;
    // expm1(cx)/cx -> 1 as cx -> 0 (the ln(f2/f1) case of a 1/f segment), without cancellation.
    const double e = std::abs(cx) < 1e-300 ? 1.0 : std::expm1(cx) / cx;
    sum += p.psd_g2_per_Hz[k] * std::pow(f1, m + 1) * x * e;
  }
  return sum;
}

double rms_g(const PsdTable& t) { return std::sqrt(psd_moment(resolve(t), 0)); }

double velocity_rms_m_per_s(const PsdTable& t, double g_m_per_s2) {
  const double k = check_g(g_m_per_s2) / (2 * std::numbers::pi);
  return k * std::sqrt(psd_moment(resolve(t), -2));
}

double displacement_rms_m(const PsdTable& t, double g_m_per_s2) {
  const double w = 2 * std::numbers::pi;
  return check_g(g_m_per_s2) / (w * w) * std::sqrt(psd_moment(resolve(t), -4));
}

std::string describe(const PsdTable& t) {
  const ResolvedPsd p = resolve(t);
  return "random " + num(p.frequency_Hz.front()) + "-" + num(p.frequency_Hz.back()) + " Hz, " +
         num(std::sqrt(psd_moment(p, 0))) + " g rms";
}

}  // namespace vrelab::vibration
