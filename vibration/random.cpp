#include "vibration/random.hpp"

#include "vibration/detail.hpp"

#include <fftw3.h>

#include <algorithm>
#include <climits>
#include <cmath>
#include <memory>
#include <mutex>
#include <new>
#include <numbers>
#include <random>
#include <sstream>
#include <stdexcept>
#include <type_traits>

namespace vrelab::vibration {

std::mutex& fftw_planner_mutex() {
  static std::mutex m;
  return m;
}
namespace {

// RAII owners for FFTW: buffers from fftw_malloc freed by fftw_free, plans destroyed by
// fftw_destroy_plan under fftw_planner_mutex() (random.hpp).
std::mutex& planner_mutex() { return fftw_planner_mutex(); }
struct FftwFree {
  void operator()(void* p) const { fftw_free(p); }
};
struct PlanDestroy {
  void operator()(fftw_plan p) const {
    std::lock_guard lock(planner_mutex());
    fftw_destroy_plan(p);
  }
};
template <class T>
using FftwBuffer = std::unique_ptr<T[], FftwFree>;
using Plan = std::unique_ptr<std::remove_pointer_t<fftw_plan>, PlanDestroy>;

template <class T>
FftwBuffer<T> fftw_buffer(std::size_t n) {
  void* p = fftw_malloc(sizeof(T) * n);
  if (p == nullptr) throw std::bad_alloc();
  return FftwBuffer<T>(static_cast<T*>(p));
}

int fft_length(std::size_t n, const char* what) {
  if (n > static_cast<std::size_t>(INT_MAX))
    throw std::invalid_argument(std::string(what) + " = " + std::to_string(n) + " samples exceeds the FFT limit of " +
                                std::to_string(INT_MAX));
  return static_cast<int>(n);
}

Plan plan_c2r(int n, fftw_complex* in, double* out) {
  std::lock_guard lock(planner_mutex());
  fftw_plan p = fftw_plan_dft_c2r_1d(n, in, out, FFTW_ESTIMATE);
  if (p == nullptr) throw std::runtime_error("fftw_plan_dft_c2r_1d failed for n = " + std::to_string(n));
  return Plan(p);
}

Plan plan_r2c(int n, double* in, fftw_complex* out) {
  std::lock_guard lock(planner_mutex());
  fftw_plan p = fftw_plan_dft_r2c_1d(n, in, out, FFTW_ESTIMATE);
  if (p == nullptr) throw std::runtime_error("fftw_plan_dft_r2c_1d failed for n = " + std::to_string(n));
  return Plan(p);
}

using detail::kAxisName;
using detail::num;

void check_rate(const RandomProfile& p, double fs) {
  if (!std::isfinite(fs) || fs <= 0)
    throw std::invalid_argument("sample_rate_Hz = " + num(fs) + " must be a finite number > 0");
  const double fmax = max_frequency_Hz(p);
  if (!(fs > 2 * fmax))
    throw std::invalid_argument("sample_rate_Hz = " + num(fs) + " must be above twice the PSD's top frequency (" +
                                num(fmax) + " Hz)");
}

// Uniform in [0, 1) from the top 53 bits: the same numbers from every standard library.
double unit_uniform(std::mt19937_64& e) { return static_cast<double>(e() >> 11) * 0x1p-53; }

}  // namespace

void detail::draw_block_phases(AxisCoupling coupling, std::uint64_t seed, std::int64_t block_index, std::size_t kmax,
                               std::array<std::vector<double>, 3>& phase, const std::array<bool, 3>& wanted) {
  const auto b = static_cast<std::uint64_t>(block_index);
  std::seed_seq seq{static_cast<std::uint32_t>(seed), static_cast<std::uint32_t>(seed >> 32),
                    static_cast<std::uint32_t>(b), static_cast<std::uint32_t>(b >> 32)};
  std::mt19937_64 engine(seq);
  const bool common = coupling == AxisCoupling::common;
  for (int a = 0; a < 3; ++a) {
    if (a > 0 && common) {
      if (wanted[static_cast<std::size_t>(a)]) phase[a] = phase[0];
      continue;
    }
    // Common: x's phases are the others' too. Independent: an axis not wanted is drawn only
    // as far as the engine must advance for a wanted axis after it.
    bool needed = wanted[static_cast<std::size_t>(a)] || (common && (wanted[1] || wanted[2]));
    if (!needed) {
      bool later = false;
      for (int c = a + 1; c < 3; ++c) later |= wanted[static_cast<std::size_t>(c)];
      if (later) engine.discard(kmax);
      continue;
    }
    phase[a].resize(kmax + 1);
    phase[a][0] = 0.0;
    for (std::size_t k = 1; k <= kmax; ++k) phase[a][k] = 2 * std::numbers::pi * unit_uniform(engine);
  }
}

Eigen::Matrix3cd CrossSpectralMatrix::at(double f) const {
  if (frequency_Hz.empty() || !(resolution_Hz > 0)) return Eigen::Matrix3cd::Zero();
  // Bin k covers [f_k - res/2, f_k + res/2]: k = ceil((f - f_0) / res - 1/2), the lower at an edge.
  const double u = (f - frequency_Hz.front()) / resolution_Hz;
  if (u < -0.5 || u > static_cast<double>(frequency_Hz.size()) - 0.5) return Eigen::Matrix3cd::Zero();
  const auto k = static_cast<std::size_t>(std::max(0.0, std::ceil(u - 0.5)));
  return s_g2_per_Hz[std::min(k, s_g2_per_Hz.size() - 1)];
}

void validate(const CrossSpectralMatrix& m) {
  if (m.frequency_Hz.empty()) throw std::invalid_argument("measured cross-spectral matrix: no bins");
  if (m.s_g2_per_Hz.size() != m.frequency_Hz.size())
    throw std::invalid_argument(std::string("measured cross-spectral matrix: ") + std::to_string(m.s_g2_per_Hz.size()) + " matrices for " +
                                std::to_string(m.frequency_Hz.size()) + " bins");
  if (!(m.resolution_Hz > 0) || !std::isfinite(m.resolution_Hz))
    throw std::invalid_argument("measured cross-spectral matrix: resolution_Hz = " + num(m.resolution_Hz) + " must be > 0");
  if (!(m.from_Hz() >= 0)) throw std::invalid_argument("measured cross-spectral matrix: the first bin reaches below 0 Hz");
  for (std::size_t k = 0; k < m.frequency_Hz.size(); ++k) {
    if (k > 0 && std::abs(m.frequency_Hz[k] - m.frequency_Hz[k - 1] - m.resolution_Hz) > 1e-6 * m.resolution_Hz)
      throw std::invalid_argument(std::string("measured cross-spectral matrix: bin ") + std::to_string(k) + " at " + num(m.frequency_Hz[k]) +
                                  " Hz is not one resolution above the previous");
    const Eigen::Matrix3cd& s = m.s_g2_per_Hz[k];
    const double scale = s.cwiseAbs().maxCoeff();
    if (!std::isfinite(scale) || (s - s.adjoint()).cwiseAbs().maxCoeff() > 1e-9 * scale)
      throw std::invalid_argument(std::string("measured cross-spectral matrix: bin ") + std::to_string(k) + " is not finite and Hermitian");
    for (int i = 0; i < 3; ++i)
      if (s(i, i).real() < 0)
        throw std::invalid_argument(std::string("measured cross-spectral matrix: bin ") + std::to_string(k) + " has a negative PSD");
  }
}

void validate(const RandomProfile& p) {
  if (p.measured) validate(*p.measured);
  bool any = false;
  for (int i = 0; i < 3; ++i) {
    if (!p.psd[i]) continue;
    any = true;
    try {
      validate(*p.psd[i]);
    } catch (const std::invalid_argument& e) {
      throw std::invalid_argument(std::string("psd[") + kAxisName[i] + "]: " + e.what());
    }
  }
  if (!any) throw std::invalid_argument("psd: no axis has a PSD table");
}

void scale_levels(RandomProfile& p, double factor) {
  if (!(factor > 0) || !std::isfinite(factor)) throw std::invalid_argument("scale_levels: factor must be positive");
  if (p.measured) throw std::invalid_argument("scale_levels: a measured cross-spectral matrix is not scaled");
  for (auto& t : p.psd)
    if (t)
      for (auto& row : t->rows)
        if (row.psd_g2_per_Hz) *row.psd_g2_per_Hz *= factor;
}

double max_frequency_Hz(const RandomProfile& p) {
  validate(p);
  double f = 0;
  for (const auto& t : p.psd)
    if (t) f = std::max(f, t->rows.back().frequency_Hz);
  return f;
}

std::string describe(const RandomProfile& p) {
  validate(p);
  std::string s = p.measured ? "random (measured cross-spectra)"
                 : p.coupling == AxisCoupling::common ? "random (common phases)" : "random (independent axes)";
  for (int i = 0; i < 3; ++i)
    if (p.psd[i]) s += std::string("; ") + kAxisName[i] + ": " + describe(*p.psd[i]);
  return s;
}

SampledSignal random_phase_block(const RandomProfile& p, std::size_t length, double fs, std::uint64_t seed,
                                 std::int64_t block_index) {
  validate(p);
  check_rate(p, fs);
  if (length < 16) throw std::invalid_argument("block length = " + std::to_string(length) + " must be >= 16 samples");
  const int n = fft_length(length, "block length");
  const std::size_t nbins = length / 2 + 1;

  // Bins 0 < k < N/2 carry power; phases are drawn for all of them (whatever the levels) so
  // the draw sequence depends only on (seed, block, N).
  const std::size_t kmax = (length - 1) / 2;  // last k with 2k < N
  std::array<std::vector<double>, 3> phase;
  detail::draw_block_phases(p.coupling, seed, block_index, kmax, phase);

  SampledSignal out;
  out.sample_rate_Hz = fs;
  auto spec = fftw_buffer<fftw_complex>(nbins);
  auto sig = fftw_buffer<double>(length);
  const Plan plan = plan_c2r(n, spec.get(), sig.get());
  for (int a = 0; a < 3; ++a) {
    out.samples_g[a].assign(length, 0.0);
    if (!p.psd[a]) continue;
    const ResolvedPsd psd = resolve(*p.psd[a]);
    for (std::size_t k = 0; k < nbins; ++k) spec[k][0] = spec[k][1] = 0.0;
    for (std::size_t k = 1; k <= kmax; ++k) {
      const double g = psd_g2_per_Hz(psd, static_cast<double>(k) * fs / static_cast<double>(length));
      if (g == 0.0) continue;
      const double amp = std::sqrt(g * fs / (2.0 * static_cast<double>(length)));
      double sn, cs;
      ::sincos(phase[a][k], &sn, &cs);  // glibc: the same numbers as std::sin and std::cos
      spec[k][0] = amp * cs;
      spec[k][1] = amp * sn;
    }
    fftw_execute_dft_c2r(plan.get(), spec.get(), sig.get());
    std::copy(sig.get(), sig.get() + length, out.samples_g[a].begin());
  }
  return out;
}

SampledSignal synthesize_random(const RandomProfile& p, double duration_s, double fs, std::uint64_t seed) {
  if (!std::isfinite(duration_s) || duration_s <= 0)
    throw std::invalid_argument("duration_s = " + num(duration_s) + " must be a finite number > 0");
  validate(p);
  check_rate(p, fs);
  const double n = std::round(duration_s * fs);
  if (n < 16)
    throw std::invalid_argument("duration_s = " + num(duration_s) + " gives " + num(n) +
                                " samples at sample_rate_Hz; at least 16 are needed");
  if (n > static_cast<double>(INT_MAX))
    throw std::invalid_argument("duration_s = " + num(duration_s) + " exceeds the single-FFT limit of " +
                                std::to_string(INT_MAX) + " samples; use RandomExcitation");
  return random_phase_block(p, static_cast<std::size_t>(n), fs, seed, 0);
}

PsdEstimate welch_psd(std::span<const double> x, double fs, std::size_t L) {
  if (!std::isfinite(fs) || fs <= 0)
    throw std::invalid_argument("sample_rate_Hz = " + num(fs) + " must be a finite number > 0");
  if (L < 8 || L % 2 != 0)
    throw std::invalid_argument("segment_length = " + std::to_string(L) + " must be even and >= 8");
  if (x.size() < L)
    throw std::invalid_argument("signal of " + std::to_string(x.size()) +
                                " samples is shorter than segment_length = " + std::to_string(L));
  const int n = fft_length(L, "segment_length");
  const std::size_t nbins = L / 2 + 1, hop = L / 2;

  std::vector<double> w(L);
  double sum_w2 = 0;
  for (std::size_t i = 0; i < L; ++i) {
    w[i] = 0.5 - 0.5 * std::cos(2 * std::numbers::pi * static_cast<double>(i) / static_cast<double>(L));
    sum_w2 += w[i] * w[i];
  }
  auto in = fftw_buffer<double>(L);
  auto out = fftw_buffer<fftw_complex>(nbins);
  const Plan plan = plan_r2c(n, in.get(), out.get());

  PsdEstimate est;
  est.psd_g2_per_Hz.assign(nbins, 0.0);
  for (std::size_t start = 0; start + L <= x.size(); start += hop) {
    for (std::size_t i = 0; i < L; ++i) in[i] = w[i] * x[start + i];
    fftw_execute_dft_r2c(plan.get(), in.get(), out.get());
    for (std::size_t k = 0; k < nbins; ++k) est.psd_g2_per_Hz[k] += out[k][0] * out[k][0] + out[k][1] * out[k][1];
    ++est.segments;
  }
  const double scale = 1.0 / (fs * sum_w2 * static_cast<double>(est.segments));
  est.frequency_Hz.resize(nbins);
  for (std::size_t k = 0; k < nbins; ++k) {
    const double c = (k == 0 || k == L / 2) ? 1.0 : 2.0;
    est.psd_g2_per_Hz[k] *= c * scale;
    est.frequency_Hz[k] = static_cast<double>(k) * fs / static_cast<double>(L);
  }
  return est;
}

RandomVibration gaussian_equivalent(const RandomProfile& p) {
  validate(p);
  RandomVibration g;
  g.correlation = Eigen::Matrix3d::Identity();
  std::array<std::optional<ResolvedPsd>, 3> r;
  for (int i = 0; i < 3; ++i)
    if (p.psd[static_cast<std::size_t>(i)]) {
      r[static_cast<std::size_t>(i)] = resolve(*p.psd[static_cast<std::size_t>(i)]);
      g.rms_g[i] = rms_g(*p.psd[static_cast<std::size_t>(i)]);
    }
  if (p.measured) {
    Eigen::Matrix3d c = Eigen::Matrix3d::Zero();
    for (const Eigen::Matrix3cd& s : p.measured->s_g2_per_Hz) c += s.real() * p.measured->resolution_Hz;
    for (int i = 0; i < 3; ++i) g.rms_g[i] = std::sqrt(std::max(0.0, c(i, i)));
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j)
        if (i != j && g.rms_g[i] > 0 && g.rms_g[j] > 0) g.correlation(i, j) = std::clamp(c(i, j) / (g.rms_g[i] * g.rms_g[j]), -1.0, 1.0);
    return g;
  }
  if (p.coupling == AxisCoupling::common) {
    // Cross integrals on a fine log grid (trapezoid in log f): the integrand is a power law
    // between merged breakpoints, so 20000 points give ~1e-8 relative.
    for (int i = 0; i < 3; ++i)
      for (int j = i + 1; j < 3; ++j) {
        const auto& a = r[static_cast<std::size_t>(i)];
        const auto& b = r[static_cast<std::size_t>(j)];
        if (!a || !b) continue;
        const double lo = std::max(a->frequency_Hz.front(), b->frequency_Hz.front());
        const double hi = std::min(a->frequency_Hz.back(), b->frequency_Hz.back());
        double integral = 0;
        if (hi > lo) {
          const int n = 20000;
          double prev = 0;
          for (int k = 0; k <= n; ++k) {
            const double f = lo * std::pow(hi / lo, static_cast<double>(k) / n);
            const double v = std::sqrt(psd_g2_per_Hz(*a, f) * psd_g2_per_Hz(*b, f)) * f;  // d f = f d ln f
            if (k > 0) integral += 0.5 * (v + prev) * std::log(hi / lo) / n;
            prev = v;
          }
        }
        g.correlation(i, j) = g.correlation(j, i) = integral / (g.rms_g[i] * g.rms_g[j]);
      }
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j)
        if (g.rms_g[i] == 0 || g.rms_g[j] == 0) g.correlation(i, j) = i == j ? 1.0 : 0.0;
  }
  return g;
}

}  // namespace vrelab::vibration
