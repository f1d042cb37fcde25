#include "rectification/prediction/frequency.hpp"

#include "rectification/prediction/second_order.hpp"

#include <cstdint>

#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include <Eigen/Dense>

#include "rectification/prediction/random.hpp"

namespace vrelab::rectification {

using plant::Accelerometer;
using plant::Coefficients;
using plant::Dynamics;
using plant::Effect;
using plant::Location;
using plant::PlantConfig;
using plant::kNumCoefficients;
using enum plant::Coef;

LoopResponse loop_response(const PlantConfig& config, double frequency_Hz) {
  if (!(frequency_Hz > 0)) throw std::invalid_argument("frequency_Hz must be positive");
  return LoopResponder(config)(frequency_Hz);
}

LoopResponder::LoopResponder(const PlantConfig& config, bool dc_gain) {
  // The linear plant: the same dynamics, K1 and the linear cross terms, no nonlinear part.
  PlantConfig lin_cfg = config;
  for (int c : {k1_asym, k2, k3, k4, k_IP, k_IO, k_PO, k_PP, k_OO}) lin_cfg.coefficients[c] = 0.0;
  lin_cfg.torquer_c2_per_g = lin_cfg.torquer_c3_per_g2 = 0.0;
  lin_cfg.effects.clear();
  for (const auto& e : config.effects)
    if (e->kept_in_linearisation()) {  // linear (a mechanical mode): keep
      lin_cfg.effects.push_back(e);
      kept_.push_back(e);
    }
  // Linear: the response does not depend on the static orientation (IA up is as good as any).
  const Accelerometer plant(lin_cfg, Vec3(1, 0, 0));
  const Accelerometer::Linear lin = plant.linearise();
  const int n = plant.size();
  // The rebalance current of the linear plant: i = k G theta + (1 - k) q + w_i r, with
  // k = lead pole / lead zero (plant/accelerometer.cpp, the servo's realisation).
  const plant::Servo& sv = plant.servo();
  const double lead_ratio = sv.lead_pole_rad_per_s / sv.lead_zero_rad_per_s;
  Eigen::VectorXd current = Eigen::VectorXd::Zero(n);
  current[Accelerometer::kTheta] = lead_ratio * sv.gain_g_per_rad;
  current[Accelerometer::kLead] = 1 - lead_ratio;
  current[Accelerometer::kIntegral] = sv.integrator_rad_per_s;
  // The states the current and the angle depend on: theirs and, repeatedly, every state
  // that enters one of them (A(i, j) != 0).
  std::vector<bool> needed(static_cast<std::size_t>(n), false);
  for (int k : {Accelerometer::kTheta, Accelerometer::kLead, Accelerometer::kIntegral}) needed[static_cast<std::size_t>(k)] = true;
  for (bool grew = true; grew;) {
    grew = false;
    for (int i = 0; i < n; ++i)
      for (int j = 0; j < n; ++j)
        if (needed[static_cast<std::size_t>(i)] && !needed[static_cast<std::size_t>(j)] && lin.A(i, j) != 0.0)
          needed[static_cast<std::size_t>(j)] = grew = true;
  }
  std::vector<int> kept_states;
  for (int k = 0; k < n; ++k)
    if (needed[static_cast<std::size_t>(k)]) kept_states.push_back(k);
  m_ = static_cast<int>(kept_states.size());
  if (m_ > kMaxStates) throw std::invalid_argument("loop_response: the loop and its kept effects have more than 32 states");
  // Scaled (x = S y): a mechanical mode's states are ~1/w_m^2 g s^2, so unscaled A spans
  // 1e-4 .. 1e11; scaled, its entries are of the loop's rates.
  const std::vector<double> scale = plant.state_scale();
  for (int r = 0; r < m_; ++r) {
    const int i = kept_states[static_cast<std::size_t>(r)];
    const double si = scale[static_cast<std::size_t>(i)];
    if (i == Accelerometer::kTheta) theta_ = r, angle_scale_ = si;
    current_row_[static_cast<std::size_t>(r)] = current[i] * si;
    for (int c = 0; c < m_; ++c) {
      const int j = kept_states[static_cast<std::size_t>(c)];
      a_[static_cast<std::size_t>(r * m_ + c)] = lin.A(i, j) * scale[static_cast<std::size_t>(j)] / si;
    }
    for (int c = 0; c < 3; ++c) b_[static_cast<std::size_t>(r * 3 + c)] = lin.B(i, c) / si;
  }
  if (!dc_gain) return;
  // DC gain of the loop from a disturbance entering before it (an input term, a torque) to
  // the current: exactly 1 with the integrator, L0 / (1 + L0) without (L0 = b G / w_p^2).
  // Evaluated at 0.01 Hz: within O((f / f_c)^2) ~ 1e-9 of DC, and clear of a singular
  // system at f = 0 (an inert state's zero pole).
  std::array<std::complex<double>, 3> i_dc{}, theta_dc{};
  solve_at(2 * std::numbers::pi * 0.01, i_dc, theta_dc);
  dc_gain_ = std::abs(i_dc[IA]);
}

void LoopResponder::solve_at(double w, std::array<std::complex<double>, 3>& current, std::array<std::complex<double>, 3>& angle) const {
  // Complex numbers as (re, im) pairs of doubles: arrays of std::complex would be zeroed at
  // every call (its constructor) for the whole capacity.
  const int m = m_;
  std::array<double, kMaxStates * kMaxStates> ar, ai;  // j w I - A
  std::array<double, kMaxStates * 3> xr, xi;           // B, then the solution
  const auto at = [m](int r, int c) { return static_cast<std::size_t>(r * m + c); };
  const auto xt = [](int r, int c) { return static_cast<std::size_t>(r * 3 + c); };
  for (int r = 0; r < m; ++r) {
    for (int c = 0; c < m; ++c) ar[at(r, c)] = -a_[at(r, c)], ai[at(r, c)] = 0;
    ai[at(r, r)] = w;
    for (int c = 0; c < 3; ++c) xr[xt(r, c)] = b_[xt(r, c)], xi[xt(r, c)] = 0;
  }
  // Elimination with partial pivoting (by |Re| + |Im|, as LAPACK's zgetrf), the pivot's
  // reciprocal kept for the back substitution.
  std::array<double, kMaxStates> inv_r, inv_i;
  for (int k = 0; k < m; ++k) {
    int p = k;
    double best = -1;
    for (int r = k; r < m; ++r) {
      const double s = std::abs(ar[at(r, k)]) + std::abs(ai[at(r, k)]);
      if (s > best) best = s, p = r;
    }
    if (p != k) {
      for (int c = k; c < m; ++c) std::swap(ar[at(k, c)], ar[at(p, c)]), std::swap(ai[at(k, c)], ai[at(p, c)]);
      for (int c = 0; c < 3; ++c) std::swap(xr[xt(k, c)], xr[xt(p, c)]), std::swap(xi[xt(k, c)], xi[xt(p, c)]);
    }
    const double pr = ar[at(k, k)], pi = ai[at(k, k)], norm = pr * pr + pi * pi;
    const double vr = pr / norm, vi = -pi / norm;
    inv_r[static_cast<std::size_t>(k)] = vr, inv_i[static_cast<std::size_t>(k)] = vi;
    for (int r = k + 1; r < m; ++r) {
      const double er = ar[at(r, k)], ei = ai[at(r, k)];
      if (er == 0 && ei == 0) continue;
      const double lr = er * vr - ei * vi, li = er * vi + ei * vr;
      for (int c = k + 1; c < m; ++c) {
        const double ur = ar[at(k, c)], ui = ai[at(k, c)];
        ar[at(r, c)] -= lr * ur - li * ui, ai[at(r, c)] -= lr * ui + li * ur;
      }
      for (int c = 0; c < 3; ++c) {
        const double ur = xr[xt(k, c)], ui = xi[xt(k, c)];
        xr[xt(r, c)] -= lr * ur - li * ui, xi[xt(r, c)] -= lr * ui + li * ur;
      }
    }
  }
  for (int k = m - 1; k >= 0; --k)
    for (int c = 0; c < 3; ++c) {
      double sr = xr[xt(k, c)], si = xi[xt(k, c)];
      for (int j = k + 1; j < m; ++j) {
        const double ur = ar[at(k, j)], ui = ai[at(k, j)], yr = xr[xt(j, c)], yi = xi[xt(j, c)];
        sr -= ur * yr - ui * yi, si -= ur * yi + ui * yr;
      }
      const double vr = inv_r[static_cast<std::size_t>(k)], vi = inv_i[static_cast<std::size_t>(k)];
      xr[xt(k, c)] = sr * vr - si * vi, xi[xt(k, c)] = sr * vi + si * vr;
    }
  for (int c = 0; c < 3; ++c) {
    double ir = 0, ii = 0;
    for (int r = 0; r < m; ++r) ir += current_row_[static_cast<std::size_t>(r)] * xr[xt(r, c)], ii += current_row_[static_cast<std::size_t>(r)] * xi[xt(r, c)];
    current[static_cast<std::size_t>(c)] = {ir, ii};
    angle[static_cast<std::size_t>(c)] = {angle_scale_ * xr[xt(theta_, c)], angle_scale_ * xi[xt(theta_, c)]};
  }
}

LoopResponse LoopResponder::operator()(double frequency_Hz) const {
  if (!(frequency_Hz > 0)) throw std::invalid_argument("frequency_Hz must be positive");
  LoopResponse out;
  const double w = 2 * std::numbers::pi * frequency_Hz;
  for (const auto& e : kept_)
    for (int j = 0; j < 3; ++j) out.mechanical[static_cast<std::size_t>(j)] *= e->transmissibility(j, w);
  solve_at(w, out.current, out.angle_rad);
  out.frequency_Hz = frequency_Hz;
  out.dc_gain = dc_gain_;
  return out;
}

PlantConfig without_films(const PlantConfig& config) {
  if (std::none_of(config.effects.begin(), config.effects.end(), [](const auto& e) { return e->amplitude_dependent_damping(); }))
    return config;
  PlantConfig out = config;
  out.effects.clear();
  for (const auto& e : config.effects)
    if (!e->amplitude_dependent_damping()) out.effects.push_back(e);
  if (!out.servo) out.servo = plant::design_servo(config.dynamics);
  return out;
}

PlantConfig amplitude_linearised(const PlantConfig& config, const vibration::SineVibration& v) {
  std::vector<const Effect*> films;  // amplitude-dependent damping (squeeze films)
  for (const auto& e : config.effects)
    if (e->amplitude_dependent_damping()) films.push_back(e.get());
  if (films.empty()) return config;
  PlantConfig out = without_films(config);
  // The damping the loop sees: 2 zeta w_p + sum of each film's c0 (describing function - 1).
  const Dynamics& d0 = config.dynamics;
  const double two_wp = 2 * 2 * std::numbers::pi * d0.pendulum_frequency_Hz;
  const double zeta0 = d0.pendulum_damping_ratio;
  Eigen::Vector3cd w;
  for (int i = 0; i < 3; ++i) w[i] = std::polar(v.amplitude_g[i], v.phase_rad[i]);
  const auto zeta_at = [&](double theta) {
    double extra = 0;
    for (const auto* f : films) extra += f->extra_damping_per_s(theta, d0.angle_gain_rad_per_s2_per_g);
    return zeta0 + extra / two_wp;
  };
  // The loop at any damping from the loop at zeta0 and twice it (damped_response: the damping
  // is a rank-one term of the plant's linear part), each plant linearised once.
  PlantConfig twice = out;
  twice.dynamics.pendulum_damping_ratio *= 2;
  const LoopResponse at_zeta0 = LoopResponder(out, false)(v.frequency_Hz);  // (the angle only: no DC gain)
  const LoopResponse at_twice = LoopResponder(twice, false)(v.frequency_Hz);
  double zeta = zeta0;
  for (int it = 0; it < 200; ++it) {
    const LoopResponse r = damped_response(at_zeta0, at_twice, zeta / zeta0 - 1);
    const double theta = std::abs(r.angle_rad[0] * w[0] + r.angle_rad[1] * w[1] + r.angle_rad[2] * w[2]);
    const double updated = 0.5 * (zeta + zeta_at(theta));  // damped: the angle falls as the damping rises
    if (std::abs(updated - zeta) < 1e-10 * zeta) {
      out.dynamics.pendulum_damping_ratio = updated;
      return out;
    }
    zeta = updated;
  }
  throw std::runtime_error("amplitude_linearised: the squeeze film's equivalent damping did not converge at " +
                           std::to_string(v.frequency_Hz) + " Hz");
}

FrequencyPrediction sine_rectification_at_frequency(const PlantConfig& config, const Vec3& a, const vibration::SineVibration& v,
                                                    std::optional<double> range_g) {
  vibration::validate(v);
  const PlantConfig lin = amplitude_linearised(config, v);
  if (pickoff_p2_per_rad(lin) == 0) return sine_rectification_at_frequency(lin, a, v, range_g, loop_response(lin, v.frequency_Hz));
  // A pickoff nonlinearity: its current at 2 f rectified too (second_order.hpp).
  const LoopResponder responder(lin);
  FrequencyPrediction out = sine_rectification_at_frequency(lin, a, v, range_g, responder(v.frequency_Hz));
  out.second_order_g = PeriodicPickoffBalance(lin, a[IA], out.pickoff_g, out.loop_dc_gain, v.frequency_Hz,
                                              {{1, out.current_amplitude_g, out.angle_amplitude_rad}}, std::cref(responder))(lin.coefficients);
  return out;
}

FrequencyPrediction sine_rectification_at_frequency(const PlantConfig& config, const Vec3& a, const vibration::SineVibration& v,
                                                    std::optional<double> range_g, const LoopResponse& h) {
  return PreparedSineRectification(config, a, v, range_g, h)(config.coefficients);
}

PreparedSineRectification::PreparedSineRectification(const PlantConfig& config, const Vec3& a, const vibration::SineVibration& v,
                                                     std::optional<double> range_g, const LoopResponse& h)
    : location_(config.location), a_(a), range_(range_g) {
  if (std::abs(h.frequency_Hz - v.frequency_Hz) > 1e-9 * v.frequency_Hz)
    throw std::invalid_argument("sine_rectification_at_frequency: the loop response is for another frequency");
  double p2 = 0.0;
  bool geometry = false;
  for (const auto& e : config.effects) {
    p2 += e->pickoff_p2_per_rad();
    geometry = geometry || e->vibropendulous();
    if (e->readout_averaged_in_prediction()) readout_.push_back(e);
  }
  Eigen::Vector3cd W;  // the case's vibration; F_: what the pendulum's base feels
  vibration::SineVibration felt = v;
  for (int i = 0; i < 3; ++i) {
    W[i] = v.amplitude_g[i] * std::exp(std::complex<double>(0, v.phase_rad[i]));
    F_[i] = h.mechanical[static_cast<std::size_t>(i)] * W[i];
    felt.amplitude_g[i] = std::abs(F_[i]);
    felt.phase_rad[i] = std::arg(F_[i]);
  }
  current_ = h.current[0] * W[0] + h.current[1] * W[1] + h.current[2] * W[2];
  const double dc_gain = h.dc_gain;
  FrequencyPrediction& out = fixed_;
  out.current_amplitude_g = current_;
  out.angle_amplitude_rad = h.angle_rad[0] * W[0] + h.angle_rad[1] * W[1] + h.angle_rad[2] * W[2];
  amp_i_ = std::abs(current_);
  vibration::SineVibration through_loop = felt;
  through_loop.amplitude_g[IA] = amp_i_;
  felt_ = sine_moments(felt), through_loop_ = sine_moments(through_loop);
  // Effects beyond (1), from the averaged torque balance.
  const Dynamics& d = config.dynamics;
  const double wp = 2 * std::numbers::pi * d.pendulum_frequency_Hz;
  const std::complex<double> theta = out.angle_amplitude_rad;
  out.pickoff_g = wp * wp / d.angle_gain_rad_per_s2_per_g * p2 * std::norm(theta) / 2;
  if (geometry)
    out.pendulum_geometry_g = dc_gain * (-0.5 * std::real(F_[PA] * std::conj(theta)) - a[IA] * std::norm(theta) / 4);
  out.loop_dc_gain = dc_gain;
}

FrequencyPrediction PreparedSineRectification::operator()(const Coefficients& coefficients) const {
  FrequencyPrediction out = fixed_;
  const double dc_gain = fixed_.loop_dc_gain;
  // Terms of (1): each through the place where it acts.
  for (int c = k0; c < kNumCoefficients; ++c) {
    if (c == k0 || c == delta_OA || c == delta_PA || coefficients[c] == 0) continue;
    Coefficients only;
    only[K1] = 1;
    only[c] = coefficients[c];
    const bool ia_term = c <= k4;
    const bool filtered = ia_term && location_[c] != Location::input;
    const Eq3Terms t = sine_rectification(only, a_, filtered ? through_loop_ : felt_);
    // What rectifies before the loop (input, torquer) reaches the output with the loop's DC gain.
    const double gain = location_[c] == Location::output ? 1.0 : dc_gain;
    for (int k = 0; k < kNumTerms; ++k) out.terms.g[k] += gain * t.g[k];
  }
  if (range_) out.terms.g[t_clipping] = clipping_sine(a_[IA], amp_i_, *range_);
  if (readout_.empty()) return out;
  // A readout polynomial: the period average of R over the output's oscillation, by the
  // trapezoidal rule on 32 points (exact for a trigonometric polynomial of degree < 32).
  // U: the output's oscillation, the current plus the output-placed cross terms' linear part
  // (their gradient at the static orientation, on what the pendulum's base feels).
  Coefficients cross_out;
  cross_out[K1] = 1;
  for (int c = delta_OA; c < kNumCoefficients; ++c)
    if (location_[c] == Location::output) cross_out[c] = coefficients[c];
  const Vec3 slope = plant::output_gradient(cross_out, a_) - Vec3::UnitX();
  std::complex<double> U = current_ + slope[IA] * F_[IA] + slope[PA] * F_[PA] + slope[OA] * F_[OA];
  const double u0 = plant::output_g(coefficients, a_);
  for (const auto& e : readout_) {
    constexpr int kN = 32;
    double mean = 0;
    for (int k = 0; k < kN; ++k) mean += e->readout(u0 + std::real(U * std::polar(1.0, 2 * std::numbers::pi * k / kN)));
    out.readout_g += mean / kN - e->readout(u0);
  }
  return out;
}

bool PeriodicInput::single_tone() const {
  return mean_g.isZero(0.0) && tones.size() == 1 && tones.front().first == 1 && loop.empty();
}

PeriodicInput film_harmonic_balance(const PlantConfig& with_films, const PlantConfig& linearised, const PeriodicInput& in,
                                    const ResponseAt& response) {
  std::vector<const Effect*> films;
  for (const auto& e : with_films.effects)
    if (e->amplitude_dependent_damping()) films.push_back(e.get());
  if (films.empty() || in.tones.empty()) return in;
  const Dynamics& d0 = with_films.dynamics;
  const double b = d0.angle_gain_rad_per_s2_per_g;
  const double wp = 2 * std::numbers::pi * d0.pendulum_frequency_Hz;
  // The damping the linearised loop already has beyond the nominal (1/s): taken back out of R.
  const double c_lin = (linearised.dynamics.pendulum_damping_ratio - d0.pendulum_damping_ratio) * 2 * wp;
  const double w = 2 * std::numbers::pi * in.frequency_Hz;
  const bool odd = std::all_of(in.tones.begin(), in.tones.end(), [](const auto& t) { return t.first % 2 == 1; });
  std::vector<int> hs;
  for (int h = 1; h <= kFilmHarmonics; h += odd ? 2 : 1) hs.push_back(h);
  const int K = static_cast<int>(hs.size());
  // The table's angle per harmonic, and the loop's angle and current per g along IA.
  std::vector<std::complex<double>> theta_table(static_cast<std::size_t>(kFilmHarmonics + 1)), A(theta_table.size()),
      C(theta_table.size());
  for (const auto& [h, W] : in.tones) {
    if (h > kFilmHarmonics) continue;
    const LoopResponse r = response(h * in.frequency_Hz);
    for (int j = 0; j < 3; ++j) theta_table[static_cast<std::size_t>(h)] += r.angle_rad[static_cast<std::size_t>(j)] * W[j];
  }
  // The film's torque acts at the pendulum, after any mechanical mode: its responses are the
  // case's per g divided by the modes' transmissibility along IA.
  for (int h : hs) {
    const LoopResponse r = response(h * in.frequency_Hz);
    const std::complex<double> t = r.mechanical[IA];
    A[static_cast<std::size_t>(h)] = r.angle_rad[IA] / t;
    C[static_cast<std::size_t>(h)] = r.current[IA] / t;
  }
  // e^{j h phi_k} on the period's points: e^{j 2 pi (h k mod N) / N}, from one table of N.
  std::vector<std::complex<double>> unit(static_cast<std::size_t>(kFilmPoints));
  for (int k = 0; k < kFilmPoints; ++k) unit[static_cast<std::size_t>(k)] = std::polar(1.0, 2 * std::numbers::pi * k / kFilmPoints);
  std::vector<std::complex<double>> ph(static_cast<std::size_t>(kFilmPoints * K));
  for (int k = 0; k < kFilmPoints; ++k)
    for (int i = 0; i < K; ++i)
      ph[static_cast<std::size_t>(k * K + i)] = unit[static_cast<std::size_t>((hs[static_cast<std::size_t>(i)] * k) % kFilmPoints)];
  // x: the real and imaginary parts of R_h (g). F(x) = R(theta(x))_h - x.
  // The same phasors split into real and imaginary parts (the loops below in real arithmetic,
  // as the complex products computed them: the same numbers, without the products' NaN checks).
  std::vector<double> ph_re(ph.size()), ph_im(ph.size()), hw(static_cast<std::size_t>(K));
  for (std::size_t q = 0; q < ph.size(); ++q) ph_re[q] = ph[q].real(), ph_im[q] = ph[q].imag();
  for (int i = 0; i < K; ++i) hw[static_cast<std::size_t>(i)] = hs[static_cast<std::size_t>(i)] * w;
  const auto residual = [&](const Eigen::VectorXd& x) {
    std::vector<double> th_re(static_cast<std::size_t>(K)), th_im(th_re.size()), R_re(th_re.size()), R_im(th_re.size());
    for (int i = 0; i < K; ++i) {
      const auto h = static_cast<std::size_t>(hs[static_cast<std::size_t>(i)]);
      const std::complex<double> t = theta_table[h] + A[h] * std::complex<double>(x[2 * i], x[2 * i + 1]);
      th_re[static_cast<std::size_t>(i)] = t.real(), th_im[static_cast<std::size_t>(i)] = t.imag();
    }
    const auto Ks = static_cast<std::size_t>(K);
    for (std::size_t k = 0; k < static_cast<std::size_t>(kFilmPoints); ++k) {
      const double* pr = ph_re.data() + k * Ks;
      const double* pi = ph_im.data() + k * Ks;
      double theta = 0, rate = 0;
      for (std::size_t i = 0; i < Ks; ++i) {
        // z = th e^{j h phi}: Im z = a d + b c, Re z = a c - b d (a + jb = th, c + jd = e).
        theta += th_re[i] * pi[i] + th_im[i] * pr[i];
        rate += hw[i] * (th_re[i] * pr[i] - th_im[i] * pi[i]);  // d/dt Im(Th e^{jh w t})
      }
      double r = c_lin * rate / b;
      for (const Effect* f : films) r += f->extra_input_g(theta, rate, 0.0, Vec3::Zero());
      // Im(R_h e^{j h phi}) resolved: R_h = (2 / N) sum r e^{-j h phi} times j.
      for (std::size_t i = 0; i < Ks; ++i) R_re[i] += r * pr[i], R_im[i] += r * -pi[i];
    }
    Eigen::VectorXd F(2 * K);
    for (int i = 0; i < K; ++i) {
      const auto si = static_cast<std::size_t>(i);
      const std::complex<double> Rh = std::complex<double>(0, 2.0 / kFilmPoints) * std::complex<double>(R_re[si], R_im[si]);
      F[2 * i] = Rh.real() - x[2 * i], F[2 * i + 1] = Rh.imag() - x[2 * i + 1];
    }
    return F;
  };
  // From the describing function (R = 0): the plain iteration R <- R(theta(R)) first (the
  // linearised loop already carries the film's fundamental damping, so it contracts fast away
  // from contact: one residual a step); where it does not, Newton, slopes by forward
  // differences, a halved step while |F| does not fall.
  // g: the size of the film's fundamental, c_lin |theta_1| w / b, for steps and tolerances.
  const double scale = std::max(std::abs(c_lin) * std::abs(theta_table[1]) * w / b, 1e-12);
  Eigen::VectorXd x = Eigen::VectorXd::Zero(2 * K);
  Eigen::VectorXd F = residual(x);
  for (int it = 0; it < 30 && F.norm() > 1e-12 * scale; ++it) {
    const Eigen::VectorXd xn = x + F, Fn = residual(xn);
    if (!(Fn.norm() < 0.5 * F.norm())) break;  // not contracting well: Newton from here
    x = xn, F = Fn;
  }
  for (int it = 0; it < 50 && F.norm() > 1e-12 * scale; ++it) {
    Eigen::MatrixXd J(2 * K, 2 * K);
    const double step = 1e-7 * scale;
    for (int c = 0; c < 2 * K; ++c) {
      Eigen::VectorXd xp = x;
      xp[c] += step;
      J.col(c) = (residual(xp) - F) / step;
    }
    const Eigen::VectorXd dx = J.partialPivLu().solve(-F);
    double t = 1;
    Eigen::VectorXd xn = x + dx, Fn = residual(xn);
    while (Fn.norm() >= F.norm() && t > 1e-3) {
      t /= 2;
      xn = x + t * dx, Fn = residual(xn);
    }
    if (Fn.norm() >= F.norm()) break;  // no further progress: at the sampling's rounding
    x = xn, F = Fn;
  }
  if (!(F.norm() <= 1e-6 * scale))
    // invalid_argument: a hypothesis' value the prediction cannot make (the fit leaves it out).
    throw std::invalid_argument("film_harmonic_balance: the squeeze film's harmonic balance did not converge at " +
                             std::to_string(in.frequency_Hz) + " Hz");
  PeriodicInput out = in;
  for (int i = 0; i < K; ++i) {
    const auto h = static_cast<std::size_t>(hs[static_cast<std::size_t>(i)]);
    const std::complex<double> Rh(x[2 * i], x[2 * i + 1]);
    out.loop.push_back({hs[static_cast<std::size_t>(i)], C[h] * Rh, A[h] * Rh});
  }
  return out;
}

std::string film_balance_key(const PlantConfig& config, const vibration::SineVibration& v, const PeriodicInput& in) {
  if (std::none_of(config.effects.begin(), config.effects.end(), [](const auto& e) { return e->amplitude_dependent_damping(); }))
    return {};
  std::string key;
  const auto put = [&key](const auto& x) { key.append(reinterpret_cast<const char*>(&x), sizeof x); };
  // Every part of variable length after its length (its count of items, each item of a fixed
  // size for its tag): the bytes then say where each part ends, so that two different inputs
  // cannot give the same bytes (e.g. 9 tones and no loop tone against no tone and 13 loop
  // tones, 468 bytes each without the counts).
  const auto count = [&put](std::size_t n) { put(static_cast<std::uint64_t>(n)); };
  count(config.coefficients.v.size());
  for (double c : config.coefficients.v) put(c);
  count(config.location.size());
  for (const Location l : config.location) put(static_cast<int>(l));
  const Dynamics& d = config.dynamics;
  for (double x : {d.pendulum_frequency_Hz, d.pendulum_damping_ratio, d.angle_gain_rad_per_s2_per_g, d.loop_bandwidth_Hz,
                   d.phase_margin_deg, d.integrator_zero_ratio, d.antialias_Hz})
    put(x);
  put(static_cast<int>(d.integrator));
  put(static_cast<int>(config.servo.has_value()));
  if (config.servo)
    for (double x : {config.servo->gain_g_per_rad, config.servo->lead_zero_rad_per_s, config.servo->lead_pole_rad_per_s,
                     config.servo->integrator_rad_per_s})
      put(x);
  put(config.torquer_c2_per_g), put(config.torquer_c3_per_g2);
  count(config.effects.size());
  for (const auto& e : config.effects) {
    if (const std::optional<std::string> k = e->cache_key()) {
      put(1);
      count(k->size());
      key += *k;
    } else {
      put(2);
      put(reinterpret_cast<std::uintptr_t>(e.get()));
    }
  }
  for (int i = 0; i < 3; ++i) put(v.amplitude_g[i]), put(v.phase_rad[i]);
  put(v.frequency_Hz);
  put(in.frequency_Hz);
  for (int i = 0; i < 3; ++i) put(in.mean_g[i]);
  count(in.tones.size());
  for (const auto& [h, W] : in.tones) {
    put(h);
    for (int i = 0; i < 3; ++i) put(W[i].real()), put(W[i].imag());
  }
  count(in.loop.size());
  for (const PeriodicInput::LoopTone& l : in.loop) put(l.h), put(l.current_g.real()), put(l.current_g.imag()), put(l.angle_rad.real()), put(l.angle_rad.imag());
  return key;
}

PeriodicInput periodic_input(const vibration::SineVibration& v) {
  vibration::validate(v);
  PeriodicInput p;
  p.frequency_Hz = v.frequency_Hz;
  Eigen::Vector3cd w;
  for (int i = 0; i < 3; ++i) w[i] = std::polar(v.amplitude_g[i], v.phase_rad[i]);
  p.tones.push_back({1, w});
  return p;
}

namespace {

constexpr int kInputPoints = 64, kInputMaxHarmonic = 16;

// e^{-j 2 pi h k / N} for periodic_input's DFT (h = 1..16, k = 0..63), computed once by the
// same expression as each call computed it (the same numbers).
const std::vector<std::complex<double>>& input_twiddles() {
  static const std::vector<std::complex<double>> table = [] {
    constexpr int kN = kInputPoints;
    std::vector<std::complex<double>> t;
    for (int h = 1; h <= kInputMaxHarmonic; ++h)
      for (int k = 0; k < kN; ++k) t.push_back(std::polar(1.0, -2 * std::numbers::pi * h * k / kN));
    return t;
  }();
  return table;
}

// e^{j h phi_k}, phi_k = 2 pi k / 64, for periodic_rectification's 64 points (h = 1..10, where
// it takes 64 points), by the same expression as the loop computes it.
constexpr int kPeriodPoints = 64, kPeriodMaxHarmonic = 10;
const std::vector<std::complex<double>>& period_phasors() {
  static const std::vector<std::complex<double>> table = [] {
    constexpr int kM = kPeriodPoints;
    std::vector<std::complex<double>> t;
    for (int h = 1; h <= kPeriodMaxHarmonic; ++h)
      for (int k = 0; k < kM; ++k) {
        const double phi = 2 * std::numbers::pi * k / kM;
        t.push_back(std::polar(1.0, h * phi));
      }
    return t;
  }();
  return table;
}

// The same for kM = 6 h_max + 1 points (h_max = 11..kFilmHarmonics: a squeeze film's
// harmonics through the loop), e^{j h phi_k}, phi_k = 2 pi k / kM, h = 1..h_max, by the same
// expression as the loop computes them (the same numbers), rather than a sincos per point and
// harmonic of every run of every film value.
constexpr int kLongMaxHarmonic = kFilmHarmonics;
const std::vector<std::complex<double>>* long_period_phasors(int points) {
  static const std::vector<std::vector<std::complex<double>>> tables = [] {
    std::vector<std::vector<std::complex<double>>> all(static_cast<std::size_t>(kLongMaxHarmonic + 1));
    for (int h_max = kPeriodMaxHarmonic + 1; h_max <= kLongMaxHarmonic; ++h_max) {
      const int kM = 6 * h_max + 1;
      std::vector<std::complex<double>>& t = all[static_cast<std::size_t>(h_max)];
      for (int h = 1; h <= h_max; ++h)
        for (int k = 0; k < kM; ++k) {
          const double phi = 2 * std::numbers::pi * k / kM;
          t.push_back(std::polar(1.0, h * phi));
        }
    }
    return all;
  }();
  if (points % 6 != 1) return nullptr;
  const int h_max = (points - 1) / 6;
  if (h_max <= kPeriodMaxHarmonic || h_max > kLongMaxHarmonic) return nullptr;
  return &tables[static_cast<std::size_t>(h_max)];
}

}  // namespace

PeriodicInput periodic_input(const vibration::Excitation& e, double frequency_Hz) {
  if (!(frequency_Hz > 0)) throw std::invalid_argument("periodic_input: frequency_Hz must be positive");
  constexpr int kN = kInputPoints, kMaxHarmonic = kInputMaxHarmonic;
  const std::vector<std::complex<double>>& twiddle = input_twiddles();
  std::array<Vec3, kN> a;
  for (int k = 0; k < kN; ++k) a[static_cast<std::size_t>(k)] = e.acceleration_g(k / (kN * frequency_Hz));
  // Parts below the sampling's rounding (1e-12 of the largest sample) are noise, not motion.
  double peak = 0;
  for (const Vec3& x : a) peak = std::max(peak, x.cwiseAbs().maxCoeff());
  const double floor_g = 1e-12 * peak;
  PeriodicInput p;
  p.frequency_Hz = frequency_Hz;
  for (const Vec3& x : a) p.mean_g += x / kN;
  // The axes whose samples are not all zero (a run along one axis moves one).
  std::array<bool, 3> moves{false, false, false};
  for (const Vec3& x : a)
    for (int i = 0; i < 3; ++i) moves[static_cast<std::size_t>(i)] = moves[static_cast<std::size_t>(i)] || x[i] != 0;
  for (int i = 0; i < 3; ++i)
    if (std::abs(p.mean_g[i]) <= floor_g) p.mean_g[i] = 0.0;
  for (int h = 1; h <= kMaxHarmonic; ++h) {
    // X_h = sum_k a_k e^{-j 2 pi h k / N}; for a_k = Im(W e^{j 2 pi h k / N}), X_h = N W / (2j).
    // (In real arithmetic, as the complex product (a + 0j)(c + js) = (a c - 0 s) + j (a s + 0 c)
    // computes it, less its zero terms: a c - 0 s is a c but for the sign of a zero, and a sum
    // that ends at zero is a part dropped below (|w| <= floor): the same numbers, without the
    // product's NaN checks.)
    double xr[3] = {0, 0, 0}, xi[3] = {0, 0, 0};
    const std::complex<double>* tw = twiddle.data() + static_cast<std::ptrdiff_t>(h - 1) * kN;
    for (int i = 0; i < 3; ++i) {
      if (!moves[i]) continue;  // 0 + 0 c + 0 c + ... is 0: an axis at rest adds nothing
      for (int k = 0; k < kN; ++k) {
        const double ak = a[static_cast<std::size_t>(k)][i];
        xr[i] += ak * tw[k].real(), xi[i] += ak * tw[k].imag();
      }
    }
    Eigen::Vector3cd x;
    for (int i = 0; i < 3; ++i) x[i] = std::complex<double>(xr[i], xi[i]);
    Eigen::Vector3cd w = std::complex<double>(0, 2.0 / kN) * x;
    for (int i = 0; i < 3; ++i)
      // |w| >= max(|Re w|, |Im w|) holds for the rounded modulus too (faithful rounding of a
      // value at least that representable number): the modulus only where it can decide.
      if (std::max(std::abs(w[i].real()), std::abs(w[i].imag())) <= floor_g && std::abs(w[i]) <= floor_g) w[i] = 0.0;
    if (!w.isZero(0.0)) p.tones.push_back({h, w});
  }
  return p;
}


FrequencyPrediction periodic_rectification(const PlantConfig& config, const Vec3& a, const PeriodicInput& in,
                                           const ResponseAt& response, bool allow_closed_form, bool second_order) {
  return PreparedPeriodicRectification(config, a, in, response, allow_closed_form, second_order)(config.coefficients);
}

PreparedPeriodicRectification::PreparedPeriodicRectification(const PlantConfig& config, const Vec3& a, const PeriodicInput& in,
                                                             const ResponseAt& response, bool allow_closed_form,
                                                             bool second_order)
    : location_(config.location), a_(a), mean_g_(in.mean_g) {
  if (!(in.frequency_Hz > 0)) throw std::invalid_argument("periodic_rectification: frequency_Hz must be positive");
  if (allow_closed_form && in.single_tone()) {
    vibration::SineVibration v;
    v.frequency_Hz = in.frequency_Hz;
    const Eigen::Vector3cd& w = in.tones.front().second;
    for (int i = 0; i < 3; ++i) v.amplitude_g[i] = std::abs(w[i]), v.phase_rad[i] = std::arg(w[i]);
    closed_form_.emplace(config, a, v, std::nullopt, response(in.frequency_Hz));
    if (second_order && pickoff_p2_per_rad(config) != 0) {
      const FrequencyPrediction f = (*closed_form_)(config.coefficients);
      balance_ = std::make_shared<const PeriodicPickoffBalance>(config, a[IA], f.pickoff_g, f.loop_dc_gain, in.frequency_Hz,
                                                                std::vector<PeriodicTone>{{1, f.current_amplitude_g, f.angle_amplitude_rad}}, response);
      fixed_.loop_dc_gain = f.loop_dc_gain;
    }
    return;
  }
  double p2 = 0.0;
  bool geometry = false;
  for (const auto& e : config.effects) {
    p2 += e->pickoff_p2_per_rad();
    geometry = geometry || e->vibropendulous();
    if (e->readout_averaged_in_prediction()) readout_.push_back(e);
  }
  // Per harmonic: what the pendulum's base feels F, the rebalance current I, the angle Theta
  // (and, per coefficients, the output's oscillation U: the current plus the output-placed
  // cross terms' slope).
  double dc_gain = 1.0;
  for (const auto& [h, W] : in.tones) {
    const LoopResponse r = response(h * in.frequency_Hz);
    dc_gain = r.dc_gain;
    Harmonic x{h, Eigen::Vector3cd::Zero(), 0.0, 0.0};
    for (int j = 0; j < 3; ++j) {
      const auto sj = static_cast<std::size_t>(j);
      x.F[j] = r.mechanical[sj] * W[j];
      x.I += r.current[sj] * W[j];
      x.Theta += r.angle_rad[sj] * W[j];
    }
    hs_.push_back(x);
  }
  for (const PeriodicInput::LoopTone& l : in.loop) {  // inside the loop: the current and angle only
    auto it = std::find_if(hs_.begin(), hs_.end(), [&l](const Harmonic& x) { return x.h == l.h; });
    if (it == hs_.end()) {
      hs_.push_back({l.h, Eigen::Vector3cd::Zero(), 0.0, 0.0});
      it = hs_.end() - 1;
    }
    it->I += l.current_g, it->Theta += l.angle_rad;
  }
  FrequencyPrediction& out = fixed_;
  out.loop_dc_gain = dc_gain;
  if (!hs_.empty() && hs_.front().h == 1) out.current_amplitude_g = hs_.front().I, out.angle_amplitude_rad = hs_.front().Theta;

  // One period on kM points: the felt acceleration (about the static point moved by the
  // input's mean) and the current's oscillation; each coefficient's basis function averaged
  // at its place (less its static value, per coefficients).
  int h_max = 1;
  for (const Harmonic& x : hs_) h_max = std::max(h_max, x.h);
  const int kM = std::max(64, 6 * h_max + 1);  // exact for degree-6 trigonometric polynomials
  points_ = kM;
  const Vec3 a_mean = a + in.mean_g;
  b0_ = plant::basis(a);
  if (!readout_.empty()) phasors_.reserve(static_cast<std::size_t>(kM) * hs_.size());
  const bool positive = std::all_of(hs_.begin(), hs_.end(), [](const Harmonic& x) { return x.h >= 1; });
  const std::vector<std::complex<double>>* table =
      !positive ? nullptr : kM == kPeriodPoints && h_max <= kPeriodMaxHarmonic ? &period_phasors() : long_period_phasors(kM);
  // Harmonics only inside the loop (a film's) move the current, not the felt acceleration.
  std::vector<char> felt_moves(hs_.size());
  for (std::size_t j = 0; j < hs_.size(); ++j) felt_moves[j] = !hs_[j].F.isZero(0.0);
  const bool pow2 = (kM & (kM - 1)) == 0;
  const double inv_points = 1.0 / kM;
  for (int k = 0; k < kM; ++k) {
    const double phi = 2 * std::numbers::pi * k / kM;
    Vec3 felt = a_mean;
    double current = 0;
    for (std::size_t j = 0; j < hs_.size(); ++j) {
      const Harmonic& x = hs_[j];
      const std::complex<double> e = table ? (*table)[static_cast<std::size_t>((x.h - 1) * kM + k)] : std::polar(1.0, x.h * phi);
      // Im(z e) written out as the complex product computes it, a d + b c (the same numbers
      // without the product's NaN checks); a zero F adds only zeros.
      if (felt_moves[j])
        for (int i = 0; i < 3; ++i) felt[i] += x.F[i].real() * e.imag() + x.F[i].imag() * e.real();
      current += x.I.real() * e.imag() + x.I.imag() * e.real();
      if (!readout_.empty()) phasors_.push_back(e);
    }
    const plant::Basis bf = plant::basis(felt);
    Vec3 loop = felt;
    loop[IA] = a_mean[IA] + current;
    const plant::Basis bl = plant::basis(loop);
    if (pow2)  // x / kM = x (1 / kM) exactly for a power of two (both the same real number rounded)
      for (int c = 0; c < kNumCoefficients; ++c) at_input_[c] += bf[c] * inv_points, in_loop_[c] += bl[c] * inv_points;
    else
      for (int c = 0; c < kNumCoefficients; ++c) at_input_[c] += bf[c] / kM, in_loop_[c] += bl[c] / kM;
  }
  out.input_mean_g = 0.0;
  // Effects beyond (1): quadratic in the angle, so harmonics add (their cross products
  // average out over a period).
  const Dynamics& d = config.dynamics;
  const double wp = 2 * std::numbers::pi * d.pendulum_frequency_Hz;
  double theta2 = 0, pa_theta = 0;  // <theta^2>, <f_PA theta>
  for (const Harmonic& x : hs_) theta2 += std::norm(x.Theta) / 2, pa_theta += std::real(x.F[PA] * std::conj(x.Theta)) / 2;
  out.pickoff_g = wp * wp / d.angle_gain_rad_per_s2_per_g * p2 * theta2;
  if (geometry) out.pendulum_geometry_g = dc_gain * (-pa_theta - a_mean[IA] * theta2 / 2);
  if (second_order && p2 != 0) {
    std::vector<PeriodicTone> tones;
    for (const Harmonic& x : hs_) tones.push_back({x.h, x.I, x.Theta});
    if (positive) balance_ = std::make_shared<const PeriodicPickoffBalance>(config, a_mean[IA], out.pickoff_g, dc_gain, in.frequency_Hz, tones, response);
    else out.second_order_left_out = true;
  }
}

void PreparedPeriodicRectification::add_second_order(FrequencyPrediction& out, const Coefficients& c) const {
  if (balance_) out.second_order_g = (*balance_)(c);
}

FrequencyPrediction PreparedPeriodicRectification::operator()(const Coefficients& coefficients) const {
  if (closed_form_) {
    FrequencyPrediction out = (*closed_form_)(coefficients);
    add_second_order(out, coefficients);
    return out;
  }
  FrequencyPrediction out = fixed_;
  add_second_order(out, coefficients);
  const double dc_gain = fixed_.loop_dc_gain;
  for (int c = k1_asym; c < kNumCoefficients; ++c) {
    if (coefficients[c] == 0) continue;
    const bool filtered = c <= k4 && location_[c] != Location::input;
    const double gain = location_[c] == Location::output ? 1.0 : dc_gain;
    const double g = gain * coefficients[c] * ((filtered ? in_loop_[c] : at_input_[c]) - b0_[c]);
    const int t = term_of_coefficient(c);  // -1: the misalignments, from the input's mean
    if (t >= 0) out.terms.g[t] += g;
    else out.input_mean_g += g;
  }
  out.input_mean_g += dc_gain * mean_g_[IA];
  if (readout_.empty()) return out;
  // The readout polynomials averaged over the output's oscillation u (the static output moved
  // by the input's mean, plus each harmonic's U).
  Coefficients cross_out;
  cross_out[K1] = 1;
  for (int c = delta_OA; c < kNumCoefficients; ++c)
    if (location_[c] == Location::output) cross_out[c] = coefficients[c];
  const Vec3 slope = plant::output_gradient(cross_out, a_) - Vec3::UnitX();
  std::vector<std::complex<double>> U;
  for (const Harmonic& x : hs_) U.push_back(x.I + slope[IA] * x.F[IA] + slope[PA] * x.F[PA] + slope[OA] * x.F[OA]);
  const double u0 = plant::output_g(coefficients, a_);
  const double u_mean = u0 + mean_g_[IA] + slope.dot(mean_g_);
  const int kM = points_;
  double readout_mean = 0;
  for (int k = 0; k < kM; ++k) {
    double u = u_mean;
    for (std::size_t j = 0; j < hs_.size(); ++j) u += std::imag(U[j] * phasors_[static_cast<std::size_t>(k) * hs_.size() + j]);
    for (const auto& e : readout_) readout_mean += (e->readout(u) - u) / kM;
  }
  for (const auto& e : readout_) readout_mean -= e->readout(u0) - u0;
  out.readout_g = readout_mean;
  return out;
}

}  // namespace vrelab::rectification
