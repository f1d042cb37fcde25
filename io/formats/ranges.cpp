#include "io/formats/ranges.hpp"

#include <cmath>

#include <fmt/format.h>

namespace vrelab::io {

std::string range_problem(const PhysicalRange& r, double x) {
  const double v = r.magnitude ? std::abs(x) : x;
  const bool below = r.min_open ? !(v > r.min) : !(v >= r.min);
  if (!below && v <= r.max) return "";
  const std::string bounds = r.magnitude ? fmt::format("|x| <= {:g}", r.max)
                                         : fmt::format("{}{:g}, {:g}]", r.min_open ? "(" : "[", r.min, r.max);
  return fmt::format("{:g} {} is outside {}'s range {} {} (docs/data-format.md, Ranges and limits)", x, r.unit, r.quantity,
                     bounds, r.unit);
}

std::string rows_problem(std::size_t limit, const std::string& what, const std::string& why) {
  return fmt::format("more than {} {}: {} (docs/data-format.md, Ranges and limits)", limit, what, why);
}

}  // namespace vrelab::io
