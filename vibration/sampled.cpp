#include "vibration/sampled.hpp"

#include "vibration/detail.hpp"

#include <fftw3.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <new>
#include <numbers>
#include <sstream>
#include <stdexcept>
#include <utility>

namespace vrelab::vibration {
namespace {

constexpr std::int64_t kMargin = kQuinticPrefilterMargin;
constexpr double kPoles[2] = {-0.43057534709997379, -0.043096288203264653};

using detail::num;

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

// Weights of nodes floor(p) - 2 .. floor(p) + 3 at fraction u = p - floor(p) in [0, 1):
// beta5(u - k), k = -2..3 (Thevenaz, Blu & Unser's factorised form, exact to rounding).
std::array<double, 6> quintic_weights(double u) {
  std::array<double, 6> w{};
  double w2 = u * u;
  w[5] = (1.0 / 120.0) * u * w2 * w2;
  w2 -= u;
  const double w4 = w2 * w2;
  const double h = u - 0.5;
  const double t = w2 * (w2 - 3.0);
  w[0] = (1.0 / 24.0) * (1.0 / 5.0 + w2 + w4) - w[5];
  double t0 = (1.0 / 24.0) * (w2 * (w2 - 5.0) + 46.0 / 5.0);
  double t1 = (-1.0 / 12.0) * h * (t + 4.0);
  w[2] = t0 + t1;
  w[3] = t0 - t1;
  t0 = (1.0 / 16.0) * (9.0 / 5.0 - t);
  t1 = (1.0 / 24.0) * h * (w4 - w2 - 5.0);
  w[1] = t0 + t1;
  w[4] = t0 - t1;
  return w;
}

std::int64_t floor_div(std::int64_t a, std::int64_t b) { return a / b - ((a % b != 0) && ((a < 0) != (b < 0))); }

double check_time(double t, double fs) {
  const double p = t * fs;
  if (!std::isfinite(p) || std::abs(p) > 9.0e15)
    throw std::invalid_argument("t_s = " + num(t) + " is not finite or too large for the sample index");
  return p;
}

using Coefficients3 = std::array<std::vector<double>, 3>;

}  // namespace

void quintic_prefilter(std::vector<double>& c) { prefilter(c); }

// ---------------------------------------------------------------- SampledExcitation

SampledExcitation::SampledExcitation(const SampledSignal& s, EndBehaviour end, double content_max_frequency_Hz)
    : fs_(s.sample_rate_Hz), n_(s.size()), end_(end), max_frequency_Hz_(content_max_frequency_Hz) {
  if (!std::isfinite(fs_) || fs_ <= 0)
    throw std::invalid_argument("sample_rate_Hz = " + num(fs_) + " must be a finite number > 0");
  if (n_ < 6) throw std::invalid_argument("samples_g: " + std::to_string(n_) + " samples; at least 6 are needed");
  for (int a = 0; a < 3; ++a) {
    if (s.samples_g[a].size() != n_)
      throw std::invalid_argument("samples_g: the axes have different lengths (" + std::to_string(n_) + " and " +
                                  std::to_string(s.samples_g[a].size()) + ")");
    for (double v : s.samples_g[a])
      if (!std::isfinite(v)) throw std::invalid_argument("samples_g has a non-finite sample");
  }
  if (!std::isfinite(max_frequency_Hz_) || max_frequency_Hz_ < 0 || max_frequency_Hz_ > fs_ / 2)
    throw std::invalid_argument("content_max_frequency_Hz = " + num(max_frequency_Hz_) +
                                " must be in [0, sample_rate_Hz / 2]");
  if (max_frequency_Hz_ == 0) max_frequency_Hz_ = fs_ / 2;

  const auto n = static_cast<std::int64_t>(n_);
  for (int a = 0; a < 3; ++a) {
    const std::vector<double>& x = s.samples_g[a];
    // Periodic: the period [0, N) with kMargin wrapped samples on each side.
    // Zero: [-kMargin, N + kMargin) of the zero-extended sequence, itself with margins of zeros.
    const std::int64_t lo = end_ == EndBehaviour::periodic ? -kMargin : -2 * kMargin;
    const std::int64_t hi = end_ == EndBehaviour::periodic ? n + kMargin : n + 2 * kMargin;
    std::vector<double> buf(static_cast<std::size_t>(hi - lo));
    for (std::int64_t i = lo; i < hi; ++i) {
      double v = 0;
      if (end_ == EndBehaviour::periodic)
        v = x[static_cast<std::size_t>(((i % n) + n) % n)];
      else if (i >= 0 && i < n)
        v = x[static_cast<std::size_t>(i)];
      buf[static_cast<std::size_t>(i - lo)] = v;
    }
    prefilter(buf);
    coef_[a].assign(buf.begin() + kMargin, buf.end() - kMargin);
  }
}

Vec3 SampledExcitation::acceleration_g(double t) const {
  const double p = check_time(t, fs_);
  const double fl = std::floor(p);
  const auto m = static_cast<std::int64_t>(fl);
  const std::array<double, 6> w = quintic_weights(p - fl);
  const auto n = static_cast<std::int64_t>(n_);
  const auto size = static_cast<std::int64_t>(coef_[0].size());
  Vec3 out = Vec3::Zero();
  for (int k = 0; k < 6; ++k) {
    std::int64_t i = m - 2 + k;
    if (end_ == EndBehaviour::periodic) {
      i = ((i % n) + n) % n;
    } else {
      i += kMargin;
      if (i < 0 || i >= size) continue;
    }
    for (int a = 0; a < 3; ++a) out[a] += w[k] * coef_[a][static_cast<std::size_t>(i)];
  }
  return out;
}

std::string SampledExcitation::describe() const {
  return "sampled signal, " + std::to_string(n_) + " samples at " + num(fs_) + " Hz (" + num(duration_s()) + " s, " +
         (end_ == EndBehaviour::periodic ? "periodic" : "zero outside") + ")";
}

// ---------------------------------------------------------------- RandomExcitation

// Named rather than anonymous: RandomExcitation::Cache, a class with linkage, holds them (GCC's
// -Wsubobject-linkage when this file is compiled inside a unity build).
namespace sampled_internal {

// Small least-recently-used cache keyed by an index.
template <class T>
class Lru {
 public:
  explicit Lru(std::size_t capacity) : capacity_(capacity) {}
  template <class Make>
  std::shared_ptr<const T> get(std::int64_t key, Make&& make) {
    for (std::size_t i = 0; i < items_.size(); ++i)
      if (items_[i].first == key) {
        std::rotate(items_.begin(), items_.begin() + static_cast<std::ptrdiff_t>(i),
                    items_.begin() + static_cast<std::ptrdiff_t>(i) + 1);
        return items_.front().second;
      }
    auto value = std::make_shared<const T>(make());
    items_.insert(items_.begin(), {key, value});
    if (items_.size() > capacity_) items_.pop_back();
    return value;
  }
  std::size_t capacity() const { return capacity_; }

 private:
  std::size_t capacity_;
  std::vector<std::pair<std::int64_t, std::shared_ptr<const T>>> items_;
};

// random_phase_block(profile, M, fs, seed, j) for a RandomExcitation's blocks, bit for bit,
// with what does not depend on j made once: the amplitude of every bin (the PSD's log-log
// interpolation, a pow and a log per bin), the FFTW plan (FFTW_ESTIMATE, as random_phase_block
// plans it; an FFTW plan gives the same numbers for the same size and flags) and its aligned
// buffers. The phases are drawn by the same function (detail::draw_block_phases) and turned
// into the spectrum exactly as random_phase_block does (test
// RandomExcitation.BlocksEqualRandomPhaseBlockBitForBit checks the equality).
class BlockSynthesiser {
 public:
  BlockSynthesiser(const RandomProfile& p, double fs, std::uint64_t seed, std::size_t m)
      : profile_(p), seed_(seed), m_(m), kmax_((m - 1) / 2) {
    for (int a = 0; a < 3; ++a) {
      if (!p.psd[a]) continue;
      const ResolvedPsd psd = resolve(*p.psd[a]);
      for (std::size_t k = 1; k <= kmax_; ++k) {
        const double g = psd_g2_per_Hz(psd, static_cast<double>(k) * fs / static_cast<double>(m));
        if (g == 0.0) continue;
        bins_[a].push_back(k);
        amp_[a].push_back(std::sqrt(g * fs / (2.0 * static_cast<double>(m))));
      }
    }
    spec_ = static_cast<fftw_complex*>(fftw_malloc(sizeof(fftw_complex) * (m / 2 + 1)));
    sig_ = static_cast<double*>(fftw_malloc(sizeof(double) * m));
    if (spec_ == nullptr || sig_ == nullptr) {
      release();
      throw std::bad_alloc();
    }
    std::lock_guard lock(fftw_planner_mutex());
    plan_ = fftw_plan_dft_c2r_1d(static_cast<int>(m), spec_, sig_, FFTW_ESTIMATE);
    if (plan_ == nullptr) {
      release();
      throw std::runtime_error("fftw_plan_dft_c2r_1d failed for n = " + std::to_string(m));
    }
  }
  ~BlockSynthesiser() { release(); }
  BlockSynthesiser(const BlockSynthesiser&) = delete;
  BlockSynthesiser& operator=(const BlockSynthesiser&) = delete;

  SampledSignal block(double fs, std::int64_t block_index) {
    // Only the axes with a PSD are drawn and kept: stream_samples reads no other (an axis
    // without one is +0, written there); the wanted axes' numbers are the same.
    const std::array<bool, 3> wanted{static_cast<bool>(profile_.psd[0]), static_cast<bool>(profile_.psd[1]),
                                     static_cast<bool>(profile_.psd[2])};
    detail::draw_block_phases(profile_.coupling, seed_, block_index, kmax_, phase_, wanted);
    SampledSignal out;
    out.sample_rate_Hz = fs;
    const std::size_t nbins = m_ / 2 + 1;
    for (int a = 0; a < 3; ++a) {
      if (!profile_.psd[a]) continue;  // left empty
      for (std::size_t k = 0; k < nbins; ++k) spec_[k][0] = spec_[k][1] = 0.0;
      for (std::size_t i = 0; i < bins_[a].size(); ++i) {
        const std::size_t k = bins_[a][i];
        double sn, cs;
        ::sincos(phase_[a][k], &sn, &cs);  // glibc: the same numbers as std::sin and std::cos
        spec_[k][0] = amp_[a][i] * cs;
        spec_[k][1] = amp_[a][i] * sn;
      }
      fftw_execute_dft_c2r(plan_, spec_, sig_);
      out.samples_g[a].assign(sig_, sig_ + m_);
    }
    return out;
  }
  std::size_t bytes() const {
    std::size_t n = sizeof(fftw_complex) * (m_ / 2 + 1) + sizeof(double) * m_;
    for (int a = 0; a < 3; ++a) n += bins_[a].size() * (sizeof(std::size_t) + sizeof(double)) + phase_[a].capacity() * sizeof(double);
    return n;
  }

 private:
  void release() {
    if (plan_ != nullptr) {
      std::lock_guard lock(fftw_planner_mutex());
      fftw_destroy_plan(plan_);
    }
    fftw_free(spec_);
    fftw_free(sig_);
    plan_ = nullptr, spec_ = nullptr, sig_ = nullptr;
  }
  const RandomProfile& profile_;
  std::uint64_t seed_;
  std::size_t m_, kmax_;
  std::array<std::vector<std::size_t>, 3> bins_;  // bins with power, per axis
  std::array<std::vector<double>, 3> amp_;        // their amplitudes
  std::array<std::vector<double>, 3> phase_;      // the block's phases (storage reused)
  fftw_complex* spec_ = nullptr;
  double* sig_ = nullptr;
  fftw_plan plan_ = nullptr;
};

}  // namespace sampled_internal

struct RandomExcitation::Cache {
  std::mutex mutex;
  sampled_internal::Lru<SampledSignal> blocks{4};
  sampled_internal::Lru<Coefficients3> stretches{3};
  // Made on first use (a RandomExcitation that is only described costs nothing).
  std::unique_ptr<sampled_internal::BlockSynthesiser> synthesiser;
  // The overlap-add weights cos(pi r / M), sin(pi r / M), r = 0 .. M/2 - 1.
  std::vector<double> w0, w1;
};

RandomExcitation::RandomExcitation(const RandomProfile& profile, double fs, std::uint64_t seed, std::size_t m,
                                   const Eigen::Matrix3d& turn)
    : profile_(profile), fs_(fs), seed_(seed), m_(m), max_frequency_Hz_(0), turn_(turn), turned_(!turn.isIdentity(0)),
      cache_(std::make_unique<Cache>()) {
  max_frequency_Hz_ = vibration::max_frequency_Hz(profile_);  // validates the profile
  if (!turn_.allFinite()) throw std::invalid_argument("turn: not finite");
  if (m_ < 1024 || m_ % 2 != 0)
    throw std::invalid_argument("block_length = " + std::to_string(m_) + " must be even and >= 1024");
  double narrowest = std::numeric_limits<double>::infinity();
  for (const auto& t : profile_.psd)
    if (t)
      for (std::size_t i = 1; i < t->rows.size(); ++i)
        narrowest = std::min(narrowest, t->rows[i].frequency_Hz - t->rows[i - 1].frequency_Hz);
  if (fs_ / static_cast<double>(m_) > narrowest / 4)
    throw std::invalid_argument("block_length = " + std::to_string(m_) + " gives a bin of " +
                                num(fs_ / static_cast<double>(m_)) +
                                " Hz, more than a quarter of the narrowest "
                                "PSD segment (" +
                                num(narrowest) + " Hz)");
  // Checks sample_rate_Hz against the profile once, here, rather than on first use.
  (void)random_phase_block(profile_, 16, fs_, seed_, 0);
}

RandomExcitation::~RandomExcitation() = default;

std::size_t RandomExcitation::memory_bytes() const {
  return cache_->blocks.capacity() * 3 * m_ * sizeof(double) +
         cache_->stretches.capacity() * 3 * (m_ / 2) * sizeof(double);
}

std::size_t RandomExcitation::synthesis_bytes() const {
  std::lock_guard lock(cache_->mutex);
  return (cache_->synthesiser ? cache_->synthesiser->bytes() : 0) + (cache_->w0.size() + cache_->w1.size()) * sizeof(double);
}

namespace {

// Stream samples [first, first + count) into out (count per axis); the cache's lock is held.
void stream_samples(const RandomProfile& profile, double fs, std::uint64_t seed, std::size_t m,
                    RandomExcitation::Cache& cache, std::int64_t first, std::size_t count, Coefficients3& out) {
  const auto h = static_cast<std::int64_t>(m / 2);
  if (!cache.synthesiser) {
    cache.synthesiser = std::make_unique<sampled_internal::BlockSynthesiser>(profile, fs, seed, m);
    cache.w0.resize(static_cast<std::size_t>(h));
    cache.w1.resize(static_cast<std::size_t>(h));
    for (std::int64_t r = 0; r < h; ++r) {
      const double theta = std::numbers::pi * static_cast<double>(r) / static_cast<double>(m);
      cache.w0[static_cast<std::size_t>(r)] = std::cos(theta);
      cache.w1[static_cast<std::size_t>(r)] = std::sin(theta);
    }
  }
  sampled_internal::BlockSynthesiser& synth = *cache.synthesiser;
  // The axes with a PSD are written in full below; the others are +0.
  for (int a = 0; a < 3; ++a) {
    if (profile.psd[a])
      out[a].resize(count);
    else
      out[a].assign(count, 0.0);
  }
  std::size_t i = 0;
  while (i < count) {
    const std::int64_t c = floor_div(first + static_cast<std::int64_t>(i), h);  // [cH, (c+1)H): blocks c, c+1
    const auto b0 = cache.blocks.get(c, [&] { return synth.block(fs, c); });
    const auto b1 = cache.blocks.get(c + 1, [&] { return synth.block(fs, c + 1); });
    // Block c+1 at m = r has weight sin(pi r / M); block c at m = r + H has sin(pi r / M + pi/2).
    const std::int64_t r0 = first + static_cast<std::int64_t>(i) - c * h;  // 0 .. H-1
    const std::size_t n = std::min(count - i, static_cast<std::size_t>(h - r0));
    for (int a = 0; a < 3; ++a) {
      if (!profile.psd[a]) continue;  // the blocks' samples are +0 (assigned above)
      const double* x0 = b0->samples_g[a].data() + r0 + h;
      const double* x1 = b1->samples_g[a].data() + r0;
      const double* w0 = cache.w0.data() + r0;
      const double* w1 = cache.w1.data() + r0;
      double* o = out[a].data() + i;
      for (std::size_t q = 0; q < n; ++q) o[q] = w0[q] * x0[q] + w1[q] * x1[q];
    }
    i += n;
  }
}

}  // namespace

SampledSignal RandomExcitation::samples(std::int64_t first, std::size_t count) const {
  SampledSignal out;
  samples_into(first, count, out);
  return out;
}

void RandomExcitation::samples_into(std::int64_t first, std::size_t count, SampledSignal& out) const {
  out.sample_rate_Hz = fs_;
  std::lock_guard lock(cache_->mutex);
  stream_samples(profile_, fs_, seed_, m_, *cache_, first, count, out.samples_g);
  if (!turned_) return;
  auto& x = out.samples_g;
  for (std::size_t n = 0; n < count; ++n) {
    const Vec3 v = turn_ * Vec3(x[0][n], x[1][n], x[2][n]);
    for (int a = 0; a < 3; ++a) x[a][n] = v[a];
  }
}

Vec3 RandomExcitation::acceleration_g(double t) const {
  const double p = check_time(t, fs_);
  const double fl = std::floor(p);
  const auto m = static_cast<std::int64_t>(fl);
  const std::array<double, 6> w = quintic_weights(p - fl);
  const auto h = static_cast<std::int64_t>(m_ / 2);

  std::lock_guard lock(cache_->mutex);
  // Coefficients of stretch c from the stream samples [cH - kMargin, (c+1)H + kMargin).
  auto stretch = [&](std::int64_t c) {
    return cache_->stretches.get(c, [&] {
      Coefficients3 x;
      stream_samples(profile_, fs_, seed_, m_, *cache_, c * h - kMargin,
                     static_cast<std::size_t>(h + 2 * kMargin), x);
      for (auto& v : x) {
        prefilter(v);
        v.erase(v.end() - kMargin, v.end());
        v.erase(v.begin(), v.begin() + kMargin);
      }
      return x;
    });
  };
  const std::int64_t c_lo = floor_div(m - 2, h), c_hi = floor_div(m + 3, h);
  const auto s_lo = stretch(c_lo);
  const auto s_hi = c_hi == c_lo ? s_lo : stretch(c_hi);
  Vec3 out = Vec3::Zero();
  for (int k = 0; k < 6; ++k) {
    const std::int64_t n = m - 2 + k;
    const bool hi = floor_div(n, h) != c_lo;
    const auto& s = hi ? *s_hi : *s_lo;
    const auto i = static_cast<std::size_t>(n - (hi ? c_hi : c_lo) * h);
    for (int a = 0; a < 3; ++a) out[a] += w[k] * s[a][i];
  }
  return turned_ ? Vec3(turn_ * out) : out;
}

std::string RandomExcitation::describe() const {
  return vibration::describe(profile_) + ", fs " + num(fs_) + " Hz, seed " + std::to_string(seed_) + ", blocks of " +
         std::to_string(m_) + (turned_ ? ", turned" : "");
}

}  // namespace vrelab::vibration
