#pragma once
// rectification/measurement/reference.hpp -- the table's measured motion from reference-
// accelerometer channels (docs/data-format.md, "Reference channels").
//
// Takes: samples (time s, acceleration g per sensor axis IA, PA, OA; one to three axes
//        present) in time order, streamed one at a time, and the vibration window [from, to)
//        (s): for a sine run its frequency (the caller cuts the window to whole periods),
//        for a random run the Welch segment length (0: chosen from the window).
// Gives: per axis the mean and the rms about it; for a sine run the complex amplitude of
//        the fundamental and of the 2nd and 3rd harmonics (a least-squares fit of the mean
//        and the three tones over the window's samples, in the sine convention of
//        vibration::SineVibration, a = Im(W e^{j h w t}); over whole periods it is the
//        single-bin DFT W_h = 2 j mean(x e^{-j h w t}) but for the O(1/N) by which sampled
//        tones are not orthogonal when a period is not a whole number of samples) and the
//        residual's rms; for a
//        random run the one-sided PSD and cross-spectra by Welch (periodic Hann window, 50 %
//        overlap, each segment's mean removed, density scaling as vibration::welch_psd,
//        then each axis scaled so that its bins sum to the window's mean square: Welch for
//        the spectrum's shape, the samples for its integral).
//        Then how the motion departs from the command (MotionDeparture).
// Memory is bounded: sums for a sine run, one segment per axis and the spectra's sums for a
// random run (the segment at most 4096 samples), whatever the record's length.
//
// Uncertainties. Sine: with the residual white of variance s^2 over N samples, each real
// and imaginary part of W_h has sigma s sqrt(2 / N) (amplitude_sigma_g); the ratios' sigmas
// follow to first order. Random: Welch's estimate of one bin is chi^2 with
// nu = 2 K / (1 + 2 c^2) degrees of freedom, K segments, c = 0.167 the periodic Hann window's
// correlation at 50 % overlap (Welch 1967; Harris 1978): relative sigma sqrt(2 / nu).
#include <array>
#include <complex>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Dense>

#include "plant/model1.hpp"
#include "rectification/simulation/vibration_kind.hpp"
#include "vibration/random.hpp"

namespace vrelab::rectification {

struct ReferenceWindow {
  double from_s = 0, to_s = 0;  // half-open [from, to)
  double frequency_Hz = 0;      // > 0: a sine run (harmonics 1, 2, 3); 0: a random run (Welch)
  // A sine on random run (frequency_Hz > 0): the harmonics and the random part's Welch
  // spectra with the fitted fundamental taken off every segment (the 2nd and 3rd harmonics
  // stay in the spectra: the prediction takes one sine).
  bool sine_on_random = false;
  int segment_samples = 0;      // random: Welch segment length (even, >= 16); 0: the largest
                                // power of two <= samples / 8, within [64, 4096]
};

struct ReferenceAnalysis {
  std::array<bool, 3> present{};  // the axes with a channel
  long samples = 0;               // in the window
  double sample_rate_Hz = 0;
  Vec3 mean_g = Vec3::Zero(), rms_g = Vec3::Zero();  // rms about the mean, per axis
  // Sine: W_h per axis (h = 1, 2, 3; index 0 unused), g peak, sine convention.
  double frequency_Hz = 0;
  std::array<Eigen::Vector3cd, 4> harmonic_g{Eigen::Vector3cd::Zero(), Eigen::Vector3cd::Zero(),
                                             Eigen::Vector3cd::Zero(), Eigen::Vector3cd::Zero()};
  Vec3 residual_rms_g = Vec3::Zero();  // what the mean and the three tones leave
  Vec3 amplitude_sigma_g = Vec3::Zero();  // sigma of Re and Im of each W_h, per axis
  // Random: bins k fs / L, k = 1 .. L/2 - 1 (DC and Nyquist left out), one-sided g^2/Hz;
  // cross-spectra S_ij = 2 <X_i conj(X_j)> / (fs sum w^2) for (IA,PA), (IA,OA), (PA,OA).
  std::vector<double> bin_Hz;
  std::array<std::vector<double>, 3> psd_g2_per_Hz;
  std::array<std::vector<std::complex<double>>, 3> csd_g2_per_Hz;
  int segment_samples = 0, segments = 0;
  double resolution_Hz = 0, dof = 0;  // Welch's chi^2 degrees of freedom per bin
  // Sine on random: the spectra above are of the motion less the fundamental W_1 (each
  // segment's windowed FFT less the fitted sine's, exactly: the sums are kept per bin and the
  // fit, known at the window's end, taken off them then), scaled to the mean square less |W_1|^2/2.
  bool sine_removed = false;
  // The covariance of the motion over [from_Hz, to_Hz] from the spectra (Re of the
  // integrated cross-spectra), g^2; the whole band when from = to = 0.
  Eigen::Matrix3d band_covariance_g2(double from_Hz = 0, double to_Hz = 0) const;
};

// Streams the reference channels of one run. add() throws std::invalid_argument for time
// that does not increase, a sample interval that changes by more than 1 % (another rate),
// or a set of axes that changes; finish() for a window holding too few samples (a sine: two
// periods' worth; a random run: two Welch segments of at least 64 samples).
class ReferenceAnalyzer {
 public:
  explicit ReferenceAnalyzer(const ReferenceWindow& w);
  ~ReferenceAnalyzer();
  ReferenceAnalyzer(const ReferenceAnalyzer&) = delete;
  ReferenceAnalyzer& operator=(const ReferenceAnalyzer&) = delete;
  void add(double t_s, const std::array<double, 3>& ref_g, const std::array<bool, 3>& present);
  ReferenceAnalysis finish();
  long samples_seen() const { return seen_; }

 private:
  void segment();
  ReferenceWindow w_;
  ReferenceAnalysis a_;
  bool started_ = false;
  double last_t_ = 0, dt_ = 0;
  long seen_ = 0, n_ = 0;
  Vec3 sum_ = Vec3::Zero(), sum2_ = Vec3::Zero();
  // Sine: the least-squares fit of the mean and three tones, streamed (the basis
  // 1, sin h w t, cos h w t, h = 1..3: its Gram matrix and each axis's projections).
  Eigen::Matrix<double, 7, 7> gram_ = Eigen::Matrix<double, 7, 7>::Zero();
  Eigen::Matrix<double, 7, 3> proj_ = Eigen::Matrix<double, 7, 3>::Zero();
  // Welch
  int L_ = 0;
  std::array<std::vector<double>, 3> buf_;
  std::array<std::vector<double>, 3> pxx_;
  std::array<std::vector<std::complex<double>>, 3> pxy_;
  // Sine on random: the segment's sample times, and per bin the sums of X_i conj(B_m) and
  // B_m conj(B_n) for the fundamental's basis B_0 = sin(w t), B_1 = cos(w t) as each
  // segment sees it (mean removed, windowed, transformed).
  std::vector<double> tbuf_;
  std::array<std::array<std::vector<std::complex<double>>, 2>, 3> pxb_;
  std::array<std::vector<std::complex<double>>, 4> pbb_;  // (m, n) = (0,0), (0,1), (1,0), (1,1)
  std::vector<double> window_;
  struct Fft;
  Fft* fft_ = nullptr;
};

// How the measured motion departs from the commanded one.
struct MotionDeparture {
  VibrationKind kind = VibrationKind::sine;  // sine or random
  std::string axes;  // the reference axes, e.g. "IA,PA"
  double sample_rate_Hz = 0;
  long samples = 0;
  double commanded_rms_g = 0, measured_rms_g = 0;  // of the motion's magnitude (axes with a channel)
  double rms_ratio = NAN;                           // measured / commanded
  Vec3 measured_rms_axis_g = Vec3::Zero();
  // Sine: |W_h| / |W_1| over the axes, h = 2, 3, and their sigmas.
  double harmonic2_ratio = NAN, harmonic2_sigma = NAN, harmonic3_ratio = NAN, harmonic3_sigma = NAN;
  // The fundamental (sine) or the covariance (random) across the commanded direction d:
  // |part across d| / |part along d| (rms for random), and its sigma; per axis the part
  // across over the part along.
  double transverse_ratio = NAN, transverse_sigma = NAN;
  Vec3 transverse_axis_ratio = Vec3::Constant(NAN);
  // Sine: the phase of the fundamental along d against the commanded (rad), |W1 . d| / A.
  double fundamental_ratio = NAN;
  // Random: Welch's settings and dof.
  double resolution_Hz = 0, dof = 0;
  int segments = 0;
};

// commanded_g: the commanded fundamental per axis (signed amplitude, in phase), g peak.
MotionDeparture sine_departure(const ReferenceAnalysis& a, const Vec3& commanded_g);
// commanded_covariance_g2: the commanded motion's covariance (e.g. from the PSD tables).
MotionDeparture random_departure(const ReferenceAnalysis& a, const Eigen::Matrix3d& commanded_covariance_g2);

// The measured motion a prediction takes: per-axis tones (sine) or the measured cross-spectral
// matrix with PSD tables from the Welch bins in [from_Hz, to_Hz] (random; welch_matrix, and
// welch_table: each bin a step over its width, so that the table integrates to the bins'
// sum; bins <= 0 raised to 1e-12 of the largest).
struct MeasuredMotion {
  std::array<bool, 3> present{};
  double frequency_Hz = 0;
  std::vector<std::pair<int, Eigen::Vector3cd>> tones;  // (h, W_h), h = 1, 2, 3
  std::optional<vibration::RandomProfile> random;
  MotionDeparture departure;
  // The prediction takes the motion as measured (tones or random hold it); else it is reported only.
  bool used() const { return !tones.empty() || random.has_value(); }
};
vibration::PsdTable welch_table(const ReferenceAnalysis& a, int axis, double from_Hz, double to_Hz);
// The measured 3x3 cross-spectral matrix over the Welch bins in [from_Hz, to_Hz] (the PSDs on
// its diagonal, S_ij = the cross-spectrum of (i, j), S_ji its conjugate), for a reference on
// all three axes (std::invalid_argument otherwise, or when no bin is in the band).
vibration::CrossSpectralMatrix welch_matrix(const ReferenceAnalysis& a, double from_Hz, double to_Hz);

}  // namespace vrelab::rectification
