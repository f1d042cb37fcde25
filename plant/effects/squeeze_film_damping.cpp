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

namespace {
// f = c / c0 on the film's law, held beyond 0.95 theta_gap (as extra_input_g).
double film_law(double theta, double gap) {
  const double x = std::min(std::abs(theta) / gap, 0.95);
  const double y = 1 - x * x;
  return 1 / (y * std::sqrt(y));
}

// E[f(u + G)], G ~ N(0, sigma^2): 8-point Gauss-Legendre on pieces no wider than sigma
// over u +- 8 sigma, cut where the law is held (|theta| = 0.95 theta_gap, a kink) and at
// 0.6, 0.8 and 0.9 theta_gap, where the law nears its pole at theta_gap (each piece then at
// least its own width from the pole: the rule's error ~1e-11); the mass beyond 8 sigma
// (1e-15) is left out.
double gaussian_mean_law(double u, double sigma, double gap) {
  if (!(sigma > 0)) return film_law(u, gap);
  static constexpr std::array<double, 8> x{-0.9602898564975363, -0.7966664774136267, -0.5255324099163290, -0.1834346424956498,
                                           0.1834346424956498,  0.5255324099163290,  0.7966664774136267,  0.9602898564975363};
  static constexpr std::array<double, 8> w{0.1012285362903763, 0.2223810344533745, 0.3137066458778873, 0.3626837833783620,
                                           0.3626837833783620, 0.3137066458778873, 0.2223810344533745, 0.1012285362903763};
  std::array<double, 10> cuts{};
  cuts.fill(8);
  cuts[0] = -8;
  int n = 1;
  for (double k : {-0.95, -0.9, -0.8, -0.6, 0.6, 0.8, 0.9, 0.95})  // (ascending)
    if (const double t = (k * gap - u) / sigma; t > -8 && t < 8) cuts[static_cast<std::size_t>(n++)] = t;
  const double norm = 1 / std::sqrt(2 * std::numbers::pi);
  double sum = 0;
  for (int i = 0; i < n; ++i) {
    const double a = cuts[static_cast<std::size_t>(i)], b = cuts[static_cast<std::size_t>(i + 1)];
    const int pieces = std::max(1, static_cast<int>(std::ceil(b - a)));
    const double h = (b - a) / pieces;
    for (int m = 0; m < pieces; ++m)
      for (std::size_t j = 0; j < x.size(); ++j) {
        const double t = a + (m + 0.5 * (1 + x[j])) * h;
        sum += 0.5 * h * w[j] * norm * std::exp(-0.5 * t * t) * film_law(u + sigma * t, gap);
      }
  }
  return sum;
}
}  // namespace

double SqueezeFilmDamping::damping_factor_on_random(double theta_amplitude, double rate_amplitude, double sigma,
                                                    double sigma_rate) const {
  const double sine_power = 0.5 * rate_amplitude * rate_amplitude, random_power = sigma_rate * sigma_rate;
  if (!(sine_power + random_power > 0)) return 1;  // no motion: the nominal damping
  if (!(theta_amplitude > 0) || !(sine_power > 0)) return gaussian_mean_law(0, sigma, gap_rad_);
  // The phase average by the trapezoid over a period (kDampingPoints, spectral for a smooth
  // periodic integrand); E[f(u + G)] is even in u, so the points share it by |sin phi|.
  const DampingTable& t = damping_table();
  std::vector<double> mean(t.distinct.size());
  for (std::size_t d = 0; d < t.distinct.size(); ++d)
    mean[d] = gaussian_mean_law(theta_amplitude * std::abs(t.sin[static_cast<std::size_t>(t.distinct[d])]), sigma, gap_rad_);
  double sum = 0;
  for (int k = 0; k < kDampingPoints; ++k) {
    const auto kk = static_cast<std::size_t>(k);
    sum += mean[static_cast<std::size_t>(t.of[kk])] * (rate_amplitude * rate_amplitude * t.cos2[kk] + random_power);
  }
  return sum / kDampingPoints / (sine_power + random_power);
}

}  // namespace vrelab::plant
