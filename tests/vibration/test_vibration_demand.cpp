// What a profile asks of the shaker (vibration/demand.hpp): hand values for sine and sweep,
// the PSD integrals for random, sine-on-random, and the feasibility check's messages.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <stdexcept>
#include <string>

#include "support/constants.hpp"
#include "support/vibrations.hpp"
#include "vibration/demand.hpp"

namespace test_vibration_demand {

using namespace vrelab;
using namespace vrelab::vibration;
using vrelab::test::gevs_on_ia;
using vrelab::test::kG;

namespace {

std::string message(auto&& f) {
  try {
    f();
  } catch (const std::invalid_argument& e) {
    return e.what();
  }
  return "(no exception)";
}

}  // namespace

// Sine 10 g at 100 Hz: v = 10 x 9.80665 / (2 pi 100) = 0.1560777 m/s, d = v / (2 pi 100)
// = 2.484053e-4 m (by hand); rms = peak / sqrt 2; the PA axis at 5 g halves them; the table
// moves along (10, 5) g: stroke 2 sqrt(1 + 0.25) x 2.484053e-4 m. 1e-6 relative: the hand
// values are rounded to 7 figures.
TEST(ShakerDemand, SineByHand) {
  const ShakerDemand d = shaker_demand(SineVibration{Vec3(10, 5, 0), Vec3(0, 0, 0), 100}, kG);
  EXPECT_NEAR(d.acceleration_peak_g[IA], 10, 1e-15);
  EXPECT_NEAR(d.acceleration_rms_g[IA], 10 / std::sqrt(2.0), 1e-14);
  EXPECT_NEAR(d.velocity_peak_m_per_s[IA], 0.1560777, 1e-6 * 0.156);
  EXPECT_NEAR(d.velocity_rms_m_per_s[IA], 0.1560777 / std::sqrt(2.0), 1e-6 * 0.156);
  EXPECT_NEAR(d.displacement_peak_m[IA], 2.484053e-4, 1e-6 * 2.48e-4);
  EXPECT_NEAR(d.displacement_peak_m[PA], 2.484053e-4 / 2, 1e-6 * 2.48e-4);
  EXPECT_EQ(d.displacement_peak_m[OA], 0);
  EXPECT_NEAR(d.table_stroke_peak_to_peak_m(), 2 * std::sqrt(1.25) * 2.484053e-4, 1e-6 * 5.6e-4);
  EXPECT_NE(message([] {
              shaker_demand(SineVibration{Vec3(1, 0, 0), Vec3::Zero(), 0}, kG);
            }).find("frequency_Hz"),
            std::string::npos);
  EXPECT_NE(message([] {
              shaker_demand(SineVibration{Vec3(1, 0, 0), Vec3::Zero(), 50}, -1);
            }).find("g_m_per_s2"),
            std::string::npos);
}

// A sweep asks the most velocity and displacement at its lowest frequency: 2 g from 5 Hz
// (either direction): stroke 2 x 2 x 9.80665 / (2 pi 5)^2 = 39.74486 mm peak-to-peak.
TEST(ShakerDemand, SweepAtItsLowestFrequency) {
  SweptSine s;
  s.amplitude_g = Vec3(2, 0, 0);
  s.start_frequency_Hz = 500;
  s.end_frequency_Hz = 5;
  s.rate_octaves_per_min = 1;
  const ShakerDemand d = shaker_demand(s, kG);
  EXPECT_NEAR(d.table_stroke_peak_to_peak_m(), 39.74486e-3, 1e-8);
  EXPECT_NEAR(d.acceleration_peak_g[IA], 2, 1e-15);
}

// Random: rms from the PSD integrals, peak 3 sigma. GEVS: 14.136 g rms, 0.1103 m/s rms,
// 0.3819 mm rms (numpy, see test_vibration_psd): stroke 6 x 0.3819 = 2.2915 mm p-p,
// velocity 3 x 0.1103 = 0.3309 m/s peak.
TEST(ShakerDemand, RandomFromThePsdWithThreeSigmaPeaks) {
  const ShakerDemand d = shaker_demand(gevs_on_ia(), kG);
  EXPECT_NEAR(d.acceleration_rms_g[IA], 14.13561372, 1e-7);
  EXPECT_NEAR(d.acceleration_peak_g[IA], 3 * 14.13561372, 3e-7);
  EXPECT_NEAR(d.table_stroke_peak_to_peak_m(), 2.2915099e-3, 1e-10);
  EXPECT_NEAR(d.table_velocity_peak_m_per_s(), 0.33093807, 1e-8);
  EXPECT_EQ(d.acceleration_rms_g[PA], 0);
}

// Feasibility: GEVS fits a 25.4 mm, 1.8 m/s shaker; the 5 Hz sweep needs 39.7 mm (stroke
// message names the limit and both values); a 10 g sine at 5 Hz needs 3.12 m/s.
TEST(ShakerDemand, FeasibilityCheckNamesLimitAndNeed) {
  const ShakerLimits lim{25.4e-3, 1.8};
  EXPECT_NO_THROW(check_feasible(shaker_demand(gevs_on_ia(), kG), lim));
  SweptSine s;
  s.amplitude_g = Vec3(2, 0, 0);
  s.start_frequency_Hz = 5;
  s.end_frequency_Hz = 500;
  s.rate_octaves_per_min = 1;
  const std::string m = message([&] { check_feasible(shaker_demand(s, kG), lim); });
  for (const char* part : {"stroke_peak_to_peak_m", "25.4 mm", "39.74 mm", "peak-to-peak"})
    EXPECT_NE(m.find(part), std::string::npos) << part << " not in: " << m;
  const std::string v = message([&] {
    check_feasible(shaker_demand(SineVibration{Vec3(10, 0, 0), Vec3::Zero(), 5}, kG), {1.0, 1.8});
  });
  for (const char* part : {"velocity_peak_m_per_s", "1.8 m/s", "3.122 m/s"})
    EXPECT_NE(v.find(part), std::string::npos) << part << " not in: " << v;
  EXPECT_NE(message([] {
              check_feasible(ShakerDemand{}, {0.0, 1.0});
            }).find("stroke_peak_to_peak_m"),
            std::string::npos);
  EXPECT_NO_THROW(check_feasible(shaker_demand(s, kG), ShakerLimits{}));  // defaults: no limits
  // Sine on random: peaks add, rms add in quadrature.
  const ShakerDemand sr =
      combine(shaker_demand(SineVibration{Vec3(3, 0, 0), Vec3::Zero(), 100}, kG), shaker_demand(gevs_on_ia(), kG));
  EXPECT_NEAR(sr.acceleration_peak_g[IA], 3 + 3 * 14.13561372, 3e-7);
  EXPECT_NEAR(sr.acceleration_rms_g[IA], std::sqrt(4.5 + 14.13561372 * 14.13561372), 1e-7);
}

}  // namespace test_vibration_demand
