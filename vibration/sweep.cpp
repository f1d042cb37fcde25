#include "vibration/sweep.hpp"

#include "vibration/detail.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <sstream>
#include <stdexcept>

namespace vrelab::vibration {
namespace {

using detail::kTwoPi;
using detail::num;

void check_positive(double v, const char* field) {
  if (!std::isfinite(v) || v <= 0)
    throw std::invalid_argument(std::string(field) + " = " + num(v) + " must be a finite number > 0");
}

}  // namespace

void validate(const SweptSine& s) {
  validate(SineVibration{s.amplitude_g, s.phase_rad, 0.0});  // amplitude_g, phase: finite, amplitudes >= 0
  check_positive(s.start_frequency_Hz, "start_frequency_Hz");
  check_positive(s.end_frequency_Hz, "end_frequency_Hz");
  if (s.start_frequency_Hz == s.end_frequency_Hz)
    throw std::invalid_argument("end_frequency_Hz = " + num(s.end_frequency_Hz) + " equals start_frequency_Hz");
  if (s.law == SweepLaw::linear)
    check_positive(s.rate_Hz_per_s, "rate_Hz_per_s");
  else
    check_positive(s.rate_octaves_per_min, "rate_octaves_per_min");
}

double sweep_duration_s(const SweptSine& s) {
  validate(s);
  if (s.law == SweepLaw::linear) return std::abs(s.end_frequency_Hz - s.start_frequency_Hz) / s.rate_Hz_per_s;
  return 60.0 * std::abs(std::log2(s.end_frequency_Hz / s.start_frequency_Hz)) / s.rate_octaves_per_min;
}

SweptSineExcitation::SweptSineExcitation(const SweptSine& s) : s_(s), duration_s_(sweep_duration_s(s)) {}

CarrierState SweptSineExcitation::one_pass(double tau) const {
  const double f1 = s_.start_frequency_Hz;
  const double dir = s_.end_frequency_Hz > f1 ? 1.0 : -1.0;
  if (s_.law == SweepLaw::linear) {
    const double r = dir * s_.rate_Hz_per_s;
    return {kTwoPi * (f1 * tau + 0.5 * r * tau * tau), f1 + r * tau, r};
  }
  const double k = dir * s_.rate_octaves_per_min * std::numbers::ln2 / 60.0;  // 1/s
  const double f = f1 * std::exp(k * tau);
  // theta = 2 pi f1 (e^{k tau} - 1) / k, written with expm1 to keep small k tau exact.
  return {kTwoPi * f1 * std::expm1(k * tau) / k, f, k * f};
}

CarrierState SweptSineExcitation::carrier(double t) const {
  const double T = duration_s_;
  if (t <= 0) return {kTwoPi * s_.start_frequency_Hz * t, s_.start_frequency_Hz, 0.0};
  if (t <= T) return one_pass(t);
  const CarrierState end = one_pass(T);
  if (s_.at_end == SweepEnd::hold)
    return {end.phase_rad + kTwoPi * s_.end_frequency_Hz * (t - T), s_.end_frequency_Hz, 0.0};
  const double cycle = std::floor(t / (2 * T));
  const double u = t - 2 * T * cycle;
  const double base = cycle * 2 * end.phase_rad;
  if (u <= T) {
    const CarrierState c = one_pass(u);
    return {base + c.phase_rad, c.frequency_Hz, c.rate_Hz_per_s};
  }
  const CarrierState c = one_pass(2 * T - u);
  return {base + 2 * end.phase_rad - c.phase_rad, c.frequency_Hz, -c.rate_Hz_per_s};
}

double SweptSineExcitation::max_frequency_Hz() const { return std::max(s_.start_frequency_Hz, s_.end_frequency_Hz); }

std::string SweptSineExcitation::describe() const {
  std::ostringstream o;
  o << (s_.law == SweepLaw::linear ? "linear" : "logarithmic") << " sweep " << s_.start_frequency_Hz << " -> "
    << s_.end_frequency_Hz << " Hz at ";
  if (s_.law == SweepLaw::linear)
    o << s_.rate_Hz_per_s << " Hz/s";
  else
    o << s_.rate_octaves_per_min << " oct/min";
  o << " (" << duration_s_ << " s per pass, " << (s_.at_end == SweepEnd::hold ? "then hold" : "up and down")
    << "), peak [" << s_.amplitude_g[0] << ", " << s_.amplitude_g[1] << ", " << s_.amplitude_g[2] << "] g";
  return o.str();
}

}  // namespace vrelab::vibration
