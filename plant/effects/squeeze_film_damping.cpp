#include "plant/effects/squeeze_film_damping.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>
#include <stdexcept>
#include <vector>

namespace vrelab::plant {

SqueezeFilmDamping::SqueezeFilmDamping(double gap, double c0, double b) : gap_rad_(gap), c0_(c0), b_(b) {
  if (!(gap > 0) || !std::isfinite(gap)) throw std::invalid_argument("squeeze film gap_angle_rad must be positive");
  if (!(c0 >= 0) || !std::isfinite(c0)) throw std::invalid_argument("squeeze film c0_per_s must be >= 0");
  if (!(b > 0) || !std::isfinite(b)) throw std::invalid_argument("squeeze film angle_gain must be positive");
}

std::optional<std::string> SqueezeFilmDamping::cache_key() const {
  std::string key = name();
  for (double x : {gap_rad_, c0_, b_}) key.append(reinterpret_cast<const char*>(&x), sizeof x);
  return key;
}

double SqueezeFilmDamping::extra_input_g(double theta, double omega, double, const Vec3&) const {
  const double x = std::min(std::abs(theta) / gap_rad_, 0.95);
  const double y = 1 - x * x;
  const double factor = 1 / (y * std::sqrt(y)) - 1;  // (1 - x^2)^(-3/2)
  return -c0_ * factor * omega / b_;  // the plant multiplies by b
}

namespace {
constexpr int kDampingPoints = 128;  // trapezoid over a period: spectral for the smooth law below 0.95 theta_gap
// sin(phi_k) and cos(phi_k)^2 on the period's points, computed once by the same expressions
// as the sum would compute them (the same numbers; damping_factor is called ~13 times per run
// and film value by the fixed point of rectification::amplitude_linearised).
// The film's factor depends on |sin(phi_k)| only, which repeats over the period's quarters
// up to the sine's rounding (97 distinct values of 128): the points whose |sin| is the same
// number (bit for bit) share one pow (`distinct`: the
// first point of each such value, `of`: each point's); the sum still runs over every point in
// order, so the result is the same number.
struct DampingTable {
  std::array<double, kDampingPoints> sin{}, cos2{};
  std::array<int, kDampingPoints> of{};
  std::vector<int> distinct;
  DampingTable() {
    for (int k = 0; k < kDampingPoints; ++k) {
      const double phi = 2 * std::numbers::pi * k / kDampingPoints;
      sin[static_cast<std::size_t>(k)] = std::sin(phi);
      cos2[static_cast<std::size_t>(k)] = std::cos(phi) * std::cos(phi);
    }
    for (int k = 0; k < kDampingPoints; ++k) {
      const double s = std::abs(sin[static_cast<std::size_t>(k)]);
      std::size_t d = 0;
      while (d < distinct.size() && std::abs(sin[static_cast<std::size_t>(distinct[d])]) != s) ++d;
      if (d == distinct.size()) distinct.push_back(k);
      of[static_cast<std::size_t>(k)] = static_cast<int>(d);
    }
  }
};
const DampingTable& damping_table() {
  static const DampingTable table;
  return table;
}
}  // namespace

double SqueezeFilmDamping::damping_factor(double theta_amplitude) const {
  constexpr int kN = kDampingPoints;
  const DampingTable& t = damping_table();
  // |theta_amplitude * s| = |theta_amplitude| |s| exactly, so equal |s| give equal x.
  std::array<double, kN> p{};
  for (std::size_t d = 0; d < t.distinct.size(); ++d) {
    const double x = std::min(std::abs(theta_amplitude * t.sin[static_cast<std::size_t>(t.distinct[d])]) / gap_rad_, 0.95);
    p[d] = std::pow(1 - x * x, 1.5);
  }
  double sum = 0;
  for (int k = 0; k < kN; ++k) {
    const auto kk = static_cast<std::size_t>(k);
    sum += t.cos2[kk] / p[static_cast<std::size_t>(t.of[kk])];
  }
  return 2 * sum / kN;
}

}  // namespace vrelab::plant
