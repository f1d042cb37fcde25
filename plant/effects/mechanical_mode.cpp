#include "plant/effects/mechanical_mode.hpp"

#include <cmath>
#include <numbers>
#include <stdexcept>

namespace vrelab::plant {

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
