#pragma once
// vibration/demand.hpp -- what a profile asks of the shaker, and whether the shaker can.
//
// Takes: a profile (sine, sine with harmonics, sweep, PSD-specified random; two demands
//        combine for sine-on-random), the site's gravity in m/s^2, and shaker limits.
// Gives: per sensor axis [IA, PA, OA]: acceleration rms and peak (g), velocity rms and peak
//        (m/s), displacement rms and peak (m); check_feasible() throws std::invalid_argument
//        naming the limit and the value the profile needs when a limit is exceeded.
//
// Sine A (g peak) at f: velocity A g / w, displacement A g / w^2, w = 2 pi f; rms = peak/sqrt 2.
// Harmonics h (ratio r_h): peaks are bounds (all in phase): A sum r_h g / (h w)^p, p = 0, 1, 2
// (r_1 = 1); rms exact: A g/(w^p sqrt 2) sqrt(sum (r_h / h^p)^2).
// Sweep: the values at the frequency where each is largest (velocity and displacement at the
// lowest frequency).
// Random: rms from the PSD (vibration/psd.hpp); peak = 3 rms (shaker drives clip at 3 sigma).
// Sine-on-random (combine): rms add in quadrature (components at different frequencies are
// uncorrelated), peaks add (a bound).
// Limits: the table moves along one line when the axes are in phase (a tilted fixture on a
// one-axis shaker); its excursion is then the root-sum-square over the axes of the per-axis
// values, and for any other motion that root-sum-square is an upper bound. check_feasible
// compares: stroke, PEAK-TO-PEAK (as shaker data sheets give it), with 2 x rss of the
// displacement peaks; velocity, peak, with the rss of the velocity peaks.
#include <limits>
#include <string>
#include <vector>

#include "vibration/decorators.hpp"
#include "vibration/random.hpp"
#include "vibration/sweep.hpp"

namespace vrelab::vibration {

inline constexpr double kRandomPeakFactor = 3.0;

struct ShakerDemand {
  Vec3 acceleration_rms_g = Vec3::Zero();
  Vec3 acceleration_peak_g = Vec3::Zero();
  Vec3 velocity_rms_m_per_s = Vec3::Zero();
  Vec3 velocity_peak_m_per_s = Vec3::Zero();
  Vec3 displacement_rms_m = Vec3::Zero();
  Vec3 displacement_peak_m = Vec3::Zero();

  double table_velocity_peak_m_per_s() const { return velocity_peak_m_per_s.norm(); }
  double table_stroke_peak_to_peak_m() const { return 2 * displacement_peak_m.norm(); }
  std::string report() const;
};

// Throw std::invalid_argument when the profile is invalid, g_m_per_s2 is not > 0, or a
// sine's frequency_Hz is 0 (not given).
ShakerDemand shaker_demand(const SineVibration& v, double g_m_per_s2);
ShakerDemand shaker_demand(const SineVibration& v, const std::vector<Harmonic>& harmonics, double g_m_per_s2);
ShakerDemand shaker_demand(const SweptSine& s, double g_m_per_s2);
ShakerDemand shaker_demand(const RandomProfile& p, double g_m_per_s2);
ShakerDemand combine(const ShakerDemand& a, const ShakerDemand& b);

struct ShakerLimits {
  double stroke_peak_to_peak_m = std::numeric_limits<double>::infinity();  // infinity: no limit
  double velocity_peak_m_per_s = std::numeric_limits<double>::infinity();
};
void check_feasible(const ShakerDemand& d, const ShakerLimits& limits);

}  // namespace vrelab::vibration
