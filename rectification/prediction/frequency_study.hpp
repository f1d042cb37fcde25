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

#include "plant/accelerometer.hpp"

namespace vrelab::rectification {

struct FrequencyStudySettings {
  std::vector<double> frequencies_Hz;      // the grid of the prediction
  std::vector<double> ode_frequencies_Hz;  // where the ODE measures
  double amplitude_g = 3.0;
  Vec3 direction = Vec3(1, 1, 1).normalized();  // in phase; on every axis so every cross term acts
  double pickoff_p2_per_rad = 20.0;
  // False (with the reason, naming the setting, in *why) for an empty grid, a frequency or
  // the amplitude not positive, or a zero direction.
  bool IsValid(std::string* why) const;
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
