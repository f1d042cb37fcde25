#include "rectification/simulation/discretised.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

#include <Eigen/Dense>
#include <unsupported/Eigen/MatrixFunctions>

#include "core/cancel.hpp"

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

// The quintic B-spline prefilter of vibration/sampled.hpp and its context on each side.
constexpr std::int64_t kMargin = vibration::kQuinticPrefilterMargin;

// fs / rate = p / q in lowest terms with q <= 256, or q = 0 when there is none.
std::pair<std::int64_t, std::int64_t> rational_ratio(double ratio) {
  for (std::int64_t q = 1; q <= 256; ++q) {
    const double pq = ratio * static_cast<double>(q);
    const std::int64_t p = std::llround(pq);
    if (p >= 1 && std::abs(pq - static_cast<double>(p)) <= 1e-12 * pq) return {p, q};
  }
  return {0, 0};
}

// The per-step arithmetic on the states that move (`act`), with fixed sizes for the common
// plants (5 such states: the pendulum's two, the lead, the PI integral and the quadrature;
// 1-3 excited axes) so that Eigen unrolls the small products, Dynamic otherwise.
template <int N, int W>
struct Kernel {
  using MapM = Eigen::Map<const Eigen::Matrix<double, N, N>>;
  using MapV = Eigen::Map<Eigen::Matrix<double, N, 1>>;
  using MapCV = Eigen::Map<const Eigen::Matrix<double, N, 1>>;
  // kw = K w;  z <- E z + kw;  sigma <- sigma + kw + P1 g + E P2 dN.
  static void propagate(const StepData& d) {
    const int n = d.n, w = d.w;
    const MapM e(d.e, n, n), p1(d.p1, n, n), ep2(d.ep2, n, n);
    const Eigen::Map<const Eigen::Matrix<double, N, W>> k(d.k, n, w);
    const Eigen::Map<const Eigen::Matrix<double, W, 1>> window(d.window, w);
    MapV z(d.z, n), sigma(d.sigma, n);
    const MapCV g(d.g, n), dn(d.dn, n);
    Eigen::Matrix<double, N, 1> kw(n), t(n);
    kw.noalias() = k * window;
    t.noalias() = e * z;
    z = t + kw;
    t.noalias() = p1 * g;
    t.noalias() += ep2 * dn;
    sigma += kw + t;
  }
  // g <- f - B a (f in g on entry); N = g - A sigma; dN = N - N_prev (0 at the start);
  // returns C P2 dN (the output's correction from sigma to the corrected state).
  // Also gathers f (the plant's derivative, all states) into g first, and sets *linear to the
  // companion's linear output.
  static double correct(const StepData& d, bool first) {
    const int n = d.n;
    const MapM a(d.a, n, n);
    MapV g_out(d.g, n), nprev(d.n_prev, n), dn(d.dn, n);
    const MapCV sigma(d.sigma, n), cp2(d.c_p2, n);
    // Gathered into a local (scalar stores read back as pairs would stall the store forwarding).
    Eigen::Matrix<double, N, 1> g(n);
    for (int i = 0; i < n; ++i) g[i] = d.f[d.act[i]];
    for (int i = 0; i < d.k_axes; ++i) g -= Eigen::Map<const Eigen::Matrix<double, N, 1>>(d.b + i * n, n) * d.a_k[i];
    g_out = g;
    Eigen::Matrix<double, N, 1> nnow(n);
    nnow = g;
    nnow.noalias() -= a * sigma;
    if (first)
      dn.setZero();
    else
      dn = nnow - nprev;
    nprev = nnow;
    double lin = MapCV(d.q_row, n).dot(MapCV(d.z, n));
    double lin_input = 0;
    for (int i = 0; i < d.k_axes; ++i) lin_input += d.q_input[i] * d.a_k[i];
    *d.linear = lin + lin_input;
    return cp2.dot(dn);
  }
};

}  // namespace

// The excitation's spline coefficients, streamed: a window of kLength coefficients refilled
// from RandomExcitation::samples (bounded memory for any run length), the excited axes
// interleaved (coefficient i of axis slot a at (i - first) k + a: the 7 k coefficients of a
// step are contiguous, in the order of the step matrices' columns).
struct DiscretisedRandomPlant::Coefficients {
  static constexpr std::int64_t kLength = 8192;
  const vibration::RandomExcitation& ex;
  std::vector<int> axes;
  std::int64_t first = std::numeric_limits<std::int64_t>::min();
  std::vector<double> c;
  vibration::SampledSignal s;  // the window's samples (storage reused)

  // Coefficients [lo, hi] available.
  void ensure(std::int64_t lo, std::int64_t hi) {
    if (first != std::numeric_limits<std::int64_t>::min() && lo >= first && hi < first + kLength) return;
    core::throw_if_cancelled();  // a caller's cancel flag (core/cancel.hpp), every 8192 knots
    first = lo;
    ex.samples_into(first - kMargin, static_cast<std::size_t>(kLength + 2 * kMargin), s);
    const std::size_t k = axes.size();
    c.resize(static_cast<std::size_t>(kLength) * k);  // every element written below
    for (std::size_t a = 0; a < k; ++a) {
      std::vector<double>& v = s.samples_g[static_cast<std::size_t>(axes[a])];  // prefiltered in place
      vibration::quintic_prefilter(v);
      for (std::int64_t i = 0; i < kLength; ++i)
        c[static_cast<std::size_t>(i) * k + a] = v[static_cast<std::size_t>(i + kMargin)];
    }
    for (int axis = 0; axis < 3; ++axis)
      if (std::find(axes.begin(), axes.end(), axis) == axes.end())
        for (double v : s.samples_g[static_cast<std::size_t>(axis)])
          if (v != 0.0) throw std::logic_error("DiscretisedRandomPlant: an axis at rest moved");
  }
  // The coefficients from i on (ensure first).
  const double* from(std::int64_t i) const { return c.data() + static_cast<std::size_t>(i - first) * axes.size(); }
};

std::string DiscretisedRandomPlant::unsupported(const plant::PlantConfig& config, const vibration::RandomExcitation& ex,
                                                double rate) {
  for (const auto& e : config.effects) {
    const std::string name = e->name();
    if (name == "current_saturation" || name == "readout_clipping")
      return name + " is not smooth (the correction to the linear loop is neither small nor smooth)";
    // Measured against CVODE under GEVS (docs/performance.md): p2 = 20 /rad moves the answer by
    // 0.3 % (0.04 sigma of a 0.5 s run); the squeeze film is not checked.
    if (name == "pickoff_nonlinearity" || name == "squeeze_film_damping")
      return name + " is not verified on the sample grid (the correction differs from CVODE)";
  }
  const double fs = ex.sample_rate_Hz();
  if (!(rate >= fs * (1 - 1e-12))) return "the output is sampled below the excitation's sample rate";
  if (rational_ratio(fs / rate).second == 0)
    return "the output's sample rate is not a small rational multiple of the excitation's";
  return "";
}

DiscretisedRandomPlant::DiscretisedRandomPlant(const Accelerometer& plant, const Accelerometer::Linear& lin,
                                               const std::vector<double>& x_eq, const vibration::RandomExcitation& ex,
                                               double rate, bool quadrature)
    : plant_(plant), x_eq_(x_eq), rate_(rate), n_(plant.size()) {
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
  coef_ = std::make_unique<Coefficients>(Coefficients{ex, axes_, std::numeric_limits<std::int64_t>::min(), {}, {}});

  const Eigen::Index n = n_, k = k_;
  a_mat_ = lin.A;
  b_mat_.resize(n, k);
  for (Eigen::Index a = 0; a < k; ++a) b_mat_.col(a) = lin.B.col(axes_[static_cast<std::size_t>(a)]);

  // The plant augmented by the input polynomial's derivative chain (time in knot intervals):
  // [z; a; a'; ...; a^(5)]' = [[A/fs, B/fs, 0..], [0, 0, I, ..], ..., [0 ..]] [...].
  const Eigen::Index n_aug = n + 6 * k;
  Eigen::MatrixXd aug = Eigen::MatrixXd::Zero(n_aug, n_aug);
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
  // Restricted to the states that move: the inert ones (zero row and column of A, zero row
  // of B: the anti-alias filter when off) stay at rest, their blocks of every matrix being 0.
  // The quadrature feeds nothing back (its column of A is 0): stepped last, and only when
  // residual_quadrature is wanted.
  std::vector<int> inert;
  for (int i = 0; i < n_; ++i) {
    const bool still = lin.A.row(i).cwiseAbs().maxCoeff() == 0 && lin.A.col(i).cwiseAbs().maxCoeff() == 0 &&
                       lin.B.row(i).cwiseAbs().maxCoeff() == 0;
    if (still)
      inert.push_back(i);
    else if (i != Accelerometer::kQuadrature)
      act_.push_back(i);
  }
  if (lin.A.col(Accelerometer::kQuadrature).cwiseAbs().maxCoeff() != 0)
    throw std::logic_error("DiscretisedRandomPlant: the quadrature feeds back");
  if (quadrature) {
    q_index_ = static_cast<int>(act_.size());
    act_.push_back(Accelerometer::kQuadrature);
  }
  inert_ = inert;
  na_ = static_cast<int>(act_.size());
  const Eigen::Index na = na_;
  // Rows on the moving states; columns too when they are states (square), else all.
  auto restrict = [&](const Eigen::MatrixXd& full, bool square) {
    Eigen::MatrixXd r(na, square ? na : full.cols());
    for (Eigen::Index i = 0; i < na; ++i)
      for (Eigen::Index c = 0; c < r.cols(); ++c)
        r(i, c) = full(act_[static_cast<std::size_t>(i)], square ? act_[static_cast<std::size_t>(c)] : c);
    return r;
  };
  const Eigen::MatrixXd p2 = restrict(h * phi.block(0, 2 * n, n, n), true);
  e_ = restrict(whole.topLeftCorner(n, n), true);
  p1_ = restrict(h * phi.block(0, n, n, n), true);
  ep2_ = e_ * p2;
  a_mat_ = restrict(a_mat_, true);
  b_mat_ = restrict(b_mat_, false);
  for (auto& kj : k_step_) kj = restrict(kj, false);
  Eigen::RowVectorXd c_act(na), q_row(na);
  for (Eigen::Index i = 0; i < na; ++i) {
    c_act[i] = lin.C[act_[static_cast<std::size_t>(i)]];
    q_row[i] = lin.A(Accelerometer::kQuadrature, act_[static_cast<std::size_t>(i)]);
  }
  c_p2_ = (c_act * p2).transpose();
  if (q_index_ >= 0) p2_q_ = p2.row(q_index_).transpose();
  q_row_ = q_row.transpose();
  q_input_.resize(k);
  for (Eigen::Index a = 0; a < k; ++a) q_input_[a] = lin.B(Accelerometer::kQuadrature, axes_[static_cast<std::size_t>(a)]);

  z_ = sigma_ = g_ = n_prev_ = dn_ = Eigen::VectorXd::Zero(na);
  a_k_ = Eigen::VectorXd::Zero(k);
  x_ = x_eq_;  // the states not stepped stay at the equilibrium
  f_.assign(static_cast<std::size_t>(n), 0.0);
  propagate_ = &Kernel<Eigen::Dynamic, Eigen::Dynamic>::propagate;
  correct_ = &Kernel<Eigen::Dynamic, Eigen::Dynamic>::correct;
  if (na == 4) {  // a sampled record (the quadrature not stepped)
    if (k == 1) propagate_ = &Kernel<4, 7>::propagate, correct_ = &Kernel<4, 7>::correct;
    if (k == 2) propagate_ = &Kernel<4, 14>::propagate, correct_ = &Kernel<4, 14>::correct;
    if (k == 3) propagate_ = &Kernel<4, 21>::propagate, correct_ = &Kernel<4, 21>::correct;
  }
  if (na == 5) {
    if (k == 1) propagate_ = &Kernel<5, 7>::propagate, correct_ = &Kernel<5, 7>::correct;
    if (k == 2) propagate_ = &Kernel<5, 14>::propagate, correct_ = &Kernel<5, 14>::correct;
    if (k == 3) propagate_ = &Kernel<5, 21>::propagate, correct_ = &Kernel<5, 21>::correct;
  }
  data_ = step_data();
  evaluate_at_grid_point();
}

DiscretisedRandomPlant::~DiscretisedRandomPlant() = default;

double DiscretisedRandomPlant::residual_quadrature() const {
  if (q_index_ < 0) throw std::logic_error("DiscretisedRandomPlant: built without the quadrature");
  // y_Q = Q - z_Q at the corrected state sigma + P2 dN.
  return sigma_[q_index_] - z_[q_index_] + p2_q_.dot(dn_);
}

StepData DiscretisedRandomPlant::step_data() {
  StepData d;
  d.n = na_;
  d.w = 7 * k_;
  d.k_axes = k_;
  d.e = e_.data();
  d.p1 = p1_.data();
  d.ep2 = ep2_.data();
  d.a = a_mat_.data();
  d.b = b_mat_.data();
  d.c_p2 = c_p2_.data();
  d.z = z_.data();
  d.sigma = sigma_.data();
  d.g = g_.data();
  d.n_prev = n_prev_.data();
  d.dn = dn_.data();
  d.a_k = a_k_.data();
  d.f = f_.data();
  d.act = act_.data();
  d.q_row = q_row_.data();
  d.q_input = q_input_.data();
  d.linear = &linear_;
  return d;
}

void DiscretisedRandomPlant::advance() {
  // The step from m to m + 1 starts in knot interval knot_ at phase_ / q.
  coef_->ensure(knot_ - 2, knot_ + 4);
  data_.window = coef_->from(knot_ - 2);
  data_.k = k_step_[static_cast<std::size_t>(phase_)].data();
  propagate_(data_);
  ++m_;
  phase_ += p_;
  while (phase_ >= q_) phase_ -= q_, ++knot_;
  evaluate_at_grid_point();
}

void DiscretisedRandomPlant::evaluate_at_grid_point() {
  coef_->ensure(knot_ - 2, knot_ + 4);
  const double* w = weights_[static_cast<std::size_t>(phase_)].data();
  const double* c = coef_->from(knot_ - 2);
  a_.setZero();
  for (int a = 0; a < k_; ++a) {
    double s = 0;
    for (int i = 0; i < 6; ++i) s += w[i] * c[i * k_ + a];
    a_[axes_[static_cast<std::size_t>(a)]] = s;
    a_k_[a] = s;
  }
  for (int i = 0; i < na_; ++i) {
    const std::size_t k = static_cast<std::size_t>(act_[static_cast<std::size_t>(i)]);
    x_[k] = x_eq_[k] + sigma_[i];
  }
  out_ = plant_.rhs_output(a_, x_.data(), f_.data());
  ++evaluations_;
  for (int i : inert_)
    if (f_[static_cast<std::size_t>(i)] != 0.0)
      throw std::logic_error("DiscretisedRandomPlant: a state the linearisation holds still moved");
  out_ += correct_(data_, m_ == 0);  // also the linear output
}

}  // namespace vrelab::rectification
