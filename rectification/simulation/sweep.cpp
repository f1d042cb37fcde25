#include "rectification/simulation/sweep.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <stdexcept>

#include "core/dispatch.hpp"
#include "plant/ode_solver.hpp"
#include "rectification/prediction/eq3.hpp"

namespace vrelab::rectification {

vibration::SineVibration SweepCondition::vibration() const {
  vibration::SineVibration v;
  v.frequency_Hz = frequency_Hz;
  for (int i = 0; i < 3; ++i) {
    v.amplitude_g[i] = amplitude_g * std::abs(direction[i]);
    v.phase_rad[i] = direction[i] < 0 ? std::numbers::pi : 0.0;
  }
  return v;
}

bool SweepGrid::IsValid(std::string* why) const {
  auto fail = [&](const std::string& m) {
    if (why) *why = m;
    return false;
  };
  if (size() == 0) return fail("the grid is empty (frequencies, amplitudes, directions and orientations each need one)");
  for (double f : frequencies_Hz)
    if (!(f > 0)) return fail("frequencies must be positive");
  for (double a : amplitudes_g)
    if (!(a > 0)) return fail("amplitudes_g: amplitudes must be positive");
  for (const Vec3& d : directions)
    if (!(d.norm() > 0)) return fail("directions: a direction must not be zero");
  return true;
}

SweepCondition sweep_condition(const SweepGrid& g, std::size_t index) {
  if (index >= g.size()) throw std::out_of_range("sweep condition index");
  SweepCondition c;
  c.index = index;
  std::size_t k = index;
  c.frequency_Hz = g.frequencies_Hz[k % g.frequencies_Hz.size()];
  k /= g.frequencies_Hz.size();
  c.amplitude_g = g.amplitudes_g[k % g.amplitudes_g.size()];
  k /= g.amplitudes_g.size();
  c.direction = g.directions[k % g.directions.size()];
  k /= g.directions.size();
  c.orientation_g = g.orientations_g[k];
  return c;
}

std::vector<double> spaced(double f1, double f2, int n, bool logarithmic) {
  if (n < 1) throw std::invalid_argument("points must be at least 1");
  if (logarithmic && !(f1 > 0 && f2 > 0)) throw std::invalid_argument("log spacing needs positive ends");
  std::vector<double> f;
  for (int i = 0; i < n; ++i) {
    const double u = n == 1 ? 0.0 : static_cast<double>(i) / (n - 1);
    f.push_back(logarithmic ? f1 * std::pow(f2 / f1, u) : f1 + (f2 - f1) * u);
  }
  return f;
}

namespace {

// A row's result as text: ok, the numbers (17 significant digits: read back exactly), the
// error last (any characters).
std::string row_text(const SweepRow& r) {
  char head[256];
  std::snprintf(head, sizeof head, "%d %.17g %.17g %.17g %.17g %.17g %ld ", r.ok ? 1 : 0, r.measured_g, r.sigma_g,
                r.predicted_eq3_g, r.settle_s, r.wall_s, r.steps);
  return head + r.error;
}

SweepRow row_from_text(const SweepCondition& c, const std::string& text) {
  SweepRow r;
  r.condition = c;
  int ok = 0, used = 0;
  if (std::sscanf(text.c_str(), "%d %lg %lg %lg %lg %lg %ld %n", &ok, &r.measured_g, &r.sigma_g, &r.predicted_eq3_g,
                  &r.settle_s, &r.wall_s, &r.steps, &used) < 7)
    throw std::runtime_error("sweep: a condition's result could not be read back");
  r.ok = ok != 0;
  r.error = text.substr(static_cast<std::size_t>(used));
  return r;
}

}  // namespace

void run_sweep(const plant::PlantConfig& plant, const plant::Coefficients& truth, const ShakeSettings& settings,
               const SweepGrid& grid,
               const std::vector<std::size_t>& skip, int threads, const std::function<void(const SweepRow&)>& on_row) {
  std::vector<std::size_t> todo;
  for (std::size_t i = 0; i < grid.size(); ++i)
    if (!std::binary_search(skip.begin(), skip.end(), i)) todo.push_back(i);
  // Longest first, so that no long condition is left for the end (cost ~ simulated time x
  // steps per second: settling ~0.05 s plus 4 periods, at ~max(f, 50 Hz) steps' worth).
  auto cost = [&](std::size_t i) {
    const double f = sweep_condition(grid, i).frequency_Hz;
    return (0.05 + 5 / f) * std::max(f, 50.0);
  };
  std::stable_sort(todo.begin(), todo.end(), [&](std::size_t a, std::size_t b) { return cost(a) > cost(b); });
  // Each condition's row travels as text (core::dispatch: from another rank under MPI) and
  // is read back on rank 0 into the row the threads would have given: every number exactly.
  core::dispatch(
      todo, threads,
      [&](std::size_t index) {
        SweepRow row;
        row.condition = sweep_condition(grid, index);
        const auto t0 = std::chrono::steady_clock::now();
        try {
          const vibration::SineVibration v = row.condition.vibration();
          ShakeSettings own = settings;  // independent readout noise per condition
          own.readout.seed = settings.readout.seed + row.condition.index;
          const ShakeResult r = shake_sine(plant, row.condition.orientation_g, v, own);
          row.measured_g = r.measured_g;
          row.sigma_g = r.sigma_g;
          row.settle_s = r.settle_s;
          row.steps = r.steps;
          row.predicted_eq3_g = sine_rectification(truth, row.condition.orientation_g, v).total_g();
          row.ok = true;
        } catch (const plant::SolverError& e) {
          row.error = e.what();
        } catch (const std::invalid_argument& e) {
          row.error = e.what();
        }
        row.wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
        return row_text(row);
      },
      [&](std::size_t index, const std::string& text) { on_row(row_from_text(sweep_condition(grid, index), text)); });
}

}  // namespace vrelab::rectification
