#include "vibration/decorators.hpp"

#include "vibration/detail.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <complex>
#include <sstream>
#include <stdexcept>

namespace vrelab::vibration {
namespace {

using detail::kAxisName;
using detail::kTwoPi;
using detail::num;

void check_axis(int axis, const char* field) {
  if (axis < 0 || axis > 2)
    throw std::invalid_argument(std::string(field) + " = " + std::to_string(axis) +
                                " must be 0 (IA), 1 (PA) or 2 (OA)");
}

void check_finite(double v, const std::string& field) {
  if (!std::isfinite(v)) throw std::invalid_argument(field + " is not a finite number");
}

void check_non_negative(double v, const std::string& field) {
  if (!std::isfinite(v) || v < 0) throw std::invalid_argument(field + " = " + num(v) + " must be finite and >= 0");
}

template <class P>
P not_null(P p, const char* what) {
  if (!p) throw std::invalid_argument(std::string(what) + " is null");
  return p;
}

}  // namespace

// ---------------------------------------------------------------- SumExcitation

SumExcitation::SumExcitation(std::vector<std::shared_ptr<const Excitation>> parts) : parts_(std::move(parts)) {
  if (parts_.empty()) throw std::invalid_argument("parts is empty");
  for (std::size_t i = 0; i < parts_.size(); ++i)
    if (!parts_[i]) throw std::invalid_argument("parts[" + std::to_string(i) + "] is null");
}

Vec3 SumExcitation::acceleration_g(double t) const {
  Vec3 a = Vec3::Zero();
  for (const auto& p : parts_) a += p->acceleration_g(t);
  return a;
}

double SumExcitation::max_frequency_Hz() const {
  double f = 0;
  for (const auto& p : parts_) f = std::max(f, p->max_frequency_Hz());
  return f;
}

Vec3 SumExcitation::mean_g() const {
  Vec3 m = Vec3::Zero();
  for (const auto& p : parts_) m += p->mean_g();
  return m;
}

std::string SumExcitation::describe() const {
  std::string s;
  for (const auto& p : parts_) s += (s.empty() ? "" : " + ") + p->describe();
  return s;
}

// ---------------------------------------------------------------- TransverseMotion

void validate(const TransverseSpec& s) {
  check_axis(s.from_axis, "from_axis");
  check_axis(s.to_axis, "to_axis");
  if (s.from_axis == s.to_axis) throw std::invalid_argument("to_axis must differ from from_axis");
  check_non_negative(s.ratio, "ratio");
  check_finite(s.phase_rad, "phase_rad");
}

SineVibration with_transverse(const SineVibration& v, const TransverseSpec& s) {
  validate(v);
  validate(s);
  // Phasors A e^{i phase}: the transverse part is ratio A_from e^{i (phase_from + phase_rad)}.
  const std::complex<double> now = std::polar(v.amplitude_g[s.to_axis], v.phase_rad[s.to_axis]);
  const std::complex<double> add =
      std::polar(s.ratio * v.amplitude_g[s.from_axis], v.phase_rad[s.from_axis] + s.phase_rad);
  const std::complex<double> sum = now + add;
  SineVibration out = v;
  out.amplitude_g[s.to_axis] = std::abs(sum);
  out.phase_rad[s.to_axis] = std::arg(sum);
  return out;
}

TransverseMotion::TransverseMotion(std::shared_ptr<const ToneExcitation> tone, const TransverseSpec& spec)
    : inner_(not_null(tone, "tone")), tone_(tone), spec_(spec) {
  validate(spec_);
}

TransverseMotion::TransverseMotion(std::shared_ptr<const Excitation> inner, const TransverseSpec& spec,
                                   double reference_frequency_Hz)
    : inner_(not_null(std::move(inner), "inner")), spec_(spec) {
  validate(spec_);
  if (spec_.phase_rad != 0.0) {
    if (!std::isfinite(reference_frequency_Hz) || reference_frequency_Hz <= 0)
      throw std::invalid_argument("reference_frequency_Hz = " + num(reference_frequency_Hz) +
                                  " must be > 0 to turn phase_rad into a time shift");
    shift_s_ = spec_.phase_rad / (kTwoPi * reference_frequency_Hz);
  }
}

Vec3 TransverseMotion::acceleration_g(double t) const {
  Vec3 a = inner_->acceleration_g(t);
  if (tone_) {
    const double theta = tone_->carrier(t).phase_rad;
    a[spec_.to_axis] += spec_.ratio * tone_->amplitude_g()[spec_.from_axis] *
                        std::sin(theta + tone_->phase_rad()[spec_.from_axis] + spec_.phase_rad);
  } else {
    const double main = shift_s_ == 0.0 ? a[spec_.from_axis] : inner_->acceleration_g(t + shift_s_)[spec_.from_axis];
    a[spec_.to_axis] += spec_.ratio * main;
  }
  return a;
}

std::string TransverseMotion::describe() const {
  return inner_->describe() + "; transverse " + num(spec_.ratio) + " x " + kAxisName[spec_.from_axis] + " on " +
         kAxisName[spec_.to_axis] + " at " + num(spec_.phase_rad) + " rad" + (tone_ ? "" : " (time-shift form)");
}

// ---------------------------------------------------------------- HarmonicDistortion

void validate(const std::vector<Harmonic>& hs) {
  for (std::size_t i = 0; i < hs.size(); ++i) {
    const std::string f = "harmonics[" + std::to_string(i) + "].";
    if (hs[i].order < 2) throw std::invalid_argument(f + "order = " + std::to_string(hs[i].order) + " must be >= 2");
    check_non_negative(hs[i].ratio, f + "ratio");
    check_finite(hs[i].phase_rad, f + "phase_rad");
  }
}

HarmonicDistortion::HarmonicDistortion(std::shared_ptr<const ToneExcitation> tone, std::vector<Harmonic> harmonics)
    : tone_(not_null(std::move(tone), "tone")), harmonics_(std::move(harmonics)) {
  validate(harmonics_);
}

Vec3 HarmonicDistortion::acceleration_g(double t) const {
  const double theta = tone_->carrier(t).phase_rad;
  const Vec3 amp = tone_->amplitude_g(), ph = tone_->phase_rad();
  Vec3 a;
  for (int i = 0; i < 3; ++i) {
    // An axis the tone does not move stays at rest (its sines are not evaluated: most runs
    // shake along one axis). +0 where amp * s would give a zero of s's sign, which no sum sees.
    if (amp[i] == 0) {
      a[i] = 0.0;
      continue;
    }
    const double psi = theta + ph[i];
    double s = std::sin(psi);
    for (const Harmonic& h : harmonics_) s += h.ratio * std::sin(h.order * psi + h.phase_rad);
    a[i] = amp[i] * s;
  }
  return a;
}

double HarmonicDistortion::max_frequency_Hz() const {
  int top = 1;
  for (const Harmonic& h : harmonics_) top = std::max(top, h.order);
  return top * tone_->max_frequency_Hz();
}

double HarmonicDistortion::total_harmonic_distortion() const {
  double s = 0;
  for (const Harmonic& h : harmonics_) s += h.ratio * h.ratio;
  return std::sqrt(s);
}

std::string HarmonicDistortion::describe() const {
  return tone_->describe() + "; harmonic distortion " + num(100 * total_harmonic_distortion()) + " %";
}

// ---------------------------------------------------------------- Rocking

void validate(const RockingSpec& s) {
  for (int i = 0; i < 3; ++i) {
    check_finite(s.axis[i], std::string("axis[") + kAxisName[i] + "]");
    check_finite(s.static_gravity_g[i], std::string("static_gravity_g[") + kAxisName[i] + "]");
  }
  if (s.axis.norm() == 0) throw std::invalid_argument("axis is the zero vector");
  check_non_negative(s.amplitude_rad, "amplitude_rad");
  check_finite(s.phase_rad, "phase_rad");
  if (s.lever_arm_m) {
    for (int i = 0; i < 3; ++i) check_finite((*s.lever_arm_m)[i], std::string("lever_arm_m[") + kAxisName[i] + "]");
    if (!std::isfinite(s.g_m_per_s2) || s.g_m_per_s2 <= 0)
      throw std::invalid_argument("g_m_per_s2 = " + num(s.g_m_per_s2) + " must be > 0 with a lever arm");
  }
}

Rocking::Rocking(std::shared_ptr<const ToneExcitation> tone, const RockingSpec& spec)
    : Rocking(std::shared_ptr<const Excitation>(tone), tone, spec) {}

Rocking::Rocking(std::shared_ptr<const Excitation> inner, std::shared_ptr<const ToneExcitation> carrier,
                 const RockingSpec& spec)
    : inner_(not_null(std::move(inner), "inner")), carrier_(not_null(std::move(carrier), "carrier")), spec_(spec) {
  validate(spec_);
  spec_.axis.normalize();
}

double Rocking::angle_rad(double t) const {
  return spec_.amplitude_rad * std::sin(carrier_->carrier(t).phase_rad + spec_.phase_rad);
}

Vec3 Rocking::acceleration_g(double t) const {
  const CarrierState c = carrier_->carrier(t);
  const double psi = c.phase_rad + spec_.phase_rad;
  const double alpha = spec_.amplitude_rad * std::sin(psi);
  const Vec3& e = spec_.axis;
  const Vec3& g0 = spec_.static_gravity_g;
  const Vec3 a_in = inner_->acceleration_g(t);
  auto rotate_t = [&](const Vec3& v) -> Vec3 {  // R(alpha)^T v
    return v * std::cos(alpha) - e.cross(v) * std::sin(alpha) + e * e.dot(v) * (1 - std::cos(alpha));
  };
  Vec3 a = spec_.rotate_shaker_motion ? Vec3(rotate_t(g0 + a_in) - g0) : Vec3(rotate_t(g0) - g0 + a_in);
  if (spec_.lever_arm_m) {
    const double w = kTwoPi * c.frequency_Hz;  // theta'
    const double alpha_dot = spec_.amplitude_rad * std::cos(psi) * w;
    const double alpha_ddot =
        -spec_.amplitude_rad * std::sin(psi) * w * w + spec_.amplitude_rad * std::cos(psi) * kTwoPi * c.rate_Hz_per_s;
    const Vec3& r = *spec_.lever_arm_m;
    const Vec3 r_perp = r - e * e.dot(r);
    a += (alpha_ddot * e.cross(r) - alpha_dot * alpha_dot * r_perp) / spec_.g_m_per_s2;
  }
  return a;
}

Vec3 Rocking::mean_g() const {
  constexpr int kPoints = 256;
  const double period_s = 1 / carrier_->carrier(0.0).frequency_Hz;
  Vec3 m = Vec3::Zero();
  for (int k = 0; k < kPoints; ++k) m += acceleration_g(period_s * k / kPoints) / kPoints;
  return m;
}

double Rocking::max_frequency_Hz() const {
  return std::max(inner_->max_frequency_Hz(), 2 * carrier_->max_frequency_Hz());
}

std::string Rocking::describe() const {
  return inner_->describe() + "; rocking " + num(spec_.amplitude_rad) + " rad about [" + num(spec_.axis[0]) + ", " +
         num(spec_.axis[1]) + ", " + num(spec_.axis[2]) + "]" +
         (spec_.lever_arm_m ? ", lever arm " + num(spec_.lever_arm_m->norm()) + " m" : "");
}

}  // namespace vrelab::vibration
