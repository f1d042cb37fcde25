#pragma once
// rectification/simulation/shaker_motion.hpp -- the shaker table's motion for a run on the
// virtual shaker: the commanded vibration with the shaker's imperfections, and its demand.
//
// Takes: the commanded vibration (sine, random or sine-on-random from PSD tables, swept
//        sine), the shaker's imperfections (transverse motion, harmonic distortion, rocking:
//        each off unless given; they act on sine and swept-sine tones), the static
//        orientation (gravity in sensor axes, g), the site's gravity (m/s^2) and the seed of
//        the random part.
// Gives: the table's motion as one Excitation (tone, decorated by the imperfections, plus
//        the random part), the shaker's demand (rms/peak acceleration, velocity,
//        displacement) and the highest frequency in the motion (Hz). Throws
//        std::invalid_argument naming the setting for a request the shaker cannot make.
// The one builder of a shaker run's motion: `shake` uses it, and the diagnosis' virtual lab
// can build its runs' motion with it (validation/diagnosis has its own today).
#include <cstdint>
#include <memory>
#include <optional>
#include <vector>

#include "rectification/simulation/vibration_kind.hpp"
#include "vibration/decorators.hpp"
#include "vibration/demand.hpp"
#include "vibration/excitation.hpp"
#include "vibration/profile.hpp"
#include "vibration/psd.hpp"
#include "vibration/sweep.hpp"

namespace vrelab::rectification {

// The commanded vibration.
struct VibrationRequest {
  VibrationKind type = VibrationKind::sine;
  vibration::SineVibration sine;                // sine, sine_on_random
  std::optional<vibration::RandomProfile> psd;  // random, sine_on_random: PSD tables
  std::optional<vibration::SweptSine> swept;    // swept_sine
};

// The shaker's imperfections, each off unless given.
struct ShakerImperfections {
  std::optional<vibration::TransverseSpec> transverse;
  std::vector<vibration::Harmonic> harmonics;
  std::optional<vibration::RockingSpec> rocking;
  bool imperfect() const { return transverse || !harmonics.empty() || rocking; }
};

struct ShakerMotion {
  std::shared_ptr<const vibration::Excitation> motion;
  vibration::ShakerDemand demand;
  double top_Hz = 0;      // highest frequency in the motion
  bool periodic = false;  // a pure sine request: measured over whole periods (shake_sine)
};

ShakerMotion shaker_motion(const VibrationRequest& v, const ShakerImperfections& shaker, const Vec3& a_static_g,
                         double g_m_per_s2, std::uint64_t seed);

}  // namespace vrelab::rectification
