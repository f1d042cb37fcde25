#pragma once
// vibration/profile.hpp -- descriptions of the vibration a shaker applies.
//
// Takes: amplitudes (peak, g) or rms values (g) per sensor axis [IA, PA, OA], per-axis
//        phases (rad), an optional frequency (Hz), an optional correlation matrix.
// Gives: validated descriptions that the rectification predictions (and, later, the
//        time-series generators) consume. validate() throws std::invalid_argument whose
//        message names the offending field.
//
// Conventions: the vibration on axis i is w_i * sin(omega t + phase_i). Amplitudes and rms
// values are non-negative; a direction with a negative component is written with a phase
// of 180 deg on that axis. A random vibration is zero-mean Gaussian with covariance
// C_ij = rms_i * rms_j * rho_ij; by default rho_ij = 1 (one vibration direction).
#include <Eigen/Core>

#include "plant/model1.hpp"

namespace vrelab::vibration {

struct SineVibration {
  Vec3 amplitude_g = Vec3::Zero();  // peak, per axis
  Vec3 phase_rad = Vec3::Zero();    // per axis
  double frequency_Hz = 0.0;        // 0: not given (the static-model predictions ignore it)
};

struct RandomVibration {
  Vec3 rms_g = Vec3::Zero();
  Eigen::Matrix3d correlation = Eigen::Matrix3d::Ones();
  Eigen::Matrix3d covariance_g2() const;
};

void validate(const SineVibration& v);
void validate(const RandomVibration& v);

}  // namespace vrelab::vibration
