#pragma once
// io/services/internal.hpp -- helpers internal to the services (not part of their API).
#include <chrono>
#include <numbers>

namespace vrelab::io::internal {

// One arcsecond in rad: the dividing head's errors are reported in arcsec.
inline constexpr double kArcsec = std::numbers::pi / (180.0 * 3600.0);

// Seconds of wall time since `start` (a result's wall_s).
inline double seconds_since(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

}  // namespace vrelab::io::internal
