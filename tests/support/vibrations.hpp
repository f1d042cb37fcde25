#pragma once
// The tests' vibrations, defined once: the GEVS random spectrum (GSFC-STD-7000A
// qualification, <= 22.7 kg; the standard quotes 14.1 g rms) and a sine given by its amplitude
// vector and frequency.
#include "plant/model1.hpp"
#include "vibration/profile.hpp"
#include "vibration/psd.hpp"
#include "vibration/random.hpp"

namespace vrelab::test {

// GEVS: +6 dB/octave from 0.026 g^2/Hz at 20 Hz to 0.16 at 50 Hz, flat to 800 Hz, -6 dB/octave
// to 0.026 at 2000 Hz (14.14 g rms); every level times `scale` (the rms times its root).
inline vibration::PsdTable gevs_psd(double scale = 1.0) {
  vibration::PsdTable t;
  t.rows = {vibration::PsdRow::level(20, 0.026 * scale), vibration::PsdRow::level(50, 0.16 * scale),
            vibration::PsdRow::level(800, 0.16 * scale), vibration::PsdRow::level(2000, 0.026 * scale)};
  return t;
}

// A flat PSD of `level_g2_per_Hz` from from_Hz to to_Hz.
inline vibration::PsdTable flat_psd(double from_Hz, double to_Hz, double level_g2_per_Hz) {
  vibration::PsdTable t;
  t.rows = {vibration::PsdRow::level(from_Hz, level_g2_per_Hz), vibration::PsdRow::level(to_Hz, level_g2_per_Hz)};
  return t;
}

// GEVS along IA alone.
inline vibration::RandomProfile gevs_on_ia() {
  vibration::RandomProfile p;
  p.psd[IA] = gevs_psd();
  return p;
}

// A sine of peak amplitude `amplitude_g` (per axis, all in phase) at f_Hz.
inline vibration::SineVibration sine(const Vec3& amplitude_g, double f_Hz) {
  vibration::SineVibration v;
  v.amplitude_g = amplitude_g;
  v.frequency_Hz = f_Hz;
  return v;
}

}  // namespace vrelab::test
