#pragma once
// validation/identification/uncertainty.hpp -- how the test's errors reach the identified coefficients.
//
// Takes: an estimator (readings -> coefficients), the readings of one test, and the
//        first-order error budget of each reading (dividing_head.hpp: reading_budget).
// Gives: first-order propagation: sigma_k = sqrt(sum_i J_ki^2 var_i) and the bias
//        sum_i J_ki bias_i, with J = d(estimate)/d(reading) by central differences;
//        Monte Carlo: the mean error and the scatter of each coefficient over N simulated
//        tests (fresh set-angle errors and noise, the same initial orientation error).
#include <array>
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "core/settings_description.hpp"
#include "plant/model1.hpp"
#include "validation/identification/dividing_head.hpp"
#include "validation/identification/identification.hpp"

namespace vrelab::validation {

using CoefArray = std::array<double, plant::kNumCoefficients>;
using Estimator = std::function<Estimate(const std::vector<Reading>&)>;

struct Propagation {
  CoefArray sigma{};  // standard uncertainty, coefficient units
  CoefArray bias{};   // first-order effect of the initial orientation error
  // Covariance of the estimates (coefficient units squared), from the same Jacobian: what a
  // prediction that combines several coefficients (eq. (3)) needs.
  std::array<CoefArray, plant::kNumCoefficients> covariance{};
};

Propagation propagate_first_order(const Estimator& estimator, const std::vector<Reading>& readings,
                                  const ReadingBudget& budget);

struct MonteCarloStats {
  int n = 0;
  CoefArray mean_error{};  // mean of (estimate - truth)
  CoefArray std{};         // sample standard deviation of the estimate
};

// Runs `n` simulated tests from `seed`; one MonteCarloStats per estimator. The trials go in
// blocks of 256, block b drawn from its own stream (seed, b), on `threads` threads (0: all
// cores) or the ranks of mpirun (core/dispatch.hpp); the blocks' means and squared deviations
// are merged in block order: the result is the same to the bit whatever ran them.
//
// With `checkpoint.path` set, each block's result is appended to that file (one line, its
// numbers as hexadecimal floats, a checksum) as rank 0 receives it, under a header naming
// `checkpoint.fingerprint`, the trials and the seed; a run that finds the file reads the
// blocks back (a cut or altered line is dropped and its block run again) and runs only the
// others: the result is that of an uninterrupted run to the bit. A header that differs
// throws std::invalid_argument. The file is kept at the end (docs/mpi.md).
//
// Describe lists its fields (core/settings_description.hpp): both set by the command, no table.
struct MonteCarloCheckpoint {
  std::string path;         // empty: none
  std::string fingerprint;  // one line: the case and the program (the caller's choice)
  template <class V>
  static void Describe(V& v) {
    using S = MonteCarloCheckpoint;
    v(core::field("path", &S::path, "", core::any_value(), "The trials' resume file; empty: none").set_by("--checkpoint"));
    v(core::field("fingerprint", &S::fingerprint, "", core::any_value(),
                  "One line naming the case and the program, checked against the file's header")
          .set_by("the command, from the case's content and the program's version"));
  }
  bool IsValid(std::string* why) const {
    if (fingerprint.find('\n') != std::string::npos) {
      if (why) *why = "fingerprint: must be one line";
      return false;
    }
    return core::validate(*this, why);
  }
};

std::vector<MonteCarloStats> monte_carlo(const std::vector<Estimator>& estimators,
                                         const plant::Coefficients& truth, const OutputSource& source,
                                         const std::vector<Position>& positions,
                                         const StaticTestErrors& errors, int n, std::uint64_t seed, int threads = 0,
                                         const MonteCarloCheckpoint& checkpoint = {});

}  // namespace vrelab::validation
