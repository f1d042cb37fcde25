#include "rectification/simulation/shake.hpp"

#include "core/cancel.hpp"
#include "rectification/simulation/discretised.hpp"
#include "vibration/sampled.hpp"

#include <algorithm>
#include <cmath>
#include <complex>
#include <limits>
#include <numbers>
#include <optional>
#include <random>
#include <sstream>
#include <stdexcept>

#include <Eigen/Dense>
#include <unsupported/Eigen/MatrixFunctions>

namespace vrelab::rectification {
namespace {
using plant::Accelerometer;

// The plant and, beside it, its own linearisation driven by the same input: z' = A z + B a.
// The companion's quadrature state integrates the linear output, so Q - z_Q integrates what
// the linear dynamics do not explain: the rectification, without the edge effects of a
// finite window on a random record (the loop's delay times the input's change across the
// window, ~25 mg per 0.25 s block at 14 g rms).
class WithLinearCompanion final : public plant::OdeSystem {
 public:
  WithLinearCompanion(const Accelerometer& p, Accelerometer::Linear lin, std::function<Vec3(double)> in)
      : plant_(p), lin_(std::move(lin)), input_(std::move(in)), n_(p.size()) {}
  int size() const override { return 2 * n_; }
  void rhs(double t, const double* x, double* dx) const override {
    plant_.rhs(t, x, dx);
    const Eigen::Map<const Eigen::VectorXd> z(x + n_, n_);
    Eigen::Map<Eigen::VectorXd> dz(dx + n_, n_);
    dz.noalias() = lin_.A * z + lin_.B * input_(t);
  }
  // [[J_plant, 0], [0, A]]: the companion does not depend on the plant's state.
  bool has_jacobian() const override { return plant_.has_jacobian(); }
  void jacobian(double t, const double* x, double* j) const override {
    Eigen::Map<Eigen::MatrixXd> m(j, 2 * n_, 2 * n_);
    Eigen::MatrixXd jp(n_, n_);
    plant_.jacobian(t, x, jp.data());
    m.setZero();
    m.topLeftCorner(n_, n_) = jp;
    m.bottomRightCorner(n_, n_) = lin_.A;
  }
  // The companion's linear output deviation (U/K1 - baseline) at state x.
  double linear_output(double t, const double* x) const {
    const Eigen::Map<const Eigen::VectorXd> z(x + n_, n_);
    return lin_.A.row(Accelerometer::kQuadrature).dot(z) + lin_.B.row(Accelerometer::kQuadrature).dot(input_(t));
  }

 private:
  const Accelerometer& plant_;
  Accelerometer::Linear lin_;
  std::function<Vec3(double)> input_;
  int n_;
};

// The companion's linear output per g of a constant input (its DC gain, a row over the input's
// axes): the steady state of the linearisation without the quadrature state, which feeds
// nothing back (its column of A is zero), and without the states the plant does not use
// (their rows and columns zero: an anti-aliasing filter left off), read through the
// quadrature's row.
Vec3 companion_dc_gain(const Accelerometer::Linear& lin) {
  std::vector<int> rest;
  for (int i = 0; i < static_cast<int>(lin.A.rows()); ++i)
    if (i != Accelerometer::kQuadrature && !(lin.A.row(i).isZero(0.0) && lin.A.col(i).isZero(0.0))) rest.push_back(i);
  const Eigen::MatrixXd steady = -lin.A(rest, rest).partialPivLu().solve(lin.B(rest, Eigen::all));
  return (lin.A(Accelerometer::kQuadrature, rest) * steady + lin.B.row(Accelerometer::kQuadrature)).transpose();
}

// Standard uncertainty of the mean of equal blocks: std(block means) / sqrt(blocks).
double batch_sigma(const std::vector<double>& means, double mean) {
  double ss = 0;
  for (double b : means) ss += (b - mean) * (b - mean);
  const double k = static_cast<double>(means.size());
  return std::sqrt(ss / (k - 1) / k);
}

// The data acquisition of a run (Readout): the record at rest first (t < 0, the equilibrium
// output), then the vibration record; noise and quantisation on every sample; block sums
// for the batch means and least-squares sums of the running integral for the paper's slope.
class SampledRecorder {
 public:
  // rest_closed_form: without noise and without a sink every sample at rest is the same
  // number, and each block's sum is taken as block_n times it (the running sum of block_n
  // equal terms differs from it by rounding only, ~block_n ulp of the baseline; the sine
  // paths keep the running sum).
  SampledRecorder(const Readout& ro, double k1, double baseline_g, int blocks, long block_n, double dt,
                  const SampleSink& sink, bool rest_closed_form = false)
      : ro_(ro), k1_(k1), baseline_(baseline_g), block_n_(block_n), dt_(dt), sink_(sink), rng_(ro.seed),
        rest_(static_cast<std::size_t>(blocks), 0.0), vib_(rest_) {
    const long rest_n = blocks * block_n;
    if (rest_closed_form && !sink_ && !(ro_.noise_sigma_g > 0)) {
      // The exponential-integrator path: without noise, quantisation or a sink, a sample is
      // taken as the output itself, not K1 (out) / K1, which differs from it by an ulp at most
      // (~1e-16 g at 1 g, the same for the record at rest; the mean moves by < 1e-15 g).
      exact_ = !(ro_.quantisation_lsb_g > 0);
      const double u = exact_ ? k1_ * baseline_g : acquire(baseline_g);
      for (double& r : rest_) r = static_cast<double>(block_n) * (exact_ ? baseline_g : u / k1);
      samples_ = rest_n;
      return;
    }
    long m = 0;
    for (std::size_t b = 0; b < rest_.size(); ++b)
      for (long i = 0; i < block_n; ++i, ++m) {
        if (m % 65536 == 0) core::throw_if_cancelled();  // a long record at rest (Ctrl-C from Python)
        const double u = acquire(baseline_g);
        rest_[b] += u / k1;
        if (sink_) sink_(static_cast<double>(m - rest_n) * dt, Vec3::Zero(), u);
      }
    samples_ = rest_n;
  }
  // One sample of the vibration record at t; `measured_index` >= 0 counts the samples of the
  // measuring interval (negative while settling); `linear_g` is taken off (the companion).
  void sample(double t, const Vec3& input_g, double out_g, long measured_index, double linear_g = 0.0) {
    ++samples_;
    if (exact_) {  // no noise, no quantisation, no sink: u / K1 is out_g (to an ulp; see exact_)
      if (measured_index < 0) return;
      accumulate(out_g - linear_g, measured_index);
      return;
    }
    const double u = acquire(out_g);
    if (sink_) sink_(t, input_g, u);
    if (measured_index < 0) return;
    accumulate(u / k1_ - linear_g, measured_index);
  }
  void accumulate(double x, long measured_index) {
    // The block of measured_index: counted along (the samples come in order), no division.
    if (measured_index != next_index_) {
      block_ = measured_index / block_n_;
      in_block_ = measured_index % block_n_;
    }
    vib_[static_cast<std::size_t>(block_)] += x;
    next_index_ = measured_index + 1;
    if (++in_block_ == block_n_) in_block_ = 0, ++block_;
    integral_ += (x - baseline_) * dt_;
    const double tm = static_cast<double>(measured_index + 1) * dt_;
    st_ += tm, stt_ += tm * tm, si_ += integral_, sti_ += tm * integral_;
    ++n_fit_;
  }
  void finish(ShakeResult& r) const {
    std::vector<double> vib_mean, rest_mean;
    double vib_total = 0, rest_total = 0;
    const double blocks = static_cast<double>(vib_.size());
    for (std::size_t b = 0; b < vib_.size(); ++b) {
      vib_mean.push_back(vib_[b] / static_cast<double>(block_n_));
      rest_mean.push_back(rest_[b] / static_cast<double>(block_n_));
      vib_total += vib_mean.back() / blocks;
      rest_total += rest_mean.back() / blocks;
    }
    r.measured_g = vib_total - rest_total;
    const double n = static_cast<double>(n_fit_);
    r.integral_slope_g = (n * sti_ - st_ * si_) / (n * stt_ - st_ * st_) - (rest_total - baseline_);
    const double sv = batch_sigma(vib_mean, vib_total), sr = batch_sigma(rest_mean, rest_total);
    r.sigma_g = std::sqrt(sv * sv + sr * sr);
    r.samples = samples_;
  }

 private:
  double acquire(double out_g) {
    double u = k1_ * (out_g + (ro_.noise_sigma_g > 0 ? ro_.noise_sigma_g * normal_(rng_) : 0.0));
    if (ro_.quantisation_lsb_g > 0) u = k1_ * ro_.quantisation_lsb_g * std::round(u / (k1_ * ro_.quantisation_lsb_g));
    return u;
  }
  const Readout& ro_;
  double k1_, baseline_;
  long block_n_;
  double dt_;
  const SampleSink& sink_;
  std::mt19937_64 rng_;
  std::normal_distribution<double> normal_{0.0, 1.0};
  std::vector<double> rest_, vib_;
  double integral_ = 0, st_ = 0, stt_ = 0, si_ = 0, sti_ = 0;
  long n_fit_ = 0, samples_ = 0;
  long next_index_ = 0, block_ = 0, in_block_ = 0;  // the next measured sample expected, its block
  bool exact_ = false;
};


// The plant written as the deviation y = x - x_lin(t) from the linear periodic solution
// x_lin(t) = x_eq + Im(X e^{jwt}) of the commanded sine: y' = f(t, x_lin + y) - x_lin'(t),
// exact for any X (x_lin' is differentiated analytically). The linear response, 10^4-10^5
// times the rectifying part, is then not integrated at all: the same absolute tolerances
// allow far longer steps. x_lin's quadrature is periodic, so over whole periods
// Q(t2) - Q(t1) = y_Q(t2) - y_Q(t1).
class DeviationFromLinear final : public plant::OdeSystem {
 public:
  DeviationFromLinear(const Accelerometer& p, const std::vector<double>& x_eq, const Eigen::VectorXcd& phasor, double w)
      : plant_(p), x_eq_(x_eq), phasor_(phasor), w_(w), x_(x_eq.size()) {}
  int size() const override { return plant_.size(); }
  void rhs(double t, const double* y, double* dy) const override {
    const double sn = std::sin(w_ * t), cs = std::cos(w_ * t);
    for (std::size_t k = 0; k < x_.size(); ++k) x_[k] = linear(k, sn, cs) + y[k];
    plant_.rhs(t, x_.data(), dy);
    for (std::size_t k = 0; k < x_.size(); ++k) {
      const std::complex<double> p = phasor_[static_cast<Eigen::Index>(k)];
      dy[k] -= w_ * (p.real() * cs - p.imag() * sn);
    }
  }
  // The linearisation's A: the loop is linear but for small terms, so it serves CVODE's
  // Newton iteration as the Jacobian (a difference quotient on the deviation, 1e-5 of the
  // state it is added to, would lose its digits to rounding).
  bool has_jacobian() const override { return jacobian_ != nullptr; }
  void jacobian(double, const double*, double* j) const override {
    Eigen::Map<Eigen::MatrixXd>(j, jacobian_->rows(), jacobian_->cols()) = *jacobian_;
  }
  void use_jacobian(const Eigen::MatrixXd* a) { jacobian_ = a; }
  double output_g(double t, const double* y) const {
    const double sn = std::sin(w_ * t), cs = std::cos(w_ * t);
    for (std::size_t k = 0; k < x_.size(); ++k) x_[k] = linear(k, sn, cs) + y[k];
    return plant_.output_g(t, x_.data());
  }

 private:
  double linear(std::size_t k, double sn, double cs) const {
    const std::complex<double> p = phasor_[static_cast<Eigen::Index>(k)];
    return x_eq_[k] + p.real() * sn + p.imag() * cs;
  }
  const Accelerometer& plant_;
  const std::vector<double>& x_eq_;
  const Eigen::VectorXcd& phasor_;
  double w_;
  const Eigen::MatrixXd* jacobian_ = nullptr;
  mutable std::vector<double> x_;  // scratch (one run per object, one thread)
};

// One period of the deviation system from (t0, y0): the end state, the quadrature's
// increment and, when sample times are given, the output at each.
struct PeriodPass {
  std::vector<double> y_start, y_end;
  double dq = 0;
  std::vector<double> outputs;
};

}  // namespace

namespace {

// What a sine run's two paths share: the drive, the plant at rest (equilibrium, linearisation,
// the linear periodic solution's phasor), the solver's settings and the run's timing (settling
// and measured periods, sampling).
struct SinePlan {
  const ShakeSettings* s = nullptr;
  double frequency_Hz = 0, w = 0, period = 0;
  std::vector<double> x_eq;
  Accelerometer::Linear lin;
  int n = 0;
  Eigen::VectorXcd phasor;  // X = (jwI - A)^-1 B W of the linear periodic steady state
  plant::SolverSettings solver;
  double amplitude = 0;  // the largest axis' amplitude, g (1e-12 at least)
  int settle_periods = 0, per_block = 0;
  double k1 = 0;
  bool sampled = false;
  long per_period = 0;   // samples per period (sampled only)
  double floor = 0;      // the floor of sigma: the quadrature's own tolerance over the measured span, g
};

// The plant at rest, the linear steady state, the tolerances and the timing of a sine run;
// r's baseline, slowest time constant, settling, periods and sample rate are set.
SinePlan plan_sine(const plant::PlantConfig& config, const vibration::SineVibration& v,
                   const ShakeSettings& s, const SampleSink& sink, const Accelerometer& rest, ShakeResult& r) {
  SinePlan p;
  p.s = &s;
  p.frequency_Hz = v.frequency_Hz;
  p.w = 2 * std::numbers::pi * v.frequency_Hz;
  p.period = 1 / v.frequency_Hz;
  const double period = p.period;

  // The plant at rest: baseline, equilibrium, linearisation.
  p.x_eq = rest.equilibrium();
  r.baseline_g = rest.output_g(0, p.x_eq.data());
  p.lin = rest.linearise();
  p.n = rest.size();
  const int n = p.n;

  r.slowest_time_constant_s = rest.slowest_time_constant_s(p.lin);

  // Linear periodic steady state: x = x_eq + Im(X e^{jwt}), X = (jwI - A)^-1 B W.
  Eigen::Vector3cd wc;
  for (int i = 0; i < 3; ++i) wc[i] = v.amplitude_g[i] * std::exp(std::complex<double>(0, v.phase_rad[i]));
  const Eigen::MatrixXcd resolvent =
      std::complex<double>(0, p.w) * Eigen::MatrixXcd::Identity(n, n) - p.lin.A.cast<std::complex<double>>();
  p.phasor = resolvent.fullPivLu().solve(p.lin.B.cast<std::complex<double>>() * wc);

  p.solver.relative_tolerance = s.relative_tolerance;
  p.solver.analytic_jacobian = s.analytic_jacobian;
  const std::vector<double> scale = rest.state_scale();
  p.amplitude = std::max(v.amplitude_g.cwiseAbs().maxCoeff(), 1e-12);
  for (int k = 0; k < n; ++k) {
    const std::size_t kk = static_cast<std::size_t>(k);
    const double typical = std::max({std::abs(p.phasor[k]), std::abs(p.x_eq[kk]), 1e-6 * p.amplitude * scale[kk]});
    p.solver.absolute_tolerance.push_back(s.relative_tolerance * typical);
  }
  p.solver.max_step_s = period / 8;

  // Settling: whole periods covering ln(1/decay) slowest time constants. Counted in double and
  // refused beyond int (an int would overflow silently for min_measure_s = 1e9).
  const double settle_count = std::ceil(std::log(1 / s.settle_decay) * r.slowest_time_constant_s / period);
  const double block_count = std::max(1.0, std::ceil(s.min_measure_s / (s.blocks * period)));
  constexpr double kMaxPeriods = std::numeric_limits<int>::max() / 2;
  const auto too_many = [&](const char* key, double setting, double count) {
    std::ostringstream m;
    m << key << " = " << setting << ": " << count << " periods of " << v.frequency_Hz << " Hz (slowest time constant "
      << r.slowest_time_constant_s << " s), more than " << kMaxPeriods;
    return std::invalid_argument(m.str());
  };
  if (!(settle_count <= kMaxPeriods)) throw too_many("settle_decay", s.settle_decay, settle_count);
  if (!(block_count * s.blocks <= kMaxPeriods)) throw too_many("min_measure_s", s.min_measure_s, block_count * s.blocks);
  p.settle_periods = static_cast<int>(settle_count);
  r.settle_s = p.settle_periods * period;
  p.per_block = static_cast<int>(block_count);
  r.periods = p.per_block * s.blocks;

  p.k1 = config.coefficients[plant::K1];
  const Readout& ro = s.readout;
  p.sampled = ro.active() || static_cast<bool>(sink);
  if (p.sampled) {
    const double wanted = ro.active() ? ro.sample_rate_Hz : 50 * v.frequency_Hz;
    p.per_period = std::max<long>(2, static_cast<long>(std::ceil(wanted / v.frequency_Hz - 1e-9)));
    // Synchronous sampling folds the output's N-th harmonic (N samples per period) exactly
    // onto DC: demand 10 samples per period (harmonics of (1) reach the 4th, k1' more)
    // unless the anti-alias filter is on.
    if (p.per_period < 10 && !(config.dynamics.antialias_Hz > 0))
      throw std::invalid_argument("sample_rate_Hz: " + std::to_string(p.per_period) +
                                  " samples per period alias the output's harmonics onto DC; use at least 10 per "
                                  "period (" + std::to_string(10 * v.frequency_Hz) + " Hz) or an anti-alias filter");
    r.sample_rate_Hz = p.per_period * v.frequency_Hz;
  }
  p.floor = s.relative_tolerance * std::abs(p.phasor[Accelerometer::kQuadrature]) / (r.periods * period);
  return p;
}

// The periodic steady state directly (docs/performance.md): the deviation from the linear
// periodic solution, either settled for ln(1/decay) time constants when that is shorter than
// a period, or found by shooting (Newton on the one-period map, its Jacobian the
// linearisation's monodromy e^{AT}); then one period measured stands for all of them.
// True with r complete; false when the shooting did not converge (r counts the attempt).
template <class Motion>
bool periodic_path(const SinePlan& p, const Accelerometer& shaken, const Motion& table_motion, const SampleSink& sink,
                   ShakeResult& r) {
  const ShakeSettings& s = *p.s;
  const double period = p.period;
  const int n = p.n;
  const Accelerometer::Linear& lin = p.lin;
  DeviationFromLinear dev(shaken, p.x_eq, p.phasor, p.w);
  dev.use_jacobian(&lin.A);
  const double dt = p.sampled ? 1 / r.sample_rate_Hz : 0.0;
  long steps = 0, rhs_evaluations = 0;
  double simulated = 0;
  // From (t0, y0) to t_measure, then one period, sampled at t_measure + m dt if wanted.
  // Tolerances: 1/100 of the transient path's absolute ones. The deviation is 1e-4..1e-5
  // of the state, so this is still a loose relative tolerance on it (cheap), and it puts
  // the answer's own error near 1e-11 g, below the transient path's (~5e-10 g at 5 g).
  plant::SolverSettings dev_solver = p.solver;
  dev_solver.analytic_jacobian = true;  // the linearisation's A below (not the plant's Jacobian)
  for (double& a : dev_solver.absolute_tolerance) a *= 0.01;
  auto pass = [&](double t0, const std::vector<double>& y0, double t_measure) {
    plant::OdeSolver ode(dev, t0, y0, dev_solver);
    PeriodPass pp;
    pp.y_start = ode.advance(t_measure);
    const double q0 = pp.y_start[Accelerometer::kQuadrature];
    for (long m = 0; m < p.per_period; ++m) {
      const double t = t_measure + static_cast<double>(m) * dt;
      pp.outputs.push_back(dev.output_g(t, ode.advance(t).data()));
    }
    pp.y_end = ode.advance(t_measure + period);
    pp.dq = pp.y_end[Accelerometer::kQuadrature] - q0;
    steps += ode.steps();
    rhs_evaluations += ode.rhs_evaluations();
    simulated += t_measure + period - t0;
    return pp;
  };
  std::optional<PeriodPass> measured;
  double measured_t0 = 0, correction_g = 0, residual_g = 0;
  const double raw_settle_s = std::log(1 / s.settle_decay) * r.slowest_time_constant_s;
  // The states that feed back: not the quadrature (nothing depends on it) nor the inert
  // states (zero row and column of A).
  std::vector<int> act;
  for (int k = 0; k < n; ++k) {
    const bool inert = lin.A.row(k).cwiseAbs().maxCoeff() == 0 && lin.A.col(k).cwiseAbs().maxCoeff() == 0;
    if (k != Accelerometer::kQuadrature && !inert) act.push_back(k);
  }
  const Eigen::Index m = static_cast<Eigen::Index>(act.size());
  Eigen::MatrixXd a_act(m, m);
  Eigen::RowVectorXd c_q(m);
  for (Eigen::Index i = 0; i < m; ++i) {
    c_q[i] = lin.A(Accelerometer::kQuadrature, act[static_cast<std::size_t>(i)]);
    for (Eigen::Index j = 0; j < m; ++j) a_act(i, j) = lin.A(act[static_cast<std::size_t>(i)], act[static_cast<std::size_t>(j)]);
  }
  // A start off the orbit by d gives the residual r = (M - I) d after a period (M = e^{AT},
  // the monodromy) and adds C A^-1 (M - I) d = C A^-1 r to Q over that period.
  const Eigen::RowVectorXd q_gain = a_act.transpose().partialPivLu().solve(c_q.transpose()).transpose();
  // The measured mean to 1e-11 of the larger of the output's and the input's amplitude.
  const double q_tolerance =
      0.1 * s.relative_tolerance * std::max(std::abs(p.phasor[Accelerometer::kQuadrature]) / period, p.amplitude);
  Eigen::VectorXd res(m);
  // Is the pass periodic to the tolerance? Sets res and *q_err (the mean's error from the
  // start being off the orbit); returns the largest residual per typical state size and
  // whether the pass is accepted.
  auto periodic = [&](const PeriodPass& pp, double* q_err) {
    double scaled = 0;
    for (Eigen::Index i = 0; i < m; ++i) {
      const std::size_t k = static_cast<std::size_t>(act[static_cast<std::size_t>(i)]);
      res[i] = pp.y_end[k] - pp.y_start[k];
      scaled = std::max(scaled, std::abs(res[i]) / (p.solver.absolute_tolerance[k] / s.relative_tolerance));
    }
    *q_err = q_gain.dot(res) / period;
    return std::pair<double, bool>(scaled, scaled <= 100 * s.relative_tolerance && std::abs(*q_err) <= q_tolerance);
  };
  const std::vector<double> y_zero(static_cast<std::size_t>(n), 0.0);
  try {
    if (raw_settle_s <= period) {
      r.path = "settle + one period";
      measured_t0 = p.sampled ? std::ceil(raw_settle_s / dt) * dt : raw_settle_s;
      PeriodPass pp = pass(0.0, y_zero, measured_t0);
      double q_err = 0;
      if (periodic(pp, &q_err).second) {
        measured = std::move(pp);
        correction_g = -q_err;
        residual_g = std::abs(q_err);
      }
    } else {
      r.path = "shooting";
      const Eigen::MatrixXd monodromy = (a_act * period).exp();
      const Eigen::PartialPivLU<Eigen::MatrixXd> newton((Eigen::MatrixXd::Identity(m, m) - monodromy).eval());
      std::vector<double> y = y_zero;
      double previous = std::numeric_limits<double>::infinity();
      constexpr int kMaxIterations = 8;
      for (int it = 1; it <= kMaxIterations; ++it) {
        PeriodPass pp = pass(0.0, y, 0.0);
        r.shooting_iterations = it;
        double q_err = 0;
        const auto [scaled, done] = periodic(pp, &q_err);
        if (done) {
          measured = std::move(pp);
          correction_g = -q_err;
          residual_g = std::abs(q_err);
          break;
        }
        if (!(scaled < 0.5 * previous)) break;  // not contracting: leave it to the transient path
        previous = scaled;
        const Eigen::VectorXd step = newton.solve(res);
        for (Eigen::Index i = 0; i < m; ++i) y[static_cast<std::size_t>(act[static_cast<std::size_t>(i)])] += step[i];
      }
    }
  } catch (const plant::SolverError&) {
    measured.reset();  // e.g. Newton on the linear Jacobian failing in a far nonlinear loop
  }
  r.steps = steps;
  r.rhs_evaluations = rhs_evaluations;
  r.simulated_s = simulated;
  if (!measured) return false;
  if (!p.sampled) {
    r.method = "continuous integral";
    r.measured_g = measured->dq / period + correction_g;
    r.integral_slope_g = r.measured_g;
    r.sigma_g = std::max(p.floor, residual_g);
  } else {
    // The record as the transient path takes it (same samples, same noise draws), each
    // sample the steady state's output at its phase.
    r.method = "sampled record";
    const long settle_n = p.settle_periods * p.per_period, block_n = p.per_block * p.per_period;
    const long first = std::llround(measured_t0 / dt);
    SampledRecorder rec(s.readout, p.k1, r.baseline_g, s.blocks, block_n, dt, sink);
    const long total_n = settle_n + s.blocks * block_n;
    for (long k = 0; k < total_n; ++k) {
      const double t = static_cast<double>(k) * dt;
      const long phase = ((k - first) % p.per_period + p.per_period) % p.per_period;
      rec.sample(t, table_motion(t), measured->outputs[static_cast<std::size_t>(phase)], k - settle_n);
    }
    rec.finish(r);
  }
  return true;
}

// The transient path: the whole run integrated from the linear steady state's start x0,
// settled, then measured over r.periods periods (continuous integral or sampled record).
template <class Motion>
void transient_path(const SinePlan& p, Accelerometer& shaken, const Motion& table_motion, const std::vector<double>& x0,
                    const SampleSink& sink, ShakeResult& r) {
  const ShakeSettings& s = *p.s;
  const double period = p.period;
  plant::OdeSolver ode(shaken, 0.0, x0, p.solver);
  const double block_s = p.per_block * period;
  if (!p.sampled) {
    // Continuous integral: Q is a state of the ODE.
    r.method = "continuous integral";
    double q_prev = ode.advance(r.settle_s)[Accelerometer::kQuadrature];
    const double q_start = q_prev;
    std::vector<double> block_mean;
    for (int b = 1; b <= s.blocks; ++b) {
      const double q = ode.advance(r.settle_s + b * block_s)[Accelerometer::kQuadrature];
      block_mean.push_back((q - q_prev) / block_s);
      q_prev = q;
    }
    r.measured_g = (q_prev - q_start) / (r.periods * period);
    r.integral_slope_g = r.measured_g;
    r.sigma_g = std::max(batch_sigma(block_mean, r.measured_g), p.floor);
  } else {
    // Sampled record, synchronous with the vibration.
    r.method = "sampled record";
    const double dt = 1 / r.sample_rate_Hz;
    const long settle_n = p.settle_periods * p.per_period, block_n = p.per_block * p.per_period;
    SampledRecorder rec(s.readout, p.k1, r.baseline_g, s.blocks, block_n, dt, sink);
    const long total_n = settle_n + s.blocks * block_n;
    for (long k = 0; k < total_n; ++k) {
      const double t = static_cast<double>(k) * dt;
      rec.sample(t, table_motion(t), shaken.output_g(t, ode.advance(t).data()), k - settle_n);
    }
    rec.finish(r);
  }
  r.steps += ode.steps();
  r.rhs_evaluations += ode.rhs_evaluations();
  r.simulated_s += r.settle_s + r.periods * period;
}

}  // namespace

ShakeResult shake_sine(const plant::PlantConfig& config, const Vec3& a_static, const vibration::SineVibration& v,
                       const ShakeSettings& s, const SampleSink& sink, const vibration::Excitation* input) {
  std::string why;
  if (!s.IsValid(&why)) throw std::invalid_argument(why);
  vibration::validate(v);
  if (!(v.frequency_Hz > 0)) throw std::invalid_argument("frequency_Hz must be positive for a shaker run");
  const double w = 2 * std::numbers::pi * v.frequency_Hz;

  const Accelerometer rest(config, a_static);
  ShakeResult r;
  const SinePlan plan = plan_sine(config, v, s, sink, rest, r);

  auto table_motion = [v, w, input](double t) {
    if (input) return input->acceleration_g(t);
    Vec3 a;
    for (int i = 0; i < 3; ++i) a[i] = v.amplitude_g[i] * std::sin(w * t + v.phase_rad[i]);
    return a;
  };
  Accelerometer shaken(config, a_static, table_motion);
  shaken.set_quadrature_reference(r.baseline_g);

  // The deviation path works at 1/100 of the transient path's absolute tolerances; below a
  // relative tolerance of 1e-13 that asks for less than ~50 ulp of the state, which CVODE
  // cannot deliver (it takes ever smaller steps instead of refusing, as the deviation starts
  // at 0): the transient path runs, and CVODE refuses too much accuracy at its first step.
  if (s.periodic_steady_state && s.relative_tolerance >= 1e-13) {
    if (periodic_path(plan, shaken, table_motion, sink, r)) return r;
    r.path = "transient";  // the shooting did not converge; its attempt is counted in r
  }
  // The transient path starts on the linear periodic solution.
  std::vector<double> x0(plan.x_eq);
  for (int k = 0; k < plan.n; ++k) x0[static_cast<std::size_t>(k)] += plan.phasor[k].imag();
  transient_path(plan, shaken, table_motion, x0, sink, r);
  return r;
}

ShakeResult shake_excitation(const plant::PlantConfig& config, const Vec3& a_static, const vibration::Excitation& input,
                             double measure_s, const ShakeSettings& s, const SampleSink& sink) {
  std::string why;
  if (!s.IsValid(&why)) throw std::invalid_argument(why);
  if (!(measure_s > 0) || !std::isfinite(measure_s)) throw std::invalid_argument("duration_s must be positive");
  const double f_top = input.max_frequency_Hz();
  if (!(f_top > 0)) throw std::invalid_argument("the excitation reports no frequency content");

  const Accelerometer rest(config, a_static);
  const std::vector<double> x_eq = rest.equilibrium();
  ShakeResult r;
  r.baseline_g = rest.output_g(0, x_eq.data());
  Accelerometer::Linear lin = rest.linearise();
  r.slowest_time_constant_s = rest.slowest_time_constant_s(lin);
  r.settle_s = std::log(1 / s.settle_decay) * r.slowest_time_constant_s;
  const int n = rest.size();

  auto table = [&input](double t) { return input.acceleration_g(t); };
  Accelerometer shaken(config, a_static, table);
  shaken.set_quadrature_reference(r.baseline_g);
  const double k1 = config.coefficients[plant::K1];
  const Readout& ro = s.readout;

  // A random excitation: one step per sample (rectification/simulation/discretised.hpp).
  const ShakeResult before = r;  // (what a fallback to CVODE starts from)
  const vibration::RandomExcitation* random = input.random_samples();
  std::string cvode_reason = "not a random excitation";
  if (!s.exponential_integrator) cvode_reason = "exponential_integrator off";
  if (random && s.exponential_integrator) {
    const bool sampled = ro.active() || static_cast<bool>(sink);
    const double rate = ro.active() ? ro.sample_rate_Hz : sampled ? 8 * f_top : random->sample_rate_Hz();
    cvode_reason = DiscretisedRandomPlant::unsupported(config, *random, rate);
    if (cvode_reason.empty()) {
      DiscretisedRandomPlant plant(shaken, lin, x_eq, *random, rate, !sampled);
      r.path = "exponential integrator";
      const double dt = 1 / rate;
      const long settle_n = static_cast<long>(std::ceil(r.settle_s * rate));
      const long block_n = std::max<long>(2, static_cast<long>(std::llround(measure_s * rate / s.blocks)));
      const long total_n = settle_n + s.blocks * block_n;
      long steps_done = total_n;
      if (!sampled) {
        // The blocks of the CVODE path (edges at settle_s + b measure_s / blocks): the residual
        // integral y_Q between grid points by the cubic Hermite through its values and slopes
        // (the slope: output - baseline - linear output), an error ~(w h)^4 / 384 of a step's
        // increment, ~1e-11 g at 4 kHz content on a 16 kHz grid.
        r.method = "continuous integral";
        auto slope = [&] { return plant.output_g() - r.baseline_g - plant.linear_output_g(); };
        double t0 = 0, q0 = plant.residual_quadrature(), d0 = slope();
        auto residual_at = [&](double t) {
          while (plant.time_s() < t) {
            t0 = plant.time_s(), q0 = plant.residual_quadrature(), d0 = slope();
            plant.advance();
          }
          const double t1 = plant.time_s(), q1 = plant.residual_quadrature(), d1 = slope();
          if (!(t1 > t0) || t >= t1) return q1;
          const double h = t1 - t0, u = (t - t0) / h, u2 = u * u, u3 = u2 * u;
          return (2 * u3 - 3 * u2 + 1) * q0 + (u3 - 2 * u2 + u) * h * d0 + (3 * u2 - 2 * u3) * q1 + (u3 - u2) * h * d1;
        };
        const double block_s = measure_s / s.blocks;
        double q_prev = residual_at(r.settle_s);
        std::vector<double> block_mean;
        r.measured_g = 0;
        for (int b = 1; b <= s.blocks; ++b) {
          const double q = residual_at(r.settle_s + b * block_s);
          block_mean.push_back((q - q_prev) / block_s);
          r.measured_g += block_mean.back() / s.blocks;
          q_prev = q;
        }
        r.integral_slope_g = r.measured_g;
        r.sigma_g = batch_sigma(block_mean, r.measured_g);
        steps_done = plant.index();
      } else {
        r.method = "sampled record";
        r.sample_rate_Hz = rate;
        SampledRecorder rec(ro, k1, r.baseline_g, s.blocks, block_n, dt, sink, true);
        for (long k = 0; k < total_n; ++k) {
          if (k > 0) plant.advance();
          rec.sample(static_cast<double>(k) * dt, plant.input_g(), plant.output_g(), k - settle_n, plant.linear_output_g());
        }
        rec.finish(r);
      }
      r.periods = 0;
      r.simulated_s = static_cast<double>(steps_done) * dt;
      r.steps = plant.index();
      r.rhs_evaluations = plant.plant_evaluations();
      if (std::isfinite(r.measured_g) && std::isfinite(r.sigma_g)) return r;
      // Not finite (seen: a lightly damped 603 Hz mode under 11 g rms): CVODE, with its own
      // step control, unless a sink already received the samples.
      if (sink)
        throw std::runtime_error("shake_excitation: the exponential integrator's measured error is not finite (" +
                                 std::to_string(r.simulated_s) + " s simulated)");
      r = before;
      cvode_reason = "the exponential integrator's answer was not finite";
    }
  }
  r.path = "CVODE: " + cvode_reason;
  const double mean_part_g = companion_dc_gain(lin).dot(input.mean_g());
  const WithLinearCompanion system(shaken, std::move(lin), table);
  // Size of the motion (for the absolute tolerances): rms over the first 2000 points of 0.1 s.
  double ms = 0;
  for (int k = 0; k < 2000; ++k) ms += input.acceleration_g(0.1 * k / 2000).squaredNorm() / 2000;
  const double amplitude = std::max(std::sqrt(ms), 1e-6);
  plant::SolverSettings solver;
  solver.relative_tolerance = s.relative_tolerance;
  solver.analytic_jacobian = s.analytic_jacobian;
  const std::vector<double> scale = rest.state_scale();
  for (int copy = 0; copy < 2; ++copy)
    for (int k = 0; k < n; ++k)
      solver.absolute_tolerance.push_back(
          s.relative_tolerance * std::max(amplitude * scale[static_cast<std::size_t>(k)],
                                          copy == 0 ? std::abs(x_eq[static_cast<std::size_t>(k)]) : 0.0));
  solver.max_step_s = 1 / (8 * f_top);  // resolve the top of the spectrum
  std::vector<double> x0(x_eq);
  x0.resize(static_cast<std::size_t>(2 * n), 0.0);  // the companion starts at rest too
  plant::OdeSolver ode(system, 0.0, x0, solver);
  const int zq = n + Accelerometer::kQuadrature;
  if (!ro.active() && !sink) {
    r.method = "continuous integral";
    const double block_s = measure_s / s.blocks;
    auto residual_integral = [&](double t) {
      const std::vector<double>& x = ode.advance(t);
      return x[Accelerometer::kQuadrature] - x[static_cast<std::size_t>(zq)];
    };
    double q_prev = residual_integral(r.settle_s);
    std::vector<double> block_mean;
    r.measured_g = 0;
    for (int b = 1; b <= s.blocks; ++b) {
      const double q = residual_integral(r.settle_s + b * block_s);
      block_mean.push_back((q - q_prev) / block_s);
      r.measured_g += block_mean.back() / s.blocks;
      q_prev = q;
    }
    r.integral_slope_g = r.measured_g;
    r.sigma_g = batch_sigma(block_mean, r.measured_g);
  } else {
    r.method = "sampled record";
    r.sample_rate_Hz = ro.active() ? ro.sample_rate_Hz : 8 * f_top;
    const double dt = 1 / r.sample_rate_Hz;
    const long block_n = std::max<long>(2, static_cast<long>(std::llround(measure_s * r.sample_rate_Hz / s.blocks)));
    const long settle_n = static_cast<long>(std::ceil(r.settle_s * r.sample_rate_Hz));
    SampledRecorder rec(ro, k1, r.baseline_g, s.blocks, block_n, dt, sink);
    const long total_n = settle_n + s.blocks * block_n;
    for (long k = 0; k < total_n; ++k) {
      const double t = static_cast<double>(k) * dt;
      const std::vector<double>& x = ode.advance(t);
      rec.sample(t, input.acceleration_g(t), shaken.output_g(t, x.data()), k - settle_n, system.linear_output(t, x.data()));
    }
    rec.finish(r);
  }
  // The companion took off the linear output of the input's deterministic mean too (a rocking
  // fixture's): that part is the instrument's reading of a real mean, given back.
  r.measured_g += mean_part_g, r.integral_slope_g += mean_part_g;
  r.periods = 0;
  r.simulated_s = r.settle_s + measure_s;
  r.steps = ode.steps();
  r.rhs_evaluations = ode.rhs_evaluations();
  if (!std::isfinite(r.measured_g) || !std::isfinite(r.sigma_g))
    throw std::runtime_error("shake_excitation: the measured error is not finite (" + r.path + ", " + std::to_string(r.simulated_s) +
                             " s simulated)");
  return r;
}

}  // namespace vrelab::rectification
