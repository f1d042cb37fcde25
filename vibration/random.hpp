#pragma once
// vibration/random.hpp -- Gaussian random vibration synthesised from PSD tables, and the
// Welch estimator that checks it.
//
// Takes: a RandomProfile (one PSD table per sensor axis [IA, PA, OA], or none for an axis
//        at rest, and how the axes are coupled), a duration (s), a sample rate (Hz) and a
//        64-bit seed.
// Gives: samples in g, per axis, at that rate (synthesize_random); one-sided PSD estimates
//        in g^2/Hz of any sampled signal (welch_psd).
//
// Synthesis (random-phase multisine, one inverse real FFT per axis): N samples at fs, bin k
// at f_k = k fs / N. The signal is x[n] = sum_k A_k cos(2 pi k n / N + phi_k) with cosine
// amplitude A_k = sqrt(2 G(f_k) fs / N), so that the mean square over the N samples is
// exactly sum_k G(f_k) fs/N (Parseval), the Riemann sum of the integral of G. The FFTW c2r
// transform is unnormalised, x[n] = sum over all N bins of X_k e^{+2 pi i k n / N}, hence
// X_k = (A_k / 2) e^{i phi_k} = sqrt(G(f_k) fs / (2 N)) e^{i phi_k} for 0 < k < N/2
// (the "sqrt(PSD N fs / 2)" of a 1/N-normalised inverse, divided by N). DC and Nyquist
// bins are 0. Phases: phi_k = 2 pi u, u = (top 53 bits of an std::mt19937_64 draw) / 2^53,
// drawn in order of k, axis by axis (IA, PA, OA), from an engine seeded by
// std::seed_seq{seed lo, seed hi, block lo, block hi} -- bit-identical on every platform.
// The result is exactly periodic with period N / fs (a wrap-around is seamless).
//
// Coupling: `independent` draws separate phases per axis (zero coherence between axes);
// `common` uses the same phases on every axis (coherence 1 and zero relative phase at every
// frequency; with proportional tables, G_i = d_i^2 G, the motion is along one fixed direction).
//
// Memory: 8 bytes per sample per axis for the result (fs = 20 kHz: 9.6 MB per minute per
// axis), plus 16 (N/2 + 1) bytes of FFT buffer per axis while transforming. For long runs
// use RandomExcitation (vibration/sampled.hpp), which synthesises in blocks.
#include <array>
#include <complex>
#include <cstdint>
#include <memory>
#include <mutex>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include <Eigen/Dense>

#include "vibration/profile.hpp"
#include "vibration/psd.hpp"

namespace vrelab::vibration {

// FFTW's planner is not thread-safe: every plan in the process (the excitation's synthesis
// here, the reference channels' Welch in rectification/measurement/reference.cpp) is made and
// destroyed under this one mutex (fftw_execute itself is thread-safe).
std::mutex& fftw_planner_mutex();

enum class AxisCoupling { independent, common };

// A measured cross-spectral matrix, one-sided, g^2/Hz: S_ij = 2 <X_i conj(X_j)> / (fs sum w^2)
// as Welch estimates it (rectification/measurement/reference.hpp), Hermitian and positive
// semi-definite, its diagonal the axes' PSDs. Bins of width resolution_Hz centred on
// frequency_Hz (evenly spaced, increasing), each a step over its width; 0 outside the bins.
// Complex: a transverse motion that lags the drive by a delay or a resonance has a cross-
// spectrum whose phase turns with frequency; the rectification of real signals takes
// Re(H_y S H_z^H) (rectification/prediction/random.hpp), which needs S whole, not |S| or Re S
// alone.
struct CrossSpectralMatrix {
  std::vector<double> frequency_Hz;
  double resolution_Hz = 0;
  std::vector<Eigen::Matrix3cd> s_g2_per_Hz;  // one per bin
  // S(f): the bin whose step holds f (|f - f_k| <= resolution / 2; the lower bin at an
  // edge), else 0.
  Eigen::Matrix3cd at(double frequency_Hz) const;
  double from_Hz() const { return frequency_Hz.front() - resolution_Hz / 2; }
  double to_Hz() const { return frequency_Hz.back() + resolution_Hz / 2; }
};
// Throws std::invalid_argument for no bins, a size mismatch, bins not evenly spaced by
// resolution_Hz from above 0, a matrix not finite or not Hermitian, a negative diagonal.
void validate(const CrossSpectralMatrix& m);

struct RandomProfile {
  std::array<std::optional<PsdTable>, 3> psd;  // per axis [IA, PA, OA]; empty: axis at rest
  AxisCoupling coupling = AxisCoupling::common;
  // A measured motion (the reference channels of a random run, io/formats/lab_data.cpp): when set,
  // the prediction takes S(f) from it, diagonal and cross terms, and `coupling` is not used
  // (the psd tables then hold its diagonal, as steps over the same bins, for the rms, the
  // band and the description). The synthesis (synthesize_random, RandomExcitation) does not
  // use it. Shared: a profile is copied with its run.
  std::shared_ptr<const CrossSpectralMatrix> measured;
};

// Throws std::invalid_argument if no axis has a table, or a table is invalid (the message
// names the axis, then the table's field and row).
void validate(const RandomProfile& p);
// Every table's levels times factor (> 0; slopes in dB/octave unchanged): the rms times
// sqrt(factor). A measured matrix is refused (std::invalid_argument): it is a record, not a demand.
void scale_levels(RandomProfile& p, double factor);
// Highest table frequency over the axes, Hz.
double max_frequency_Hz(const RandomProfile& p);
std::string describe(const RandomProfile& p);

// The Gaussian description of a profile for the analytic prediction: rms per axis (the
// spec's) and the correlation, 0 between independent axes and, for common phases,
// rho_ij = integral sqrt(G_i G_j) df / (sigma_i sigma_j) (1 for proportional tables); with a
// measured matrix, rms and correlation from its bins (sum of Re S_ij x resolution).
RandomVibration gaussian_equivalent(const RandomProfile& p);

struct SampledSignal {
  double sample_rate_Hz = 0.0;
  std::array<std::vector<double>, 3> samples_g;  // per axis, all of one length
  std::size_t size() const { return samples_g[0].size(); }
};

// One period of N = round(duration_s * sample_rate_Hz) samples (N >= 16). Throws
// std::invalid_argument naming duration_s or sample_rate_Hz when invalid, and naming
// sample_rate_Hz when it is not above twice the profile's top frequency.
SampledSignal synthesize_random(const RandomProfile& p, double duration_s, double sample_rate_Hz, std::uint64_t seed);

// The same periodic block of `length` samples that RandomExcitation draws as its block
// `block_index` (synthesize_random is block 0 of length N).
SampledSignal random_phase_block(const RandomProfile& p, std::size_t length, double sample_rate_Hz, std::uint64_t seed,
                                 std::int64_t block_index);

struct PsdEstimate {
  std::vector<double> frequency_Hz;   // k fs / L, k = 0 .. L/2
  std::vector<double> psd_g2_per_Hz;  // one-sided
  std::size_t segments = 0;           // number of averaged segments
};

// Welch: segments of `segment_length` samples (even, >= 8), 50 % overlap, periodic Hann
// window w[n] = 0.5 - 0.5 cos(2 pi n / L), no detrending, one-sided density scaling
// P_k = c |sum_n w[n] x[n] e^{-2 pi i k n / L}|^2 / (fs sum_n w[n]^2), c = 2 for
// 0 < k < L/2 and 1 at DC and Nyquist, averaged over the segments.
PsdEstimate welch_psd(std::span<const double> x_g, double sample_rate_Hz, std::size_t segment_length);

}  // namespace vrelab::vibration
