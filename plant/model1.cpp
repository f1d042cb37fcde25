#include "plant/model1.hpp"

#include <cmath>

namespace vrelab::plant {

std::optional<std::pair<std::string, double>> datasheet_unit(std::string_view u) {
  if (u == "g") return std::pair<std::string, double>{"ug", 1e6};
  if (u == "1") return std::pair<std::string, double>{"ug/g", 1e6};
  if (u == "1/g") return std::pair<std::string, double>{"ug/g^2", 1e6};
  if (u == "rad") return std::pair<std::string, double>{"urad", 1e6};
  if (u == "rad/g") return std::pair<std::string, double>{"urad/g", 1e6};
  if (u.substr(0, 4) == "1/g^" && u.size() > 4 && u.find_first_not_of("0123456789", 4) == std::string_view::npos)
    return std::pair<std::string, double>{"ug/g^" + std::to_string(std::stoi(std::string(u.substr(4))) + 1), 1e6};
  return std::nullopt;
}

const std::array<CoefficientInfo, kNumCoefficients>& coefficient_info() {
  static const std::array<CoefficientInfo, kNumCoefficients> info{{
      {"K1", "out/g", "scale factor (sensitivity)"},
      {"k0", "g", "bias (offset)"},
      {"k1_asym", "1", "scale-factor asymmetry k1'"},
      {"k2", "1/g", "second-order nonlinearity"},
      {"k3", "1/g^2", "third-order nonlinearity"},
      {"k4", "1/g^3", "fourth-order nonlinearity"},
      {"delta_OA", "rad", "misalignment: sensitivity to a_PA"},
      {"delta_PA", "rad", "misalignment: sensitivity to a_OA"},
      {"k_IP", "1/g", "cross-coupling a_IA*a_PA"},
      {"k_IO", "1/g", "cross-coupling a_IA*a_OA"},
      {"k_PO", "1/g", "cross-coupling a_PA*a_OA"},
      {"k_PP", "1/g", "quadratic cross-axis a_PA^2"},
      {"k_OO", "1/g", "quadratic cross-axis a_OA^2"},
  }};
  return info;
}

std::optional<Coef> coefficient_from_name(std::string_view name) {
  const auto& info = coefficient_info();
  for (int i = 0; i < kNumCoefficients; ++i)
    if (info[i].name == name) return static_cast<Coef>(i);
  return std::nullopt;
}

Basis basis(const Vec3& a) {
  const double x = a[IA], y = a[PA], z = a[OA];
  const double x2 = x * x;
  return {x,        1.0,   0.5 * std::abs(x), x2,    x2 * x, x2 * x2, y,
          z,        x * y, x * z,             y * z, y * y,  z * z};
}

double output_g(const Coefficients& c, const Vec3& a) {
  const Basis f = basis(a);
  double sum = f[0];
  for (int i = 1; i < kNumCoefficients; ++i) sum += c[i] * f[i];
  return sum;
}

double output(const Coefficients& c, const Vec3& a) { return c[K1] * output_g(c, a); }

Vec3 output_gradient(const Coefficients& c, const Vec3& a) {
  const double x = a[IA], y = a[PA], z = a[OA];
  // At the kink of |a_IA| take the mean of the one-sided slopes; "at" includes the 1e-16 g
  // left by cos(90 deg) in floating point.
  const double sign_x = std::abs(x) <= 1e-12 ? 0.0 : (x > 0) - (x < 0);
  const double d_ia = 1.0 + 0.5 * c[k1_asym] * sign_x + 2 * c[k2] * x + 3 * c[k3] * x * x +
                      4 * c[k4] * x * x * x + c[k_IP] * y + c[k_IO] * z;
  const double d_pa = c[delta_OA] + c[k_IP] * x + c[k_PO] * z + 2 * c[k_PP] * y;
  const double d_oa = c[delta_PA] + c[k_IO] * x + c[k_PO] * y + 2 * c[k_OO] * z;
  return c[K1] * Vec3(d_ia, d_pa, d_oa);
}

}  // namespace vrelab::plant
