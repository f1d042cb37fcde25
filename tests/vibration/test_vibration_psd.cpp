// PSD breakpoint tables (vibration/psd.hpp): log-log interpolation, dB/octave rows, the
// closed-form rms of acceleration, velocity and displacement, and validation messages.
// References: hand values, published Grms of standard specs, and Gauss-Legendre quadrature
// in ln f of a log-log line written here independently (a straight line between the
// breakpoints' logarithms).
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <stdexcept>
#include <string>
#include <vector>

#include "support/constants.hpp"
#include "support/quadrature.hpp"
#include "support/vibrations.hpp"
#include "vibration/psd.hpp"

namespace test_vibration_psd {

using namespace vrelab::vibration;
using vrelab::test::gevs_psd;
using vrelab::test::kG;
using vrelab::test::kPi;

namespace {

PsdTable table(const std::vector<std::pair<double, double>>& rows) {
  PsdTable t;
  for (auto [f, p] : rows) t.rows.push_back(PsdRow::level(f, p));
  return t;
}

// Integral of f^m P(f) df by quadrature in u = ln f, P interpolated linearly in (ln f, ln P).
// The integrand e^{(m+1)u} P(e^u) is an exponential in u on each segment: 16 pieces of
// 20-point Gauss-Legendre converge to rounding (~1e-15 relative).
double quadrature_moment(const std::vector<std::pair<double, double>>& rows, int m) {
  double sum = 0;
  for (std::size_t k = 0; k + 1 < rows.size(); ++k) {
    const double u1 = std::log(rows[k].first), u2 = std::log(rows[k + 1].first);
    const double l1 = std::log(rows[k].second), l2 = std::log(rows[k + 1].second);
    sum += vrelab::test::integrate_smooth(
        [&](double u) { return std::exp(l1 + (l2 - l1) * (u - u1) / (u2 - u1) + (m + 1) * u); }, u1, u2);
  }
  return sum;
}

std::string message_of(const PsdTable& t) {
  try {
    validate(t);
  } catch (const std::invalid_argument& e) {
    return e.what();
  }
  return "(no exception)";
}

}  // namespace

// On a log-log straight line the geometric mean of two frequencies carries the geometric
// mean of their levels; breakpoints are returned exactly; the PSD is 0 outside the band.
// Tolerance 1e-14 relative: one pow/log chain, a few ulp.
TEST(PsdTable, LogLogInterpolationAtGeometricMidpoints) {
  const ResolvedPsd p = resolve(gevs_psd());
  EXPECT_NEAR(psd_g2_per_Hz(p, std::sqrt(20.0 * 50.0)), std::sqrt(0.026 * 0.16), 1e-14 * 0.1);
  EXPECT_NEAR(psd_g2_per_Hz(p, std::sqrt(800.0 * 2000.0)), std::sqrt(0.16 * 0.026), 1e-14 * 0.1);
  EXPECT_NEAR(psd_g2_per_Hz(p, 300.0), 0.16, 1e-15);
  for (double f : {50.0, 800.0})  // continuous at inner breakpoints: slope x 1e-12 relative step
    EXPECT_NEAR(psd_g2_per_Hz(p, f * (1 - 1e-12)), psd_g2_per_Hz(p, f * (1 + 1e-12)), 1e-12) << f;
  EXPECT_DOUBLE_EQ(psd_g2_per_Hz(p, 20.0), 0.026);
  EXPECT_DOUBLE_EQ(psd_g2_per_Hz(p, 2000.0), 0.026);
  EXPECT_EQ(psd_g2_per_Hz(p, 19.999), 0.0);
  EXPECT_EQ(psd_g2_per_Hz(p, 2000.001), 0.0);
  EXPECT_EQ(psd_g2_per_Hz(p, 0.0), 0.0);
}

// A row given as +6 dB/octave: by the definition of the unit, 10 log10(P2/P1) / log2(f2/f1)
// is 6 dB per octave again (to rounding, 1e-12 dB), and the GEVS table written with slopes
// (+6 dB/oct to 50 Hz, -6 dB/oct from 800 Hz) gives 14.1 g rms like the level form (the
// published 0.16 and 0.026 are themselves rounded from +-6 dB/oct: agreement to 1 %).
TEST(PsdTable, SlopeRowsInDecibelsPerOctave) {
  PsdTable t;
  t.rows = {PsdRow::level(20, 0.026), PsdRow::slope(50, 6.0), PsdRow::level(800, 0.16), PsdRow::slope(2000, -6.0)};
  const ResolvedPsd p = resolve(t);
  EXPECT_NEAR(10 * std::log10(p.psd_g2_per_Hz[1] / p.psd_g2_per_Hz[0]) / std::log2(50.0 / 20.0), 6.0, 1e-12);
  EXPECT_NEAR(10 * std::log10(p.psd_g2_per_Hz[3] / p.psd_g2_per_Hz[2]) / std::log2(2000.0 / 800.0), -6.0, 1e-12);
  EXPECT_NEAR(p.psd_g2_per_Hz[1], 0.16, 0.01 * 0.16);
  EXPECT_NEAR(rms_g(t), rms_g(gevs_psd()), 0.01 * rms_g(gevs_psd()));
  // 3 dB/octave is a factor 10^0.3 ~ 1.995 per octave: 20 -> 80 Hz (2 octaves) at +3 dB/oct.
  PsdTable n;
  n.rows = {PsdRow::level(20, 0.01), PsdRow::slope(80, 3.0)};
  EXPECT_NEAR(psd_g2_per_Hz(n, 80.0), 0.01 * std::pow(10.0, 0.6), 1e-15);
}

// The closed-form moments against quadrature (1e-12 relative: both are converged to ~1e-15;
// the margin covers the pow/expm1 rounding of the closed form), and the published Grms of
// standard specs (rounded to 3 figures: 0.5 %).
TEST(PsdTable, RmsOfStandardSpecsClosedFormVersusQuadrature) {
  struct Spec {
    const char* name;
    std::vector<std::pair<double, double>> rows;
    double published_grms;  // 0: none quoted
  };
  const std::vector<Spec> specs = {
      {"GEVS", {{20, 0.026}, {50, 0.16}, {800, 0.16}, {2000, 0.026}}, 14.1},
      {"NAVMAT P-9492", {{20, 0.01}, {80, 0.04}, {350, 0.04}, {2000, 0.007}}, 6.06},
      {"MIL-STD-1540B workmanship", {{20, 0.0053}, {150, 0.04}, {600, 0.04}, {2000, 0.0036}}, 0},
      {"MIL-STD-810H common carrier", {{5, 0.015}, {40, 0.015}, {500, 0.00015}}, 0},
  };
  for (const Spec& s : specs) {
    const PsdTable t = table(s.rows);
    const double a2 = quadrature_moment(s.rows, 0), v2 = quadrature_moment(s.rows, -2),
                 d2 = quadrature_moment(s.rows, -4);
    EXPECT_NEAR(rms_g(t), std::sqrt(a2), 1e-12 * std::sqrt(a2)) << s.name;
    const double v = kG / (2 * kPi) * std::sqrt(v2), d = kG / (4 * kPi * kPi) * std::sqrt(d2);
    EXPECT_NEAR(velocity_rms_m_per_s(t, kG), v, 1e-12 * v) << s.name;
    EXPECT_NEAR(displacement_rms_m(t, kG), d, 1e-12 * d) << s.name;
    if (s.published_grms > 0) {
      EXPECT_NEAR(rms_g(t), s.published_grms, 0.005 * s.published_grms) << s.name;
    }
  }
  // Independent figures from a numpy trapezoid on 2e6 log-spaced points (agree to 1e-8).
  EXPECT_NEAR(rms_g(gevs_psd()), 14.13561372, 1e-7);
  EXPECT_NEAR(velocity_rms_m_per_s(gevs_psd(), kG), 0.1103126913, 1e-9);
  EXPECT_NEAR(displacement_rms_m(gevs_psd(), kG), 3.819183224e-4, 1e-11);
}

// Hand integrals: a 1/f segment (the ln case of the closed form, c = 0): P = 0.1 (100/f)
// from 10 to 100 Hz integrates to 10 ln 10; a flat segment's velocity mean square is
// G g^2/(4 pi^2) (1/f1 - 1/f2), its displacement's G g^2/(16 pi^4) (1/f1^3 - 1/f2^3)/3.
TEST(PsdTable, HandIntegralsOfOneOverFAndFlatSegments) {
  EXPECT_NEAR(rms_g(table({{10, 1.0}, {100, 0.1}})), std::sqrt(10 * std::log(10.0)), 1e-13);
  // Slope -1 + tiny: the expm1 form must not lose digits next to c = 0.
  EXPECT_NEAR(rms_g(table({{10, 1.0}, {100, 0.1 * (1 + 1e-13)}})), std::sqrt(10 * std::log(10.0)), 1e-12);
  const double G = 0.04, f1 = 20, f2 = 2000;
  const PsdTable flat = table({{f1, G}, {f2, G}});
  EXPECT_NEAR(rms_g(flat), std::sqrt(G * (f2 - f1)), 1e-13);
  EXPECT_NEAR(velocity_rms_m_per_s(flat, kG), kG / (2 * kPi) * std::sqrt(G * (1 / f1 - 1 / f2)), 1e-15);
  EXPECT_NEAR(displacement_rms_m(flat, kG),
              kG / (4 * kPi * kPi) * std::sqrt(G * (1 / (f1 * f1 * f1) - 1 / (f2 * f2 * f2)) / 3), 1e-17);
}

TEST(PsdTable, ValidationNamesFieldAndRow) {
  auto expect = [](const PsdTable& t, const std::vector<std::string>& parts) {
    const std::string m = message_of(t);
    for (const auto& p : parts) EXPECT_NE(m.find(p), std::string::npos) << "'" << p << "' not in: " << m;
  };
  expect(table({{20, 0.026}}), {"at least 2"});
  expect(table({{20, 0.026}, {50, 0.16}, {50, 0.1}}), {"row 3", "frequency_Hz", "strictly"});
  expect(table({{20, 0.026}, {10, 0.16}}), {"row 2", "frequency_Hz"});
  expect(table({{0, 0.026}, {10, 0.16}}), {"row 1", "frequency_Hz"});
  expect(table({{20, 0.026}, {50, -0.16}}), {"row 2", "psd_g2_per_Hz"});
  expect(table({{20, 0.026}, {50, 0.0}}), {"row 2", "psd_g2_per_Hz"});
  expect(table({{20, 0.026}, {NAN, 0.1}}), {"row 2", "frequency_Hz"});
  expect(table({{20, 0.026}, {50, INFINITY}}), {"row 2", "psd_g2_per_Hz"});
  PsdTable t;
  t.rows = {PsdRow::slope(20, 3.0), PsdRow::level(50, 0.1)};
  expect(t, {"row 1", "first row"});
  t.rows = {PsdRow::level(20, 0.1), PsdRow{50, 0.1, 3.0}};
  expect(t, {"row 2", "exactly one"});
  t.rows = {PsdRow::level(20, 0.1), PsdRow{50, {}, {}}};
  expect(t, {"row 2", "exactly one"});
  t.rows = {PsdRow::level(20, 0.1), PsdRow::slope(50, NAN)};
  expect(t, {"row 2", "slope_dB_per_octave"});
  t.rows = {PsdRow::level(1, 0.1), PsdRow::slope(1e300, 1e5)};  // overflows
  expect(t, {"row 2", "slope_dB_per_octave", "not a finite"});
  EXPECT_THROW(velocity_rms_m_per_s(gevs_psd(), 0.0), std::invalid_argument);
  EXPECT_EQ(message_of(gevs_psd()), "(no exception)");
}

}  // namespace test_vibration_psd
