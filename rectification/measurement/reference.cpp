#include "rectification/measurement/reference.hpp"

#include <algorithm>
#include <cmath>
#include <mutex>
#include <numbers>
#include <stdexcept>

#include <fftw3.h>
#include <fmt/format.h>

#include "vibration/random.hpp"

namespace vrelab::rectification {
namespace {

constexpr const char* kAxis[3] = {"IA", "PA", "OA"};

// FFTW's planner is not thread-safe: the process's one planner mutex (vibration/random.hpp).
std::mutex& planner_mutex() { return vibration::fftw_planner_mutex(); }

}  // namespace

struct ReferenceAnalyzer::Fft {
  explicit Fft(int n) : n_(n) {
    in = static_cast<double*>(fftw_malloc(sizeof(double) * static_cast<std::size_t>(n)));
    out = static_cast<fftw_complex*>(fftw_malloc(sizeof(fftw_complex) * static_cast<std::size_t>(n / 2 + 1)));
    if (!in || !out) throw std::bad_alloc();
    std::lock_guard lock(planner_mutex());
    plan = fftw_plan_dft_r2c_1d(n, in, out, FFTW_ESTIMATE);
    if (!plan) throw std::runtime_error("fftw_plan_dft_r2c_1d failed");
  }
  ~Fft() {
    {
      std::lock_guard lock(planner_mutex());
      if (plan) fftw_destroy_plan(plan);
    }
    fftw_free(in);
    fftw_free(out);
  }
  Fft(const Fft&) = delete;
  Fft& operator=(const Fft&) = delete;
  int n_;
  double* in = nullptr;
  fftw_complex* out = nullptr;
  fftw_plan plan = nullptr;
};

ReferenceAnalyzer::ReferenceAnalyzer(const ReferenceWindow& w) : w_(w) {
  if (!(std::isfinite(w.from_s) && std::isfinite(w.to_s) && w.to_s > w.from_s))
    throw std::invalid_argument("reference window: to must be after from");
  if (!(w.frequency_Hz >= 0) || !std::isfinite(w.frequency_Hz))
    throw std::invalid_argument("reference window: frequency_Hz must be finite and >= 0");
  if (w.segment_samples != 0 && (w.segment_samples < 16 || w.segment_samples % 2 != 0))
    throw std::invalid_argument("reference window: segment_samples must be even and >= 16");
  a_.frequency_Hz = w.frequency_Hz;
}

ReferenceAnalyzer::~ReferenceAnalyzer() { delete fft_; }

void ReferenceAnalyzer::add(double t, const std::array<double, 3>& x, const std::array<bool, 3>& present) {
  if (!std::isfinite(t)) throw std::invalid_argument("reference channels: time is not finite");
  for (int i = 0; i < 3; ++i)
    if (present[static_cast<std::size_t>(i)] && !std::isfinite(x[static_cast<std::size_t>(i)]))
      throw std::invalid_argument(fmt::format("reference channel {}: sample is not a finite number", kAxis[i]));
  if (!started_) {
    a_.present = present;
  } else {
    if (present != a_.present) throw std::invalid_argument("reference channels: the set of axes changes within the record");
    if (!(t > last_t_)) throw std::invalid_argument("reference channels: time does not increase");
    const double dt = t - last_t_;
    if (dt_ == 0) {
      dt_ = dt;
      a_.sample_rate_Hz = 1 / dt;
    } else if (std::abs(dt - dt_) > 0.01 * dt_) {
      throw std::invalid_argument(fmt::format("reference channels: the sample interval changes from {:g} s to {:g} s at t = {:g} s "
                                              "(another rate, or a gap in the reference)",
                                              dt_, dt, t));
    }
  }
  started_ = true;
  last_t_ = t;
  ++seen_;
  if (t < w_.from_s || t >= w_.to_s) return;
  ++n_;
  for (int i = 0; i < 3; ++i) {
    if (!a_.present[static_cast<std::size_t>(i)]) continue;
    const double v = x[static_cast<std::size_t>(i)];
    sum_[i] += v, sum2_[i] += v * v;
  }
  if (w_.frequency_Hz > 0) {
    const double th = 2 * std::numbers::pi * w_.frequency_Hz * t;
    Eigen::Matrix<double, 7, 1> b;
    b[0] = 1;
    for (int h = 1; h <= 3; ++h) b[2 * h - 1] = std::sin(h * th), b[2 * h] = std::cos(h * th);
    gram_.selfadjointView<Eigen::Lower>().rankUpdate(b);
    for (int i = 0; i < 3; ++i)
      if (a_.present[static_cast<std::size_t>(i)]) proj_.col(i) += x[static_cast<std::size_t>(i)] * b;
    if (!w_.sine_on_random) return;
  }
  // Welch: the segment length once the rate is known (the second sample in the window).
  if (L_ == 0) {
    if (dt_ == 0) {  // the first sample: held until the rate is known
      for (std::size_t i = 0; i < 3; ++i) buf_[i].push_back(x[i]);
      tbuf_.push_back(t);
      return;
    }
    if (w_.segment_samples > 0) {
      L_ = w_.segment_samples;
    } else {
      const double expected = (w_.to_s - w_.from_s) / dt_;
      L_ = 64;
      while (L_ * 2 <= 4096 && L_ * 2 * 8 <= expected) L_ *= 2;
    }
    window_.resize(static_cast<std::size_t>(L_));
    for (int k = 0; k < L_; ++k) window_[static_cast<std::size_t>(k)] = 0.5 - 0.5 * std::cos(2 * std::numbers::pi * k / L_);
    const std::size_t nb = static_cast<std::size_t>(L_ / 2 + 1);
    for (std::size_t i = 0; i < 3; ++i) {
      pxx_[i].assign(nb, 0.0);
      pxy_[i].assign(nb, 0.0);
      buf_[i].reserve(static_cast<std::size_t>(L_));
      if (w_.sine_on_random)
        for (auto& v : pxb_[i]) v.assign(nb, 0.0);
    }
    if (w_.sine_on_random)
      for (auto& v : pbb_) v.assign(nb, 0.0);
    fft_ = new Fft(L_);
  }
  for (std::size_t i = 0; i < 3; ++i) buf_[i].push_back(x[i]);
  tbuf_.push_back(t);
  if (static_cast<int>(buf_[0].size()) == L_) {
    segment();
    for (std::size_t i = 0; i < 3; ++i) buf_[i].erase(buf_[i].begin(), buf_[i].begin() + L_ / 2);
    tbuf_.erase(tbuf_.begin(), tbuf_.begin() + L_ / 2);
  }
}

void ReferenceAnalyzer::segment() {
  const std::size_t nb = static_cast<std::size_t>(L_ / 2 + 1);
  std::array<std::vector<std::complex<double>>, 3> X;
  for (std::size_t i = 0; i < 3; ++i) {
    if (!a_.present[i]) continue;
    double m = 0;
    for (double v : buf_[i]) m += v;
    m /= L_;
    for (std::size_t k = 0; k < static_cast<std::size_t>(L_); ++k) fft_->in[k] = (buf_[i][k] - m) * window_[k];
    fftw_execute(fft_->plan);
    X[i].resize(nb);
    for (std::size_t k = 0; k < nb; ++k) X[i][k] = {fft_->out[k][0], fft_->out[k][1]};
    for (std::size_t k = 0; k < nb; ++k) pxx_[i][k] += std::norm(X[i][k]);
  }
  static constexpr std::array<std::pair<std::size_t, std::size_t>, 3> pairs{{{0, 1}, {0, 2}, {1, 2}}};
  for (std::size_t p = 0; p < 3; ++p) {
    const auto [i, j] = pairs[p];
    if (!a_.present[i] || !a_.present[j]) continue;
    for (std::size_t k = 0; k < nb; ++k) pxy_[p][k] += X[i][k] * std::conj(X[j][k]);
  }
  if (w_.sine_on_random) {
    // The fundamental's basis over this segment's own sample times, processed as the samples
    // are (mean removed, Hann window, FFT): the fitted sine's spectrum in this segment is
    // Re(W_1) B_0 + Im(W_1) B_1 (a = Im(W e^{jwt}) = Re W sin wt + Im W cos wt).
    std::array<std::vector<std::complex<double>>, 2> B;
    const double w = 2 * std::numbers::pi * w_.frequency_Hz;
    for (std::size_t m = 0; m < 2; ++m) {
      double mean = 0;
      for (std::size_t k = 0; k < static_cast<std::size_t>(L_); ++k)
        fft_->in[k] = m == 0 ? std::sin(w * tbuf_[k]) : std::cos(w * tbuf_[k]), mean += fft_->in[k];
      mean /= L_;
      for (std::size_t k = 0; k < static_cast<std::size_t>(L_); ++k) fft_->in[k] = (fft_->in[k] - mean) * window_[k];
      fftw_execute(fft_->plan);
      B[m].resize(nb);
      for (std::size_t k = 0; k < nb; ++k) B[m][k] = {fft_->out[k][0], fft_->out[k][1]};
    }
    for (std::size_t i = 0; i < 3; ++i)
      if (a_.present[i])
        for (std::size_t m = 0; m < 2; ++m)
          for (std::size_t k = 0; k < nb; ++k) pxb_[i][m][k] += X[i][k] * std::conj(B[m][k]);
    for (std::size_t mn = 0; mn < 4; ++mn)
      for (std::size_t k = 0; k < nb; ++k) pbb_[mn][k] += B[mn / 2][k] * std::conj(B[mn % 2][k]);
  }
  ++a_.segments;
}

ReferenceAnalysis ReferenceAnalyzer::finish() {
  ReferenceAnalysis a = a_;
  a.samples = n_;
  if (!started_ || dt_ == 0) throw std::invalid_argument("reference channels: fewer than two samples");
  const double N = static_cast<double>(n_);
  for (int i = 0; i < 3; ++i) {
    if (!a.present[static_cast<std::size_t>(i)] || n_ == 0) continue;
    a.mean_g[i] = sum_[i] / N;
    a.rms_g[i] = std::sqrt(std::max(0.0, sum2_[i] / N - a.mean_g[i] * a.mean_g[i]));
  }
  if (w_.frequency_Hz > 0) {
    const double per_period = a.sample_rate_Hz / w_.frequency_Hz;
    if (N < 2 * per_period || per_period < 8)
      throw std::invalid_argument(fmt::format("reference channels: the vibration window holds {} samples at {:g} Hz; the "
                                              "harmonics need two periods of {:g} Hz with at least 8 samples each",
                                              n_, a.sample_rate_Hz, w_.frequency_Hz));
    // The least-squares fit: c = G^-1 P per axis; W_h = c_sin + j c_cos (a = Im(W e^{j h w t})
    // = Re W sin + Im W cos); the residual sum of squares x.x - P.c.
    const Eigen::Matrix<double, 7, 7> G = gram_.selfadjointView<Eigen::Lower>();
    const Eigen::Matrix<double, 7, 3> c = G.ldlt().solve(proj_);
    for (int h = 1; h <= 3; ++h)
      for (int i = 0; i < 3; ++i) a.harmonic_g[static_cast<std::size_t>(h)][i] = {c(2 * h - 1, i), c(2 * h, i)};
    for (int i = 0; i < 3; ++i) {
      if (!a.present[static_cast<std::size_t>(i)]) continue;
      a.residual_rms_g[i] = std::sqrt(std::max(0.0, (sum2_[i] - proj_.col(i).dot(c.col(i))) / N));
      a.amplitude_sigma_g[i] = a.residual_rms_g[i] * std::sqrt(2.0 / N);
    }
    if (!w_.sine_on_random) return a;
  }
  if (a.segments < 2)
    throw std::invalid_argument(fmt::format("reference channels: the vibration window holds {} samples; Welch's PSD needs "
                                            "at least two segments of {} (50 % overlap: {} samples)",
                                            n_, std::max(L_, 64), 3 * std::max(L_, 64) / 2));
  if (w_.sine_on_random) {
    // Take the fitted fundamental off the sums (reference.hpp): with q_i = (Re W_1i, Im W_1i),
    // sum_s (X_i - q_i.B)(X_j - q_j.B)^* = P_ij - q_j.XB_i - conj(q_i.XB_j) + q_i^T BB q_j.
    a.sine_removed = true;
    const std::size_t nb = static_cast<std::size_t>(L_ / 2 + 1);
    std::array<std::array<double, 2>, 3> q{};
    for (std::size_t i = 0; i < 3; ++i) q[i] = {a.harmonic_g[1][static_cast<int>(i)].real(), a.harmonic_g[1][static_cast<int>(i)].imag()};
    const auto residual = [&](std::size_t i, std::size_t j, std::size_t k) {
      std::complex<double> v = 0;
      for (std::size_t m = 0; m < 2; ++m) {
        v -= q[j][m] * pxb_[i][m][k] + q[i][m] * std::conj(pxb_[j][m][k]);
        for (std::size_t n = 0; n < 2; ++n) v += q[i][m] * q[j][n] * pbb_[2 * m + n][k];
      }
      return v;
    };
    static constexpr std::array<std::pair<std::size_t, std::size_t>, 3> pairs{{{0, 1}, {0, 2}, {1, 2}}};
    for (std::size_t k = 0; k < nb; ++k) {
      for (std::size_t i = 0; i < 3; ++i)
        if (a.present[i]) pxx_[i][k] = std::max(0.0, pxx_[i][k] + residual(i, i, k).real());
      for (std::size_t p = 0; p < 3; ++p)
        if (a.present[pairs[p].first] && a.present[pairs[p].second]) pxy_[p][k] += residual(pairs[p].first, pairs[p].second, k);
    }
  }
  const double fs = a.sample_rate_Hz;
  double sw2 = 0;
  for (double v : window_) sw2 += v * v;
  const double scale = 2.0 / (fs * sw2 * a.segments);
  a.segment_samples = L_;
  a.resolution_Hz = fs / L_;
  const double c = 0.167;  // periodic Hann, 50 % overlap
  a.dof = 2.0 * a.segments / (1 + 2 * c * c);
  for (int k = 1; k < L_ / 2; ++k) a.bin_Hz.push_back(k * fs / L_);
  // Each axis's spectrum scaled so that its bins sum to the window's mean square about the mean
  // (the cross-spectra by the geometric mean of the two axes' factors): what a term such as
  // k2 rectifies is the record's own mean square, known far better from the samples than from
  // the sum of Welch's bins (relative sigma ~ sqrt(2 / (dof x bins / 2)), 4 % for 1.2 s at
  // 7.8 Hz bins); Welch gives how it is spread over frequency.
  std::array<double, 3> norm{1, 1, 1};
  for (std::size_t i = 0; i < 3; ++i) {
    if (!a.present[i]) continue;
    double sum = 0;
    for (int k = 1; k < L_ / 2; ++k) sum += pxx_[i][static_cast<std::size_t>(k)] * scale * a.resolution_Hz;
    const int ii = static_cast<int>(i);
    const double ms = a.rms_g[ii] * a.rms_g[ii] - (a.sine_removed ? std::norm(a.harmonic_g[1][ii]) / 2 : 0.0);
    // Not for a sine on random run: there rms^2 - |W_1|^2 / 2 is a difference of large numbers
    // (the sampled sine's departure from |W_1|^2 / 2, O(1 / N) of it, is 20 % of a 1e-4 g noise's
    // power under a 2 g sine: tests/rectification/test_reference.cpp), so Welch's own integral is
    // kept (its segments have the fitted sine taken off exactly).
    if (sum > 0 && !a.sine_removed) norm[i] = std::max(0.0, ms) / sum;
  }
  static constexpr std::array<std::pair<std::size_t, std::size_t>, 3> pairs{{{0, 1}, {0, 2}, {1, 2}}};
  for (std::size_t i = 0; i < 3; ++i) {
    if (a.present[i])
      for (int k = 1; k < L_ / 2; ++k) a.psd_g2_per_Hz[i].push_back(pxx_[i][static_cast<std::size_t>(k)] * scale * norm[i]);
    const double nij = std::sqrt(norm[pairs[i].first] * norm[pairs[i].second]);
    if (!pxy_[i].empty() && std::abs(pxy_[i][1]) > 0)
      for (int k = 1; k < L_ / 2; ++k) a.csd_g2_per_Hz[i].push_back(pxy_[i][static_cast<std::size_t>(k)] * scale * nij);
  }
  return a;
}

Eigen::Matrix3d ReferenceAnalysis::band_covariance_g2(double from_Hz, double to_Hz) const {
  Eigen::Matrix3d C = Eigen::Matrix3d::Zero();
  const bool all = from_Hz == 0 && to_Hz == 0;
  static constexpr std::array<std::pair<int, int>, 3> pairs{{{0, 1}, {0, 2}, {1, 2}}};
  for (std::size_t k = 0; k < bin_Hz.size(); ++k) {
    if (!all && (bin_Hz[k] < from_Hz || bin_Hz[k] > to_Hz)) continue;
    for (int i = 0; i < 3; ++i)
      if (!psd_g2_per_Hz[static_cast<std::size_t>(i)].empty()) C(i, i) += psd_g2_per_Hz[static_cast<std::size_t>(i)][k] * resolution_Hz;
    for (std::size_t p = 0; p < 3; ++p)
      if (!csd_g2_per_Hz[p].empty()) {
        const auto [i, j] = pairs[p];
        C(i, j) += csd_g2_per_Hz[p][k].real() * resolution_Hz;
        C(j, i) = C(i, j);
      }
  }
  return C;
}

namespace {

std::string axes_of(const std::array<bool, 3>& present) {
  std::string s;
  for (int i = 0; i < 3; ++i)
    if (present[static_cast<std::size_t>(i)]) s += std::string(s.empty() ? "" : ",") + kAxis[i];
  return s;
}

}  // namespace

MotionDeparture sine_departure(const ReferenceAnalysis& a, const Vec3& commanded_g) {
  MotionDeparture d;
  d.kind = VibrationKind::sine, d.axes = axes_of(a.present), d.sample_rate_Hz = a.sample_rate_Hz, d.samples = a.samples;
  Vec3 mask = Vec3::Zero();
  for (int i = 0; i < 3; ++i) mask[i] = a.present[static_cast<std::size_t>(i)] ? 1.0 : 0.0;
  d.commanded_rms_g = commanded_g.cwiseProduct(mask).norm() / std::sqrt(2.0);
  d.measured_rms_g = a.rms_g.norm();
  d.measured_rms_axis_g = a.rms_g;
  if (d.commanded_rms_g > 0) d.rms_ratio = d.measured_rms_g / d.commanded_rms_g;
  const Eigen::Vector3cd& W1 = a.harmonic_g[1];
  const double w1 = W1.norm();
  // sigma of |W| for a vector of complex parts each with sigma s_i per real component: to
  // first order the projection of the noise on W's direction, bounded by the largest s_i.
  const double s = a.amplitude_sigma_g.maxCoeff();
  if (w1 > 0) {
    for (int h = 2; h <= 3; ++h) {
      const double wh = a.harmonic_g[static_cast<std::size_t>(h)].norm();
      const double r = wh / w1, sr = s / w1 * std::sqrt(1 + r * r);
      (h == 2 ? d.harmonic2_ratio : d.harmonic3_ratio) = r;
      (h == 2 ? d.harmonic2_sigma : d.harmonic3_sigma) = sr;
    }
  }
  const double A = commanded_g.norm();
  // The harmonic and transverse ratios are about the commanded direction: only when every axis
  // it has a part on is measured (else |W_1| is a transverse part alone).
  bool along_measured = true;
  for (int i = 0; i < 3; ++i) along_measured = along_measured && (commanded_g[i] == 0 || a.present[static_cast<std::size_t>(i)]);
  if (!along_measured) d.harmonic2_ratio = d.harmonic2_sigma = d.harmonic3_ratio = d.harmonic3_sigma = NAN;
  if (A > 0 && w1 > 0 && along_measured) {
    const Vec3 dir = commanded_g / A;
    // The part along d (complex: its phase is the table's), the rest across.
    const std::complex<double> along = dir.cast<std::complex<double>>().dot(W1);
    const Eigen::Vector3cd across = W1 - along * dir.cast<std::complex<double>>();
    const double al = std::abs(along);
    d.fundamental_ratio = al / A;
    if (al > 0) {
      d.transverse_ratio = across.norm() / al;
      d.transverse_sigma = s / al * std::sqrt(1 + d.transverse_ratio * d.transverse_ratio);
      for (int i = 0; i < 3; ++i)
        d.transverse_axis_ratio[i] = a.present[static_cast<std::size_t>(i)] ? std::abs(across[i]) / al : NAN;
    }
  }
  return d;
}

MotionDeparture random_departure(const ReferenceAnalysis& a, const Eigen::Matrix3d& commanded) {
  MotionDeparture d;
  d.kind = VibrationKind::random, d.axes = axes_of(a.present);
  d.sample_rate_Hz = a.sample_rate_Hz, d.samples = a.samples;
  d.resolution_Hz = a.resolution_Hz, d.dof = a.dof, d.segments = a.segments;
  Eigen::Matrix3d mask = Eigen::Matrix3d::Zero();
  for (int i = 0; i < 3; ++i) mask(i, i) = a.present[static_cast<std::size_t>(i)] ? 1.0 : 0.0;
  d.commanded_rms_g = std::sqrt((mask * commanded * mask).trace());
  d.measured_rms_g = a.rms_g.norm();
  d.measured_rms_axis_g = a.rms_g;
  if (d.commanded_rms_g > 0) d.rms_ratio = d.measured_rms_g / d.commanded_rms_g;
  // The commanded direction: the principal axis of the commanded covariance.
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> es(commanded);
  const Vec3 dir = es.eigenvectors().col(2);
  const Eigen::Matrix3d C = a.band_covariance_g2();
  const double along = dir.dot(C * dir), total = C.trace();
  if (along > 0) {
    const double across = std::max(0.0, total - along);
    d.transverse_ratio = std::sqrt(across / along);
    // The band covariance sums many bins: its relative sigma is that of a chi^2 with about
    // dof x (bins) / 2 degrees of freedom (adjacent Hann bins are correlated: / 2). The
    // ratio of two such estimates (square root): sigma ~ ratio x sqrt(2 / nu_band) / sqrt(2).
    const double nu_band = std::max(1.0, a.dof * static_cast<double>(a.bin_Hz.size()) / 2);
    d.transverse_sigma = d.transverse_ratio * std::sqrt(1.0 / nu_band);
    for (int i = 0; i < 3; ++i) {
      if (!a.present[static_cast<std::size_t>(i)]) continue;
      const Vec3 e = Vec3::Unit(i) - dir * dir[i];
      d.transverse_axis_ratio[i] = std::sqrt(std::max(0.0, e.dot(C * e)) / along);
    }
  }
  return d;
}

vibration::PsdTable welch_table(const ReferenceAnalysis& a, int axis, double from_Hz, double to_Hz) {
  const auto& p = a.psd_g2_per_Hz[static_cast<std::size_t>(axis)];
  vibration::PsdTable t;
  double top = 0;
  for (std::size_t k = 0; k < p.size(); ++k)
    if (a.bin_Hz[k] >= from_Hz && a.bin_Hz[k] <= to_Hz) top = std::max(top, p[k]);
  // Each bin a step over its width (two rows, 0.1 % of a bin apart from the next bin's), so
  // that the table's integral is Welch's sum of bins (Parseval: the measured variance); a
  // straight line on log-log axes between bin centres would lose the power at a sharp band edge.
  const double half = 0.499 * a.resolution_Hz;
  for (std::size_t k = 0; k < p.size(); ++k)
    if (a.bin_Hz[k] >= from_Hz && a.bin_Hz[k] <= to_Hz) {
      const double level = std::max(p[k], 1e-12 * top);
      t.rows.push_back(vibration::PsdRow::level(a.bin_Hz[k] - half, level));
      t.rows.push_back(vibration::PsdRow::level(a.bin_Hz[k] + half, level));
    }
  return t;
}

vibration::CrossSpectralMatrix welch_matrix(const ReferenceAnalysis& a, double from_Hz, double to_Hz) {
  if (!(a.present[0] && a.present[1] && a.present[2]))
    throw std::invalid_argument("reference channels: the cross-spectral matrix needs all three axes");
  static constexpr std::array<std::pair<int, int>, 3> pairs{{{0, 1}, {0, 2}, {1, 2}}};
  vibration::CrossSpectralMatrix m;
  m.resolution_Hz = a.resolution_Hz;
  for (std::size_t k = 0; k < a.bin_Hz.size(); ++k) {
    if (a.bin_Hz[k] < from_Hz || a.bin_Hz[k] > to_Hz) continue;
    Eigen::Matrix3cd s = Eigen::Matrix3cd::Zero();
    for (int i = 0; i < 3; ++i) s(i, i) = a.psd_g2_per_Hz[static_cast<std::size_t>(i)][k];
    for (std::size_t p = 0; p < 3; ++p) {
      const auto [i, j] = pairs[p];
      const std::complex<double> v = a.csd_g2_per_Hz[p].empty() ? 0.0 : a.csd_g2_per_Hz[p][k];
      s(i, j) = v, s(j, i) = std::conj(v);
    }
    m.frequency_Hz.push_back(a.bin_Hz[k]);
    m.s_g2_per_Hz.push_back(s);
  }
  if (m.frequency_Hz.empty())
    throw std::invalid_argument(fmt::format("reference channels: no Welch bin ({:g} Hz bins) in {:g} - {:g} Hz", a.resolution_Hz,
                                            from_Hz, to_Hz));
  return m;
}

}  // namespace vrelab::rectification
