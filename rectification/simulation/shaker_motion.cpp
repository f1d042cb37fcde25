#include "rectification/simulation/shaker_motion.hpp"

#include <algorithm>
#include <stdexcept>
#include <string>

#include "vibration/sampled.hpp"

namespace vrelab::rectification {

namespace {

using ExcitationPtr = std::shared_ptr<const vibration::Excitation>;

// The tone with the shaker's imperfections: harmonics, then transverse motion, then rocking.
ExcitationPtr imperfect_tone(const std::shared_ptr<const vibration::ToneExcitation>& tone, const VibrationRequest& v,
                             const ShakerImperfections& shaker, const Vec3& a_static_g, double g_m_per_s2) {
  ExcitationPtr m = tone;
  if (!shaker.harmonics.empty()) m = std::make_shared<vibration::HarmonicDistortion>(tone, shaker.harmonics);
  if (shaker.transverse) {
    if (shaker.harmonics.empty())
      m = std::make_shared<vibration::TransverseMotion>(tone, *shaker.transverse);
    else
      m = std::make_shared<vibration::TransverseMotion>(m, *shaker.transverse, v.sine.frequency_Hz);
  }
  if (shaker.rocking) {
    vibration::RockingSpec r = *shaker.rocking;
    r.static_gravity_g = a_static_g;
    r.g_m_per_s2 = g_m_per_s2;
    m = std::make_shared<vibration::Rocking>(m, tone, r);
  }
  return m;
}

}  // namespace

ShakerMotion shaker_motion(const VibrationRequest& v, const ShakerImperfections& shaker, const Vec3& a_static_g,
                         double g_m_per_s2, std::uint64_t seed) {
  ShakerMotion t;
  t.periodic = v.type == VibrationKind::sine;
  if (has_random_part(v.type) && !v.psd)
    throw std::invalid_argument("rms_g: a shaken " + to_string(v.type) +
                                " profile needs PSD tables psd_IA / psd_PA / psd_OA");
  if (t.periodic && !(v.sine.frequency_Hz > 0))
    throw std::invalid_argument("frequency_Hz: a shaker run needs a positive frequency");
  std::shared_ptr<const vibration::ToneExcitation> tone;
  if (has_sine_tone(v.type)) tone = std::make_shared<vibration::SineExcitation>(v.sine);
  if (v.swept) tone = std::make_shared<vibration::SweptSineExcitation>(*v.swept);
  if (!tone && shaker.imperfect())
    throw std::invalid_argument("transverse motion, harmonics and rocking apply to sine and swept-sine runs");
  ExcitationPtr m = tone ? imperfect_tone(tone, v, shaker, a_static_g, g_m_per_s2) : nullptr;
  if (v.psd) {
    t.top_Hz = vibration::max_frequency_Hz(*v.psd);
    auto random = std::make_shared<vibration::RandomExcitation>(*v.psd, 8 * t.top_Hz, seed);
    m = m ? ExcitationPtr(std::make_shared<vibration::SumExcitation>(std::vector<ExcitationPtr>{m, random})) : random;
    t.demand = vibration::shaker_demand(*v.psd, g_m_per_s2);
  }
  if (v.swept) t.demand = vibration::shaker_demand(*v.swept, g_m_per_s2);
  if (has_sine_tone(v.type)) {
    const auto d = vibration::shaker_demand(v.sine, shaker.harmonics, g_m_per_s2);
    t.demand = v.type == VibrationKind::sine ? d : vibration::combine(d, t.demand);
  }
  if (!m) throw std::invalid_argument("type: no motion for vibration type '" + to_string(v.type) + "'");
  t.top_Hz = std::max(t.top_Hz, m->max_frequency_Hz());
  t.motion = m;
  return t;
}

}  // namespace vrelab::rectification
