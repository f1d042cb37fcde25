#pragma once
// validation/diagnosis/effects/common.hpp -- what the effect files share: grids, the blind
// draws' distributions, the in-phase and phasor views of a sine, the usual checks, and the
// families of effects that differ only in a number (higher_order_term, shaker_harmonic; their
// bodies in validation/diagnosis/effect.cpp: every .cpp in this folder is taken for an effect).
// Internal to validation/diagnosis/.
//
// The folder's convention. One effect per file, <name>.cpp, defining `Effect effect_<name>()`
// in namespace vrelab::validation (the registry's list is generated from the file names,
// validation/CMakeLists.txt); adding an effect is adding its file here and, when the virtual
// lab needs a new module for its truth, one in plant/effects/. The file
//  - opens with one line of what the effect is, with the plant module or shaker decorator of
//    its truth (if any) in parentheses; "Outside the library:" first for an effect only the
//    virtual lab knows (no hypothesis, in_library false, rank above 100);
//  - includes the standard headers it uses, its plant module's header, then this header;
//  - keeps its own helpers in an anonymous namespace, then sets, in this order: name (the
//    file's stem), rank, in_library, acts_on and the flags, physics, the parameters (the size
//    first, then the natural form's), hypothesis, truth, draw, draw_form, check;
//  - writes the truth out from the plant's modules and the shaker's decorators, sharing none of
//    the hypothesis' own code (the views and checks here aside): a wrong sign or axis in the
//    hypothesis then shows in `blind`;
//  - starts `draw` with a sign (used or not: a blind seed then draws the same truths whatever
//    the effect).
// An effect of a family is one call of the family's function.
#include <algorithm>
#include <cmath>
#include <complex>
#include <numbers>
#include <random>
#include <string>
#include <vector>

#include <Eigen/Dense>

#include "validation/diagnosis/effect.hpp"

namespace vrelab::validation::effects {

// n values from `from` to `to` in geometric steps.
inline std::vector<double> geometric(double from, double to, int n) {
  std::vector<double> v;
  for (int k = 0; k < n; ++k) v.push_back(from * std::pow(to / from, k / (n - 1.0)));
  return v;
}

// 0 and +-from .. +-to in n geometric steps, sorted: the grid of a signed parameter.
inline std::vector<double> symmetric_geometric(double from, double to, int n) {
  std::vector<double> v = {0};
  for (double x : geometric(from, to, n)) v.push_back(x), v.push_back(-x);
  std::sort(v.begin(), v.end());
  return v;
}

// The blind draws: every effect's draw starts with a sign (used or not), then its range, so
// that a blind seed draws the same truths whatever the effect.
inline double random_sign(std::mt19937_64& rng) {
  std::bernoulli_distribution sign(0.5);
  return sign(rng) ? 1 : -1;
}
inline bool coin(std::mt19937_64& rng) { return std::bernoulli_distribution(0.5)(rng); }
inline double log_uniform(std::mt19937_64& rng, double lo, double hi) {
  return std::exp(std::uniform_real_distribution<double>(std::log(lo), std::log(hi))(rng));
}

// A sine whose axes move in phase or in antiphase as one signed amplitude vector (g), and
// back (the hypotheses of the shaker effects that redistribute the table's motion).
inline Vec3 signed_in_phase(const vibration::SineVibration& v) {
  Vec3 a;
  for (int i = 0; i < 3; ++i) a[i] = v.amplitude_g[i] * std::cos(v.phase_rad[i]);
  return a;
}
inline void set_in_phase(vibration::SineVibration& v, const Vec3& a) {
  for (int i = 0; i < 3; ++i) v.amplitude_g[i] = std::abs(a[i]), v.phase_rad[i] = a[i] < 0 ? std::numbers::pi : 0.0;
}

// A sine as phasors W = A e^{j phase} (g), and back (the truths: any phase).
inline Eigen::Vector3cd phasors(const vibration::SineVibration& v) {
  Eigen::Vector3cd w;
  for (int i = 0; i < 3; ++i) w[i] = std::polar(v.amplitude_g[i], v.phase_rad[i]);
  return w;
}
inline void set_phasors(vibration::SineVibration& v, const Eigen::Vector3cd& w) {
  for (int i = 0; i < 3; ++i) v.amplitude_g[i] = std::abs(w[i]), v.phase_rad[i] = std::arg(w[i]);
}

// A hypothesis, present (1) or not (0): the truth takes nothing else.
inline bool present_or_not(const std::string& name, ParameterValues p, std::string* why) {
  if (p[0] == 0 || p[0] == 1) return true;
  if (why) *why = name + " is present (1) or not (0), got " + std::to_string(p[0]);
  return false;
}
// A harmonic's ratio to the fundamental, in [0, 1).
inline bool harmonic_ratio(const std::string& name, ParameterValues p, std::string* why) {
  if (p[0] >= 0 && p[0] < 1) return true;
  if (why) *why = name + " is a harmonic's ratio to the fundamental, in [0, 1), got " + std::to_string(p[0]);
  return false;
}

// A harmonic's phase (rad) against the fundamental, as sin(n t + phase): nominal 0 (the
// library's default form), periodic in [-pi, pi), a start in each quadrant (at a phase far
// from the truth the ratio's grid fit can end near 0, where the phase has no slope).
inline EffectParameter harmonic_phase(const std::string& name) {
  EffectParameter q(name, "rad");
  q.nominal = 0, q.lower = -std::numbers::pi, q.upper = std::numbers::pi, q.example = std::numbers::pi / 2;
  q.periodic = true, q.step = 2e-2;
  q.starts = {0, std::numbers::pi / 2, -std::numbers::pi, -std::numbers::pi / 2};
  return q;
}

// An input-axis term k_n a^n beyond model (1) (n = 5, 6), on the readout
// (plant::OutputPolynomial): linear in k_n, acting at rest too (the static test takes part of
// it up), the instrument's own in the virtual lab; drawn log-uniform in [lo, hi] with a sign.
Effect higher_order_term(int n, int rank, std::string physics, double unit_value, double example, double lo, double hi);

// The table's motion carries a harmonic of `order` (2 to 5) on every axis
// (vibration::HarmonicDistortion): its ratio h to the fundamental (the size, grid 0 and
// 0.01-0.5, drawn log-uniform in [0.1, 0.3]) and its phase (the natural form, drawn uniform);
// the parameters are named <ordinal>_harmonic_ratio and <ordinal>_harmonic_phase_rad.
Effect shaker_harmonic(int order, std::string name, int rank, std::string physics);

}  // namespace vrelab::validation::effects

namespace vrelab::validation {
// The effect files' factories in one list (generated by validation/CMakeLists.txt from the
// files in validation/diagnosis/effects/).
std::vector<Effect> registered_effects();
}  // namespace vrelab::validation
