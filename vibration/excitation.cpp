#include "vibration/excitation.hpp"

#include <cmath>
#include <numbers>
#include <sstream>

namespace vrelab::vibration {

SineExcitation::SineExcitation(const SineVibration& v) : v_(v) { validate(v_); }

Vec3 SineExcitation::acceleration_g(double t) const {
  const double wt = 2 * std::numbers::pi * v_.frequency_Hz * t;
  Vec3 a;
  for (int i = 0; i < 3; ++i) a[i] = v_.amplitude_g[i] * std::sin(wt + v_.phase_rad[i]);
  return a;
}

CarrierState SineExcitation::carrier(double t) const {
  return {2 * std::numbers::pi * v_.frequency_Hz * t, v_.frequency_Hz, 0.0};
}

Vec3 ToneExcitation::acceleration_g(double t) const {
  const double theta = carrier(t).phase_rad;
  const Vec3 amp = amplitude_g(), ph = phase_rad();
  Vec3 a;
  for (int i = 0; i < 3; ++i) a[i] = amp[i] * std::sin(theta + ph[i]);
  return a;
}

std::string SineExcitation::describe() const {
  std::ostringstream s;
  s << "sine " << v_.frequency_Hz << " Hz, peak [" << v_.amplitude_g[0] << ", " << v_.amplitude_g[1] << ", "
    << v_.amplitude_g[2] << "] g";
  return s.str();
}

}  // namespace vrelab::vibration
