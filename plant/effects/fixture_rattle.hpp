#pragma once
// plant/effects/fixture_rattle.hpp -- a loose bolted joint between the shaker's table and the
// sensor's bracket opens and claps shut. Header-only (no build file to touch): the virtual
// lab's out-of-library truth module.
#include <cmath>
#include <stdexcept>

#include "plant/effects/effect.hpp"

namespace vrelab::plant {

// Fixture rattle (contact separation of a preloaded joint). The bracket that carries the
// sensor sits on the table's face along the unit direction n (sensor axes: the shaker's axis,
// across the joint) and is held on it by a bolt whose preload, per unit mass of the sensor
// and bracket, is P g. One relative coordinate x (m, the bracket's lift off the face along n,
// x < 0: the contact is compressed) and its rate v; the forces on the bracket per unit mass:
//   contact  F_c = w_c^2 eps softplus(-x / eps) + 2 zeta_c w_c (-v) sigmoid(-x / eps)
//   bolt     F_b = -P g - w_b^2 x - 2 zeta_b w_b v
// and, the joint being the bracket's only support along n, the sensor's specific force along
// n is (F_c + F_b) / g, the other components the table's: x'' = F_c + F_b - g f_table.n.
// At rest the contact carries P g + g f_static.n (the bolt's preload and gravity's component)
// and the sensor reads what the table does. Under a vibration along n whose pull exceeds that
// (the table's specific force below -(P + f_static.n) over part of a period, i.e. amplitude
// A > P + f_static.n in the quasi-static limit) the joint opens, the bolt pulls the bracket
// back and the joint claps shut: the sensor sees a short deceleration spike per period. The
// mean specific force does not move (x is periodic: <x''> = 0, so <F_c + F_b> = g <f_table.n>);
// what rectifies is the instrument's nonlinearity (k2, k3, k4 and the cross terms) meeting the
// spikes' power, with a threshold in amplitude that depends on the static orientation through
// f_static.n, and nothing below it but the contact's own tiny compliance (w_c well above the
// design's band: 1 + (f / f_c)^2, 0.25 % at 1.5 kHz for f_c = 30 kHz).
// Smoothing: the contact's unilateral spring is softplus-smoothed over eps = g / (2 w_c^2) (half
// its compression under 1 g: the contact's stiffness w_c^2 sigmoid(compression / eps) is 0.98
// w_c^2 at rest under 2 g, a contact law that stiffens with load as a Hertzian one does) and
// its damping switched by the matching sigmoid; both are C-infinity, so CVODE's BDF steps
// through a clap without a discontinuity: it crosses eps in ~1e-7 s at a mm/s closing rate,
// resolves the contact's ~1/(2 f_c) duration with small steps, and takes large ones while the
// joint is shut (the contact mode is then at rest).
class FixtureRattle final : public Effect {
 public:
  // direction: the joint's normal n in sensor axes (normalised here; not zero);
  // preload_g: P (>= 0); contact_Hz, bolt_Hz: the contact's and the bolt's frequencies with
  // the sensor and bracket's mass; zetas: their damping ratios; g_m_per_s2: the site's gravity.
  FixtureRattle(const Vec3& direction, double preload_g, double contact_Hz = 30000, double contact_zeta = 0.3,
                double bolt_Hz = 1000, double bolt_zeta = 0.05, double g_m_per_s2 = 9.80665)
      : n_(direction), P_(preload_g), g_(g_m_per_s2) {
    if (!(n_.norm() > 0) || !n_.allFinite()) throw std::invalid_argument("fixture rattle direction must be a non-zero vector");
    n_.normalize();
    if (!(P_ >= 0) || !std::isfinite(P_)) throw std::invalid_argument("fixture rattle preload_g must be >= 0");
    if (!(contact_Hz > 0) || !(bolt_Hz > 0) || !(bolt_Hz < contact_Hz) || !std::isfinite(contact_Hz))
      throw std::invalid_argument("fixture rattle needs 0 < bolt_Hz < contact_Hz");
    if (!(contact_zeta >= 0) || !(bolt_zeta >= 0)) throw std::invalid_argument("fixture rattle damping ratios must be >= 0");
    constexpr double two_pi = 6.283185307179586;
    wc_ = two_pi * contact_Hz, wb_ = two_pi * bolt_Hz;
    cc_ = 2 * contact_zeta * wc_, cb_ = 2 * bolt_zeta * wb_;
    eps_ = 0.5 * g_ / (wc_ * wc_);  // the smoothing (header comment)
  }
  std::string name() const override { return "fixture_rattle"; }
  int num_states() const override { return 2; }
  double state_scale(int k) const override { return k == 0 ? g_ / (wb_ * wb_) : g_ / wb_; }  // x, v per g
  void rest_state(const Vec3& a, double* s) const override {
    // F_c(x) - P g - w_b^2 x = g f.n, solved by Newton (monotone in x): the contact compressed.
    const double load = g_ * (P_ + a.dot(n_));
    double x = -std::max(load, 0.0) / (wc_ * wc_);
    for (int it = 0; it < 60; ++it) {
      const double f = spring(x) - g_ * P_ - wb_ * wb_ * x - g_ * a.dot(n_);
      const double slope = -wc_ * wc_ * sigmoid(-x / eps_) - wb_ * wb_;
      const double dx = f / slope;
      x -= dx;
      if (std::abs(dx) <= 1e-15 * (std::abs(x) + eps_)) break;
    }
    s[0] = x, s[1] = 0;
  }
  Vec3 input(const Vec3& a, const double* s, double* ds) const override {
    const double x = s[0], v = s[1];
    const double force = spring(x) - cc_ * v * sigmoid(-x / eps_) - g_ * P_ - wb_ * wb_ * x - cb_ * v;  // per unit mass, m/s^2
    const double along = a.dot(n_);
    ds[0] = v;
    ds[1] = force - g_ * along;
    return a + (force / g_ - along) * n_;
  }

  // The contact's unilateral spring force per unit mass (m/s^2, pushes +n), and the smooth step.
  double spring(double x) const {
    const double z = -x / eps_;
    const double softplus = z > 30 ? z : std::log1p(std::exp(z));
    return wc_ * wc_ * eps_ * softplus;
  }
  static double sigmoid(double z) { return z > 0 ? 1 / (1 + std::exp(-z)) : std::exp(z) / (1 + std::exp(z)); }

 private:
  Vec3 n_;
  double P_, g_, wc_, wb_, cc_, cb_, eps_;
};

}  // namespace vrelab::plant
