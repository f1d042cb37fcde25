#include "vibration/profile.hpp"

#include <cmath>
#include <stdexcept>
#include <string>

#include <Eigen/Eigenvalues>

namespace vrelab::vibration {
namespace {

void check_axes(const Vec3& v, const char* field, bool non_negative) {
  static const char* axis[3] = {"IA", "PA", "OA"};
  for (int i = 0; i < 3; ++i) {
    if (!std::isfinite(v[i]))
      throw std::invalid_argument(std::string(field) + "[" + axis[i] + "] is not a finite number");
    if (non_negative && v[i] < 0)
      throw std::invalid_argument(std::string(field) + "[" + axis[i] + "] = " + std::to_string(v[i]) + " is negative" +
                                  (std::string(field) == "amplitude_g" ? " (use a phase of 180 deg for a reversed axis)" : ""));
  }
}

}  // namespace

Eigen::Matrix3d RandomVibration::covariance_g2() const {
  return rms_g.asDiagonal() * correlation * rms_g.asDiagonal();
}

void validate(const SineVibration& v) {
  check_axes(v.amplitude_g, "amplitude_g", true);
  check_axes(v.phase_rad, "phase", false);
  if (!std::isfinite(v.frequency_Hz) || v.frequency_Hz < 0)
    throw std::invalid_argument("frequency_Hz = " + std::to_string(v.frequency_Hz) +
                                " must be a finite, non-negative number");
}

void validate(const RandomVibration& v) {
  check_axes(v.rms_g, "rms_g", true);
  const Eigen::Matrix3d& r = v.correlation;
  if (!r.allFinite()) throw std::invalid_argument("correlation has a non-finite entry");
  if ((r - r.transpose()).cwiseAbs().maxCoeff() > 1e-12)
    throw std::invalid_argument("correlation is not symmetric");
  for (int i = 0; i < 3; ++i)
    if (std::abs(r(i, i) - 1.0) > 1e-12)
      throw std::invalid_argument("correlation must have ones on its diagonal");
  const double min_eig = Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(r).eigenvalues().minCoeff();
  if (min_eig < -1e-12)
    throw std::invalid_argument("correlation is not positive semi-definite (smallest eigenvalue " +
                                std::to_string(min_eig) + ")");
}

}  // namespace vrelab::vibration
