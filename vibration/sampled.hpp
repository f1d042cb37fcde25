#pragma once
// vibration/sampled.hpp -- Excitations built from sample sequences: a stored signal
// (SampledExcitation) and a PSD-driven random vibration synthesised in blocks
// (RandomExcitation).
//
// Takes: samples in g per axis [IA, PA, OA] at a sample rate fs (Hz); or a RandomProfile,
//        fs, a seed and a block length.
// Gives: acceleration_g(t) continuous in t: the quintic B-spline interpolant through the
//        samples (C4 in t, passes through every sample; see below for its accuracy).
//
// Interpolation: s(t) = sum_n c[n] beta5(t fs - n), the spline coefficients c from the
// samples by the exact inverse of the sampled B-spline (two-pole recursive prefilter,
// Unser 1999, run over each stretch with 48 samples of margin on each side: the poles
// are -0.4306 and -0.0431, so the margin's truncation error is below 0.4306^48 ~ 3e-18 of
// the signal). For a pure tone the interpolant's worst error over t, relative to the
// amplitude, is 2.6e-7 at fs/16 and 2.1e-5 at fs/8 (test SampledExcitation.ToneErrorBelowFs8);
// above fs/8 it grows (5e-4 at fs/5, 3e-3 at fs/4): keep fs >= 8 x the top frequency.
//
// SampledExcitation, past the ends: `periodic` (default) takes the N samples as one period,
// s(t + N/fs) = s(t) -- seamless for synthesize_random, which is exactly periodic; `zero`
// takes the samples as zero before t = 0 and from t = N/fs on (the shaker at rest; the
// interpolant rings over a few samples at the ends). Memory: the spline coefficients, 8 bytes
// per sample per axis (the samples themselves are not kept).
//
// RandomExcitation: a stationary Gaussian stream of unlimited length. Block j (M = block
// length samples, hop H = M/2) is random_phase_block(profile, M, fs, seed, j), placed on
// samples [(j-1) H, (j+1) H) and weighted by w(m) = sin(pi m / M); neighbours overlap by H.
// Blocks are independent and w(m)^2 + w(m + H)^2 = 1, so the variance is the spec's at every
// sample; the PSD is the spec smoothed over about 2 fs/M (test RandomExcitation.*). Any
// block, hence any time (also t < 0), is regenerated from (seed, j): random access, no
// stored history. Memory is bounded and does not grow with the run: at most 4 blocks
// (3 x 8 M bytes each) and 3 coefficient stretches (3 x 8 H bytes each) are cached --
// memory_bytes(); M = 32768 at 20 kHz: 4.3 MB. Cost: one M-point inverse FFT per axis
// per H samples. The caches are guarded by a mutex: one object may be shared by threads.
#include <array>
#include <cstdint>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "vibration/excitation.hpp"
#include "vibration/random.hpp"

namespace vrelab::vibration {

// In place: samples -> quintic B-spline coefficients (Unser's causal/anticausal recursions).
// Outside the buffer the input is taken as zero; give kQuinticPrefilterMargin samples of real
// context on each side, so that assumption's error has decayed below 0.4306^48 ~ 3e-18 of the
// signal in the middle.
inline constexpr std::int64_t kQuinticPrefilterMargin = 48;
void quintic_prefilter(std::vector<double>& c);

enum class EndBehaviour { periodic, zero };

class SampledExcitation final : public Excitation {
 public:
  // content_max_frequency_Hz: what max_frequency_Hz() reports (the signal's highest
  // frequency when known, e.g. the PSD's top frequency); 0 means fs/2.
  explicit SampledExcitation(const SampledSignal& s, EndBehaviour end = EndBehaviour::periodic,
                             double content_max_frequency_Hz = 0.0);
  Vec3 acceleration_g(double t_s) const override;
  double max_frequency_Hz() const override { return max_frequency_Hz_; }
  std::string describe() const override;
  double duration_s() const { return static_cast<double>(n_) / fs_; }
  double sample_rate_Hz() const { return fs_; }

 private:
  double fs_;
  std::size_t n_;
  EndBehaviour end_;
  double max_frequency_Hz_;
  std::array<std::vector<double>, 3> coef_;  // periodic: n = 0..N-1; zero: n = -P..N+P-1
};

class RandomExcitation final : public Excitation {
 public:
  struct Cache;
  static constexpr std::size_t kDefaultBlockLength = 32768;
  // block_length M: even, >= 1024, and fine enough that fs/M is at most a quarter of the
  // narrowest table segment (otherwise std::invalid_argument naming block_length).
  // turn: the motion in sensor axes is turn x the profile's, sample by sample (a fixture that
  // holds the sensor turned: S' = turn S turn^T); finite, else std::invalid_argument naming turn.
  RandomExcitation(const RandomProfile& profile, double sample_rate_Hz, std::uint64_t seed,
                   std::size_t block_length = kDefaultBlockLength, const Eigen::Matrix3d& turn = Eigen::Matrix3d::Identity());
  ~RandomExcitation() override;
  Vec3 acceleration_g(double t_s) const override;
  double max_frequency_Hz() const override { return max_frequency_Hz_; }
  std::string describe() const override;
  const RandomExcitation* random_samples() const override { return this; }

  // Stream samples n = first .. first + count - 1 (the values acceleration_g passes through
  // at t = n / fs), per axis.
  SampledSignal samples(std::int64_t first, std::size_t count) const;
  // The same into `out`, reusing its vectors' storage (a stream read window by window
  // allocates nothing after the first window).
  void samples_into(std::int64_t first, std::size_t count, SampledSignal& out) const;
  std::size_t memory_bytes() const;
  // Beside the caches, fixed for the object's life once it has synthesised: the amplitude of
  // every bin with power, the FFT's buffers and plan, the blocks' overlap weights (~1.2 MB
  // at M = 32768 with one axis; 0 before the first sample).
  std::size_t synthesis_bytes() const;
  double sample_rate_Hz() const { return fs_; }
  std::size_t block_length() const { return m_; }

 private:
  RandomProfile profile_;
  double fs_;
  std::uint64_t seed_;
  std::size_t m_;
  double max_frequency_Hz_;
  Eigen::Matrix3d turn_;
  bool turned_;  // turn_ is not the identity
  std::unique_ptr<Cache> cache_;
};

}  // namespace vrelab::vibration
