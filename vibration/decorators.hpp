#pragma once
// vibration/decorators.hpp -- Excitations made of other Excitations: sums (sine-on-random)
// and the test-setup imperfections of a shaker, each one switchable by wrapping or not.
//
// Takes: shared, immutable Excitations (std::shared_ptr<const ...>) and the parameters of
//        each imperfection; the imperfections that need the vibration's phase take a
//        ToneExcitation (fixed sine or sweep).
// Gives: Excitations in sensor axes [IA, PA, OA], g, that the plant consumes.
//
// SumExcitation: a(t) = sum of the parts (sine on random: a sine + a RandomExcitation).
//
// TransverseMotion (cross-axis motion of the table): a fraction `ratio` of the motion on
// axis `from_axis` also appears on `to_axis`, shifted by `phase_rad` (positive: leads).
//  - on a tone, exact at every instant, also during a sweep:
//      a_to += ratio A_from sin(theta(t) + phase_from + phase_rad);
//    with_transverse() gives the same for a SineVibration in closed (phasor) form;
//  - on any Excitation, phase_rad = 0 is exact: a_to += ratio a_from(t); a phase is made a
//    time shift, a_to += ratio a_from(t + phase_rad / (2 pi f_ref)), exact for content at
//    f_ref and a linear-phase approximation elsewhere (no Hilbert transform is done).
//
// HarmonicDistortion (on a tone): a_i += sum_h ratio_h A_i sin(h (theta(t) + phase_i) + phase_h),
// h = 2, 3, ...; total harmonic distortion sqrt(sum ratio_h^2) (MIL-P-82534 allows 10 %).
//
// Rocking (angular vibration of the table about the unit axis e, sensor axes), angle
// alpha(t) = alpha0 sin(theta(t) + phase_rad), theta the tone's carrier. A vector fixed in
// the laboratory appears in the rocked sensor axes as R(alpha)^T v (Rodrigues:
// R^T v = v cos alpha - (e x v) sin alpha + e (e.v)(1 - cos alpha)). The decorator gives
//   a(t) = R^T (g_static + a_inner(t)) - g_static              (rotate_shaker_motion)
//   a(t) = R^T g_static - g_static + a_inner(t)                  (otherwise)
// plus, with a lever arm r (m, sensor position from a point on the rocking axis), the rigid-
// body acceleration of that point, [alpha'' e x r - alpha'^2 (r - (r.e) e)] / g_m_per_s2.
// g_static is the static specific force in sensor axes (g), the one the plant adds. The
// gravity term rectifies: its mean on a gravity-aligned axis is -(1 - J0(alpha0)) g_static
// (about -alpha0^2/4). max_frequency_Hz is twice the tone's (alpha^2 terms live at 2f).
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "vibration/excitation.hpp"

namespace vrelab::vibration {

class SumExcitation final : public Excitation {
 public:
  // At least one part, none null (std::invalid_argument naming `parts`).
  explicit SumExcitation(std::vector<std::shared_ptr<const Excitation>> parts);
  Vec3 acceleration_g(double t_s) const override;
  double max_frequency_Hz() const override;
  std::string describe() const override;
  Vec3 mean_g() const override;  // the parts' sum

 private:
  std::vector<std::shared_ptr<const Excitation>> parts_;
};

struct TransverseSpec {
  int from_axis = IA;
  int to_axis = PA;
  double ratio = 0.0;      // >= 0
  double phase_rad = 0.0;  // of the transverse motion relative to the main axis
};
void validate(const TransverseSpec& s);
// The sine with the transverse part added on to_axis (phasor sum with what is there).
SineVibration with_transverse(const SineVibration& v, const TransverseSpec& s);

class TransverseMotion final : public Excitation {
 public:
  TransverseMotion(std::shared_ptr<const ToneExcitation> tone, const TransverseSpec& spec);  // exact
  // General signal; reference_frequency_Hz (> 0) is needed only when spec.phase_rad != 0.
  TransverseMotion(std::shared_ptr<const Excitation> inner, const TransverseSpec& spec, double reference_frequency_Hz);
  Vec3 acceleration_g(double t_s) const override;
  double max_frequency_Hz() const override { return inner_->max_frequency_Hz(); }
  std::string describe() const override;

 private:
  std::shared_ptr<const Excitation> inner_;
  std::shared_ptr<const ToneExcitation> tone_;  // set for the exact form
  TransverseSpec spec_;
  double shift_s_ = 0.0;
};

struct Harmonic {
  int order = 2;           // >= 2
  double ratio = 0.0;      // amplitude relative to the fundamental, >= 0
  double phase_rad = 0.0;  // relative to order x the fundamental's phase
};

class HarmonicDistortion final : public Excitation {
 public:
  HarmonicDistortion(std::shared_ptr<const ToneExcitation> tone, std::vector<Harmonic> harmonics);
  Vec3 acceleration_g(double t_s) const override;
  double max_frequency_Hz() const override;
  std::string describe() const override;
  double total_harmonic_distortion() const;  // sqrt(sum ratio^2)
  const std::vector<Harmonic>& harmonics() const { return harmonics_; }

 private:
  std::shared_ptr<const ToneExcitation> tone_;
  std::vector<Harmonic> harmonics_;
};
// Throws std::invalid_argument naming harmonics[i].order / .ratio / .phase_rad.
void validate(const std::vector<Harmonic>& harmonics);

struct RockingSpec {
  Vec3 axis = Vec3::UnitZ();             // rocking axis in sensor axes (normalised; not zero)
  double amplitude_rad = 0.0;            // alpha0 >= 0
  double phase_rad = 0.0;                // of alpha relative to the tone's carrier
  Vec3 static_gravity_g = Vec3::Zero();  // static specific force in sensor axes, g
  bool rotate_shaker_motion = true;
  std::optional<Vec3> lever_arm_m;  // sensor position from a point on the axis, m
  double g_m_per_s2 = 0.0;          // the site's gravity; needed with a lever arm
};

class Rocking final : public Excitation {
 public:
  // The rocking follows the tone, which is also the shaker motion that is rotated.
  Rocking(std::shared_ptr<const ToneExcitation> tone, const RockingSpec& spec);
  // The rocking follows `carrier`; `inner` is the shaker motion (e.g. a distorted tone).
  Rocking(std::shared_ptr<const Excitation> inner, std::shared_ptr<const ToneExcitation> carrier,
          const RockingSpec& spec);
  Vec3 acceleration_g(double t_s) const override;
  double max_frequency_Hz() const override;
  std::string describe() const override;
  // Over one period of the carrier at its frequency at t = 0 (a steady tone's mean), 256
  // points: exact for content below the 128th harmonic (the rotation's series in alpha0, a
  // few 1e-5 rad, has none that matters there).
  Vec3 mean_g() const override;
  double angle_rad(double t_s) const;

 private:
  std::shared_ptr<const Excitation> inner_;
  std::shared_ptr<const ToneExcitation> carrier_;
  RockingSpec spec_;
};
void validate(const RockingSpec& s);

}  // namespace vrelab::vibration
