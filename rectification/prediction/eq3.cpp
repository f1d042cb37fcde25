#include "rectification/prediction/eq3.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <tuple>

namespace vrelab::rectification {
namespace {

using plant::Coef;
constexpr double kPi = std::numbers::pi;

double normal_cdf(double x) { return 0.5 * std::erfc(-x / std::numbers::sqrt2); }
double normal_pdf(double x) { return std::exp(-0.5 * x * x) / std::sqrt(2 * kPi); }
double clip(double x, double r) { return std::clamp(x, -r, r); }

// Mean over a period of min(0, R - (a + w sin)): the (negative) part cut off above +R.
double cut_above_sine(double a, double w, double r) {
  if (w == 0) return std::min(0.0, r - a);
  const double u = (r - a) / w;
  if (u >= 1) return 0.0;
  if (u <= -1) return r - a;
  return ((r - a) * (kPi - 2 * std::asin(u)) - 2 * w * std::sqrt(1 - u * u)) / (2 * kPi);
}

// E[min(0, R - X)] = -E[(X - R)^+] for X ~ N(m, sigma^2).
double cut_above_gaussian(double m, double sigma, double r) {
  if (sigma == 0) return std::min(0.0, r - m);
  const double z = (m - r) / sigma;
  return -((m - r) * normal_cdf(z) + sigma * normal_pdf(z));
}

// The terms that depend only on the second and fourth moments of the vibration and on
// the covariance between axes; shared by sine and random vibration.
void moment_terms(const plant::Coefficients& c, const Vec3& a, const Eigen::Matrix3d& cov,
                  double m4_ia, Eq3Terms& t) {
  const double s2 = cov(IA, IA);
  t.g[t_k2] = c[Coef::k2] * s2;
  t.g[t_k3] = 3 * c[Coef::k3] * a[IA] * s2;
  t.g[t_k4] = c[Coef::k4] * (6 * a[IA] * a[IA] * s2 + m4_ia);
  t.g[t_k_IP] = c[Coef::k_IP] * cov(IA, PA);
  t.g[t_k_IO] = c[Coef::k_IO] * cov(IA, OA);
  t.g[t_k_PO] = c[Coef::k_PO] * cov(PA, OA);
  t.g[t_k_PP] = c[Coef::k_PP] * cov(PA, PA);
  t.g[t_k_OO] = c[Coef::k_OO] * cov(OA, OA);
}

}  // namespace

std::string_view term_name(int t) {
  static constexpr std::array<std::string_view, kNumTerms> names{
      "k2", "k3", "k4", "k1_asym", "k_IP", "k_IO", "k_PO", "k_PP", "k_OO", "clipping"};
  return names.at(t);
}

double Eq3Terms::total_g() const {
  double s = 0;
  for (double x : g) s += x;
  return s;
}

double asymmetry_sine(double a, double w) {
  w = std::abs(w);
  if (std::abs(a) >= w) return 0.0;
  return (a * std::asin(a / w) + std::sqrt(w * w - a * a) - kPi * std::abs(a) / 2) / kPi;
}

double asymmetry_gaussian(double a, double sigma) {
  if (sigma == 0) return 0.0;
  const double mean_abs = sigma * std::sqrt(2 / kPi) * std::exp(-a * a / (2 * sigma * sigma)) +
                          a * (1 - 2 * normal_cdf(-a / sigma));
  return 0.5 * (mean_abs - std::abs(a));
}

double clipping_sine(double a, double w, double r) {
  w = std::abs(w);
  // Below -R: by the symmetry x -> -x the cut-off part below is minus the part above for -a.
  const double mean_clip = a + cut_above_sine(a, w, r) - cut_above_sine(-a, w, r);
  return mean_clip - clip(a, r);
}

double clipping_gaussian(double a, double sigma, double r) {
  const double mean_clip = a + cut_above_gaussian(a, sigma, r) - cut_above_gaussian(-a, sigma, r);
  return mean_clip - clip(a, r);
}

int term_of_coefficient(int coef) {
  switch (coef) {
    case Coef::k1_asym: return t_k1_asym;
    case Coef::k2: return t_k2;
    case Coef::k3: return t_k3;
    case Coef::k4: return t_k4;
    case Coef::k_IP: return t_k_IP;
    case Coef::k_IO: return t_k_IO;
    case Coef::k_PO: return t_k_PO;
    case Coef::k_PP: return t_k_PP;
    case Coef::k_OO: return t_k_OO;
    default: return -1;
  }
}

SineMoments sine_moments(const vibration::SineVibration& v) {
  // Covariance of w_i sin(wt + p_i) and w_j sin(wt + p_j): w_i w_j cos(p_i - p_j) / 2.
  SineMoments m;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j)
      m.covariance_g2(i, j) = 0.5 * v.amplitude_g[i] * v.amplitude_g[j] * std::cos(v.phase_rad[i] - v.phase_rad[j]);
  m.amplitude_ia_g = v.amplitude_g[IA];
  return m;
}

Eq3Terms sine_rectification(const plant::Coefficients& c, const Vec3& a, const SineMoments& m, std::optional<double> range_g) {
  const double w = m.amplitude_ia_g;
  Eq3Terms t;
  moment_terms(c, a, m.covariance_g2, 3.0 / 8.0 * w * w * w * w, t);
  t.g[t_k1_asym] = c[Coef::k1_asym] * asymmetry_sine(a[IA], w);
  if (range_g) t.g[t_clipping] = clipping_sine(a[IA], w, *range_g);
  return t;
}

Eq3Terms sine_rectification(const plant::Coefficients& c, const Vec3& a,
                            const vibration::SineVibration& v, std::optional<double> range_g) {
  return sine_rectification(c, a, sine_moments(v), range_g);
}

Eq3Terms random_rectification(const plant::Coefficients& c, const Vec3& a,
                              const vibration::RandomVibration& v, std::optional<double> range_g) {
  const Eigen::Matrix3d cov = v.covariance_g2();
  const double s2 = cov(IA, IA);
  Eq3Terms t;
  moment_terms(c, a, cov, 3 * s2 * s2, t);
  t.g[t_k1_asym] = c[Coef::k1_asym] * asymmetry_gaussian(a[IA], v.rms_g[IA]);
  if (range_g) t.g[t_clipping] = clipping_gaussian(a[IA], v.rms_g[IA], *range_g);
  return t;
}

SinePhasePoints sine_phase_points(const Vec3& a, const vibration::SineVibration& sine) {
  SinePhasePoints points;
  constexpr int n = std::tuple_size_v<SinePhasePoints>;
  for (int k = 0; k < n; ++k) {
    const double theta = 2 * kPi * k / n;
    Vec3 shifted = a;
    for (int i = 0; i < 3; ++i) shifted[i] += sine.amplitude_g[i] * std::sin(theta + sine.phase_rad[i]);
    points[static_cast<std::size_t>(k)] = shifted;
  }
  return points;
}

Eq3Terms sine_on_random_rectification(const plant::Coefficients& c, const Vec3& a,
                                      const vibration::SineVibration& sine, const vibration::RandomVibration& random,
                                      std::optional<double> range_g) {
  return sine_on_random_rectification(c, a, sine, sine_phase_points(a, sine), random, range_g);
}

Eq3Terms sine_on_random_rectification(const plant::Coefficients& c, const Vec3& a, const vibration::SineVibration& sine,
                                      const SinePhasePoints& points, const vibration::RandomVibration& random,
                                      std::optional<double> range_g) {
  Eq3Terms t = sine_rectification(c, a, sine, range_g);
  constexpr int n = std::tuple_size_v<SinePhasePoints>;
  for (const Vec3& shifted : points) {
    const Eq3Terms g = random_rectification(c, shifted, random, range_g);
    for (int j = 0; j < kNumTerms; ++j) t.g[j] += g.g[j] / n;
  }
  return t;
}

double sine_rectification_as_printed(const plant::Coefficients& c, const Vec3& a_g,
                                     const vibration::SineVibration& v) {
  const double a = a_g[IA];
  const double wi = v.amplitude_g[IA], wp = v.amplitude_g[PA], wo = v.amplitude_g[OA];
  double e = c[Coef::k2] / 2 * wi * wi + 1.5 * c[Coef::k3] * wi * wi * a +
             3 * c[Coef::k4] * a * a * wi * wi + 3.0 / 8.0 * c[Coef::k4] * wi * wi * wi * wi +
             c[Coef::k_IO] / 2 * wi * wo + c[Coef::k_IP] / 2 * wi * wp + c[Coef::k_PO] / 2 * wp * wo;
  if (std::abs(a) < std::abs(wi))
    e += c[Coef::k1_asym] / kPi *
         (std::asin(a / wi) + std::sqrt(wi * wi - a * a) - kPi * std::abs(a) / 2);
  return e;
}

}  // namespace vrelab::rectification
