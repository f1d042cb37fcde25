#pragma once
// vibration/detail.hpp -- helpers internal to the vibration stage (not part of its API).
#include <sstream>
#include <string>

namespace vrelab::vibration::detail {

// A number as messages and descriptions print it.
inline std::string num(double x, int precision = 6) {
  std::ostringstream s;
  s.precision(precision);
  s << x;
  return s.str();
}

}  // namespace vrelab::vibration::detail
