#pragma once
// The tests' constants, defined once.
#include <numbers>

namespace vrelab::test {

inline constexpr double kPi = std::numbers::pi;
inline constexpr double kG = 9.80665;                                 // standard gravity, m/s^2 (the case file's default)
inline constexpr double kArcsec = std::numbers::pi / (180 * 3600);  // one arc second, rad

}  // namespace vrelab::test
