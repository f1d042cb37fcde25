#include "validation/reproduce/reproduce.hpp"

#include <algorithm>
#include <cmath>
#include <map>
#include <numbers>
#include <stdexcept>
#include <memory>
#include <sstream>

#include <Eigen/Dense>
#include <fmt/format.h>

#include "core/parallel.hpp"
#include "core/progress.hpp"
#include "rectification/prediction/eq3.hpp"
#include "rectification/prediction/frequency.hpp"
#include "rectification/prediction/gradient.hpp"
#include "rectification/simulation/sweep.hpp"

namespace vrelab::validation {
namespace {

using plant::Coefficients;
vibration::SineVibration sine_of(const Vec3& direction, double amplitude_g, double frequency_Hz) {
  rectification::SweepCondition c;
  c.direction = direction, c.amplitude_g = amplitude_g, c.frequency_Hz = frequency_Hz;
  return c.vibration();
}

using Model = std::function<double(const Coefficients&)>;

}  // namespace

void predict_run(RunResult& r, const plant::PlantConfig& nominal,
                 const std::array<CoefArray, plant::kNumCoefficients>& cov) {
  const Coefficients& c = nominal.coefficients;
  const vibration::SineVibration v = sine_of(r.direction_unit, r.amplitude_g, r.frequency_Hz);
  const Vec3 a = r.orientation_g;
  const Model quasi_static = [&](const Coefficients& k) { return rectification::sine_rectification(k, a, v).total_g(); };
  const Model at_frequency = [&](const Coefficients& k) {
    plant::PlantConfig p = nominal;
    p.coefficients = k;
    return rectification::sine_rectification_at_frequency(p, a, v).terms.total_g();
  };
  r.predicted = predict_with_uncertainty(quasi_static, c, cov);
  r.printed_g = rectification::sine_rectification_as_printed(c, a, v);
  r.at_frequency = predict_with_uncertainty(at_frequency, c, cov);
}

Prediction predicted_change(const RunResult& r, const RunResult& ref, const plant::PlantConfig& nominal,
                            const std::array<CoefArray, plant::kNumCoefficients>& cov) {
  const auto at = [&](const RunResult& x, const Coefficients& k) {
    plant::PlantConfig p = nominal;
    p.coefficients = k;
    return rectification::sine_rectification_at_frequency(p, x.orientation_g,
                                                          sine_of(x.direction_unit, x.amplitude_g, x.frequency_Hz))
        .terms.total_g();
  };
  return predict_with_uncertainty([&](const Coefficients& k) { return at(r, k) - at(ref, k); }, nominal.coefficients, cov);
}

namespace {

// Runs the grid on the plant and returns one RunResult per condition (grid order), with
// the measurement filled in. A failed condition throws (the reproduction needs them all).
std::vector<RunResult> shake_grid(const plant::PlantConfig& plant, const rectification::ShakeSettings& shake,
                                  const rectification::SweepGrid& grid, const std::vector<NamedVector>& directions,
                                  const std::vector<NamedVector>& orientations, int threads,
                                  std::ostream* progress_out, const std::string& label) {
  std::vector<RunResult> runs(grid.size());
  std::vector<std::string> failures;
  std::unique_ptr<core::Progress> progress;
  if (progress_out) progress = std::make_unique<core::Progress>(*progress_out, label, grid.size());
  rectification::run_sweep(plant, plant.coefficients, shake, grid, {}, threads, [&](const rectification::SweepRow& row) {
    if (progress) progress->tick();
    const rectification::SweepCondition& c = row.condition;
    if (!row.ok) {
      failures.push_back(row.error);
      return;
    }
    RunResult& r = runs[c.index];
    const std::size_t per_direction = grid.frequencies_Hz.size() * grid.amplitudes_g.size();
    const std::size_t d = (c.index / per_direction) % grid.directions.size();
    const std::size_t o = c.index / (per_direction * grid.directions.size());
    r.direction = directions[d].name, r.orientation = orientations[o].name;
    r.direction_unit = c.direction, r.orientation_g = c.orientation_g;
    r.frequency_Hz = c.frequency_Hz, r.amplitude_g = c.amplitude_g;
    r.measured_g = row.measured_g, r.sigma_measured_g = row.sigma_g;
    r.true_eq3_g = row.predicted_eq3_g;
    r.true_at_frequency_g =
        rectification::sine_rectification_at_frequency(plant, c.orientation_g, c.vibration()).total_g();
  });
  if (progress) progress->finish();
  if (!failures.empty()) throw std::runtime_error("reproduce: a shaker run failed: " + failures.front());
  return runs;
}

rectification::SweepGrid grid_of(const std::vector<double>& frequencies_Hz, const std::vector<double>& amplitudes_g,
                                  const std::vector<NamedVector>& directions,
                                  const std::vector<NamedVector>& orientations) {
  rectification::SweepGrid g;
  g.frequencies_Hz = frequencies_Hz;
  g.amplitudes_g = amplitudes_g;
  for (const auto& d : directions) g.directions.push_back(d.v.normalized());
  for (const auto& o : orientations) g.orientations_g.push_back(o.v);
  return g;
}

}  // namespace

double RunResult::combined_sigma_g() const {
  return std::sqrt(sigma_measured_g * sigma_measured_g + predicted.sigma_g * predicted.sigma_g);
}

Prediction predict_with_uncertainty(const Model& f, const Coefficients& c,
                                    const std::array<CoefArray, plant::kNumCoefficients>& covariance) {
  const CoefArray g = rectification::prediction_gradient(f, c);
  double var = 0;
  for (int i = 0; i < plant::kNumCoefficients; ++i)
    for (int j = 0; j < plant::kNumCoefficients; ++j) var += g[i] * covariance[i][j] * g[j];
  return {f(c), std::sqrt(std::max(var, 0.0))};
}

namespace {

// Why a static orientation a is not gravity in sensor axes; "" when it is.
std::string gravity_problem(const Vec3& a) {
  if (std::abs(a.norm() - 1) <= kGravityNormTolerance_g) return "";
  return fmt::format("a static orientation is gravity in sensor axes [IA, PA, OA], |a| = 1 g (within {:g}); got |a| = {:.6g} g",
                     kGravityNormTolerance_g, a.norm());
}

bool fail_with(std::string* why, const std::string& m) {
  if (why) *why = m;
  return false;
}

}  // namespace

bool ConfirmationSettings::IsValid(std::string* why) const {
  if (!core::validate(*this, why)) return false;
  if (!(direction.v.norm() > 0)) return fail_with(why, "direction: not set (a zero vector)");
  if (const std::string p = gravity_problem(orientation.v); !p.empty())
    return fail_with(why, "orientation '" + orientation.name + "': " + p);
  return true;
}

bool ReproduceSettings::IsValid(std::string* why) const {
  if (!core::validate(*this, why)) return false;
  const std::string needs = ": none; the amplitude study needs amplitudes, directions and orientations";
  if (amplitudes_g.empty()) return fail_with(why, "amplitudes_g" + needs);
  if (directions.empty()) return fail_with(why, "directions" + needs);
  if (orientations.empty()) return fail_with(why, "orientations" + needs);
  for (const NamedVector& d : directions)
    if (!(d.v.norm() > 0)) return fail_with(why, "directions: '" + d.name + "' is a zero vector");
  for (const NamedVector& o : orientations)
    if (const std::string p = gravity_problem(o.v); !p.empty()) return fail_with(why, "orientations: '" + o.name + "': " + p);
  if (positions.empty()) return fail_with(why, "positions: none; the static test needs them ([dividing_head])");
  const Identifiability ident = identifiability(positions, fixed);
  if (!ident.full_rank())
    return fail_with(why, "positions: rank " + std::to_string(ident.rank) + " of " + std::to_string(ident.parameters) +
                              " with the coefficients held fixed ([dividing_head] with [identification] fixed); fix more "
                              "coefficients (the paper fixes k1_asym, k_PP and k_OO)");
  return true;
}

bool ReproduceLists::IsValid(std::string* why) const {
  if (!core::validate(*this, why)) return false;
  const auto names_fit = [&](const char* key, const std::vector<std::string>& names, const char* of, std::size_t n) {
    if (!names.empty() && names.size() != n)
      return fail_with(why, fmt::format("{}: expected an array of {} strings, one per entry of {} (got {})", key, n, of,
                                        names.size()));
    for (std::size_t i = 0; i < names.size(); ++i)
      if (names[i].empty()) return fail_with(why, fmt::format("{}[{}]: must not be empty", key, i));
    return true;
  };
  if (directions.empty()) return fail_with(why, "directions: none; the amplitude study needs at least one");
  if (orientations_g.empty()) return fail_with(why, "orientations_g: none; the amplitude study needs at least one");
  if (!names_fit("direction_names", direction_names, "directions", directions.size())) return false;
  if (!names_fit("orientation_names", orientation_names, "orientations_g", orientations_g.size())) return false;
  for (std::size_t i = 0; i < directions.size(); ++i)
    if (!(directions[i].norm() > 0))
      return fail_with(why, fmt::format("directions[{}] = {}: a direction must not be zero", i, core::format_value(directions[i])));
  for (std::size_t i = 0; i < orientations_g.size(); ++i)
    if (const std::string p = gravity_problem(orientations_g[i]); !p.empty())
      return fail_with(why, fmt::format("orientations_g[{}] = {}: {}", i, core::format_value(orientations_g[i]), p));
  const auto index_fits = [&](const char* key, int index, const char* of, std::size_t n) {
    if (static_cast<std::size_t>(index) <= n) return true;
    return fail_with(why, fmt::format("confirmation.{} = {}: must be at most {}, the entries of {}", key, index, n, of));
  };
  return index_fits("orientation", confirmation.orientation, "orientations_g", orientations_g.size()) &&
         index_fits("direction", confirmation.direction, "directions", directions.size());
}

void ReproduceLists::apply(ReproduceSettings& s) const {
  const auto named = [](const std::vector<Vec3>& v, const std::vector<std::string>& names, bool unit) {
    std::vector<NamedVector> out;
    for (std::size_t i = 0; i < v.size(); ++i) {
      const Vec3 x = unit ? v[i].normalized() : v[i];
      out.push_back({names.empty() ? fmt::format("[{:.3g}, {:.3g}, {:.3g}]", x[0], x[1], x[2]) : names[i], x});
    }
    return out;
  };
  s.directions = named(directions, direction_names, true);
  s.orientations = named(orientations_g, orientation_names, false);
  s.confirmation.orientation = s.orientations.at(static_cast<std::size_t>(confirmation.orientation - 1));
  s.confirmation.direction = s.directions.at(static_cast<std::size_t>(confirmation.direction - 1));
}

std::string run_label(const RunResult& r) {
  std::ostringstream a, f;
  a << r.amplitude_g, f << r.frequency_Hz;  // as {:g}
  return a.str() + " g along " + r.direction + " at " + r.orientation + " (" + f.str() + " Hz)";
}

Agreement agreement(const std::vector<RunResult>& runs) {
  Agreement a;
  std::vector<double> rel;
  double ss = 0;
  for (const RunResult& r : runs) {
    const double z = std::abs(r.z());
    ++a.n;
    if (z <= 2) ++a.within_2;
    if (z <= 3) ++a.within_3;
    if (z >= a.max_abs_z) a.max_abs_z = z, a.worst = run_label(r);
    ss += r.residual_g() * r.residual_g();
    a.max_abs_residual_g = std::max(a.max_abs_residual_g, std::abs(r.residual_g()));
    if (std::abs(r.predicted.value_g) > 3 * r.predicted.sigma_g && r.predicted.value_g != 0)
      rel.push_back(std::abs(r.residual_g() / r.predicted.value_g));
  }
  a.rms_residual_g = runs.empty() ? 0 : std::sqrt(ss / static_cast<double>(runs.size()));
  if (!rel.empty()) {
    std::sort(rel.begin(), rel.end());
    a.median_relative = rel[rel.size() / 2];
  }
  return a;
}

namespace {

AmplitudeAnalysis analyse_amplitude(const std::vector<RunResult>& runs, const ReproduceSettings& s) {
  AmplitudeAnalysis a;
  a.max_amplitude_g = *std::max_element(s.amplitudes_g.begin(), s.amplitudes_g.end());
  a.all = agreement(runs);
  std::vector<RunResult> nonzero;  // by symmetry, e.g. along PA or OA with k_PP = k_OO = 0, some are zero
  for (std::size_t i = 0; i < runs.size(); ++i) {
    const RunResult& r = runs[i];
    const double d = r.measured_g - r.printed_g;
    if (std::abs(d) > 3 * r.combined_sigma_g()) {
      ++a.printed_off_runs;
      if (std::abs(d) > std::abs(a.printed_worst_g)) a.printed_worst_g = d;
      const std::string where = r.orientation + " along " + r.direction;
      if (std::find(a.printed_off_where.begin(), a.printed_off_where.end(), where) == a.printed_off_where.end())
        a.printed_off_where.push_back(where);
    }
    if (std::abs(r.printed_g - r.predicted.value_g) > a.printed_gap_g)
      a.printed_gap_g = std::abs(r.printed_g - r.predicted.value_g), a.printed_gap_where = run_label(r),
      a.printed_gap_sigma_g = r.combined_sigma_g();
    if (r.predicted.value_g != 0) nonzero.push_back(r);
    if (r.predicted.sigma_g > r.sigma_measured_g) ++a.prediction_dominates;
    if (r.predicted.value_g != 0)
      a.frequency_departure_g = std::max(a.frequency_departure_g, std::abs(r.at_frequency.value_g - r.predicted.value_g));
    if (r.amplitude_g == a.max_amplitude_g && r.direction == s.directions.front().name && r.predicted.value_g != 0)
      a.growth_runs.push_back(i);
  }
  a.nonzero = agreement(nonzero);
  return a;
}

// Eq. (3) from the identified coefficients over amplitude, per orientation and direction.
std::vector<CurvePoint> amplitude_curves(const ReproduceResult& res, const ReproduceSettings& s) {
  constexpr int kCurvePoints = 61;
  const double a_max = res.amplitude.max_amplitude_g;
  std::vector<CurvePoint> curves;
  for (const auto& ori : s.orientations)
    for (const auto& d : s.directions)
      for (int k = 0; k < kCurvePoints; ++k) {
        CurvePoint p;
        p.orientation = ori.name, p.direction = d.name;
        p.amplitude_g = a_max * k / (kCurvePoints - 1);
        const vibration::SineVibration v{p.amplitude_g * d.v.normalized(), Vec3::Zero(), s.frequency_Hz};
        const Model qs = [&](const Coefficients& c) { return rectification::sine_rectification(c, ori.v, v).total_g(); };
        p.predicted = predict_with_uncertainty(qs, res.identified, res.identified_uncertainty.covariance);
        p.printed_g = rectification::sine_rectification_as_printed(res.identified, ori.v, v);
        curves.push_back(p);
      }
  return curves;
}

// The departure in frequency: the change from the reference run (the study's frequency, or
// the lowest), measured (sigma: the two runs') against the change the frequency-dependent
// eq. (3) predicts (with its own sigma: the coefficient errors do not cancel in it, the terms
// scale differently with frequency).
DepartureAnalysis analyse_departure(const ReproduceResult& res, const ReproduceSettings& s) {
  DepartureAnalysis a;
  const auto& runs = res.frequency_runs;
  if (runs.empty()) return a;
  const auto& cov = res.identified_uncertainty.covariance;
  for (std::size_t i = 0; i < runs.size(); ++i)  // sorted: the lowest unless the study's is there
    if (runs[i].frequency_Hz == s.frequency_Hz) a.reference = i;
  const RunResult& ref = runs[a.reference];
  a.reference_Hz = ref.frequency_Hz;
  for (std::size_t i = 0; i < runs.size(); ++i) {
    const RunResult& r = runs[i];
    const bool is_ref = i == a.reference;
    FrequencyChange c;
    c.measured_g = r.measured_g - ref.measured_g;
    c.sigma_measured_g = is_ref ? 0.0 : std::hypot(r.sigma_measured_g, ref.sigma_measured_g);
    c.predicted = is_ref ? Prediction{} : predicted_change(r, ref, res.nominal, cov);
    c.true_g = r.true_at_frequency_g - ref.true_at_frequency_g;
    const double sz = std::hypot(c.sigma_measured_g, c.predicted.sigma_g);
    c.z = sz > 0 ? (c.measured_g - c.predicted.value_g) / sz : 0.0;
    if (c.sigma_measured_g > 0 && std::abs(c.measured_g) > 3 * c.sigma_measured_g) a.departs_Hz.push_back(r.frequency_Hz);
    if (std::abs(c.z) >= a.worst_z_change) a.worst_z_change = std::abs(c.z), a.worst_z_change_Hz = r.frequency_Hz;
    if (c.sigma_measured_g > 0) a.worst_z_true = std::max(a.worst_z_true, std::abs(c.measured_g - c.true_g) / c.sigma_measured_g);
    a.changes.push_back(c);
  }
  const auto& f = s.departure_frequencies_Hz;
  const double lo = *std::min_element(f.begin(), f.end()) / 1.5, hi = *std::max_element(f.begin(), f.end()) * 1.5;
  for (int k = 0; k < 80; ++k) {
    RunResult r = runs.front();
    r.frequency_Hz = lo * std::pow(hi / lo, k / 79.0);
    predict_run(r, res.nominal, cov);
    a.curve.push_back(r);
  }
  return a;
}

using Covariance = std::array<CoefArray, plant::kNumCoefficients>;

// 1. The static test on the plant, settled in each position; the coefficients least squares
// identifies, their uncertainty, and the simulation a lab would build from them.
void identify_statically(const plant::PlantConfig& truth_plant, const ReproduceSettings& s, ReproduceResult& out) {
  StaticTestSettings st;
  st.fixed = s.fixed;
  st.seed = s.seed;
  const OutputSource settled = [&truth_plant](const Vec3& a) {
    return truth_plant.coefficients[plant::K1] * plant::settled_output_g(truth_plant, a);
  };
  out.static_test = run_static_test(truth_plant.coefficients, s.positions, s.errors, st, settled);
  const MethodResult& ls = out.static_test.methods.back();  // least squares is always last
  out.identified = ls.estimate.value;
  out.identified_uncertainty = ls.first_order;
  // The simulation a lab would build: identified coefficients, nominal dynamics, no effects.
  out.nominal = truth_plant;
  out.nominal.coefficients = out.identified;
  out.nominal.effects.clear();
}

// The confirmation record's running integral (rectangle rule at the sampling step), its fit
// over the measuring time (offset, slope and 3 harmonics) and the integral without the swing.
void fit_running_integral(ConfirmationRecord& c, double frequency_Hz) {
  const std::size_t n = c.t_s.size();
  c.integral_g_s.assign(n, 0.0);
  for (std::size_t i = 1; i < n; ++i)
    c.integral_g_s[i] = c.integral_g_s[i - 1] + (c.output[i] / c.K1 - c.rest_mean_g) * (c.t_s[i] - c.t_s[i - 1]);
  constexpr int kHarmonics = 3;
  const double w = 2 * std::numbers::pi * frequency_Hz;
  auto row = [&](double t) {
    Eigen::RowVectorXd r(2 + 2 * kHarmonics);
    r(0) = 1, r(1) = t;
    for (int h = 1; h <= kHarmonics; ++h) r(2 * h) = std::cos(h * w * t), r(2 * h + 1) = std::sin(h * w * t);
    return r;
  };
  std::vector<std::size_t> fit;
  for (std::size_t i = 0; i < n; ++i)
    if (c.t_s[i] >= c.t_measure_start_s) fit.push_back(i);
  c.integral_without_oscillation_g_s = c.integral_g_s;
  if (fit.size() > 4 * (2 + 2 * kHarmonics)) {
    Eigen::MatrixXd A(static_cast<Eigen::Index>(fit.size()), 2 + 2 * kHarmonics);
    Eigen::VectorXd y(A.rows());
    for (Eigen::Index k = 0; k < A.rows(); ++k) {
      A.row(k) = row(c.t_s[fit[static_cast<std::size_t>(k)]]);
      y(k) = c.integral_g_s[fit[static_cast<std::size_t>(k)]];
    }
    const Eigen::VectorXd beta = A.colPivHouseholderQr().solve(y);
    c.integral_slope_g = beta(1);
    c.oscillation_amplitude_g_s = std::hypot(beta(2), beta(3));
    // Taken off from t = 0 on, as p(t) - p(0): the swing starts with the vibration.
    const auto p = [&](double t) { return row(t).segment(2, 2 * kHarmonics).dot(beta.segment(2, 2 * kHarmonics)); };
    const double p0 = p(0.0);
    for (std::size_t i = 0; i < n; ++i)
      if (c.t_s[i] >= 0) c.integral_without_oscillation_g_s[i] -= p(c.t_s[i]) - p0;
  }
}

// 2. The confirmation run: the sampled record kept for the figure, its rest level and running
// integral, and eq. (3)'s prediction for it from the identified coefficients.
void confirmation_run(const plant::PlantConfig& truth_plant, const ReproduceSettings& s, const plant::PlantConfig& nominal,
                      const Covariance& cov, ConfirmationRecord& c) {
  rectification::ShakeSettings cs = s.shake;
  cs.min_measure_s = s.confirmation.record_s;
  c.K1 = truth_plant.coefficients[plant::K1];
  const vibration::SineVibration v =
      sine_of(s.confirmation.direction.v.normalized(), s.confirmation.amplitude_g, s.frequency_Hz);
  c.shake = rectification::shake_sine(truth_plant, s.confirmation.orientation.v, v, cs,
                                      [&c](double t, const Vec3&, double u) {
                                        c.t_s.push_back(t);
                                        c.output.push_back(u);
                                      });
  double rest = 0;
  long n_rest = 0;
  for (std::size_t i = 0; i < c.t_s.size() && c.t_s[i] < 0; ++i, ++n_rest) rest += c.output[i] / c.K1;
  c.rest_mean_g = n_rest > 0 ? rest / static_cast<double>(n_rest) : c.shake.baseline_g;
  c.t_measure_start_s = c.shake.settle_s;
  c.t_end_s = c.t_s.empty() ? 0.0 : c.t_s.back();
  fit_running_integral(c, s.frequency_Hz);
  RunResult r;
  r.orientation_g = s.confirmation.orientation.v, r.direction_unit = s.confirmation.direction.v.normalized();
  r.amplitude_g = s.confirmation.amplitude_g, r.frequency_Hz = s.frequency_Hz;
  predict_run(r, nominal, cov);
  c.predicted = r.predicted;
}

// The shake settings of section k: each section draws its readout noise from its own seed
// range (run i of section k: seed + k * 1000003 + i), so no two runs share a noise record.
rectification::ShakeSettings section_shake(const ReproduceSettings& s, int k) {
  rectification::ShakeSettings x = s.shake;
  x.readout.seed = s.shake.readout.seed + static_cast<std::uint64_t>(k) * 1000003u;
  return x;
}

// c fitted from the second instrument's runs (each predicted from the identified coefficients
// on the way): generalised least squares for c in residual = -c |w|^2 / 2; the runs share the
// prediction's coefficient errors, so V = diag(sigma_m^2) + G Sigma G^T.
void fit_invisible_shift(InvisibleResult& inv, const plant::PlantConfig& nominal, const Coefficients& identified,
                         const Covariance& cov) {
  const int n = static_cast<int>(inv.runs.size());
  Eigen::MatrixXd G(n, plant::kNumCoefficients), S(plant::kNumCoefficients, plant::kNumCoefficients);
  Eigen::VectorXd x(n), res(n), sm2(n);
  for (int i = 0; i < plant::kNumCoefficients; ++i)
    for (int j = 0; j < plant::kNumCoefficients; ++j) S(i, j) = cov[i][j];
  for (int k = 0; k < n; ++k) {
    RunResult& r = inv.runs[static_cast<std::size_t>(k)];
    predict_run(r, nominal, cov);
    const vibration::SineVibration v = sine_of(r.direction_unit, r.amplitude_g, r.frequency_Hz);
    const CoefArray g = rectification::prediction_gradient(
        [&](const Coefficients& c) { return rectification::sine_rectification(c, r.orientation_g, v).total_g(); },
        identified);
    for (int i = 0; i < plant::kNumCoefficients; ++i) G(k, i) = g[i];
    x(k) = -r.amplitude_g * r.amplitude_g / 2;
    res(k) = r.residual_g();
    sm2(k) = r.sigma_measured_g * r.sigma_measured_g;
  }
  const Eigen::MatrixXd V = Eigen::MatrixXd(sm2.asDiagonal()) + G * S * G.transpose();
  const Eigen::LDLT<Eigen::MatrixXd> ldlt(V);
  const double info = x.dot(ldlt.solve(x));
  inv.c_fit_per_g = x.dot(ldlt.solve(res)) / info;
  inv.c_fit_sigma_per_g = 1 / std::sqrt(info);
}

// 5. The instrument no static test can tell from the first (k0 up by c; k2, k_PP and k_OO
// down by c): how far apart their static readings are, its shaker runs along IA, PA and OA,
// and c fitted from them.
void invisible_shift(const plant::PlantConfig& truth_plant, const ReproduceSettings& s, const ReproduceResult& out,
                     const Covariance& cov, int threads, std::ostream* progress,
                     const std::function<void(const std::string&)>& say, InvisibleResult& inv) {
  inv.c_per_g = s.invisible_shift_per_g;
  plant::PlantConfig other = truth_plant;
  other.coefficients[plant::k0] += inv.c_per_g;
  for (int i : {plant::k2, plant::k_PP, plant::k_OO}) other.coefficients[i] -= inv.c_per_g;
  for (const Position& p : s.positions)
    inv.max_static_difference_g =
        std::max(inv.max_static_difference_g,
                 std::abs(plant::settled_output_g(other, p.nominal_g) - plant::settled_output_g(truth_plant, p.nominal_g)));
  const std::vector<NamedVector> axes = {{"IA", Vec3(1, 0, 0)}, {"PA", Vec3(0, 1, 0)}, {"OA", Vec3(0, 0, 1)}};
  say("invisible shift: 3 x " + std::to_string(s.amplitudes_g.size()) + " shaker runs on the second instrument");
  const rectification::SweepGrid ig = grid_of({s.frequency_Hz}, s.amplitudes_g, axes, {s.confirmation.orientation});
  inv.runs = shake_grid(other, section_shake(s, 3), ig, axes, {s.confirmation.orientation}, threads, progress,
                        "invisible shift");
  fit_invisible_shift(inv, out.nominal, out.identified, cov);
}

}  // namespace

ReproduceResult reproduce(const plant::PlantConfig& truth_plant, const ReproduceSettings& s,
                          const std::function<void(const std::string&)>& log, std::ostream* progress) {
  const std::function<void(const std::string&)> say = [&](const std::string& m) {
    if (log) log(m);
  };
  std::string why;
  if (!s.IsValid(&why)) throw std::invalid_argument("reproduce: " + why);
  const int threads = core::thread_count(s.threads);
  ReproduceResult out;
  out.truth = truth_plant.coefficients;

  // 1. The static test on the plant, settled in each position.
  say("static test: the plant settled in each position of the dividing head");
  identify_statically(truth_plant, s, out);
  const Covariance& cov = out.static_test.methods.back().first_order.covariance;  // least squares'
  const plant::PlantConfig& nominal = out.nominal;

  // 2. The confirmation run: the sampled record kept for the figure.
  say("confirmation run");
  confirmation_run(truth_plant, s, nominal, cov, out.confirmation);

  // 3. The amplitude study.
  const rectification::SweepGrid grid = grid_of({s.frequency_Hz}, s.amplitudes_g, s.directions, s.orientations);
  say("amplitude study: " + std::to_string(grid.size()) + " shaker runs");
  out.amplitude_runs =
      shake_grid(truth_plant, section_shake(s, 1), grid, s.directions, s.orientations, threads, progress, "amplitude study");
  for (RunResult& r : out.amplitude_runs) predict_run(r, nominal, cov);

  // 4. The departure in frequency.
  if (!s.departure_frequencies_Hz.empty()) {
    say("frequency departure: " + std::to_string(s.departure_frequencies_Hz.size()) + " shaker runs");
    const rectification::SweepGrid fg = grid_of(s.departure_frequencies_Hz, {s.confirmation.amplitude_g},
                                                {s.confirmation.direction}, {s.confirmation.orientation});
    out.frequency_runs =
        shake_grid(truth_plant, section_shake(s, 2), fg, {s.confirmation.direction}, {s.confirmation.orientation},
                   threads, progress, "frequency departure");
    std::sort(out.frequency_runs.begin(), out.frequency_runs.end(),
              [](const RunResult& a, const RunResult& b) { return a.frequency_Hz < b.frequency_Hz; });
    for (RunResult& r : out.frequency_runs) predict_run(r, nominal, cov);
  }

  // 5. The instrument no static test can tell from the first.
  if (s.invisible_shift_per_g != 0) invisible_shift(truth_plant, s, out, cov, threads, progress, say, out.invisible);
  out.amplitude = analyse_amplitude(out.amplitude_runs, s);
  out.amplitude_curves = amplitude_curves(out, s);
  out.departure = analyse_departure(out, s);
  return out;
}

}  // namespace vrelab::validation
