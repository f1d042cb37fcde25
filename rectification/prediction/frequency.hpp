#pragma once
// rectification/prediction/frequency.hpp -- eq. (3) at a vibration frequency: what the paper left open.
//
// Takes: a plant (plant/accelerometer.hpp), the static orientation (g), a sine vibration
//        (g peak, per-axis phase, frequency in Hz).
// Gives: the vibration error per term (g) to first order in the nonlinearities, each term
//        seen through the plant's linear dynamics at that frequency (docs/frequency.md);
//        a pickoff nonlinearity beyond first order in second_order_g (second_order.hpp). The
//        first order:
//  - terms at the input (mechanical) and the cross terms: the vibration itself (eq. (3));
//  - IA terms in the loop or at the output: eq. (3) with the IA amplitude replaced by the
//    amplitude |I| of the rebalance current, I = sum_j H_ij(jw) W_j (W_j = w_j e^{j phi_j});
//    the averaged torque balance makes both places rectify alike;
//  - pickoff nonlinearity p2: (w_p^2 / b) p2 |Theta|^2 / 2, Theta = sum_j G_j(jw) W_j the
//    pendulum angle (<theta> = -p2 <theta^2> and the hinge stiffness turns it into torque);
//  - pendulum geometry: -Re(W_PA conj(Theta)) / 2 - a_IA |Theta|^2 / 4 (vibropendulous);
//  - clipping at [range]: of the current's amplitude |I|;
//  - a polynomial on the readout R(u) (plant::OutputPolynomial): <R(u0 + Re(U e^{jwt}))> -
//    R(u0), u0 the static output of (1), U = I + the output-placed cross terms' linear part.
// H and G come from the linearisation of the plant with every nonlinear part removed. What
// rectifies before the loop (input terms, the torquer, the pendulum geometry) reaches the
// output with the loop's DC gain: 1 with the integrator, L0/(1 + L0) without (L0 = b G/w_p^2).
// The pickoff formula assumes the integrator (<u> = 0).
// Behind a mechanical mode, the input-placed terms, the cross terms and the pendulum geometry
// see the vibration through the mode's transmissibility (what the pendulum's base feels).
#include <array>
#include <complex>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/Dense>

#include "plant/accelerometer.hpp"
#include "rectification/prediction/eq3.hpp"
#include "vibration/excitation.hpp"
#include "vibration/profile.hpp"

namespace vrelab::rectification {

struct FrequencyPrediction {
  Eq3Terms terms;                         // the terms of (1), at this frequency
  double pickoff_g = 0.0;                 // effect: pickoff nonlinearity
  double pendulum_geometry_g = 0.0;       // effect: vibropendulous coupling
  double readout_g = 0.0;                 // effect: a polynomial on the readout
  std::complex<double> current_amplitude_g;  // I
  std::complex<double> angle_amplitude_rad;  // Theta
  double loop_dc_gain = 1.0;  // from a disturbance before the loop to the output; 1 with the integrator
  // A periodic input's mean (periodic_rectification): the output's first-order response to it,
  // a_IA's mean plus the misalignments' share of the other axes' means. Not a rectification
  // of the sensor but the measured error contains it (e.g. a rocking fixture's centripetal part).
  double input_mean_g = 0.0;
  // The pickoff nonlinearity's current rectified by the IA terms in the loop or at the output
  // (second_order.hpp): second order, p2 times k1'..k4 and p2^2 times k2..k4. Left out (the
  // flag set) where a plant with a pickoff nonlinearity meets a motion it is not computed for.
  double second_order_g = 0.0;
  bool second_order_left_out = false;
  // Its own error where it is an expansion (Gaussian motion: PickoffSecondOrder::error_g); 0
  // where it is exact (periodic motion) or absent.
  double second_order_error_g = 0.0;
  double total_g() const { return terms.total_g() + pickoff_g + pendulum_geometry_g + readout_g + input_mean_g + second_order_g; }
};

FrequencyPrediction sine_rectification_at_frequency(const plant::PlantConfig& plant, const Vec3& a_static_g,
                                                    const vibration::SineVibration& v,
                                                    std::optional<double> range_limit_g = std::nullopt);

// An amplitude-dependent linear part (plant::SqueezeFilmDamping) replaced by its describing
// function for this vibration: the damping 2 zeta w_p plus each film's c0 times
// (damping_factor(|Theta|) - 1), |Theta| the angle amplitude of the plant so damped (a fixed
// point, found by damped iteration to 1e-10), the servo held as designed for the nominal
// damping. The harmonics the film makes are left out (their rectification is of
// higher order). Without such an effect the plant is returned as it is.
plant::PlantConfig amplitude_linearised(const plant::PlantConfig& plant, const vibration::SineVibration& v);
// The plant with its amplitude-dependent dampings (films) removed, the servo designed for its
// nominal damping (the electronics do not change with the film); the plant itself without one.
plant::PlantConfig without_films(const plant::PlantConfig& plant);

// The linear plant's response at one frequency (what the prediction filters through):
// the rebalance current and the pendulum angle per g of vibration on each sensor axis, and
// the loop's DC gain. It depends on the dynamics and the linear effects (a mechanical mode)
// only, not on the coefficients, the orientation or the amplitude: compute it once per
// (plant dynamics, frequency) and reuse it.
struct LoopResponse {
  double frequency_Hz = 0;
  std::array<std::complex<double>, 3> current{}, angle_rad{};
  // What the pendulum's base feels per g of case vibration on each axis: the mechanical
  // modes' transmissibility (1 without a mode).
  std::array<std::complex<double>, 3> mechanical{1.0, 1.0, 1.0};
  double dc_gain = 1;
};
LoopResponse loop_response(const plant::PlantConfig& plant, double frequency_Hz);
// The same, the plant linearised once for any number of frequencies (and the DC gain, the
// same at every frequency, solved once): responder(f) equals loop_response(plant, f) bit for
// bit (loop_response is this). With dc_gain false, the responses' dc_gain is left at 1 (for a
// caller that needs the current and the angle only).
//
// (j w I - A) x = B is solved on the states the current and the angle depend on (the loop's
// and a kept effect's: the quadrature and the anti-alias filter only follow the output), in
// the plant's state scales, by Gaussian elimination with partial pivoting on a stack array:
// the reduced system is the full one's rows for those states exactly (no other state enters
// them), so only the rounding differs from solving the whole.
class LoopResponder {
 public:
  explicit LoopResponder(const plant::PlantConfig& plant, bool dc_gain = true);
  LoopResponse operator()(double frequency_Hz) const;

  static constexpr int kMaxStates = 32;  // of the reduced system (the loop's 4 and the kept effects')

 private:
  std::vector<std::shared_ptr<const plant::Effect>> kept_;  // the linear effects (their transmissibility)
  // The reduced system, scaled (x = S y, S = diag(state scale)): m states, A (m x m, row-major)
  // and B (m x 3); the current's row c (i = c . y) and the angle's place and scale.
  int m_ = 0, theta_ = 0;
  double angle_scale_ = 1;
  std::array<double, kMaxStates * kMaxStates> a_{};
  std::array<double, kMaxStates * 3> b_{};
  std::array<double, kMaxStates> current_row_{};
  double dc_gain_ = 1;
  // The current and the angle per unit input on each axis at w (rad/s).
  void solve_at(double w_rad_per_s, std::array<std::complex<double>, 3>& current, std::array<std::complex<double>, 3>& angle) const;
};
// The same prediction with the response given (its frequency must be v's).
FrequencyPrediction sine_rectification_at_frequency(const plant::PlantConfig& plant, const Vec3& a_static_g,
                                                    const vibration::SineVibration& v, std::optional<double> range_limit_g,
                                                    const LoopResponse& response);

// A periodic vibration of fundamental frequency f (a distorted sine, a rocking fixture's motion):
//   a(t) = mean_g + sum_h Im(W_h e^{j h 2 pi f t}),  sensor axes, g,
// the sine convention of vibration::SineVibration (W = amplitude e^{j phase}).
struct PeriodicInput {
  double frequency_Hz = 0;
  Vec3 mean_g = Vec3::Zero();
  std::vector<std::pair<int, Eigen::Vector3cd>> tones;  // (h >= 1, W_h)
  // What a disturbance inside the loop adds (a squeeze film's torque, film_harmonic_balance):
  // per harmonic h >= 1 the current and the angle, on top of the table tones' response.
  struct LoopTone {
    int h = 1;
    std::complex<double> current_g, angle_rad;
  };
  std::vector<LoopTone> loop;
  bool single_tone() const;  // one tone at h = 1, no mean, nothing inside the loop
};
PeriodicInput periodic_input(const vibration::SineVibration& v);  // exact
// One period of `e` (which must repeat with 1 / frequency_Hz) sampled on 64 points and
// resolved into its mean and harmonics h <= 16, each harmonic's phase as e has it from t = 0
// (content at 17 <= h <= 31 is dropped, and above 31 it would alias: the shaker models here
// make 3f at most); parts at the sampling's rounding, 1e-12 of the largest sample, are dropped.
PeriodicInput periodic_input(const vibration::Excitation& e, double frequency_Hz);

// The vibration error for a periodic input: every harmonic through the plant's linear
// response at its own frequency (`response(h f)`, loop_response or a cache of it), then
// each term of (1) at its place and each effect averaged over one period by the trapezoid
// rule on max(64, 6 h_max + 1) points (exact for the polynomial terms and the readout
// polynomial, of degree <= 6; the |a_IA| of k1' converges as 1 / points^2). Cross-harmonic products are what a distorted tone adds: e.g.
// <a^3> = -(3/4) h2 sin(phi2) w^3 for w (sin t + h2 sin(2t + phi2)). The
// input's mean adds its first-order output (input_mean_g). With allow_closed_form, a single
// tone without mean goes to sine_rectification_at_frequency (the same number, faster). With
// second_order, a pickoff nonlinearity's part beyond first order (second_order.hpp); without
// it (a caller that adds a random part, where it is not computed) second_order_g stays 0.
// Clipping is not modelled here.
// (By value: a reference-returning std::function would let a by-value lambda dangle.)
using ResponseAt = std::function<LoopResponse(double frequency_Hz)>;
FrequencyPrediction periodic_rectification(const plant::PlantConfig& plant, const Vec3& a_static_g,
                                           const PeriodicInput& input, const ResponseAt& response,
                                           bool allow_closed_form = true, bool second_order = true);

// The squeeze film by harmonic balance. `linearised` is amplitude_linearised(with_films, ...):
// the films replaced by their describing function, a damping the loop responses `response`
// are for. The film's torque is not sinusoidal near contact (c(theta) theta' with c rising
// as 1 / (1 - x^2)^(3/2)): its remainder beyond that linear damping,
//   R(t) = sum_films extra_input_g(theta(t), theta'(t)) + (zeta_lin - zeta_0) 2 w_p theta'(t) / b,
// enters the pendulum like an input along IA, so theta_h = theta_table_h + A(h f) R_h and the
// current I_h = I_table_h + C(h f) R_h (A, C: the linearised loop's angle and current per g
// along IA). Solved for the harmonics R_h, h = 1..kFilmHarmonics (odd only when the table's
// tones are odd: the film, even in theta, then makes odd harmonics only), by Newton's method on
// R = R(theta(R)), each R_h from kFilmPoints samples of one period; returned as `in` with the
// film's part in `loop`, which periodic_rectification then averages with the table's tones.
// The describing function alone is this with R_h = 0. Without a film `in` is returned as it is.
inline constexpr int kFilmHarmonics = 31, kFilmPoints = 256;
PeriodicInput film_harmonic_balance(const plant::PlantConfig& with_films, const plant::PlantConfig& linearised,
                                    const PeriodicInput& in, const ResponseAt& response);

// What amplitude_linearised(with_films, v) and film_harmonic_balance(with_films, ., in, .)
// depend on, as bytes: equal keys give equal results (a caller may reuse them, e.g. for runs
// that differ only in the orientation). Effects with a cache_key (the films) are compared by
// it, every other effect by its identity (an effect made afresh gives another key). Each part
// of variable length (coefficients, locations, effects, tones, loop tones, an effect's key) is
// preceded by its count, so different inputs give different bytes. Empty without a film.
std::string film_balance_key(const plant::PlantConfig& with_films, const vibration::SineVibration& v, const PeriodicInput& in);

// The same two predictions split in two (for a caller that varies the coefficients only, such
// as a prediction's gradient in them): what does not depend on the coefficients (the vibration
// through the loop's response; for a periodic input, the period's samples of the felt
// acceleration and the current and the basis functions' averages) computed once, and what
// does (the terms of (1), the readout) for any coefficients. prepared(c) equals the function
// above for the plant with its coefficients replaced by c, bit for bit (the functions above
// are these). The plant's effects, locations and dynamics are the constructor's.
class PreparedSineRectification {
 public:
  PreparedSineRectification(const plant::PlantConfig& plant, const Vec3& a_static_g, const vibration::SineVibration& v,
                            std::optional<double> range_limit_g, const LoopResponse& response);
  FrequencyPrediction operator()(const plant::Coefficients& c) const;

 private:
  std::array<plant::Location, plant::kNumCoefficients> location_;
  std::vector<std::shared_ptr<const plant::Effect>> readout_;  // the effects averaged on the readout
  Vec3 a_;
  std::optional<double> range_;
  Eigen::Vector3cd F_;
  // What the pendulum's base feels, and the same with the current's oscillation along IA
  // (the loop-placed terms): their moments once, for every coefficient set.
  SineMoments felt_, through_loop_;
  std::complex<double> current_;
  double amp_i_ = 0;
  FrequencyPrediction fixed_;  // the parts independent of the coefficients
};

class PreparedPeriodicRectification {
 public:
  PreparedPeriodicRectification(const plant::PlantConfig& plant, const Vec3& a_static_g, const PeriodicInput& input,
                                const ResponseAt& response, bool allow_closed_form = true, bool second_order = true);
  FrequencyPrediction operator()(const plant::Coefficients& c) const;

 private:
  struct Harmonic {
    int h;
    Eigen::Vector3cd F;
    std::complex<double> I, Theta;
  };
  std::optional<PreparedSineRectification> closed_form_;
  std::array<plant::Location, plant::kNumCoefficients> location_;
  std::vector<std::shared_ptr<const plant::Effect>> readout_;  // the effects averaged on the readout
  Vec3 a_, mean_g_;
  std::vector<Harmonic> hs_;
  int points_ = 0;
  std::vector<std::complex<double>> phasors_;  // e^{j h phi_k}, per point and harmonic (a readout only)
  std::array<double, plant::kNumCoefficients> at_input_{}, in_loop_{};
  plant::Basis b0_{};
  std::shared_ptr<const class PeriodicPickoffBalance> balance_;  // with a pickoff nonlinearity (second_order.hpp)
  FrequencyPrediction fixed_;  // the parts independent of the coefficients
  void add_second_order(FrequencyPrediction& out, const plant::Coefficients& c) const;
};

}  // namespace vrelab::rectification
