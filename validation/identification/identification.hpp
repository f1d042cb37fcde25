#pragma once
// validation/identification/identification.hpp -- coefficients of model (1) from static readings.
//
// Takes: a position set (dividing_head.hpp), readings U (output units) at those positions,
//        reading weights, and the coefficients held at known values ("fixed").
// Gives: three estimators side by side, and an identifiability report:
//  - paper_printed:   the paper's formulas exactly as printed (3 x 8 set only; k1' given);
//  - paper_corrected: the team's closed forms for the 3 x 8 set (docs/identification.md);
//  - least_squares:   weighted linear least squares for any position set.
// All three estimate with the same parametrisation theta = (K1, K1 k0, ..., K1 k_OO): model
// (1) is linear in theta, so U = A(a) theta exactly and the identification is exact for
// noise-free readings.
#include <array>
#include <optional>
#include <string>
#include <vector>

#include "plant/model1.hpp"
#include "validation/identification/dividing_head.hpp"

namespace vrelab::validation {

using CoefFlags = std::array<bool, plant::kNumCoefficients>;
// Coefficients held at known values; std::nullopt = free (to be estimated).
using FixedSet = std::array<std::optional<double>, plant::kNumCoefficients>;

struct Estimate {
  plant::Coefficients value;
  CoefFlags available{};  // false: this method does not give the coefficient
  CoefFlags assumed{};    // true: taken as given (fixed in the case, or the method's assumption)
};

struct Identifiability {
  int parameters = 0;  // free coefficients
  int rank = 0;
  double condition_number = 0;  // of the column-scaled (weighted) design; inf if rank-deficient
  double condition_number_identifiable = 0;  // over the rank's singular values
  CoefFlags free{};
  CoefFlags identifiable{};  // free and determined by the readings
  // Directions in coefficient space that leave every reading unchanged, one per missing
  // rank, as (entry 0: relative change of K1; entry i: change of coefficient i).
  std::vector<std::array<double, plant::kNumCoefficients>> null_directions;
  std::vector<std::string> confounded;  // the same, in words
  bool full_rank() const { return rank == parameters; }
};

struct LeastSquaresResult {
  Estimate estimate;             // minimum-norm solution when rank-deficient
  Identifiability identifiability;
};

// Weighted least squares. weights: one per reading (1/variance), or empty for equal weights.
LeastSquaresResult least_squares(const std::vector<Position>& positions,
                                 const std::vector<Reading>& readings,
                                 const std::vector<double>& weights, const FixedSet& fixed);

// Whether an accepted identification reproduces its readings: each reading's residual
// against model (1) at the estimate, over its standard deviation (`variance`, one per
// reading, output units^2; floored at (K1 * kFitFloor_g)^2, so noise-free tests are judged
// against a resolution far below any lab's noise and far above rounding), and no estimate
// beyond its physical range (|k| > kAbsurdCoefficient in its unit). Empty when it does;
// else the reason in words (the worst reading or coefficient, and the figure).
inline constexpr double kFitFloor_g = 1e-7;         // 0.1 ug
inline constexpr double kMaxChi2PerDof = 1e4;       // an rms residual of 100 sigma
inline constexpr double kAbsurdCoefficient = 1.0;   // 1 g bias, 1/g, 1 rad, ...
struct FitCheck {
  double chi2_per_dof = 0;  // over readings - free coefficients (readings if none left)
  double max_abs_residual = 0;  // output units
  std::string problem;          // empty: accepted
};
FitCheck check_fit(const std::vector<Position>& positions, const std::vector<Reading>& readings,
                   const Estimate& estimate, const std::vector<double>& variance, int free_parameters);

// Identifiability of a position set with the given fixed coefficients (equal weights).
Identifiability identifiability(const std::vector<Position>& positions, const FixedSet& fixed);

// Mean reading U_sj (s = 1..3, j = 1..8) of the paper's 3 x 8 set, from readings at the
// positions of is_paper_set(); std::nullopt for any other set.
using PaperTable = std::array<std::array<double, 8>, 3>;
std::optional<PaperTable> paper_table(const std::vector<Position>& positions,
                                      const std::vector<Reading>& readings);

// The paper's formulas as printed; k1_tilde is k1' taken from elsewhere (as the paper does).
Estimate paper_printed(const PaperTable& u, double k1_tilde);
// The corrected closed forms, exact for model (1) with k_PP and k_OO at the given values
// (the paper assumes both zero; only their common shift with k0 and k2 is invisible).
Estimate paper_corrected(const PaperTable& u, double k1_tilde, double k_PP_known = 0.0, double k_OO_known = 0.0);

}  // namespace vrelab::validation
