#include "rectification/prediction/frequency_study.hpp"

#include <cmath>
#include <memory>

#include "rectification/prediction/eq3.hpp"
#include "rectification/prediction/frequency.hpp"
#include "rectification/simulation/shake.hpp"
#include "rectification/simulation/sweep.hpp"

namespace vrelab::rectification {

bool FrequencyStudySettings::IsValid(std::string* why) const {
  if (!core::validate(*this, why)) return false;
  auto fail = [&](const std::string& m) {
    if (why) *why = m;
    return false;
  };
  if (frequencies_Hz.empty()) return fail("frequencies_Hz: the frequency grid is empty");
  if (!(direction.norm() > 0)) return fail("direction: must not be zero");
  return true;
}

bool FrequencyGrid::IsValid(std::string* why) const {
  if (!core::validate(*this, why)) return false;
  if (!(to_Hz > from_Hz)) {
    if (why) *why = "to_Hz = " + core::format_value(to_Hz) + ": must be above from_Hz = " + core::format_value(from_Hz);
    return false;
  }
  return true;
}

void FrequencyGrid::apply(FrequencyStudySettings& s) const {
  s.frequencies_Hz = spaced(from_Hz, to_Hz, points, true);
  s.ode_frequencies_Hz.clear();
  if (ode_points > 0) s.ode_frequencies_Hz = spaced(from_Hz, to_Hz, ode_points, true);
}

std::vector<MechanismCurve> frequency_study(const plant::PlantConfig& plant, const Vec3& a, const FrequencyStudySettings& s) {
  using namespace plant;
  struct Mechanism {
    std::string name;
    PlantConfig cfg;
  };
  std::vector<Mechanism> mechanisms;
  PlantConfig bare = plant;
  for (int c = k0; c < kNumCoefficients; ++c) bare.coefficients[c] = 0.0;
  bare.effects.clear();
  for (int c = k1_asym; c < kNumCoefficients; ++c) {
    if (c == delta_OA || c == delta_PA || plant.coefficients[c] == 0) continue;
    for (Location l : {Location::input, Location::loop, Location::output}) {
      if (!location_allowed(c, l)) continue;
      PlantConfig one = bare;
      one.coefficients[c] = plant.coefficients[c];
      one.location[c] = l;
      mechanisms.push_back({std::string(coefficient_name(c)) + " (" + std::string(location_name(l)) + ")", one});
    }
  }
  {
    PlantConfig one = bare;
    one.effects.push_back(std::make_shared<PickoffNonlinearity>(s.pickoff_p2_per_rad));
    mechanisms.push_back({"pickoff_nonlinearity", one});
  }
  {
    PlantConfig one = bare;
    one.effects.push_back(std::make_shared<PendulumGeometry>());
    mechanisms.push_back({"pendulum_geometry", one});
  }

  std::vector<MechanismCurve> out;
  for (const Mechanism& m : mechanisms) {
    MechanismCurve curve;
    curve.name = m.name;
    vibration::SineVibration v;
    for (int i = 0; i < 3; ++i) {
      v.amplitude_g[i] = s.amplitude_g * std::abs(s.direction[i]);
      v.phase_rad[i] = s.direction[i] < 0 ? M_PI : 0.0;
    }
    curve.eq3_g = sine_rectification(m.cfg.coefficients, a, v).total_g();
    const bool effect = m.name == "pickoff_nonlinearity" || m.name == "pendulum_geometry";
    if (!effect && curve.eq3_g == 0) continue;  // this term sees no motion in this direction
    for (double f : s.frequencies_Hz) {
      v.frequency_Hz = f;
      const double e = sine_rectification_at_frequency(m.cfg, a, v).total_g();
      curve.predicted_g.push_back(e);
      if (curve.eq3_g != 0) {
        const double off = std::abs(e / curve.eq3_g - 1);
        if (off > 0.01 && !curve.off_1_percent_Hz) curve.off_1_percent_Hz = f;
        if (off > 0.10 && !curve.off_10_percent_Hz) curve.off_10_percent_Hz = f;
      }
    }
    for (double f : s.ode_frequencies_Hz) {
      v.frequency_Hz = f;
      const ShakeResult r = shake_sine(m.cfg, a, v);
      const double e = sine_rectification_at_frequency(m.cfg, a, v).total_g();
      curve.ode_g.push_back(r.measured_g);
      curve.ode_sigma_g.push_back(r.sigma_g);
      const double scale = std::max({std::abs(e), std::abs(curve.eq3_g), 1e-12});
      curve.worst_ode_deviation = std::max(curve.worst_ode_deviation, std::abs(r.measured_g - e) / scale);
    }
    out.push_back(std::move(curve));
  }
  return out;
}

}  // namespace vrelab::rectification
