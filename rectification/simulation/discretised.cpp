#include "rectification/simulation/discretised.hpp"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <limits>
#include <stdexcept>

#include <Eigen/Dense>
#include <unsupported/Eigen/MatrixFunctions>

namespace vrelab::rectification {
namespace {

using plant::Accelerometer;

// The uniform quintic B-spline on one knot interval, u in [0, 1): a(u) = sum_i w_i(u) c[n-2+i],
// w_i(u) = sum_p kBasis[p][i] u^p / 120 (the basis RandomExcitation interpolates with:
// w_0 = (1-u)^5/120, w_5 = u^5/120; the rows for u^1..u^5 sum to 0, the first to 120).
constexpr double kBasis[6][6] = {{1, 26, 66, 26, 1, 0},    {-5, -50, 0, 50, 5, 0}, {10, 20, -60, 20, 10, 0},
                                 {-10, 20, 0, -20, 10, 0}, {5, -20, 30, -20, 5, 0}, {-1, 5, -10, 10, -5, 1}};

// d-th derivative (d/du) of w_i at u.
double basis_derivative(int i, int d, double u) {
  double s = 0;
  for (int p = d; p < 6; ++p) {
    double falling = 1;
    for (int r = 0; r < d; ++r) falling *= p - r;
    s += kBasis[p][i] * falling * std::pow(u, p - d);
  }
  return s / 120;
}

// The samples -> quintic B-spline coefficients prefilter of vibration/sampled.cpp (Unser's
// causal/anticausal recursions, the same poles); the caller gives kMargin samples of context
// on each side (truncation error below 0.4306^48 ~ 3e-18 of the signal in the middle).
constexpr std::int64_t kMargin = 48;
constexpr double kPoles[2] = {-0.43057534709997379, -0.043096288203264653};
void prefilter(std::vector<double>& c) {
  const std::size_t n = c.size();
  double gain = 1;
  for (double z : kPoles) gain *= (1 - z) * (1 - 1 / z);
  for (double& v : c) v *= gain;
  for (double z : kPoles) {
    for (std::size_t i = 1; i < n; ++i) c[i] += z * c[i - 1];
    c[n - 1] *= z / (z * z - 1);
    for (std::size_t i = n - 1; i-- > 0;) c[i] = z * (c[i + 1] - c[i]);
  }
}

// fs / rate = p / q in lowest terms with q <= 256, or q = 0 when there is none.
std::pair<std::int64_t, std::int64_t> rational_ratio(double ratio) {
  for (std::int64_t q = 1; q <= 256; ++q) {
    const double pq = ratio * static_cast<double>(q);
    const std::int64_t p = std::llround(pq);
    if (p >= 1 && std::abs(pq - static_cast<double>(p)) <= 1e-12 * pq) return {p, q};
  }
  return {0, 0};
}

// The per-step arithmetic, with fixed sizes for the common plants (7 core states; 1-3 excited
// axes) so that Eigen unrolls and vectorises the small products, Dynamic otherwise.
template <int N, int W>
struct Kernel {
  using MapM = Eigen::Map<const Eigen::Matrix<double, N, N>>;
  using MapV = Eigen::Map<Eigen::Matrix<double, N, 1>>;
  using MapCV = Eigen::Map<const Eigen::Matrix<double, N, 1>>;
  // z <- E z + K w;  y_pred <- E y + P1 N.
  static void propagate(const StepData& d) {
    const int n = d.n, w = d.w;
    const MapM e(d.e, n, n), p1(d.p1, n, n);
    const Eigen::Map<const Eigen::Matrix<double, N, W>> k(d.k, n, w);
    const Eigen::Map<const Eigen::Matrix<double, W, 1>> window(d.window, w);
    MapV z(d.z, n), ypred(d.y_pred, n);
    const MapCV y(d.y, n), nnow(d.n_now, n);
    Eigen::Matrix<double, N, 1> t(n);
    t.noalias() = e * z;
    t.noalias() += k * window;
    z = t;
    ypred.noalias() = e * y;
    ypred.noalias() += p1 * nnow;
  }
  // N = f - A (z + y_pred) - B a (f in n_now on entry); y = y_pred + P2 (N - N_prev);
  // returns C (y - y_pred).
  static double correct(const StepData& d, bool first) {
    const int n = d.n;
    const MapM a(d.a, n, n), p2(d.p2, n, n);
    MapV nnow(d.n_now, n), nprev(d.n_prev, n), y(d.y, n);
    const MapCV z(d.z, n), ypred(d.y_pred, n), c(d.c, n);
    Eigen::Matrix<double, N, 1> x(n);
    x = z + ypred;
    nnow.noalias() -= a * x;
    for (int i = 0; i < d.k_axes; ++i) nnow -= Eigen::Map<const Eigen::Matrix<double, N, 1>>(d.b + i * n, n) * d.a_k[i];
    if (first) {
      y.setZero();
      return 0.0;
    }
    x = nnow - nprev;
    y = ypred;
    y.noalias() += p2 * x;
    return c.dot(y - ypred);
  }
};

}  // namespace

// The excitation's spline coefficients, streamed: a window of kLength coefficients refilled
// from RandomExcitation::samples (bounded memory for any run length).
struct DiscretisedRandomPlant::Coefficients {
  static constexpr std::int64_t kLength = 8192;
  const vibration::RandomExcitation& ex;
  std::vector<int> axes;
  std::int64_t first = std::numeric_limits<std::int64_t>::min();
  std::vector<std::vector<double>> c;  // per excited axis

  // Coefficients [lo, hi] available.
  void ensure(std::int64_t lo, std::int64_t hi) {
    if (first != std::numeric_limits<std::int64_t>::min() && lo >= first && hi < first + kLength) return;
    first = lo;
    const vibration::SampledSignal s = ex.samples(first - kMargin, static_cast<std::size_t>(kLength + 2 * kMargin));
    c.resize(axes.size());
    for (std::size_t a = 0; a < axes.size(); ++a) {
      std::vector<double> v = s.samples_g[static_cast<std::size_t>(axes[a])];
      prefilter(v);
      c[a].assign(v.begin() + kMargin, v.end() - kMargin);
    }
    for (int axis = 0; axis < 3; ++axis)
      if (std::find(axes.begin(), axes.end(), axis) == axes.end())
        for (double v : s.samples_g[static_cast<std::size_t>(axis)])
          if (v != 0.0) throw std::logic_error("DiscretisedRandomPlant: an axis at rest moved");
  }
  double at(std::size_t a, std::int64_t i) const { return c[a][static_cast<std::size_t>(i - first)]; }
};

std::string DiscretisedRandomPlant::unsupported(const plant::PlantConfig& config, const vibration::RandomExcitation& ex,
                                                double rate) {
  for (const auto& e : config.effects) {
    const std::string name = e->name();
    if (name == "current_saturation" || name == "readout_clipping")
      return name + " is not smooth (the correction to the linear loop is neither small nor smooth)";
  }
  const double fs = ex.sample_rate_Hz();
  if (!(rate >= fs * (1 - 1e-12))) return "the output is sampled below the excitation's sample rate";
  if (rational_ratio(fs / rate).second == 0)
    return "the output's sample rate is not a small rational multiple of the excitation's";
  return "";
}

DiscretisedRandomPlant::DiscretisedRandomPlant(const Accelerometer& plant, const Accelerometer::Linear& lin,
                                               const std::vector<double>& x_eq, const vibration::RandomExcitation& ex,
                                               double rate)
    : plant_(plant), lin_(lin), x_eq_(x_eq), rate_(rate), n_(plant.size()) {
  const std::string why = unsupported(plant.config(), ex, rate);
  if (!why.empty()) throw std::invalid_argument("discretised random path: " + why);
  const double fs = ex.sample_rate_Hz();
  std::tie(p_, q_) = rational_ratio(fs / rate);
  {
    const vibration::SampledSignal probe = ex.samples(0, 4096);
    for (int a = 0; a < 3; ++a)
      for (double v : probe.samples_g[static_cast<std::size_t>(a)])
        if (v != 0.0) {
          axes_.push_back(a);
          break;
        }
  }
  k_ = static_cast<int>(axes_.size());
  coef_ = std::make_unique<Coefficients>(Coefficients{ex, axes_, std::numeric_limits<std::int64_t>::min(), {}});

  const Eigen::Index n = n_, k = k_;
  a_mat_ = lin.A;
  b_mat_.resize(n, k);
  for (Eigen::Index a = 0; a < k; ++a) b_mat_.col(a) = lin.B.col(axes_[static_cast<std::size_t>(a)]);

  // The plant augmented by the input polynomial's derivative chain (time in knot intervals):
  // [z; a; a'; ...; a^(5)]' = [[A/fs, B/fs, 0..], [0, 0, I, ..], ..., [0 ..]] [...].
  const Eigen::Index na = n + 6 * k;
  Eigen::MatrixXd aug = Eigen::MatrixXd::Zero(na, na);
  aug.topLeftCorner(n, n) = a_mat_ / fs;
  aug.block(0, n, n, k) = b_mat_ / fs;
  for (Eigen::Index d = 0; d < 5; ++d)
    for (Eigen::Index a = 0; a < k; ++a) aug(n + d * k + a, n + (d + 1) * k + a) = 1;
  auto propagator = [&](std::int64_t num) {  // e^{aug * num/q}
    return Eigen::MatrixXd((aug * (static_cast<double>(num) / static_cast<double>(q_))).exp());
  };
  // The input's derivatives (d/du) at u for basis function i, placed for axis slot a.
  auto derivatives = [&](int i, double u, Eigen::Index a) {
    Eigen::VectorXd dv = Eigen::VectorXd::Zero(6 * k);
    for (int d = 0; d < 6; ++d) dv[d * k + a] = basis_derivative(i, d, u);
    return dv;
  };
  const Eigen::MatrixXd whole = propagator(p_);
  weights_.resize(static_cast<std::size_t>(q_));
  k_step_.resize(static_cast<std::size_t>(q_));
  for (std::int64_t j = 0; j < q_; ++j) {
    const double us = static_cast<double>(j) / static_cast<double>(q_);
    std::vector<double>& w = weights_[static_cast<std::size_t>(j)];
    w.resize(6);
    for (int i = 0; i < 6; ++i) w[static_cast<std::size_t>(i)] = basis_derivative(i, 0, us);
    // Columns w * k + a: coefficient c[n0 - 2 + w] of axis slot a, w = 0..6.
    Eigen::MatrixXd kj = Eigen::MatrixXd::Zero(n, 7 * k);
    if (j + p_ <= q_) {  // the step stays within knot interval n0
      for (int i = 0; i < 6; ++i)
        for (Eigen::Index a = 0; a < k; ++a) kj.col(i * k + a) = whole.block(0, n, n, 6 * k) * derivatives(i, us, a);
    } else {  // the step crosses knot n0 + 1
      const Eigen::MatrixXd first = propagator(q_ - j), second = propagator(j + p_ - q_);
      const Eigen::MatrixXd e2 = second.topLeftCorner(n, n);
      for (int i = 0; i < 6; ++i)
        for (Eigen::Index a = 0; a < k; ++a) {
          kj.col(i * k + a) += e2 * (first.block(0, n, n, 6 * k) * derivatives(i, us, a));
          kj.col((i + 1) * k + a) += second.block(0, n, n, 6 * k) * derivatives(i, 0.0, a);
        }
    }
    k_step_[static_cast<std::size_t>(j)] = std::move(kj);
  }
  // ETD2: exp([[A h, I, 0], [0, 0, I], [0, 0, 0]]) = [[e^{Ah}, phi1, phi2], ...].
  const double h = 1 / rate;
  Eigen::MatrixXd etd = Eigen::MatrixXd::Zero(3 * n, 3 * n);
  etd.topLeftCorner(n, n) = a_mat_ * h;
  etd.block(0, n, n, n).setIdentity();
  etd.block(n, 2 * n, n, n).setIdentity();
  const Eigen::MatrixXd phi = etd.exp();
  e_ = whole.topLeftCorner(n, n);
  p1_ = h * phi.block(0, n, n, n);
  p2_ = h * phi.block(0, 2 * n, n, n);
  if (std::getenv("VRELAB_ETD1")) p2_.setZero();

  z_ = y_ = y_pred_ = n_now_ = n_prev_ = x_ = Eigen::VectorXd::Zero(n);
  window_ = Eigen::VectorXd::Zero(7 * k);
  a_k_ = Eigen::VectorXd::Zero(k);
  c_ = lin.C.transpose();
  q_row_ = lin.A.row(Accelerometer::kQuadrature).transpose();
  q_input_.resize(k);
  for (Eigen::Index a = 0; a < k; ++a) q_input_[a] = lin.B(Accelerometer::kQuadrature, axes_[static_cast<std::size_t>(a)]);
  // The fixed-size kernels for the plants without stateful effects.
  propagate_ = &Kernel<Eigen::Dynamic, Eigen::Dynamic>::propagate;
  correct_ = &Kernel<Eigen::Dynamic, Eigen::Dynamic>::correct;
  if (n == Accelerometer::kCoreStates) {
    if (k == 1) propagate_ = &Kernel<7, 7>::propagate, correct_ = &Kernel<7, 7>::correct;
    if (k == 2) propagate_ = &Kernel<7, 14>::propagate, correct_ = &Kernel<7, 14>::correct;
    if (k == 3) propagate_ = &Kernel<7, 21>::propagate, correct_ = &Kernel<7, 21>::correct;
  }
  evaluate_at_grid_point();
}

DiscretisedRandomPlant::~DiscretisedRandomPlant() = default;

double DiscretisedRandomPlant::residual_quadrature() const { return y_[Accelerometer::kQuadrature]; }

StepData DiscretisedRandomPlant::step_data(std::int64_t j) {
  StepData d;
  d.n = n_;
  d.w = 7 * k_;
  d.k_axes = k_;
  d.e = e_.data();
  d.p1 = p1_.data();
  d.p2 = p2_.data();
  d.a = a_mat_.data();
  d.b = b_mat_.data();
  d.k = k_step_[static_cast<std::size_t>(j)].data();
  d.c = c_.data();
  d.window = window_.data();
  d.z = z_.data();
  d.y = y_.data();
  d.y_pred = y_pred_.data();
  d.n_now = n_now_.data();
  d.n_prev = n_prev_.data();
  d.a_k = a_k_.data();
  return d;
}

void DiscretisedRandomPlant::advance() {
  const std::int64_t pos = m_ * p_, n0 = pos / q_, j = pos % q_;
  coef_->ensure(n0 - 2, n0 + 4);
  for (int w = 0; w < 7; ++w)
    for (int a = 0; a < k_; ++a) window_[w * k_ + a] = coef_->at(static_cast<std::size_t>(a), n0 - 2 + w);
  propagate_(step_data(j));
  ++m_;
  evaluate_at_grid_point();
}

void DiscretisedRandomPlant::evaluate_at_grid_point() {
  const std::int64_t pos = m_ * p_, n0 = pos / q_, j = pos % q_;
  coef_->ensure(n0 - 2, n0 + 4);
  const std::vector<double>& w = weights_[static_cast<std::size_t>(j)];
  a_.setZero();
  for (int a = 0; a < k_; ++a) {
    double s = 0;
    for (int i = 0; i < 6; ++i) s += w[static_cast<std::size_t>(i)] * coef_->at(static_cast<std::size_t>(a), n0 - 2 + i);
    a_[axes_[static_cast<std::size_t>(a)]] = s;
  }
  for (int a = 0; a < k_; ++a) a_k_[a] = a_[axes_[static_cast<std::size_t>(a)]];
  for (int i = 0; i < n_; ++i) x_[i] = x_eq_[static_cast<std::size_t>(i)] + z_[i] + y_pred_[i];
  std::swap(n_prev_, n_now_);
  out_ = plant_.rhs_output(a_, x_.data(), n_now_.data());
  ++evaluations_;
  out_ += correct_(step_data(j), m_ == 0);  // y at rest at m = 0
  linear_ = q_row_.dot(z_) + q_input_.dot(a_k_);
}

}  // namespace vrelab::rectification
