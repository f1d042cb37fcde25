#pragma once
// validation/identification/static_test.hpp -- the whole virtual static test: simulate, identify, propagate.
//
// Takes: the true coefficients, a position set, the test's error sources, the fixed
//        coefficients, a seed, the number of Monte Carlo trials (0: none) and the source of
//        the readings (empty: model (1) with the true coefficients).
// Gives: the simulated readings and, per method (paper_printed, paper_corrected,
//        least_squares), the estimate, its first-order standard uncertainty and bias, and
//        the Monte Carlo statistics. The paper's methods run only on the paper's 3 x 8 set
//        with k1_asym fixed (the paper takes k1' from elsewhere); `notes` says when not.
//
// Least squares is weighted by the first-order variance of each reading (noise and
// set-angle error, evaluated at an unweighted first fit) and is exact for noise-free
// readings. The Monte Carlo trials draw from seed + 1; the test itself from seed.
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "core/settings_description.hpp"
#include "validation/identification/dividing_head.hpp"
#include "validation/identification/identification.hpp"
#include "validation/identification/uncertainty.hpp"

namespace vrelab::validation {

struct MethodResult {
  std::string name;
  Estimate estimate;
  Propagation first_order;
  std::optional<MonteCarloStats> monte_carlo;
};

// The test's settings. Describe lists each field once (core/settings_description.hpp): the
// JSON record of the settings used and IsValid. No case table holds them: each is set from
// elsewhere, as its set_by says. The source of the readings is an input of the run (a
// function, like the positions), not a setting: run_static_test takes it.
struct StaticTestSettings {
  FixedSet fixed{};
  std::uint64_t seed = 1;
  int monte_carlo_trials = 0;  // 0: none; else at least 2
  MonteCarloCheckpoint monte_carlo_checkpoint;  // the trials' resume file (uncertainty.hpp); none by default
  template <class V>
  static void Describe(V& v) {
    using S = StaticTestSettings;
    using core::field;
    v(field("fixed", &S::fixed, "", core::any_value(), "Coefficients held at a given value, not identified")
          .set_by("[identification] fixed"));
    v(field("seed", &S::seed, "", core::any_value(), "Seed of the test's draws; the Monte Carlo trials draw from seed + 1")
          .set_by("[run] seed"));
    v(field("monte_carlo_trials", &S::monte_carlo_trials, "trials", core::at_least(0),
            "Monte Carlo trials of the whole test; 0: none, else at least 2")
          .set_by("--monte-carlo"));
    v(field("monte_carlo_checkpoint", &S::monte_carlo_checkpoint, "", core::any_value(), "The trials' resume file")
          .set_by("--checkpoint"));
  }
  // False (with the reason, naming the setting, in *why) for settings no run can use: the
  // described ranges, and 1 trial (no spread from one).
  bool IsValid(std::string* why) const {
    if (monte_carlo_trials == 1 || monte_carlo_trials < 0) {
      if (why) *why = "monte_carlo_trials: needs at least 2 trials (or 0 for none)";
      return false;
    }
    return core::validate(*this, why);
  }
};

struct StaticTestReport {
  std::vector<Reading> readings;
  Identifiability identifiability;
  std::vector<MethodResult> methods;
  std::vector<std::string> notes;
  FitCheck fit;  // of least squares; run_static_test throws std::invalid_argument if not accepted
};

StaticTestReport run_static_test(const plant::Coefficients& truth, const std::vector<Position>& positions,
                                 const StaticTestErrors& errors, const StaticTestSettings& settings,
                                 const OutputSource& source = {});

}  // namespace vrelab::validation
