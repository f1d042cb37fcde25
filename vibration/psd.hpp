#pragma once
// vibration/psd.hpp -- random-vibration specifications as PSD breakpoint tables.
//
// Takes: a breakpoint table, rows of (frequency_Hz, level) where the level is either a PSD
//        in g^2/Hz or a slope in dB/octave from the previous row (as test standards write
//        "20-50 Hz: +6 dB/oct"); the site's gravity in m/s^2 where SI values are asked.
// Gives: the one-sided acceleration PSD at any frequency (straight lines on log-log axes
//        between breakpoints, zero outside [first, last] frequency), and the exact rms of
//        acceleration (g), velocity (m/s) and displacement (m) that the spec implies.
//
// A row given as a slope s dB/octave sets its level from the previous row's:
//   P_k = P_{k-1} * (f_k / f_{k-1})^(s / (10 log10 2)).
// Between breakpoints P(f) = P_k (f / f_k)^b_k, b_k = ln(P_{k+1}/P_k) / ln(f_{k+1}/f_k), so
// every moment integral has a closed form (see docs/vibration.md):
//   int_{f_k}^{f_{k+1}} f^m P(f) df = P_k f_k^(m+1) x expm1(c x)/(c x),  x = ln(f_{k+1}/f_k),
//   c = b_k + m + 1 (m = 0: acceleration; m = -2: velocity; m = -4: displacement).
// validate() throws std::invalid_argument naming the field and the row (1-based).
#include <optional>
#include <string>
#include <vector>

namespace vrelab::vibration {

struct PsdRow {
  double frequency_Hz = 0.0;
  // Exactly one of the two: the level, or the slope from the previous row (not on row 1).
  std::optional<double> psd_g2_per_Hz;
  std::optional<double> slope_dB_per_octave;

  static PsdRow level(double frequency_Hz, double psd_g2_per_Hz) { return {frequency_Hz, psd_g2_per_Hz, {}}; }
  static PsdRow slope(double frequency_Hz, double slope_dB_per_octave) {
    return {frequency_Hz, {}, slope_dB_per_octave};
  }
};

struct PsdTable {
  std::vector<PsdRow> rows;
};

// Throws std::invalid_argument if: fewer than 2 rows; a frequency is not finite or not > 0
// or not strictly above the previous row's; a row has both or neither of level and slope;
// row 1 has a slope; a level is not finite or not > 0; a slope is not finite; or a level
// resolved from a slope is not a finite positive number.
void validate(const PsdTable& table);

// The table with every level resolved (slopes turned into levels); validates first.
struct ResolvedPsd {
  std::vector<double> frequency_Hz;
  std::vector<double> psd_g2_per_Hz;
};
ResolvedPsd resolve(const PsdTable& table);

// One-sided PSD at f, g^2/Hz: log-log interpolation inside [f_first, f_last], 0 outside.
double psd_g2_per_Hz(const ResolvedPsd& psd, double frequency_Hz);
double psd_g2_per_Hz(const PsdTable& table, double frequency_Hz);

// Exact rms of the spec: sqrt of the integral of the PSD (g); of PSD * (g/(2 pi f))^2
// (m/s); of PSD * (g/(2 pi f)^2)^2 (m). g_m_per_s2: the site's gravity.
double rms_g(const PsdTable& table);
double velocity_rms_m_per_s(const PsdTable& table, double g_m_per_s2);
double displacement_rms_m(const PsdTable& table, double g_m_per_s2);

// Integral of f^m * PSD(f) over the table band (g^2 Hz^m), the closed form above.
double psd_moment(const ResolvedPsd& psd, int m);

// "20-2000 Hz, 14.1 g rms" style one-liner.
std::string describe(const PsdTable& table);

}  // namespace vrelab::vibration
