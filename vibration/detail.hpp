#pragma once
// vibration/detail.hpp -- helpers internal to the vibration stage (not part of its API).
#include <array>
#include <cstddef>
#include <cmath>
#include <cstdint>
#include <numbers>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "vibration/random.hpp"

namespace vrelab::vibration::detail {

inline constexpr double kTwoPi = 2 * std::numbers::pi;

// The sensor axes' names in messages, by index (IA, PA, OA: plant/model1.hpp).
inline constexpr const char* kAxisName[3] = {"IA", "PA", "OA"};

// A number as messages and descriptions print it.
inline std::string num(double x, int precision = 6) {
  std::ostringstream s;
  s.precision(precision);
  s << x;
  return s.str();
}

// The site's gravity g_m_per_s2 of a shaker demand or a PSD's velocity and displacement, checked
// (a finite number > 0) and returned.
inline double check_g(double g_m_per_s2) {
  if (!std::isfinite(g_m_per_s2) || g_m_per_s2 <= 0)
    throw std::invalid_argument("g_m_per_s2 = " + num(g_m_per_s2) + " must be a finite number > 0");
  return g_m_per_s2;
}

// The phases of a random block (random.hpp): phase[a][k] = 2 pi u for the bins k = 1 .. kmax
// (phase[a][0] unused), u = (top 53 bits of an std::mt19937_64 draw) / 2^53, the engine seeded
// by std::seed_seq{seed lo, seed hi, block lo, block hi}; axis by axis in the order x, y, z,
// whatever the levels, so the draw sequence depends only on (seed, block, kmax). With common
// coupling the y and z axes copy x's phases. The one draw both random_phase_block and
// RandomExcitation's block synthesiser use (their blocks are bit-identical). phase's vectors
// are resized (their storage reused between calls).
// `wanted` (default every axis): the axes whose phases the caller reads; the others' vectors
// are left as they are (not copied, not filled), their draws skipped where none follows
// (trailing axes) or discarded from the engine otherwise, so the wanted axes' phases are the
// same numbers either way.
void draw_block_phases(AxisCoupling coupling, std::uint64_t seed, std::int64_t block_index, std::size_t kmax,
                       std::array<std::vector<double>, 3>& phase,
                       const std::array<bool, 3>& wanted = {true, true, true});

}  // namespace vrelab::vibration::detail
