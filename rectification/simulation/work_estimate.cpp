#include "rectification/simulation/work_estimate.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <sstream>
#include <stdexcept>

#include <Eigen/Eigenvalues>

namespace vrelab::rectification {

PlantTimescales plant_timescales(const plant::PlantConfig& plant, const Vec3& a_static_g) {
  const plant::Accelerometer rest(plant, a_static_g);
  const plant::Accelerometer::Linear lin = rest.linearise();
  PlantTimescales t;
  t.slowest_time_constant_s = rest.slowest_time_constant_s(lin);
  const Eigen::VectorXcd eig = Eigen::EigenSolver<Eigen::MatrixXd>(lin.A, false).eigenvalues();
  for (Eigen::Index i = 0; i < eig.size(); ++i)
    t.fastest_pole_Hz = std::max(t.fastest_pole_Hz, std::abs(eig[i]) / (2 * std::numbers::pi));
  return t;
}

WorkEstimate estimate_work(const WorkRequest& r, const PlantTimescales& plant) {
  WorkEstimate e;
  e.fastest_Hz = plant.fastest_pole_Hz;
  e.fastest_key = "the plant's fastest pole ([plant] keys, [plant.effects] modes)";
  if (r.drive_Hz > e.fastest_Hz) e.fastest_Hz = r.drive_Hz, e.fastest_key = r.drive_key;
  if (r.sample_rate_Hz / 2 > e.fastest_Hz) e.fastest_Hz = r.sample_rate_Hz / 2, e.fastest_key = "[readout] sample_rate_Hz";
  const double ode_steps = r.simulated_s * kStepsPerPeriod * e.fastest_Hz;
  const double samples_per_run = r.simulated_s * r.sample_rate_Hz;
  e.steps_per_run = std::max(ode_steps, samples_per_run);  // a sampled run stops at each sample
  // A reading that costs no ODE step (a Monte Carlo trial of model (1)) counts as one.
  e.steps = r.runs * e.steps_per_run + r.samples_extra;
  e.samples = r.runs * samples_per_run + r.samples_extra;
  e.bytes = samples_per_run * kBytesPerSample;  // one run's record is held at a time
  return e;
}

std::string WorkEstimate::Describe() const {
  std::ostringstream s;
  s.precision(3);
  s << "~" << steps << " ODE steps (~" << steps_per_run << " per run; highest frequency " << fastest_Hz << " Hz, from " << fastest_key << "), ~"
    << samples << " samples, ~" << bytes / (1ull << 20) << " MiB";
  return s.str();
}

void check_work(const WorkEstimate& e, const std::string& flag) {
  if (e.steps <= kMaxSteps && e.steps_per_run <= kMaxStepsPerRun && e.bytes <= kMaxBytes) return;
  std::ostringstream s;
  s.precision(3);
  s << "this would take " << e.Describe() << ": beyond the limits of " << kMaxStepsPerRun << " steps per run, "
    << kMaxSteps << " in all and " << kMaxBytes / (1ull << 30)
    << " GiB (docs/case-files.md, Limits). Check the keys named (a Hz/kHz or s/ms slip?), "
    << "or give " << flag << " to go on anyway";
  throw std::invalid_argument(s.str());
}

}  // namespace vrelab::rectification
