#pragma once
// rectification/prediction/eq3.hpp -- the analytic vibration error of model (1): eq. (3), corrected.
//
// Takes: model (1) coefficients, the static acceleration a (g, sensor axes [IA, PA, OA]),
//        a sine vibration (peak amplitude per axis, g, and per-axis phase) or a Gaussian
//        random vibration (covariance, g^2), and optionally the range limit R (g) at which
//        the output clips.
// Gives: the vibration error e = <U/K1 under vibration> - U/K1 static, in g, per term of
//        model (1) and in total. This is the low-frequency (quasi-static) limit: the whole
//        vibration reaches every term of (1) unfiltered.
//
// Corrections to the printed eq. (3) (see docs/prediction.md and ../shared/notes):
//  1. asymmetry: (k1'/pi) [a asin(a/|w|) + sqrt(w^2 - a^2) - pi|a|/2] for |a| < |w| (the
//     printed text lacks the factor a before asin);
//  2. k_PP w_PA^2/2 and k_OO w_OA^2/2 are added (the printed form omits them);
//  3. a phase difference between axes multiplies each cross term by cos(phase_i - phase_j).
// Clipping is a leading-order term: the mean of clip(a_IA + x, -R, R) minus clip(a_IA, -R, R).
#include <array>
#include <optional>
#include <string_view>

#include "plant/model1.hpp"
#include "vibration/profile.hpp"

namespace vrelab::rectification {

enum Term : int { t_k2, t_k3, t_k4, t_k1_asym, t_k_IP, t_k_IO, t_k_PO, t_k_PP, t_k_OO, t_clipping };
inline constexpr int kNumTerms = 10;
std::string_view term_name(int t);  // "k2", ..., "k_OO", "clipping"
// The term a coefficient of (1) rectifies into (-1 for K1, k0 and the misalignments, which
// do not rectify a zero-mean vibration).
int term_of_coefficient(int coef);

struct Eq3Terms {
  std::array<double, kNumTerms> g{};  // each term's contribution, g
  double total_g() const;
  // The part the printed eq. (3) omits: the k_PP and k_OO terms.
  double omitted_by_paper_g() const { return g[t_k_PP] + g[t_k_OO]; }
};

Eq3Terms sine_rectification(const plant::Coefficients& c, const Vec3& a_g,
                            const vibration::SineVibration& v,
                            std::optional<double> range_limit_g = std::nullopt);
// What sine_rectification takes of the vibration: the axes' covariance (g^2) and the IA
// amplitude (g). A caller that evaluates many coefficient sets on one vibration computes it
// once (nine cosines); the overload below gives the same numbers as the one above.
struct SineMoments {
  Eigen::Matrix3d covariance_g2;
  double amplitude_ia_g = 0;
};
SineMoments sine_moments(const vibration::SineVibration& v);
Eq3Terms sine_rectification(const plant::Coefficients& c, const Vec3& a_g, const SineMoments& m,
                            std::optional<double> range_limit_g = std::nullopt);
Eq3Terms random_rectification(const plant::Coefficients& c, const Vec3& a_g,
                              const vibration::RandomVibration& v,
                              std::optional<double> range_limit_g = std::nullopt);

// Sine on Gaussian random (independent): E[f(a + S + G)] - f(a) =
// <random_rectification at a + S(theta)>_theta + sine_rectification at a, the average over
// the sine's phase by a 64-point trapezoid rule (exact for the polynomial terms; the
// Gaussian-smoothed |.| and clipping converge spectrally).
Eq3Terms sine_on_random_rectification(const plant::Coefficients& c, const Vec3& a_g,
                                      const vibration::SineVibration& sine, const vibration::RandomVibration& random,
                                      std::optional<double> range_limit_g = std::nullopt);
// The same with the sine's 64 points a + S(theta_k) given (sine_phase_points): one set of
// points for every coefficient of a prediction.
using SinePhasePoints = std::array<Vec3, 64>;
SinePhasePoints sine_phase_points(const Vec3& a_g, const vibration::SineVibration& sine);
Eq3Terms sine_on_random_rectification(const plant::Coefficients& c, const Vec3& a_g, const vibration::SineVibration& sine,
                                      const SinePhasePoints& points, const vibration::RandomVibration& random,
                                      std::optional<double> range_limit_g = std::nullopt);

// Eq. (3) literally as printed in the paper (in-phase amplitudes, asin without the factor
// a, no k_PP/k_OO), for showing what the printed form returns. g.
double sine_rectification_as_printed(const plant::Coefficients& c, const Vec3& a_g,
                                     const vibration::SineVibration& v);

// The building blocks, per unit coefficient, in g:
// <|a + w sin|>/2 - |a|/2 over a period (times k1' gives the asymmetry term).
double asymmetry_sine(double a_g, double amplitude_g);
// E|a + X|/2 - |a|/2 for X ~ N(0, sigma^2).
double asymmetry_gaussian(double a_g, double sigma_g);
// <clip(a + w sin, -R, R)> - clip(a, -R, R).
double clipping_sine(double a_g, double amplitude_g, double range_g);
// E[clip(a + X, -R, R)] - clip(a, -R, R) for X ~ N(0, sigma^2).
double clipping_gaussian(double a_g, double sigma_g, double range_g);

}  // namespace vrelab::rectification
