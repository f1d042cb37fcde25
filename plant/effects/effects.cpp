#include "plant/effects/effects.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <stdexcept>
#include <utility>

namespace vrelab::plant {

PickoffNonlinearity::PickoffNonlinearity(double p2) : p2_(p2) {
  if (!std::isfinite(p2)) throw std::invalid_argument("pickoff p2_per_rad must be finite");
}

CurrentSaturation::CurrentSaturation(double limit_g) : limit_g_(limit_g) {
  if (!(limit_g > 0) || !std::isfinite(limit_g)) throw std::invalid_argument("saturation limit_g must be positive");
}

double CurrentSaturation::current(double i) const { return std::clamp(i, -limit_g_, limit_g_); }

OutputPolynomial::OutputPolynomial(std::string name, const std::array<double, 7>& c) : name_(std::move(name)), c_(c) {
  if (c[0] != 0 || c[1] != 0) throw std::invalid_argument(name_ + ": the readout polynomial starts at u^2");
  for (double x : c)
    if (!std::isfinite(x)) throw std::invalid_argument(name_ + ": readout coefficients must be finite");
}

double OutputPolynomial::readout(double u) const {
  double s = 0;  // Horner on c_6 u^6 + ... + c_2 u^2
  for (int n = 6; n >= 2; --n) s = (s + c_[static_cast<std::size_t>(n)]) * u;
  return u + s * u;
}

ReadoutClipping::ReadoutClipping(double full_scale_g) : full_scale_g_(full_scale_g) {
  if (!(full_scale_g > 0) || !std::isfinite(full_scale_g)) throw std::invalid_argument("readout clipping full_scale_g must be positive");
}

double ReadoutClipping::readout(double u) const { return std::clamp(u, -full_scale_g_, full_scale_g_); }

SqueezeFilmDamping::SqueezeFilmDamping(double gap, double c0, double b) : gap_rad_(gap), c0_(c0), b_(b) {
  if (!(gap > 0) || !std::isfinite(gap)) throw std::invalid_argument("squeeze film gap_angle_rad must be positive");
  if (!(c0 >= 0) || !std::isfinite(c0)) throw std::invalid_argument("squeeze film c0_per_s must be >= 0");
  if (!(b > 0) || !std::isfinite(b)) throw std::invalid_argument("squeeze film angle_gain must be positive");
}

double SqueezeFilmDamping::extra_input_g(double theta, double omega, double, const Vec3&) const {
  const double x = std::min(std::abs(theta) / gap_rad_, 0.95);
  const double factor = 1 / std::pow(1 - x * x, 1.5) - 1;
  return -c0_ * factor * omega / b_;  // the plant multiplies by b
}

double SqueezeFilmDamping::damping_factor(double theta_amplitude) const {
  constexpr int kN = 128;  // trapezoid over a period: spectral for the smooth law below 0.95 theta_gap
  double sum = 0;
  for (int k = 0; k < kN; ++k) {
    const double phi = 2 * std::numbers::pi * k / kN;
    const double x = std::min(std::abs(theta_amplitude * std::sin(phi)) / gap_rad_, 0.95);
    sum += std::cos(phi) * std::cos(phi) / std::pow(1 - x * x, 1.5);
  }
  return 2 * sum / kN;
}

double PendulumGeometry::extra_input_g(double theta, double, double s1, const Vec3& a) const {
  return s1 * (std::cos(theta) - 1) - a[PA] * std::sin(theta);
}

MechanicalMode::MechanicalMode(double f, double z, const Vec3& mask)
    : w_(2 * std::numbers::pi * f), z_(z), mask_(mask) {
  if (!(f > 0) || !std::isfinite(f)) throw std::invalid_argument("mode frequency_Hz must be positive");
  if (!(z > 0) || !std::isfinite(z)) throw std::invalid_argument("mode damping_ratio must be positive");
}

std::complex<double> MechanicalMode::transmissibility(int axis, double w) const {
  if (mask_[axis] == 0) return 1.0;
  const std::complex<double> s(0, w);
  return (w_ * w_ + 2 * z_ * w_ * s) / (s * s + 2 * z_ * w_ * s + w_ * w_);
}

double MechanicalMode::state_scale(int k) const { return k % 2 == 0 ? 1 / (w_ * w_) : 1 / w_; }

void MechanicalMode::rest_state(const Vec3& a, double* s) const {
  for (int i = 0; i < 3; ++i) {
    s[2 * i] = mask_[i] != 0 ? -a[i] / (w_ * w_) : 0.0;
    s[2 * i + 1] = 0.0;
  }
}

Vec3 MechanicalMode::input(const Vec3& a, const double* s, double* ds) const {
  // Relative coordinate y (g s^2): y'' + 2 z w y' + w^2 y = -a_case; the pendulum's base
  // then accelerates with a_case + y'' = -(2 z w y' + w^2 y).
  Vec3 out = a;
  for (int i = 0; i < 3; ++i) {
    if (mask_[i] == 0) {
      ds[2 * i] = ds[2 * i + 1] = 0.0;
      continue;
    }
    const double y = s[2 * i], v = s[2 * i + 1];
    ds[2 * i] = v;
    ds[2 * i + 1] = -a[i] - 2 * z_ * w_ * v - w_ * w_ * y;
    out[i] = -(2 * z_ * w_ * v + w_ * w_ * y);
  }
  return out;
}

}  // namespace vrelab::plant
