#pragma once
// plant/model1.hpp -- the static model (1) of the paper (IEEE Std 1293 form).
//
// Takes: the 13 coefficients of model (1) and a specific force (acceleration) in the
//        sensor axes [a_IA, a_PA, a_OA], in g (1 g = the site's gravity).
// Gives: the output U in output units (K1 is in output units per g, e.g. mA/g), the
//        normalised output U/K1 in g, its gradient with respect to the acceleration,
//        and the regressor basis that the identification and the rectification share.
//
//   U = K1 * { k0 + (1 + (k1'/2) sign a_IA) a_IA + k2 a_IA^2 + k3 a_IA^3 + k4 a_IA^4
//              + delta_OA a_PA + delta_PA a_OA + k_IP a_IA a_PA + k_IO a_IA a_OA
//              + k_PO a_PA a_OA + k_PP a_PA^2 + k_OO a_OA^2 }
//
// (k1'/2) sign(a_IA) a_IA = (k1'/2)|a_IA|: the scale factor is K1(1 + k1'/2) for
// a_IA > 0 and K1(1 - k1'/2) for a_IA < 0. Units: k0 in g, k1' dimensionless, k2 in 1/g,
// k3 in 1/g^2, k4 in 1/g^3, delta_* in rad, the cross terms k_IP..k_OO in 1/g.
#include <array>
#include <optional>
#include <string>
#include <string_view>
#include <utility>

#include <Eigen/Core>

namespace vrelab {

using Vec3 = Eigen::Vector3d;
// Index of each sensor axis in every 3-vector of the project: [IA, PA, OA].
inline constexpr int IA = 0;
inline constexpr int PA = 1;
inline constexpr int OA = 2;

}  // namespace vrelab

namespace vrelab::plant {

inline constexpr int kNumCoefficients = 13;

// Coefficient indices, named exactly as in case files and JSON.
enum Coef : int { K1, k0, k1_asym, k2, k3, k4, delta_OA, delta_PA, k_IP, k_IO, k_PO, k_PP, k_OO };

struct CoefficientInfo {
  std::string_view name;  // as in case files and JSON
  std::string_view unit;  // "out/g" stands for the case's output unit per g
  std::string_view meaning;
};
const std::array<CoefficientInfo, kNumCoefficients>& coefficient_info();
std::optional<Coef> coefficient_from_name(std::string_view name);
inline std::string_view coefficient_name(int i) { return coefficient_info()[i].name; }

// A coefficient's unit in a datasheet's form (IEEE Std 1293): model (1)'s g-based units times
// 1e6 -- g as ug, 1 as ug/g, 1/g^n as ug/g^(n+1), rad as urad, rad/g as urad/g -- {unit,
// factor}; nullopt for any other unit (out/g, the scale factor, stays as it is).
std::optional<std::pair<std::string, double>> datasheet_unit(std::string_view model_unit);

struct Coefficients {
  std::array<double, kNumCoefficients> v{};
  double& operator[](int i) { return v[i]; }
  double operator[](int i) const { return v[i]; }
};

// The model is U = K1 * (a_IA + sum_{i=1..12} c_i * basis_i(a)), c_i the coefficient with
// index i (k0 .. k_OO). basis[i] for i = 1..12; basis[0] is a_IA (the term K1 multiplies).
using Basis = std::array<double, kNumCoefficients>;
Basis basis(const Vec3& a_g);

double output(const Coefficients& c, const Vec3& a_g);    // U, output units
double output_g(const Coefficients& c, const Vec3& a_g);  // U / K1, g
// dU/da in output units per g. At a_IA = 0 (|a_IA| <= 1e-12 g) the asymmetry term
// contributes 0 (the mean of its one-sided slopes).
Vec3 output_gradient(const Coefficients& c, const Vec3& a_g);

}  // namespace vrelab::plant
