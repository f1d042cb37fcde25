#pragma once
// rectification/prediction/random.hpp -- the frequency-dependent vibration error of Gaussian random
// and sine-on-random motion: eq. (3)'s random form through the plant's dynamics.
//
// Takes: a plant (plant/accelerometer.hpp), the static orientation (g), a random profile
//        (vibration/random.hpp: one-sided PSD per sensor axis in g^2/Hz and the axes'
//        coupling) and, for sine-on-random, the sine (g peak, phase, Hz).
// Gives: the vibration error per term of model (1) and per effect (g), to first order in the
//        nonlinearities, in the FrequencyPrediction of frequency.hpp (the same fields); a
//        pickoff nonlinearity's second order (second_order.hpp) where RandomResponse::pickoff
//        holds its moments (with_pickoff_moments), random motion alone.
//
// The random motion x(t) is zero-mean Gaussian with the one-sided cross-spectral density
// S_ij(f) (g^2/Hz): S_ii = G_i, and between axes S_ij = sqrt(G_i G_j) for `common` phases,
// 0 for `independent` ones, or a measured Hermitian matrix (RandomProfile::measured: any
// coherence and phase between the axes, e.g. a transverse motion partly coherent with the
// drive and delayed). Every linear response y = sum_j H_yj(f) x_j of the plant (the
// felt motion F_i = T_i x_i behind a mechanical mode, the rebalance current I, the pendulum
// angle Theta; rectification::loop_response) is then Gaussian too, with the covariances
//     C_yz = integral Re( sum_ij H_yi(f) S_ij(f) conj(H_zj(f)) ) df
// over the table band (piecewise Gauss-Legendre in ln f, RandomResponse; a measured
// matrix's pieces are its bins). Each term of (1)
// at its place then takes the Gaussian expectation of eq. (3)'s random form
// (eq3.hpp random_rectification), with the covariance of what it sees: IA terms in the loop
// or at the output the current's variance C_II; input terms and the cross terms the felt
// motion's covariance; so k2 C, k3 3 a C, k4 (6 a^2 C + 3 C^2) (Isserlis), k1' the mean of
// |a + X| of a Gaussian, the cross terms k_ij C_ij (the static orientation enters through
// a_IA in k3, k4, k1'). The effects: pickoff (w_p^2/b) p2 E[theta^2]; pendulum geometry
// dc_gain (-E[F_PA theta] - a_IA E[theta^2]/2); a readout polynomial E[R(u0 + U)] - R(u0) by
// 24-point Gauss-Hermite (exact for degree < 48), U = I + the output cross terms' slope . F.
// Sine on random (independent): each term's joint expectation, the random one averaged over
// the sine's phase (eq3.hpp sine_on_random_rectification) with the sine through the loop at
// its frequency; the angle's second moments add. A sine with harmonics (a shaker's
// distortion, a rocking fixture) likewise over its period, each harmonic at its frequency.
// A squeeze film's amplitude-dependent damping: by statistical linearisation
// (random_linearised_damping below), the film's harmonics and the angle's departure from a Gaussian
// left out. Not modelled: clipping beyond the current's Gaussian (range limit of I).
#include <memory>
#include <optional>
#include <vector>

#include <Eigen/Dense>

#include "plant/accelerometer.hpp"
#include "rectification/prediction/frequency.hpp"
#include "rectification/prediction/second_order.hpp"
#include "vibration/random.hpp"

namespace vrelab::rectification {

// The joint covariance of the plant's linear responses to a random input, and the input's.
// Index order of `covariance`: F_IA, F_PA, F_OA (felt, g), I (current, g), Theta (rad).
struct RandomResponse {
  enum Index : int { kF_IA = 0, kF_PA = 1, kF_OA = 2, kCurrent = 3, kAngle = 4 };
  Eigen::Matrix<double, 5, 5> covariance = Eigen::Matrix<double, 5, 5>::Zero();
  Eigen::Matrix3d input_covariance_g2 = Eigen::Matrix3d::Zero();  // of the case's motion x
  double dc_gain = 1;
  double from_Hz = 0, to_Hz = 0;
  int frequencies = 0;  // loop responses evaluated
  // A plant with a pickoff nonlinearity: the moments its second order needs (second_order.hpp,
  // gaussian_pickoff_moments; with_pickoff_moments sets them). Without them such a plant's
  // random prediction is first order (FrequencyPrediction::second_order_left_out).
  std::optional<GaussianPickoffMoments> pickoff;
};
// rr with the pickoff moments of `plant` set when it has a pickoff nonlinearity (else rr).
RandomResponse with_pickoff_moments(RandomResponse rr, const plant::PlantConfig& plant, const vibration::RandomProfile& p,
                                    const ResponseAt& response, const Eigen::Matrix3d& turn = Eigen::Matrix3d::Identity());

// Quadrature settings: each interval between table breakpoints is cut into pieces no wider
// than max_log_step in ln f, each integrated by 8-point Gauss-Legendre.
// With common_grid the pieces are instead [k h, (k + 1) h] in ln f (h = max_log_step) cut
// only at the band's ends, so that tables with the same band share their frequencies (and a
// cache of loop responses serves them all); a breakpoint inside a piece then costs O(h^2)
// locally (~1e-4 relative at h = 0.1 on the standard tables).
struct RandomQuadrature {
  double max_log_step = 0.02;
  bool common_grid = false;
};

// The one-sided cross-spectral density S(f) of the profile, g^2/Hz, Hermitian: a profile's
// measured matrix (vibration::RandomProfile::measured, the reference channels' Welch) as
// measured; else from the tables, real (the synthesis uses zero relative phase for common
// coupling, none for independent axes).
Eigen::Matrix3cd cross_spectral_matrix_g2_per_Hz(const vibration::RandomProfile& p, double frequency_Hz);
// The same at many frequencies (the profile's tables prepared once).
std::vector<Eigen::Matrix3cd> cross_spectral_matrices_g2_per_Hz(const vibration::RandomProfile& p, const std::vector<double>& frequency_Hz);
// Its real part (the covariance density of the input itself).
Eigen::Matrix3d cross_spectrum_g2_per_Hz(const vibration::RandomProfile& p, double frequency_Hz);

// turn: a fixed linear map of the motion in sensor axes, the same at every frequency (a
// fixture's turn, validation's mounting_misalignment): the case moves as M x, S' = M S M^T.
// The identity (default): the profile's motion as it is (the same numbers as without it).
RandomResponse random_response(const vibration::RandomProfile& p, const ResponseAt& response,
                               const RandomQuadrature& q = {}, const Eigen::Matrix3d& turn = Eigen::Matrix3d::Identity());
RandomResponse random_response(const plant::PlantConfig& plant, const vibration::RandomProfile& p,
                               const RandomQuadrature& q = {});

// random_response in steps, for many loops and turns of one motion (a diagnosis' hypotheses):
// the quadrature points (the band's knots, the pieces, the rule; each point's frequency,
// weight df and the input's cross-spectral density); the same turned, the points where the
// turned input has no power dropped; then the covariances of a loop given its response at
// each point (responses[k] at frequency_Hz[k]). random_response(turned_grid(random_grid(p, q),
// turn), responses) is random_response(p, response, q, turn): the same numbers.
struct RandomGrid {
  std::vector<double> frequency_Hz, weight_Hz;
  std::vector<Eigen::Matrix3cd> csd_g2_per_Hz;
  double from_Hz = 0, to_Hz = 0;  // the band
};
RandomGrid random_grid(const vibration::RandomProfile& p, const RandomQuadrature& q = {});
RandomGrid turned_grid(const RandomGrid& grid, const Eigen::Matrix3d& turn);
RandomResponse random_response(const RandomGrid& grid, const std::vector<const LoopResponse*>& responses);

// A random part through the loop at damping zeta0 (at_zeta0) kept so that its covariances at
// any other damping follow without a loop response (random_response_at_damping): per
// quadrature point, the current's and the angle's rows of w H S H^H (the point's share of the
// covariance, complex) and rho - 1 (damped_response, from at_twice).
struct DampedRandomSpectrum {
  RandomResponse at_zeta0;  // random_response(p, at_zeta0, q, turn)
  std::vector<double> frequency_Hz;
  std::vector<Eigen::Matrix<std::complex<double>, 2, 5>> loop_rows;
  std::vector<std::complex<double>> rho_minus_1;
};
DampedRandomSpectrum damped_random_spectrum(const vibration::RandomProfile& p, const ResponseAt& at_zeta0, const ResponseAt& at_twice,
                                            const RandomQuadrature& q, const Eigen::Matrix3d& turn);
// The covariances at the damping ratio zeta0 (1 + x): random_response with damped_response's
// responses, without them (the same up to rounding).
RandomResponse random_response_at_damping(const DampedRandomSpectrum& spectrum, double x);

// An amplitude-dependent damping (plant::SqueezeFilmDamping) under random or sine-on-random
// motion replaced by its statistical linearisation, as amplitude_linearised does for a sine:
// the damping ratio 2 zeta w_p plus each film's c0 (damping_factor_on_random - 1) at the angle
// the plant so damped has (its sine amplitude at the sine's frequency, its random part's
// standard deviation and rate's), a fixed point found to 1e-10 by regula falsi (Illinois).
// Returned: that damping ratio (the plant's own without a film).
// at_zeta0, at_twice: the loop's responses of without_films(plant) and of the same with its
// damping doubled; spectrum: the random part through them (damped_random_spectrum). No
// iteration needs a loop response: the angle's spectrum at zeta0 is reweighted.
double random_linearised_damping(const plant::PlantConfig& plant, const DampedRandomSpectrum& spectrum,
                                 const std::optional<vibration::SineVibration>& sine, const ResponseAt& at_zeta0,
                                 const ResponseAt& at_twice);
// The loop's response at the damping ratio zeta0 (1 + x) from those at zeta0 and 2 zeta0 (the
// plant otherwise the same): the damping is a rank-one term of the plant's linear part, on the
// angle's equation, so the angle and what the loop makes of it (the current) are the ones at
// zeta0 over 1 + x (rho - 1), rho = Theta(zeta0) / Theta(2 zeta0) (the same ratio for every
// input axis), and the base's motion and the DC gain are unchanged.
LoopResponse damped_response(const LoopResponse& at_zeta0, const LoopResponse& at_twice, double x);

// Random only (no periodic part), or a periodic part on random: a sine (periodic_input(sine))
// or a distorted or rocking table's tone with its harmonics and mean (periodic_input of the
// excitation, measured tones), each tone through `response` at its own frequency. A single
// tone takes eq3.hpp's sine_on_random_rectification (the sine's terms in closed form); several
// take periodic_rectification's period for the periodic part alone plus each term's Gaussian
// expectation averaged over that period. Clipping (range_limit_g): a single tone only.
FrequencyPrediction random_rectification_at_frequency(const plant::PlantConfig& plant, const Vec3& a_static_g,
                                                      const RandomResponse& random,
                                                      const std::optional<PeriodicInput>& periodic = std::nullopt,
                                                      const ResponseAt& response = nullptr,
                                                      std::optional<double> range_limit_g = std::nullopt);

// The same for many coefficient sets of one plant (its dynamics, locations and effects; a
// diagnosis' gradient): what does not depend on the coefficients (the sine through the loop,
// the Gaussian parts, the sine's phase points, the angle's moments) computed once.
// prepared(plant.coefficients) is random_rectification_at_frequency(plant, ...): the same numbers.
class PreparedRandomRectification {
 public:
  PreparedRandomRectification(const plant::PlantConfig& plant, const Vec3& a_static_g, const RandomResponse& random,
                              const std::optional<PeriodicInput>& periodic = std::nullopt, const ResponseAt& response = nullptr,
                              std::optional<double> range_limit_g = std::nullopt);
  FrequencyPrediction operator()(const plant::Coefficients& c) const;

 private:
  plant::PlantConfig config_;
  Vec3 a_;
  RandomResponse rr_;
  // Several tones on random: each term averaged at the period's points (random.cpp).
  class PeriodicOnRandom;
  std::shared_ptr<const PeriodicOnRandom> periodic_;
  vibration::RandomVibration felt_, through_loop_;  // what the terms of (1) see of the random part
  vibration::SineVibration sine_felt_, sine_loop_;
  std::optional<SinePhasePoints> points_felt_, points_loop_;  // with a sine
  Eigen::Vector3cd Fs_ = Eigen::Vector3cd::Zero();
  std::complex<double> Is_ = 0.0;
  double dc_gain_ = 1;
  bool readout_ = false;  // an effect averaged on the readout
  std::optional<double> clipping_g_;
  std::optional<PickoffSecondOrder> second_order_;  // with a pickoff nonlinearity (second_order.hpp)
  FrequencyPrediction fixed_;  // the parts independent of the coefficients
};

// Convenience: the loop responses computed here.
FrequencyPrediction random_rectification_at_frequency(const plant::PlantConfig& plant, const Vec3& a_static_g,
                                                      const vibration::RandomProfile& p,
                                                      std::optional<double> range_limit_g = std::nullopt);
FrequencyPrediction sine_on_random_rectification_at_frequency(const plant::PlantConfig& plant, const Vec3& a_static_g,
                                                              const vibration::SineVibration& sine,
                                                              const vibration::RandomProfile& p,
                                                              std::optional<double> range_limit_g = std::nullopt);

// A Gaussian description (rms and correlation) of a 3x3 covariance (axes at rest: rms 0,
// correlation 0 off the diagonal).
vibration::RandomVibration gaussian_of(const Eigen::Matrix3d& covariance_g2);

}  // namespace vrelab::rectification
