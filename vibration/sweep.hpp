#pragma once
// vibration/sweep.hpp -- swept sine between two frequencies, with continuous phase.
//
// Takes: peak amplitude (g) and phase (rad) per sensor axis [IA, PA, OA], start and end
//        frequencies (Hz; end below start sweeps down), the law and its rate: linear in
//        Hz/s, or logarithmic in octaves per minute, and what happens at the end.
// Gives: a ToneExcitation A_i sin(theta(t) + phase_i), theta the analytic integral of the
//        instantaneous frequency (one pass f1 -> f2 takes T seconds, s = sign(f2 - f1)):
//   linear:      f(t) = f1 + s r t,           theta(t) = 2 pi (f1 t + s r t^2 / 2),
//                T = |f2 - f1| / r;
//   logarithmic: f(t) = f1 2^(s R t / 60),    theta(t) = 2 pi f1 (e^(k t) - 1) / k,
//                k = s R ln 2 / 60,           T = 60 |log2(f2 / f1)| / R.
// Before t = 0 the tone holds f1 (theta = 2 pi f1 t). After T: `hold` stays at f2 with
// theta(T) + 2 pi f2 (t - T); `reverse` sweeps back to f1 and repeats (period 2T), the
// down leg mirroring the up leg, theta(T + u) = 2 theta(T) - theta(T - u), so theta is
// continuous and never reset (not reduced modulo 2 pi; at 2 kHz for an hour theta ~ 5e7
// rad, whose rounding is ~1e-8 rad).
// validate() throws std::invalid_argument naming the field.
#include <string>

#include "vibration/excitation.hpp"

namespace vrelab::vibration {

enum class SweepLaw { linear, logarithmic };
enum class SweepEnd { hold, reverse };

struct SweptSine {
  Vec3 amplitude_g = Vec3::Zero();  // peak, per axis, >= 0
  Vec3 phase_rad = Vec3::Zero();    // per axis
  double start_frequency_Hz = 0.0;
  double end_frequency_Hz = 0.0;
  SweepLaw law = SweepLaw::logarithmic;
  double rate_Hz_per_s = 0.0;         // linear law
  double rate_octaves_per_min = 0.0;  // logarithmic law
  SweepEnd at_end = SweepEnd::hold;
};

void validate(const SweptSine& s);
// One pass from start to end frequency, s.
double sweep_duration_s(const SweptSine& s);

class SweptSineExcitation final : public ToneExcitation {
 public:
  explicit SweptSineExcitation(const SweptSine& s);
  CarrierState carrier(double t_s) const override;
  Vec3 amplitude_g() const override { return s_.amplitude_g; }
  Vec3 phase_rad() const override { return s_.phase_rad; }
  double max_frequency_Hz() const override;
  std::string describe() const override;
  const SweptSine& sweep() const { return s_; }

 private:
  CarrierState one_pass(double tau) const;  // 0 <= tau <= T
  SweptSine s_;
  double duration_s_;
};

}  // namespace vrelab::vibration
