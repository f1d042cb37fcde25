#pragma once
// rectification/prediction/frequency_study.hpp -- the study the paper left open: the vibration error
// against frequency, per term of model (1) and per place it acts, plus the pendulum-deflection
// effects, with the frequency-dependent eq. (3) checked against the ODE.
//
// Takes: the instrument's coefficients, the static orientation (g), the dynamics, a sine
//        amplitude (g peak) and direction, a log frequency grid (Hz), the frequencies at
//        which the ODE is run, and the pickoff nonlinearity to study (1/rad).
// Gives: per mechanism (one term at one place, or one effect alone): the prediction e(f) on
//        the grid (g), its ratio to the quasi-static eq. (3), the ODE measurements, and the
//        lowest frequencies above which eq. (3) is off by 1 % and by 10 %.
#include <optional>
#include <string>
#include <vector>

#include "core/settings_description.hpp"
#include "plant/accelerometer.hpp"

namespace vrelab::rectification {

// Describe lists each field once (core/settings_description.hpp): the case's
// [frequency_study] table (the two grids through FrequencyGrid below) and the JSON record of
// the settings used.
struct FrequencyStudySettings {
  std::vector<double> frequencies_Hz;      // the grid of the prediction
  std::vector<double> ode_frequencies_Hz;  // where the ODE measures
  double amplitude_g = 3.0;
  Vec3 direction = Vec3(1, 1, 1).normalized();  // in phase; on every axis so every cross term acts
  double pickoff_p2_per_rad = 20.0;

  template <class V>
  static void Describe(V& v) {
    using S = FrequencyStudySettings;
    using core::field;
    v(field("frequencies_Hz", &S::frequencies_Hz, "Hz", core::above(0), "The grid of the prediction")
          .set_by("from_Hz, to_Hz, points (FrequencyGrid)"));
    v(field("ode_frequencies_Hz", &S::ode_frequencies_Hz, "Hz", core::above(0), "Where the ODE measures")
          .set_by("from_Hz, to_Hz, ode_points (FrequencyGrid)"));
    // At most 1000 g, as every amplitude of a case (shakers reach ~100 g).
    v(field("amplitude_g", &S::amplitude_g, "g", core::open_closed(0, 1000), "Peak amplitude along direction"));
    v(field("direction", &S::direction, "", core::any_value(),
            "Vibration direction in sensor axes [IA, PA, OA] (normalised, in phase)"));
    v(field("pickoff_p2_per_rad", &S::pickoff_p2_per_rad, "1/rad", core::any_value(),
            "The pickoff nonlinearity studied"));
  }
  // False (with the reason, naming the setting, in *why) for an empty grid, a value out of its
  // described range, or a zero direction.
  bool IsValid(std::string* why) const;
};

// The grids as a case writes them: log-spaced from from_Hz to to_Hz, `points` for the
// prediction and `ode_points` (0: none) for the ODE. Each list is a function of three keys, so
// the keys are described here, as written, and apply() is the one conversion (rather than a
// derived field in FrequencyStudySettings' description, which would need a function of
// several keys there).
struct FrequencyGrid {
  double from_Hz = 1.0, to_Hz = 5000.0;
  int points = 80, ode_points = 10;

  template <class V>
  static void Describe(V& v) {
    using S = FrequencyGrid;
    using core::field;
    v(field("from_Hz", &S::from_Hz, "Hz", core::above(0), "Lowest frequency of the log grid"));
    v(field("to_Hz", &S::to_Hz, "Hz", core::above(0), "Highest frequency of the log grid (above from_Hz)"));
    v(field("points", &S::points, "points", core::closed(2, 10000), "Frequencies of the prediction"));
    v(field("ode_points", &S::ode_points, "runs", core::closed(0, 1000), "ODE runs, log-spaced over the same range"));
  }
  // The ranges, and to_Hz above from_Hz.
  bool IsValid(std::string* why) const;
  // s's frequencies_Hz and ode_frequencies_Hz from this grid.
  void apply(FrequencyStudySettings& s) const;
};

struct MechanismCurve {
  std::string name;    // e.g. "k2 (loop)", "pickoff_nonlinearity"
  double eq3_g = 0.0;  // the quasi-static eq. (3) value; 0 for the effects beyond (1)
  std::vector<double> predicted_g;  // on the grid
  std::vector<double> ode_g;        // at the ODE frequencies
  std::vector<double> ode_sigma_g;
  double worst_ode_deviation = 0.0;  // max |ODE/prediction - 1| (relative to max(|pred|, |eq3|))
  std::optional<double> off_1_percent_Hz, off_10_percent_Hz;  // first grid frequency beyond
};

// One curve per coefficient that is non-zero in `plant.coefficients` (k1_asym .. k_OO) and
// rectifies under the chosen direction, at each place it can act, plus the pickoff
// nonlinearity and the pendulum geometry.
std::vector<MechanismCurve> frequency_study(const plant::PlantConfig& plant, const Vec3& a_static_g,
                                            const FrequencyStudySettings& s);

}  // namespace vrelab::rectification
