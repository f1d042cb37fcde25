#include "plant/accelerometer.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <complex>
#include <numbers>
#include <optional>
#include <utility>
#include <stdexcept>

#include <Eigen/Dense>
#include <Eigen/Eigenvalues>

namespace vrelab::plant {
namespace {

constexpr double kPi = std::numbers::pi;
constexpr int kIaTerms[] = {k0, k1_asym, k2, k3, k4};
constexpr int kCrossTerms[] = {delta_OA, delta_PA, k_IP, k_IO, k_PO, k_PP, k_OO};

bool is_ia_term(int c) { return c >= k0 && c <= k4; }

double ia_basis(int c, double z) {
  switch (c) {
    case k0: return 1.0;
    case k1_asym: return 0.5 * std::abs(z);
    case k2: return z * z;
    case k3: return z * z * z;
    default: return z * z * z * z;
  }
}

double ia_basis_slope(int c, double z) {
  switch (c) {
    case k0: return 0.0;
    case k1_asym: return 0.5 * ((z > 0) - (z < 0));
    case k2: return 2 * z;
    case k3: return 3 * z * z;
    default: return 4 * z * z * z;
  }
}

}  // namespace

std::string_view location_name(Location l) {
  switch (l) {
    case Location::input: return "input";
    case Location::loop: return "loop";
    default: return "output";
  }
}

bool location_allowed(int c, Location l) {
  if (c == K1) return false;
  return is_ia_term(c) || l != Location::loop;
}

std::array<Location, kNumCoefficients> PlantConfig::default_locations() {
  std::array<Location, kNumCoefficients> l{};
  for (int c = 0; c < kNumCoefficients; ++c) l[c] = is_ia_term(c) ? Location::loop : Location::output;
  return l;
}

bool Dynamics::IsValid(std::string* error) const {
  auto fail = [&](const std::string& m) {
    if (error) *error = m;
    return false;
  };
  auto positive = [](double x) { return std::isfinite(x) && x > 0; };
  if (!positive(pendulum_frequency_Hz)) return fail("pendulum_frequency_Hz must be positive");
  if (!positive(pendulum_damping_ratio)) return fail("pendulum_damping_ratio must be positive");
  if (!positive(angle_gain_rad_per_s2_per_g)) return fail("angle_gain_rad_per_s2_per_g must be positive");
  if (!positive(loop_bandwidth_Hz)) return fail("loop_bandwidth_Hz must be positive");
  if (!(phase_margin_deg >= 10 && phase_margin_deg <= 85)) return fail("phase_margin_deg must lie in [10, 85]");
  // Below 1e-4 the integrator's zero sits four decades under the crossover: it no longer acts
  // within any measurement, and the loop's slowest time constant 1/(ratio w_c) makes the
  // settling before a run grow as 1/ratio (shake-sine: 0.3 s CPU at 1e-4, 30 s at 1e-6; at
  // 1e-12 the settling period count overflows).
  if (integrator && !(integrator_zero_ratio >= 1e-4 && integrator_zero_ratio <= 0.5))
    return fail("integrator_zero_ratio must lie in [1e-4, 0.5] (the integrator zero over the crossover frequency)");
  if (!(antialias_Hz >= 0) || !std::isfinite(antialias_Hz)) return fail("antialias_Hz must not be negative");
  return true;
}

namespace {
Servo design_servo_uncached(const Dynamics& d);
bool same_dynamics(const Dynamics& a, const Dynamics& b) {
  return a.pendulum_frequency_Hz == b.pendulum_frequency_Hz && a.pendulum_damping_ratio == b.pendulum_damping_ratio &&
         a.angle_gain_rad_per_s2_per_g == b.angle_gain_rad_per_s2_per_g && a.loop_bandwidth_Hz == b.loop_bandwidth_Hz &&
         a.phase_margin_deg == b.phase_margin_deg && a.integrator == b.integrator &&
         a.integrator_zero_ratio == b.integrator_zero_ratio && a.antialias_Hz == b.antialias_Hz;
}
}  // namespace

// The design (its check for a single crossing scans 3000 frequencies: ~0.1 ms, a quarter of a
// sine condition's time if every plant constructed designed its own) is kept for the last
// dynamics seen on this thread.
Servo design_servo(const Dynamics& d) {
  thread_local std::optional<std::pair<Dynamics, Servo>> last;
  if (last && same_dynamics(last->first, d)) return last->second;
  const Servo s = design_servo_uncached(d);  // throws for invalid dynamics: nothing cached
  last.emplace(d, s);
  return s;
}

namespace {
Servo design_servo_uncached(const Dynamics& d) {
  std::string why;
  if (!d.IsValid(&why)) throw std::invalid_argument(why);
  using C = std::complex<double>;
  const double wc = 2 * kPi * d.loop_bandwidth_Hz, wp = 2 * kPi * d.pendulum_frequency_Hz;
  const C jw(0, wc);
  const C plant = d.angle_gain_rad_per_s2_per_g / (jw * jw + 2 * d.pendulum_damping_ratio * wp * jw + wp * wp);
  Servo s{};
  s.integrator_rad_per_s = d.integrator ? d.integrator_zero_ratio * wc : 0.0;
  const C pi = 1.0 + s.integrator_rad_per_s / jw;
  const double phase_deg = std::arg(plant * pi) * 180 / kPi;  // in (-360, 0]
  double lead_deg = d.phase_margin_deg - 180 - (phase_deg > 0 ? phase_deg - 360 : phase_deg);
  if (lead_deg > 75)
    throw std::invalid_argument("the phase lead needed at the crossover (" + std::to_string(lead_deg) +
                                " deg) exceeds what one lead network gives (75 deg)");
  double alpha = 1.0;
  if (lead_deg > 0) {
    const double sn = std::sin(lead_deg * kPi / 180);
    alpha = (1 + sn) / (1 - sn);
  }
  s.lead_zero_rad_per_s = wc / std::sqrt(alpha);
  s.lead_pole_rad_per_s = wc * std::sqrt(alpha);
  const C lead = (1.0 + jw / s.lead_zero_rad_per_s) / (1.0 + jw / s.lead_pole_rad_per_s);
  s.gain_g_per_rad = 1.0 / std::abs(plant * pi * lead);
  // The open loop must cross 0 dB once, at the requested frequency: below the pendulum's
  // resonance the loop can cross several times and the phase margin means nothing.
  int crossings = 0;
  double previous = 0;
  for (int k = 0; k <= 3000; ++k) {
    const C jx(0, wc * std::pow(10.0, -3.0 + 6.0 * k / 3000));
    const C p_x = d.angle_gain_rad_per_s2_per_g / (jx * jx + 2 * d.pendulum_damping_ratio * wp * jx + wp * wp);
    const C l = s.gain_g_per_rad * p_x * (1.0 + s.integrator_rad_per_s / jx) *
                (1.0 + jx / s.lead_zero_rad_per_s) / (1.0 + jx / s.lead_pole_rad_per_s);
    const double level = std::log(std::abs(l));
    if (k > 0 && (level > 0) != (previous > 0)) ++crossings;
    previous = level;
  }
  if (crossings != 1)
    throw std::invalid_argument("loop_bandwidth_Hz: the designed loop crosses 0 dB " + std::to_string(crossings) +
                                " times between 1e-3 and 1e3 times the requested crossover; put the crossover well above "
                                "the pendulum frequency (" + std::to_string(d.pendulum_frequency_Hz) + " Hz)");
  return s;
}
}  // namespace

Accelerometer::Accelerometer(PlantConfig config, const Vec3& a_static_g, Input input)
    : config_(std::move(config)),
      a_static_(a_static_g),
      input_(std::move(input)),
      servo_(config_.servo ? *config_.servo : design_servo(config_.dynamics)) {
  if (!(servo_.gain_g_per_rad > 0) || !(servo_.lead_zero_rad_per_s > 0) || !(servo_.lead_pole_rad_per_s > 0) ||
      !(servo_.integrator_rad_per_s >= 0))
    throw std::invalid_argument("the servo needs a positive gain, lead zero and lead pole");
  if (!(config_.coefficients[K1] > 0)) throw std::invalid_argument("K1 must be positive");
  for (int c = 1; c < kNumCoefficients; ++c)
    if (!location_allowed(c, config_.location[c]))
      throw std::invalid_argument(std::string(coefficient_name(c)) + " cannot act at the " +
                                  std::string(location_name(config_.location[c])));
  for (int c : kIaTerms) {
    if (config_.coefficients[c] == 0) continue;
    has_in_ia_ |= config_.location[c] == Location::input;
    has_loop_ |= config_.location[c] == Location::loop;
    has_out_ia_ |= config_.location[c] == Location::output;
  }
  for (int c : kCrossTerms)
    if (config_.coefficients[c] != 0) has_cross_[static_cast<std::size_t>(config_.location[c])] = true;
  for (int c : kIaTerms)
    if (config_.coefficients[c] != 0 && config_.location[c] != Location::output)
      newton_terms_[static_cast<std::size_t>(n_newton_terms_++)] = {c, config_.coefficients[c], config_.location[c] == Location::input};
  for (int t = 0; t < n_newton_terms_; ++t)
    if (newton_terms_[static_cast<std::size_t>(t)].c == k1_asym) newton_smooth_ = false;
  lead_ratio_ = servo_.lead_pole_rad_per_s / servo_.lead_zero_rad_per_s;
  // Without the polynomial its term is +0 (z + 0 = z, but for the sign of a zero z).
  has_torquer_poly_ = config_.torquer_c2_per_g != 0 || config_.torquer_c3_per_g2 != 0;
  n_ = kCoreStates;
  for (const auto& e : config_.effects) {
    effect_offset_.push_back(n_);
    n_ += e->num_states();
  }
}

double Accelerometer::f_ia(Location l, double z) const {
  double s = 0;
  for (int c : kIaTerms)
    if (config_.location[c] == l) s += config_.coefficients[c] * ia_basis(c, z);
  return s;
}

double Accelerometer::f_ia_slope(Location l, double z) const {
  double s = 0;
  for (int c : kIaTerms)
    if (config_.location[c] == l) s += config_.coefficients[c] * ia_basis_slope(c, z);
  return s;
}

double Accelerometer::cross(Location l, const Vec3& a) const {
  if (!has_cross_[static_cast<std::size_t>(l)]) return 0.0;  // the sum below of zero terms
  const Basis f = basis(a);
  double s = 0;
  for (int c : kCrossTerms)
    if (config_.location[c] == l) s += config_.coefficients[c] * f[c];
  return s;
}

double Accelerometer::solve_z(double i) const {
  if (!has_in_ia_ && !has_loop_) return i;
  // m_il(z) = z + F_input(z) + F_loop(z) = i: monotone, a small perturbation of z = i.
  // Sums over the IA terms with a coefficient at the input or in the loop (newton_terms_),
  // in the order of f_ia: the same sums (f_ia's zero terms add +-0 to sums that start at +0).
  const auto sums = [this](double z, double* f_in, double* f_loop, double* s_in, double* s_loop) {
    *f_in = *f_loop = *s_in = *s_loop = 0;
    for (int t = 0; t < n_newton_terms_; ++t) {
      const NewtonTerm& term = newton_terms_[static_cast<std::size_t>(t)];
      double f, sl;
      switch (term.c) {
        case k0: f = term.k * 1.0, sl = term.k * 0.0; break;
        case k1_asym: f = term.k * (0.5 * std::abs(z)), sl = term.k * (0.5 * ((z > 0) - (z < 0))); break;
        case k2: f = term.k * (z * z), sl = term.k * (2 * z); break;
        case k3: f = term.k * (z * z * z), sl = term.k * (3 * z * z); break;
        default: f = term.k * (z * z * z * z), sl = term.k * (4 * z * z * z); break;
      }
      if (term.input) {
        *f_in += f;
        *s_in += sl;
      } else {
        *f_loop += f;
        *s_loop += sl;
      }
    }
  };
  double f_in, f_loop, s_in, s_loop;
  sums(i, &f_in, &f_loop, &s_in, &s_loop);
  double z = i - f_in - f_loop;
  for (int it = 0; it < 30; ++it) {
    sums(z, &f_in, &f_loop, &s_in, &s_loop);
    const double g = z + f_in + f_loop - i;
    const double dz = g / (1 + s_in + s_loop);
    z -= dz;
    // (Stopping a step early when |F''| dz^2 bounds the next step below the tolerance moves z
    // by an ulp, which the linearisation's difference quotients amplify to 1e-10 of A: the
    // sine answers moved by 1e-8 of themselves. Not done.)
    if (std::abs(dz) <= 1e-16 * (1 + std::abs(z))) break;
  }
  return z;
}

// Inlined into evaluate (its one caller, per sample of the discretised random path).
[[gnu::always_inline]] inline double Accelerometer::solve_z_fast(double i) const {
  if (!has_in_ia_ && !has_loop_) return i;
  if (!newton_smooth_) return solve_z(i);
  // F(z) = F_input(z) + F_loop(z), its slope and a bound on its curvature |F''| at z.
  const auto sums = [this](double z, double* f, double* s, double* c) {
    *f = *s = *c = 0;
    for (int t = 0; t < n_newton_terms_; ++t) {
      const NewtonTerm& term = newton_terms_[static_cast<std::size_t>(t)];
      switch (term.c) {
        case k0: *f += term.k; break;
        case k2: *f += term.k * (z * z), *s += term.k * (2 * z), *c += std::abs(term.k) * 2; break;
        case k3: *f += term.k * (z * z * z), *s += term.k * (3 * z * z), *c += std::abs(term.k) * (6 * std::abs(z)); break;
        default: *f += term.k * (z * z * z * z), *s += term.k * (4 * z * z * z), *c += std::abs(term.k) * (12 * z * z); break;
      }
    }
  };
  double f, sl, c;
  sums(i, &f, &sl, &c);
  // z = i - F(z): z ~ i - F(i - F(i)) ~ i - F(i) + F'(i) F(i), an error O(F'^2 F + F'' F^2).
  double z = i - f + sl * f;
  for (int it = 0; it < 30; ++it) {
    sums(z, &f, &sl, &c);
    const double d = 1 + sl;
    // Far from the near-linear regime (the map not monotone here, or a non-finite step): the
    // full solver, which starts from i and damps nothing either but is the reference path.
    if (!(d > 0) || !std::isfinite(z)) return solve_z(i);
    const double dz = (z + f - i) / d;
    z -= dz;
    // Newton's next step is ~ F'' dz^2 / (2 F'); |F''| over [z - dz, z] is within twice c for
    // |dz| << |z| (the terms are polynomials of degree <= 4): stop when that is below the
    // rounding of z, or on solve_z's own criterion.
    if (std::abs(dz) <= 1e-16 * (1 + std::abs(z)) || 2 * c * dz * dz <= 1e-17 * (1 + std::abs(z)) * std::abs(d)) return z;
  }
  return solve_z(i);  // not converged in 30 steps: the reference path
}

double Accelerometer::readout(double i, const Vec3& a) const {
  double out = i + cross(Location::output, a);
  if (has_out_ia_) out += f_ia(Location::output, solve_z(i));
  for (const auto& e : config_.effects) out = e->readout(out);
  return out;
}

void Accelerometer::rhs(double t, const double* x, double* dx) const {
  evaluate(input_ ? Vec3(a_static_ + input_(t)) : a_static_, x, dx);
}

double Accelerometer::rhs_output(const Vec3& dynamic_input_g, const double* x, double* dx) const {
  return evaluate(Vec3(a_static_ + dynamic_input_g), x, dx, true);
}

double Accelerometer::evaluate(const Vec3& a_case, const double* x, double* dx, bool fast_z) const {
  Vec3 a = a_case;
  for (std::size_t e = 0; e < config_.effects.size(); ++e)
    a = config_.effects[e]->input(a, x + effect_offset_[e], dx + effect_offset_[e]);
  // (cross() is 0 without a cross term there: the call skipped, the same sums.)
  const double s1 = a[IA] + (has_in_ia_ ? f_ia(Location::input, a[IA]) : 0.0) +
                    (has_cross_[static_cast<std::size_t>(Location::input)] ? cross(Location::input, a) : 0.0);

  const double theta = x[kTheta], omega = x[kOmega];
  double p = theta;
  for (const auto& e : config_.effects) p = e->pickoff(p);
  const double u = servo_.gain_g_per_rad * p;
  const double k = lead_ratio_;  // lead pole / lead zero
  const double y = k * u + (1 - k) * x[kLead];
  dx[kLead] = servo_.lead_pole_rad_per_s * (u - x[kLead]);
  double i = y + servo_.integrator_rad_per_s * x[kIntegral];
  dx[kIntegral] = servo_.integrator_rad_per_s > 0 ? y : 0.0;
  for (const auto& e : config_.effects) i = e->current(i);

  const double z = fast_z ? solve_z_fast(i) : solve_z(i);
  double torque = has_in_ia_ ? z + f_ia(Location::input, z) : z;  // m_in(m_il^-1(i))
  if (has_torquer_poly_) torque += i * i * (config_.torquer_c2_per_g + config_.torquer_c3_per_g2 * i);
  const Dynamics& d = config_.dynamics;
  const double wp = 2 * kPi * d.pendulum_frequency_Hz;
  double drive = s1 - torque;
  for (const auto& e : config_.effects) drive += e->extra_input_g(theta, omega, s1, a);
  const double alpha = -2 * d.pendulum_damping_ratio * wp * omega - wp * wp * theta + d.angle_gain_rad_per_s2_per_g * drive;
  dx[kTheta] = omega;
  dx[kOmega] = alpha;

  double out = i + (has_cross_[static_cast<std::size_t>(Location::output)] ? cross(Location::output, a) : 0.0);
  if (has_out_ia_) out += f_ia(Location::output, z);
  for (const auto& e : config_.effects) out = e->readout(out);
  if (d.antialias_Hz > 0) {
    const double wa = 2 * kPi * d.antialias_Hz;
    dx[kAA1] = x[kAA2];
    dx[kAA2] = wa * wa * (out - x[kAA1]) - std::numbers::sqrt2 * wa * x[kAA2];
    out = x[kAA1];
  } else {
    dx[kAA1] = dx[kAA2] = 0.0;
  }
  dx[kQuadrature] = out - q_ref_;
  return out;
}

void Accelerometer::jacobian(double t, const double* x, double* jac) const {
  if (!config_.effects.empty()) {
    jacobian_with_effects(t, x, jac);
    return;
  }
  Eigen::Map<Eigen::MatrixXd> j(jac, n_, n_);
  j.setZero();
  // i = k G theta + (1 - k) L + w_i I (no effect: pickoff and current are the identity).
  const double g = servo_.gain_g_per_rad, k = lead_ratio_, wi = servo_.integrator_rad_per_s;
  const double wl = servo_.lead_pole_rad_per_s;
  const double y = k * g * x[kTheta] + (1 - k) * x[kLead];
  const double i = y + wi * x[kIntegral];
  double di[kCoreStates] = {};
  di[kTheta] = k * g, di[kLead] = 1 - k, di[kIntegral] = wi;
  // z = m_il^-1(i): dz/di = 1 / m_il'(z); torque = m_in(z) + c2 i^2 + c3 i^3.
  const double z = solve_z(i);
  const double dz = (has_in_ia_ || has_loop_) ? 1 / (1 + f_ia_slope(Location::input, z) + f_ia_slope(Location::loop, z)) : 1.0;
  const double dtorque = (has_in_ia_ ? 1 + f_ia_slope(Location::input, z) : 1.0) * dz +
                         i * (2 * config_.torquer_c2_per_g + 3 * config_.torquer_c3_per_g2 * i);
  const Dynamics& d = config_.dynamics;
  const double wp = 2 * kPi * d.pendulum_frequency_Hz, b = d.angle_gain_rad_per_s2_per_g;
  j(kTheta, kOmega) = 1;
  j(kOmega, kTheta) = -wp * wp;
  j(kOmega, kOmega) = -2 * d.pendulum_damping_ratio * wp;
  for (int c : {kTheta, kLead, kIntegral}) j(kOmega, c) += -b * dtorque * di[c];
  // Lead: L' = w_l (G theta - L).
  j(kLead, kTheta) = wl * g;
  j(kLead, kLead) = -wl;
  if (wi > 0) j(kIntegral, kTheta) = k * g, j(kIntegral, kLead) = 1 - k;  // I' = y
  // The output before the filter: i + C_output(a) + F_output(z).
  const double dout = 1 + (has_out_ia_ ? f_ia_slope(Location::output, z) * dz : 0.0);
  if (d.antialias_Hz > 0) {
    const double wa = 2 * kPi * d.antialias_Hz;
    j(kAA1, kAA2) = 1;
    for (int c : {kTheta, kLead, kIntegral}) j(kAA2, c) = wa * wa * dout * di[c];
    j(kAA2, kAA1) = -wa * wa;
    j(kAA2, kAA2) = -std::numbers::sqrt2 * wa;
    j(kQuadrature, kAA1) = 1;
  } else {
    for (int c : {kTheta, kLead, kIntegral}) j(kQuadrature, c) = dout * di[c];
  }
}

// With effects: the chain rule of evaluate() through the effects' hooks, each hook's derivative
// by a central difference of the hook alone (step 1e-6 of the argument's size plus its typical
// size: truncation ~1e-12, rounding ~1e-10 of the derivative for smooth hooks; at a kink of a
// non-smooth one, clipping or a contact, the mean of the two slopes, which is all Newton's
// iteration needs). No right-hand side is evaluated.
void Accelerometer::jacobian_with_effects(double t, const double* x, double* jac) const {
  Eigen::Map<Eigen::MatrixXd> j(jac, n_, n_);
  j.setZero();
  const std::vector<double> scale = state_scale();
  const auto step = [](double v, double typical) { return 1e-6 * (std::abs(v) + typical); };
  const auto& effects = config_.effects;

  // Mechanical path: the felt acceleration a and da/dx (3 x n: through the effects' states);
  // the rows of the effects' states, d(ds)/dx.
  Vec3 a = input_ ? Vec3(a_static_ + input_(t)) : a_static_;
  Eigen::MatrixXd da = Eigen::MatrixXd::Zero(3, n_);
  bool a_moves = false;  // da != 0
  std::vector<double> ds(static_cast<std::size_t>(n_)), dsp(ds), dsm(ds), sp, sm;
  for (std::size_t e = 0; e < effects.size(); ++e) {
    const int ns = effects[e]->num_states(), off = effect_offset_[e];
    const double* s = x + off;
    Eigen::MatrixXd je(3 + ns, 3 + ns);  // d(a_out, ds) / d(a_in, s)
    for (int c = 0; c < 3 + ns; ++c) {
      Vec3 ap = a, am = a;
      sp.assign(s, s + ns), sm = sp;
      double h;
      if (c < 3) {
        h = step(a[c], 1.0);
        ap[c] += h, am[c] -= h;
      } else {
        const std::size_t q = static_cast<std::size_t>(c - 3);
        h = step(s[q], scale[static_cast<std::size_t>(off) + q]);
        sp[q] += h, sm[q] -= h;
      }
      const Vec3 op = effects[e]->input(ap, sp.data(), dsp.data()), om = effects[e]->input(am, sm.data(), dsm.data());
      for (int r = 0; r < 3; ++r) je(r, c) = (op[r] - om[r]) / (2 * h);
      for (int r = 0; r < ns; ++r)
        je(3 + r, c) = (dsp[static_cast<std::size_t>(r)] - dsm[static_cast<std::size_t>(r)]) / (2 * h);
    }
    if (ns > 0) {
      j.block(off, 0, ns, n_) = je.bottomLeftCorner(ns, 3) * da;
      j.block(off, off, ns, ns) += je.bottomRightCorner(ns, ns);
    }
    Eigen::MatrixXd next = je.topLeftCorner(3, 3) * da;
    if (ns > 0) next.block(0, off, 3, ns) += je.topRightCorner(3, ns);
    da = next;
    a_moves = a_moves || ns > 0;
    a = effects[e]->input(a, s, ds.data());
  }
  // d f(a) / dx for a scalar function of the felt acceleration (zero unless a moves).
  const auto through_a = [&](const auto& f) {
    Eigen::RowVectorXd r = Eigen::RowVectorXd::Zero(n_);
    if (!a_moves) return r;
    for (int c = 0; c < 3; ++c) {
      const double h = step(a[c], 1.0);
      Vec3 ap = a, am = a;
      ap[c] += h, am[c] -= h;
      r += (f(ap) - f(am)) / (2 * h) * da.row(c);
    }
    return r;
  };
  const auto s1_of = [this](const Vec3& v) {
    return v[IA] + (has_in_ia_ ? f_ia(Location::input, v[IA]) : 0.0) + cross(Location::input, v);
  };
  const double s1 = s1_of(a);
  const Eigen::RowVectorXd ds1 = through_a(s1_of);

  // The loop: pickoff and current through the effects' chains.
  const auto pickoff = [&](double v) {
    for (const auto& e : effects) v = e->pickoff(v);
    return v;
  };
  const auto current = [&](double v) {
    for (const auto& e : effects) v = e->current(v);
    return v;
  };
  const double theta = x[kTheta], omega = x[kOmega];
  const double h_theta = step(theta, scale[kTheta]);
  const double p = pickoff(theta), dp = (pickoff(theta + h_theta) - pickoff(theta - h_theta)) / (2 * h_theta);
  const double g = servo_.gain_g_per_rad, k = lead_ratio_, wi = servo_.integrator_rad_per_s;
  const double wl = servo_.lead_pole_rad_per_s;
  const double y = k * g * p + (1 - k) * x[kLead];
  const double i_in = y + wi * x[kIntegral];
  const double h_i = step(i_in, 1.0);
  const double i = current(i_in), dc = (current(i_in + h_i) - current(i_in - h_i)) / (2 * h_i);
  Eigen::RowVectorXd di = Eigen::RowVectorXd::Zero(n_);
  di[kTheta] = dc * k * g * dp, di[kLead] = dc * (1 - k), di[kIntegral] = dc * wi;
  j(kLead, kTheta) = wl * g * dp;
  j(kLead, kLead) = -wl;
  if (wi > 0) j(kIntegral, kTheta) = k * g * dp, j(kIntegral, kLead) = 1 - k;  // I' = y

  // The torque balance: drive = s1 - m_in(z) - c2 i^2 - c3 i^3 + the effects' extra input.
  const double z = solve_z(i);
  const double dz = (has_in_ia_ || has_loop_) ? 1 / (1 + f_ia_slope(Location::input, z) + f_ia_slope(Location::loop, z)) : 1.0;
  const double dtorque = (has_in_ia_ ? 1 + f_ia_slope(Location::input, z) : 1.0) * dz +
                         i * (2 * config_.torquer_c2_per_g + 3 * config_.torquer_c3_per_g2 * i);
  const auto extra = [&](double th, double om, double s, const Vec3& v) {
    double sum = 0;
    for (const auto& e : effects) sum += e->extra_input_g(th, om, s, v);
    return sum;
  };
  const double h_omega = step(omega, scale[kOmega]), h_s1 = step(s1, 1.0);
  const double e_theta = (extra(theta + h_theta, omega, s1, a) - extra(theta - h_theta, omega, s1, a)) / (2 * h_theta);
  const double e_omega = (extra(theta, omega + h_omega, s1, a) - extra(theta, omega - h_omega, s1, a)) / (2 * h_omega);
  const double e_s1 = (extra(theta, omega, s1 + h_s1, a) - extra(theta, omega, s1 - h_s1, a)) / (2 * h_s1);
  const Eigen::RowVectorXd e_a = through_a([&](const Vec3& v) { return extra(theta, omega, s1, v); });
  Eigen::RowVectorXd drive = ds1 * (1 + e_s1) - dtorque * di + e_a;
  drive[kTheta] += e_theta;
  drive[kOmega] += e_omega;
  const Dynamics& d = config_.dynamics;
  const double wp = 2 * kPi * d.pendulum_frequency_Hz, b = d.angle_gain_rad_per_s2_per_g;
  j.row(kOmega) = b * drive;
  j(kOmega, kTheta) += -wp * wp;
  j(kOmega, kOmega) += -2 * d.pendulum_damping_ratio * wp;
  j(kTheta, kOmega) = 1;

  // The output: R(i + C_output(a) + F_output(z)), R the effects' readout chain.
  const auto readout_chain = [&](double v) {
    for (const auto& e : effects) v = e->readout(v);
    return v;
  };
  const double out_pre = i + cross(Location::output, a) + (has_out_ia_ ? f_ia(Location::output, z) : 0.0);
  const double h_out = step(out_pre, 1.0);
  const double dr = (readout_chain(out_pre + h_out) - readout_chain(out_pre - h_out)) / (2 * h_out);
  const Eigen::RowVectorXd dout =
      dr * ((1 + (has_out_ia_ ? f_ia_slope(Location::output, z) * dz : 0.0)) * di +
            through_a([this](const Vec3& v) { return cross(Location::output, v); }));
  if (d.antialias_Hz > 0) {
    const double wa = 2 * kPi * d.antialias_Hz;
    j.row(kAA2) = wa * wa * dout;
    j(kAA1, kAA2) = 1;
    j(kAA2, kAA1) += -wa * wa;
    j(kAA2, kAA2) += -std::numbers::sqrt2 * wa;
    j(kQuadrature, kAA1) = 1;
  } else {
    j.row(kQuadrature) = dout;
  }
}

double Accelerometer::output_g(double t, const double* x) const {
  if (config_.dynamics.antialias_Hz > 0) return x[kAA1];
  const Vec3 a_case = input_ ? Vec3(a_static_ + input_(t)) : a_static_;
  Vec3 a = a_case;
  std::vector<double> scratch(config_.effects.empty() ? 0 : static_cast<std::size_t>(n_));  // no allocation without effects
  for (std::size_t e = 0; e < config_.effects.size(); ++e)
    a = config_.effects[e]->input(a, x + effect_offset_[e], scratch.data() + effect_offset_[e]);
  double p = x[kTheta];
  for (const auto& e : config_.effects) p = e->pickoff(p);
  const double k = servo_.lead_pole_rad_per_s / servo_.lead_zero_rad_per_s;
  const double y = k * servo_.gain_g_per_rad * p + (1 - k) * x[kLead];
  double i = y + servo_.integrator_rad_per_s * x[kIntegral];
  for (const auto& e : config_.effects) i = e->current(i);
  return readout(i, a);
}

std::vector<double> Accelerometer::state_scale() const {
  const Dynamics& d = config_.dynamics;
  const double wc = 2 * kPi * d.loop_bandwidth_Hz;
  std::vector<double> s(static_cast<std::size_t>(n_), 1.0);
  s[kTheta] = d.angle_gain_rad_per_s2_per_g / (wc * wc);
  s[kOmega] = d.angle_gain_rad_per_s2_per_g / wc;
  s[kLead] = 1.0;
  s[kIntegral] = servo_.integrator_rad_per_s > 0 ? 1.0 / servo_.integrator_rad_per_s : 1.0;
  s[kQuadrature] = 1.0 / wc;
  s[kAA1] = 1.0;
  s[kAA2] = d.antialias_Hz > 0 ? 2 * kPi * d.antialias_Hz : 1.0;
  for (std::size_t e = 0; e < config_.effects.size(); ++e)
    for (int k = 0; k < config_.effects[e]->num_states(); ++k)
      s[static_cast<std::size_t>(effect_offset_[e] + k)] = config_.effects[e]->state_scale(k);
  return s;
}

std::vector<double> Accelerometer::equilibrium() const {
  // Guess: the exact rest state with the integrator (theta = 0, tau = s1), then Newton on
  // every state but the quadrature (whose value is arbitrary).
  std::vector<double> x(static_cast<std::size_t>(n_), 0.0);
  for (std::size_t e = 0; e < config_.effects.size(); ++e) config_.effects[e]->rest_state(a_static_, x.data() + effect_offset_[e]);
  const double i_rest = a_static_[IA] + f_ia(Location::input, a_static_[IA]) + f_ia(Location::loop, a_static_[IA]) +
                        cross(Location::input, a_static_);
  if (servo_.integrator_rad_per_s > 0) x[kIntegral] = i_rest / servo_.integrator_rad_per_s;
  const std::vector<double> scale = state_scale();
  std::vector<int> free;
  for (int k = 0; k < n_; ++k)
    if (k != kQuadrature && (k != kAA1 && k != kAA2 ? true : config_.dynamics.antialias_Hz > 0)) free.push_back(k);
  if (config_.dynamics.antialias_Hz > 0) x[kAA1] = output_g(0, x.data());
  const int m = static_cast<int>(free.size());
  std::vector<double> f(static_cast<std::size_t>(n_)), fp(f), fm(f);
  for (int iter = 0; iter < 20; ++iter) {
    rhs(0, x.data(), f.data());
    Eigen::VectorXd r(m);
    for (int a = 0; a < m; ++a) r[a] = f[static_cast<std::size_t>(free[a])];
    Eigen::MatrixXd j(m, m);
    for (int b = 0; b < m; ++b) {
      const std::size_t kb = static_cast<std::size_t>(free[b]);
      const double h = 1e-7 * scale[kb];
      const double keep = x[kb];
      x[kb] = keep + h;
      rhs(0, x.data(), fp.data());
      x[kb] = keep - h;
      rhs(0, x.data(), fm.data());
      x[kb] = keep;
      for (int a = 0; a < m; ++a) j(a, b) = (fp[static_cast<std::size_t>(free[a])] - fm[static_cast<std::size_t>(free[a])]) / (2 * h);
    }
    const Eigen::VectorXd step = j.fullPivLu().solve(r);
    double worst = 0;
    for (int b = 0; b < m; ++b) {
      const std::size_t kb = static_cast<std::size_t>(free[b]);
      x[kb] -= step[b];
      worst = std::max(worst, std::abs(step[b]) / scale[kb]);
    }
    if (worst < 1e-15) break;
  }
  return x;
}

Accelerometer::Linear Accelerometer::linearise() const {
  const std::vector<double> x0 = equilibrium();
  const std::vector<double> scale = state_scale();
  Linear lin;
  lin.A.resize(n_, n_);
  lin.B.resize(n_, 3);
  lin.C.resize(n_);
  std::vector<double> x = x0, fp(static_cast<std::size_t>(n_)), fm(fp);
  for (int k = 0; k < n_; ++k) {
    const std::size_t kk = static_cast<std::size_t>(k);
    const double h = 1e-6 * scale[kk];
    x[kk] = x0[kk] + h;
    rhs(0, x.data(), fp.data());
    const double op = output_g(0, x.data());
    x[kk] = x0[kk] - h;
    rhs(0, x.data(), fm.data());
    const double om = output_g(0, x.data());
    x[kk] = x0[kk];
    for (int r = 0; r < n_; ++r) lin.A(r, k) = (fp[static_cast<std::size_t>(r)] - fm[static_cast<std::size_t>(r)]) / (2 * h);
    lin.C[k] = (op - om) / (2 * h);
  }
  // Input columns: perturb the static input (the plant sees a_static + a(t)).
  Accelerometer shifted = *this;
  shifted.input_ = {};
  for (int c = 0; c < 3; ++c) {
    const double h = 1e-6;
    shifted.a_static_ = a_static_;
    shifted.a_static_[c] += h;
    shifted.rhs(0, x0.data(), fp.data());
    shifted.a_static_[c] -= 2 * h;
    shifted.rhs(0, x0.data(), fm.data());
    for (int r = 0; r < n_; ++r) lin.B(r, c) = (fp[static_cast<std::size_t>(r)] - fm[static_cast<std::size_t>(r)]) / (2 * h);
  }
  return lin;
}

double Accelerometer::slowest_time_constant_s(const Linear& lin) const {
  // Leave out the quadrature (its pole is 0 by construction) and every inert state, whose
  // row and column of A are both zero (the PI integral without an integrator, the anti-alias
  // filter when off, the masked axes of a mechanical mode): they are not part of the loop.
  std::vector<int> keep;
  for (int k = 0; k < n_; ++k) {
    const bool inert = lin.A.row(k).cwiseAbs().maxCoeff() == 0 && lin.A.col(k).cwiseAbs().maxCoeff() == 0;
    if (k != kQuadrature && !inert) keep.push_back(k);
  }
  const Eigen::Index m = static_cast<Eigen::Index>(keep.size());
  Eigen::MatrixXd a(m, m);
  for (Eigen::Index i = 0; i < m; ++i)
    for (Eigen::Index j = 0; j < m; ++j) a(i, j) = lin.A(keep[static_cast<std::size_t>(i)], keep[static_cast<std::size_t>(j)]);
  const Eigen::VectorXcd eig = Eigen::EigenSolver<Eigen::MatrixXd>(a, false).eigenvalues();
  double slowest = std::numeric_limits<double>::infinity();
  for (Eigen::Index i = 0; i < eig.size(); ++i) slowest = std::min(slowest, -eig[i].real());
  if (!(slowest > 0)) throw std::invalid_argument("the closed loop is not stable (a pole with Re >= 0)");
  return 1 / slowest;
}

double settled_output_g(const PlantConfig& config, const Vec3& a_g, double rtol) {
  const Accelerometer plant(config, a_g);
  const double tau = plant.slowest_time_constant_s(plant.linearise());
  SolverSettings s;
  s.relative_tolerance = rtol;
  s.analytic_jacobian = false;  // CVODE's quotients: the static answers independent of the Jacobian option
  const double amplitude = std::max(1.0, a_g.norm());
  for (double scale : plant.state_scale()) s.absolute_tolerance.push_back(rtol * 1e-3 * amplitude * scale);
  OdeSolver ode(plant, 0.0, std::vector<double>(static_cast<std::size_t>(plant.size()), 0.0), s);
  const std::vector<double>& x = ode.advance(30 * tau);
  return plant.output_g(30 * tau, x.data());
}

double rest_output_g(const PlantConfig& config, const Vec3& a_g) {
  const Accelerometer plant(config, a_g);
  const std::vector<double> x = plant.equilibrium();
  return plant.output_g(0.0, x.data());
}

}  // namespace vrelab::plant
