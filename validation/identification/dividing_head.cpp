#include "validation/identification/dividing_head.hpp"

#include <cmath>
#include <numbers>
#include <stdexcept>

#include <Eigen/Geometry>

namespace vrelab::validation {
namespace {

Eigen::Matrix3d rotation(const Vec3& small_angles_rad) {
  const double angle = small_angles_rad.norm();
  if (angle == 0) return Eigen::Matrix3d::Identity();
  return Eigen::AngleAxisd(angle, small_angles_rad / angle).toRotationMatrix();
}

// d(gravity in sensor axes)/d(phi) for series positions.
Vec3 series_orientation_derivative(int series, double phi) {
  return series_orientation(series, phi + std::numbers::pi / 2);  // d/dphi (-cos, -sin) = (sin, -cos)
}

// (u, v) placed on the two axes of series s that lie in the vertical plane.
Vec3 place(int series, double u, double v) {
  switch (series) {
    case 1: return Vec3(u, v, 0.0);
    case 2: return Vec3(u, 0.0, v);
    case 3: return Vec3(0.0, u, v);
    default: throw std::invalid_argument("series must be 1, 2 or 3, got " + std::to_string(series));
  }
}

}  // namespace

std::pair<double, double> cos_sin_deg(double angle_deg) {
  // remquo: angle = 90 q + r with |r| <= 45 exactly (no rounding: fmod-like reductions are
  // exact), and the low bits of q give the quadrant. At r = 0, cos and sin are exactly 1, 0.
  int q = 0;
  const double r = std::remquo(angle_deg, 90.0, &q);
  const double rad = r * (std::numbers::pi / 180.0);
  const double c = r == 0 ? 1.0 : std::cos(rad), s = r == 0 ? 0.0 : std::sin(rad);
  switch (q & 3) {
    case 0: return {c, s};
    case 1: return {-s, c};
    case 2: return {-c, -s};
    default: return {s, -c};
  }
}

Vec3 series_orientation(int series, double phi) { return place(series, -std::cos(phi), -std::sin(phi)); }

Vec3 series_orientation_deg(int series, double angle_deg) {
  const auto [c, s] = cos_sin_deg(angle_deg);
  return place(series, -c, -s);
}

Position series_position(int series, double angle_rad) {
  return Position{series, angle_rad, series_orientation(series, angle_rad)};
}

Position series_position_deg(int series, double angle_deg) {
  return Position{series, angle_deg * (std::numbers::pi / 180.0), series_orientation_deg(series, angle_deg)};
}

Position vector_position(const Vec3& a_g) { return Position{0, 0.0, a_g}; }

std::vector<Position> equally_spaced_positions(int per_series, const std::vector<int>& series) {
  if (per_series < 1) throw std::invalid_argument("positions_per_series must be at least 1");
  std::vector<Position> out;
  for (int s : series)
    for (int j = 0; j < per_series; ++j)
      out.push_back(series_position(s, 2 * std::numbers::pi * j / per_series));
  return out;
}

bool is_paper_set(const std::vector<Position>& p) {
  if (p.size() != 24) return false;
  const auto paper = equally_spaced_positions(8);
  for (std::size_t i = 0; i < 24; ++i)
    if (p[i].series != paper[i].series || std::abs(p[i].angle_rad - paper[i].angle_rad) > 1e-12)
      return false;
  return true;
}

Vec3 realised_orientation(const Position& p, const Vec3& initial_error_rad, const Vec3& d_angle) {
  // Without a set-angle error the nominal orientation (exact at multiples of 90 deg).
  const Vec3 head = p.series == 0     ? Vec3(rotation(d_angle).transpose() * p.nominal_g)
                    : d_angle[0] == 0 ? p.nominal_g
                                      : series_orientation(p.series, p.angle_rad + d_angle[0]);
  return rotation(initial_error_rad).transpose() * head;
}

OutputSource model1_source(const plant::Coefficients& truth) {
  return [truth](const Vec3& a) { return plant::output(truth, a); };
}

std::vector<Reading> simulate_static_test(const OutputSource& source, double K1,
                                          const std::vector<Position>& positions,
                                          const StaticTestErrors& e, std::mt19937_64& rng) {
  std::normal_distribution<double> normal(0.0, 1.0);
  std::vector<Reading> out;
  out.reserve(positions.size() * e.repeats);
  for (std::size_t i = 0; i < positions.size(); ++i) {
    for (int r = 0; r < e.repeats; ++r) {
      Vec3 d_angle = Vec3::Zero();
      if (e.angle_sigma_rad > 0) {
        if (positions[i].series != 0)
          d_angle[0] = e.angle_sigma_rad * normal(rng);
        else
          for (int k = 0; k < 3; ++k) d_angle[k] = e.angle_sigma_rad * normal(rng);
      }
      const Vec3 a = realised_orientation(positions[i], e.initial_error_rad, d_angle);
      double u = source(a);
      if (e.noise_sigma_g > 0) u += K1 * e.noise_sigma_g * normal(rng);
      out.push_back({static_cast<int>(i), u});
    }
  }
  return out;
}

ReadingBudget reading_budget(const plant::Coefficients& c, const std::vector<Position>& positions,
                             const std::vector<Reading>& readings, const StaticTestErrors& e) {
  ReadingBudget b;
  const double noise_var = std::pow(c[plant::K1] * e.noise_sigma_g, 2);
  const double angle_var = e.angle_sigma_rad * e.angle_sigma_rad;
  for (const Reading& r : readings) {
    const Position& p = positions.at(r.position);
    const Vec3 a = p.nominal_g;
    const Vec3 grad = plant::output_gradient(c, a);
    // Delta U = grad . Delta a (the paper's expression). Set angle: Delta a = da/dphi dphi
    // or, for vector positions, a x dtheta (each component independent).
    const double angle_term = p.series != 0 ? std::pow(grad.dot(series_orientation_derivative(p.series, p.angle_rad)), 2)
                                            : a.cross(grad).squaredNorm();
    b.variance.push_back(noise_var + angle_var * angle_term);
    // Initial error: a = R(alpha)^T a_head ~ a_head + a_head x alpha.
    b.bias.push_back(grad.dot(a.cross(e.initial_error_rad)));
  }
  return b;
}

}  // namespace vrelab::validation
