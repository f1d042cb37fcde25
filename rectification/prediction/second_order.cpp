#include "rectification/prediction/second_order.hpp"

#include <fftw3.h>

#include <algorithm>
#include <map>
#include <memory>
#include <cmath>
#include <mutex>
#include <new>
#include <numbers>
#include <stdexcept>
#include <string>

#include "rectification/prediction/random.hpp"

namespace vrelab::rectification {

using plant::Coefficients;
using plant::Location;
using plant::PlantConfig;

double pickoff_p2_per_rad(const PlantConfig& plant) {
  double p2 = 0;
  for (const auto& e : plant.effects) p2 += e->pickoff_p2_per_rad();
  return p2;
}

std::complex<double> pickoff_error_current(const plant::Dynamics& d, const LoopResponse& r) {
  const double wp = 2 * std::numbers::pi * d.pendulum_frequency_Hz, w = 2 * std::numbers::pi * r.frequency_Hz;
  const std::complex<double> inverse_pendulum(wp * wp - w * w, 2 * d.pendulum_damping_ratio * wp * w);
  return r.current[IA] / r.mechanical[IA] * inverse_pendulum / d.angle_gain_rad_per_s2_per_g;
}

double PickoffSecondOrder::error_g(const Coefficients& c, const std::array<Location, plant::kNumCoefficients>& location,
                                   double dc_gain) const {
  double k4 = 0;
  if (location[plant::k4] == Location::loop) k4 = c[plant::k4] * (dc_gain * shift[plant::k4] + loop_shift[plant::k4]);
  else if (location[plant::k4] == Location::output) k4 = c[plant::k4] * shift[plant::k4];
  return expansion * expansion * std::abs(g(c, location, dc_gain)) + std::abs(k4);
}

double PickoffSecondOrder::g(const Coefficients& c, const std::array<Location, plant::kNumCoefficients>& location, double dc_gain) const {
  double sum = pickoff_g;
  for (int k = plant::k1_asym; k <= plant::k4; ++k)
    if (location[k] == Location::loop) sum += c[k] * (dc_gain * shift[k] + loop_shift[k]);
    else if (location[k] == Location::output) sum += c[k] * shift[k];
  return sum;
}

namespace {
// The IA basis functions of (1) beyond the linear one (plant::basis).
double ia_basis(int c, double x) {
  switch (c) {
    case plant::k1_asym: return 0.5 * std::abs(x);
    case plant::k2: return x * x;
    case plant::k3: return x * x * x;
    case plant::k4: return x * x * x * x;
    default: return 0;
  }
}
}  // namespace

namespace {
// e^{j q phi_k}, phi_k = 2 pi k / M, k-major, q = 0..Q: made once per (M, Q) for every balance.
std::shared_ptr<const std::vector<std::complex<double>>> phasors(int M, int Q) {
  static std::mutex mutex;
  static std::map<std::pair<int, int>, std::shared_ptr<const std::vector<std::complex<double>>>> tables;
  const std::lock_guard lock(mutex);
  auto& t = tables[{M, Q}];
  if (!t) {
    auto v = std::make_shared<std::vector<std::complex<double>>>(static_cast<std::size_t>(M) * static_cast<std::size_t>(Q + 1));
    for (int k = 0; k < M; ++k)
      for (int q = 0; q <= Q; ++q)
        (*v)[static_cast<std::size_t>(k) * static_cast<std::size_t>(Q + 1) + static_cast<std::size_t>(q)] =
            std::polar(1.0, 2 * std::numbers::pi * static_cast<double>(q) * k / M);
    t = std::move(v);
  }
  return t;
}
}  // namespace

PeriodicPickoffBalance::PeriodicPickoffBalance(const PlantConfig& plant, double a, double pickoff_g, double dc_gain, double frequency_Hz,
                                               const std::vector<PeriodicTone>& tones, const ResponseAt& response)
    : location_(plant.location), p2_(pickoff_p2_per_rad(plant)), a_(a), pickoff_g_(pickoff_g), dc_gain_(dc_gain),
      frequency_Hz_(frequency_Hz) {
  int h_max = 1;
  for (const PeriodicTone& t : tones) {
    if (t.h < 1) throw std::invalid_argument("PeriodicPickoffBalance: harmonic orders must be positive");
    h_max = std::max(h_max, t.h);
  }
  // kM points average the fourth power of a current with harmonics up to Q exactly.
  Q_ = 4 * h_max, M_ = std::max(128, 4 * Q_ + 1);
  const plant::Dynamics& d = plant.dynamics;
  stiffness_ = std::pow(2 * std::numbers::pi * d.pendulum_frequency_Hz, 2) / d.angle_gain_rad_per_s2_per_g;
  const auto nq = static_cast<std::size_t>(Q_ + 1), M = static_cast<std::size_t>(M_);
  T_.resize(nq), G_.resize(nq), Hth_.resize(nq), Hz_.resize(nq);
  // DC: the current's gain from a disturbance before the loop, the angle's the rest of it.
  T_[0] = dc_gain * stiffness_, G_[0] = -dc_gain, Hz_[0] = dc_gain, Hth_[0] = (1 - dc_gain) / stiffness_;
  for (int q = 1; q <= Q_; ++q) {
    const LoopResponse r = response(q * frequency_Hz);
    const auto sq = static_cast<std::size_t>(q);
    T_[sq] = pickoff_error_current(d, r);
    Hz_[sq] = r.current[IA] / r.mechanical[IA], G_[sq] = -Hz_[sq];
    Hth_[sq] = r.angle_rad[IA] / r.mechanical[IA];
  }
  ph_ = phasors(M_, Q_);
  theta1_.assign(M, 0.0), z1_.assign(M, 0.0);
  for (std::size_t k = 0; k < M; ++k)
    for (const PeriodicTone& t : tones) {
      const std::complex<double> u = (*ph_)[k * nq + static_cast<std::size_t>(t.h)];
      theta1_[k] += std::imag(t.angle_rad * u), z1_[k] += std::imag(t.current_g * u);
    }
  theta0_ = theta1_, i0_.resize(M);
  for (std::size_t k = 0; k < M; ++k) i0_[k] = a_ + z1_[k];
  std::vector<double> z = i0_;
  solve(Coefficients{}, theta0_, i0_, z);
}

namespace {
// The IA terms' sum f(x) = sum c_k basis_k(x) over k1'..k4, and its slope.
double ia_sum(const Coefficients& co, double x) {
  double v = 0;
  for (int k = plant::k1_asym; k <= plant::k4; ++k)
    if (co[k] != 0) v += co[k] * ia_basis(k, x);
  return v;
}
double ia_slope(const Coefficients& co, double x) {
  return co[plant::k1_asym] * 0.5 * ((x > 0) - (x < 0)) + co[plant::k2] * 2 * x + co[plant::k3] * 3 * x * x +
         co[plant::k4] * 4 * x * x * x;
}
}  // namespace

void PeriodicPickoffBalance::solve(const Coefficients& loop, std::vector<double>& theta, std::vector<double>& i,
                                   std::vector<double>& z) const {
  const auto nq = static_cast<std::size_t>(Q_ + 1), M = static_cast<std::size_t>(M_);
  // x's mean and harmonics: x = X_0 + sum Im(X_q e^{j q phi}).
  const auto resolve = [&](const std::vector<double>& x, std::vector<std::complex<double>>& X) {
    X.assign(nq, 0.0);
    for (std::size_t k = 0; k < M; ++k)
      for (std::size_t q = 0; q < nq; ++q) X[q] += x[k] * std::conj((*ph_)[k * nq + q]);
    X[0] /= M_;
    for (std::size_t q = 1; q < nq; ++q) X[q] *= std::complex<double>(0, 2.0 / M_);
  };
  const auto through = [&](const std::vector<std::complex<double>>& H, const std::vector<std::complex<double>>& X, std::size_t k) {
    double v = std::real(H[0] * X[0]);
    for (std::size_t q = 1; q < nq; ++q) v += std::imag(H[q] * X[q] * (*ph_)[k * nq + q]);
    return v;
  };
  const bool looped = std::any_of(loop.v.begin(), loop.v.end(), [](double x) { return x != 0; });
  std::vector<double> e(M), fl(M, 0.0);
  std::vector<std::complex<double>> E, D(nq, 0.0);
  double scale = 0;
  for (const double x : theta1_) scale = std::max(scale, std::abs(x));
  for (int it = 0;; ++it) {
    for (std::size_t k = 0; k < M; ++k) {
      e[k] = p2_ * theta[k] * theta[k];
      if (!looped) {
        z[k] = i[k];
        continue;
      }
      // The torque: z + f_loop(z) = i, Newton from the last z.
      for (int n = 0; n < 20; ++n) {
        const double dz = (z[k] + ia_sum(loop, z[k]) - i[k]) / (1 + ia_slope(loop, z[k]));
        z[k] -= dz;
        if (std::abs(dz) <= 1e-15 * (1 + std::abs(z[k]))) break;
      }
      fl[k] = ia_sum(loop, z[k]);
    }
    resolve(e, E);
    if (looped) resolve(fl, D);
    double moved = 0;
    for (std::size_t k = 0; k < M; ++k) {
      const double th = theta1_[k] + through(G_, E, k) + (looped ? through(Hth_, D, k) : 0.0);
      moved = std::max(moved, std::abs(th - theta[k]));
      theta[k] = th;
      i[k] = a_ + z1_[k] + through(T_, E, k) + (looped ? through(Hz_, D, k) : 0.0);
    }
    if (moved <= 1e-14 * scale) break;
    if (it == 300 || !std::isfinite(moved))
      throw std::invalid_argument("PeriodicPickoffBalance: the loop's harmonic balance with the pickoff nonlinearity did not settle at " +
                                  std::to_string(frequency_Hz_) + " Hz");
  }
  for (std::size_t k = 0; k < M; ++k)
    for (int n = 0; looped && n < 20; ++n) {
      const double dz = (z[k] + ia_sum(loop, z[k]) - i[k]) / (1 + ia_slope(loop, z[k]));
      z[k] -= dz;
      if (std::abs(dz) <= 1e-15 * (1 + std::abs(z[k]))) break;
    }
}

double PeriodicPickoffBalance::operator()(const Coefficients& c) const {
  const auto M = static_cast<std::size_t>(M_);
  // The IA terms by place (input-placed ones stay first order).
  Coefficients loop, out;
  for (int k = plant::k1_asym; k <= plant::k4; ++k) {
    if (location_[k] == Location::loop) loop[k] = c[k];
    if (location_[k] == Location::output) out[k] = c[k];
  }
  // From the balance without the IA terms (theirs moves it by ~their size: a few iterations).
  std::vector<double> theta = theta0_, i = i0_, z = i0_;
  solve(loop, theta, i, z);
  // The output's mean against its static value a + dc_gain f_loop(a) + f_out(a), less the
  // first-order prediction on the same points.
  double full = 0, first = pickoff_g_;
  for (std::size_t k = 0; k < M; ++k) {
    full += (i[k] + ia_sum(out, z[k])) / M_;
    first += (dc_gain_ * (ia_sum(loop, a_ + z1_[k]) - ia_sum(loop, a_)) + ia_sum(out, a_ + z1_[k]) - ia_sum(out, a_)) / M_;
  }
  return full - (a_ + dc_gain_ * ia_sum(loop, a_) + ia_sum(out, a_)) - first;
}

namespace {
// FFTW's complex buffers and plans, owned; plans made and destroyed under the planner's lock.
struct Fft {
  int n;
  fftw_complex* buf;
  fftw_plan forward, backward;
  explicit Fft(int size) : n(size), buf(static_cast<fftw_complex*>(fftw_malloc(sizeof(fftw_complex) * static_cast<std::size_t>(size)))) {
    if (!buf) throw std::bad_alloc();
    std::lock_guard lock(vibration::fftw_planner_mutex());
    forward = fftw_plan_dft_1d(n, buf, buf, FFTW_FORWARD, FFTW_ESTIMATE);
    backward = fftw_plan_dft_1d(n, buf, buf, FFTW_BACKWARD, FFTW_ESTIMATE);
    if (!forward || !backward) {
      if (forward) fftw_destroy_plan(forward);
      if (backward) fftw_destroy_plan(backward);
      fftw_free(buf);
      throw std::runtime_error("gaussian_pickoff_moments: fftw_plan_dft_1d failed for n = " + std::to_string(n));
    }
  }
  ~Fft() {
    {
      std::lock_guard lock(vibration::fftw_planner_mutex());
      fftw_destroy_plan(forward), fftw_destroy_plan(backward);
    }
    fftw_free(buf);
  }
  Fft(const Fft&) = delete;
  Fft& operator=(const Fft&) = delete;
  // The transform of x (zero-padded to n).
  std::vector<std::complex<double>> transform(const std::vector<std::complex<double>>& x) {
    for (int k = 0; k < n; ++k) {
      const std::complex<double> v = k < static_cast<int>(x.size()) ? x[static_cast<std::size_t>(k)] : 0.0;
      buf[k][0] = v.real(), buf[k][1] = v.imag();
    }
    fftw_execute(forward);
    std::vector<std::complex<double>> out(static_cast<std::size_t>(n));
    for (int k = 0; k < n; ++k) out[static_cast<std::size_t>(k)] = {buf[k][0], buf[k][1]};
    return out;
  }
  // The linear convolution of two sequences from their transforms (its first `length` values).
  std::vector<std::complex<double>> convolution(const std::vector<std::complex<double>>& A, const std::vector<std::complex<double>>& B,
                                                std::size_t length) {
    for (int k = 0; k < n; ++k) {
      const std::complex<double> v = A[static_cast<std::size_t>(k)] * B[static_cast<std::size_t>(k)];
      buf[k][0] = v.real(), buf[k][1] = v.imag();
    }
    fftw_execute(backward);
    std::vector<std::complex<double>> out(length);
    for (std::size_t k = 0; k < length; ++k) out[k] = std::complex<double>(buf[k][0], buf[k][1]) / static_cast<double>(n);
    return out;
  }
};
}  // namespace

GaussianPickoffMoments gaussian_pickoff_moments(const PlantConfig& plant, const vibration::RandomProfile& p, const ResponseAt& response,
                                                const Eigen::Matrix3d& turn, int points) {
  if (points < 16 || points > (1 << 20)) throw std::invalid_argument("gaussian_pickoff_moments: points must be in [16, 2^20]");
  const double top_Hz = vibration::max_frequency_Hz(p);
  if (!(top_Hz > 0)) throw std::invalid_argument("gaussian_pickoff_moments: the profile has no band");
  const int N = points;
  const double df = top_Hz / N;
  // One-sided densities on f_n = n df (n = 1..N): the current-angle cross-spectrum and the
  // angle's and the current's spectra; T_ze on f_m, m = 0..2N (m = 0: its limit at 1e-3 df).
  std::vector<double> f(static_cast<std::size_t>(N));
  for (int n = 1; n <= N; ++n) f[static_cast<std::size_t>(n - 1)] = n * df;
  const std::vector<Eigen::Matrix3cd> csd = cross_spectral_matrices_g2_per_Hz(p, f);
  std::vector<std::complex<double>> T(static_cast<std::size_t>(2 * N + 1)), Gt(T.size());
  double W = 0;  // E[theta_1 (H_thetaF * z_1)]
  const auto sN = static_cast<std::size_t>(N);
  std::vector<std::complex<double>> s_zt(2 * sN + 1), s_tt(2 * sN + 1);  // two-sided, index n + N
  GaussianPickoffMoments out;
  for (int m = 0; m <= 2 * N; ++m) {
    const LoopResponse r = response(m == 0 ? 1e-3 * df : m * df);
    T[static_cast<std::size_t>(m)] = pickoff_error_current(plant.dynamics, r);
    Gt[static_cast<std::size_t>(m)] = -r.current[IA] / r.mechanical[IA];
    if (m == 0 || m > N) continue;
    const Eigen::Matrix3cd S = turn * csd[static_cast<std::size_t>(m - 1)] * turn.transpose();
    Eigen::Vector3cd hz, ht;
    for (int i = 0; i < 3; ++i) hz[i] = r.current[static_cast<std::size_t>(i)], ht[i] = r.angle_rad[static_cast<std::size_t>(i)];
    const std::complex<double> g_zt = hz.transpose() * S * ht.conjugate();
    const double g_tt = std::real(std::complex<double>(ht.transpose() * S * ht.conjugate()));
    const double g_zz = std::real(std::complex<double>(hz.transpose() * S * hz.conjugate()));
    out.current_var += g_zz * df, out.angle_var_first += g_tt * df;
    // (one-sided: the two sides' conjugates sum to twice the real part; g_zt's conjugate is g_tz)
    W += std::real(std::conj(g_zt) * std::conj(r.angle_rad[IA] / r.mechanical[IA])) * df;
    const auto up = sN + static_cast<std::size_t>(m), down = sN - static_cast<std::size_t>(m);
    s_zt[up] = g_zt / 2.0, s_zt[down] = std::conj(g_zt) / 2.0;
    s_tt[up] = g_tt / 2.0, s_tt[down] = g_tt / 2.0;
  }
  // T over m = -2N..2N (index m + 2N): T(-f) = conj T(f).
  std::vector<std::complex<double>> T2(4 * sN + 1), G2(T2.size());
  for (std::size_t m = 0; m <= 2 * sN; ++m) {
    T2[2 * sN + m] = T[m], T2[2 * sN - m] = std::conj(T[m]);
    G2[2 * sN + m] = Gt[m], G2[2 * sN - m] = std::conj(Gt[m]);
  }
  // Linear convolutions by FFT (length >= 6N + 1).
  int size = 1;
  while (size < 6 * N + 2) size *= 2;
  Fft fft(size);
  const auto Szt = fft.transform(s_zt), Stt = fft.transform(s_tt), FT = fft.transform(T2), FG = fft.transform(G2);
  // Q(F_m) = int s(f) s(F_m - f) df, m = -2N..2N at index m + 2N.
  const auto Qzt = fft.convolution(Szt, Szt, 4 * sN + 1), Qtt = fft.convolution(Stt, Stt, 4 * sN + 1);
  // Y(m) = int s_zt(f) T(F_m - f) df, m = -3N..3N at index m + 3N.
  const auto Y = fft.convolution(Szt, FT, 6 * sN + 1), YG = fft.convolution(Stt, FG, 6 * sN + 1);
  double J = 0, V = 0, A2 = 0;
  for (std::size_t k = 0; k <= 4 * sN; ++k) {
    // F_m with m = k - 2N: T(-F_m) at index 2N - m = 4N - k of T2.
    J += std::real(Qzt[k] * T2[4 * sN - k]) * df * df;
    V += 2 * std::norm(T2[k]) * std::real(Qtt[k]) * df * df;
    // K2 = int Q_zt(F) G(-F) Y(-F) dF: G(-F_m) at 4N - k of G2, Y(-F_m) at 3N - m = 5N - k of Y.
    out.K2 += std::real(Qzt[k] * G2[4 * sN - k] * Y[5 * sN - k]) * df * df * df;
    A2 += 2 * std::norm(G2[k]) * std::real(Qtt[k]) * df * df;  // E[theta_2^2] / p2^2
  }
  double K = 0;
  for (std::size_t g = 0; g <= 2 * sN; ++g) {
    // gamma = g - N; X(gamma) = Y(-gamma) at index 3N - gamma, X(-gamma) = Y(gamma) at 3N + gamma.
    K += std::real(s_tt[g] * Y[4 * sN - g] * Y[2 * sN + g]) * df * df * df;
    // 2 E[theta_1 theta_3] / p2^2 = 8 int s(f) G(-f) X_G(f), X_G(f) = int s(f') G(-f - f') = Y_G(-f);
    // G(-gamma) at index 2N - gamma = 3N - g of G2.
    A2 += 8 * std::real(s_tt[g] * G2[3 * sN - g] * YG[4 * sN - g]) * df * df;
    out.loop_slope += std::real(s_tt[g] * G2[3 * sN - g]) * df;
    // The current's: 2 E[z_1 z_3] / p2^2 = 8 int s_zt(f) T(-f) Y_G(-f); int s_zt(f) T(-f).
    out.current_z3 += 8 * std::real(s_zt[g] * T2[3 * sN - g] * YG[4 * sN - g]) * df * df;
    out.current_slope += std::real(s_zt[g] * T2[3 * sN - g]) * df;
  }
  out.J = J, out.z2_var = V, out.K = K, out.angle_var = A2, out.angle_force = W;
  return out;
}

PickoffSecondOrder gaussian_second_order(const GaussianPickoffMoments& m, const plant::Dynamics& d, double p2, double s2, double angle_var,
                                         double a) {
  PickoffSecondOrder out;
  if (p2 == 0 || !(s2 > 0)) return out;
  // The pickoff's own: <theta> = -p2 <theta^2>, <theta^2> = E[theta_1^2] + <theta>^2 +
  // E[theta_2^2 + 2 theta_1 theta_3] + 2 E[theta_1 theta_3'] (theta_3' = G * (2 p2 <theta> theta_1)).
  const double stiffness = std::pow(2 * std::numbers::pi * d.pendulum_frequency_Hz, 2) / d.angle_gain_rad_per_s2_per_g;
  const double mean_angle = -p2 * angle_var;
  out.expansion = std::abs(p2) * std::sqrt(angle_var);
  out.pickoff_g = stiffness * p2 * (mean_angle * mean_angle + p2 * p2 * m.angle_var + 4 * p2 * mean_angle * m.loop_slope);
  const double delta = stiffness * p2 * angle_var + out.pickoff_g;  // the current's mean shift
  const double s = std::sqrt(s2), u = a / s;
  const double phi = std::exp(-u * u / 2) / std::sqrt(2 * std::numbers::pi), Phi = 0.5 * std::erfc(-u / std::numbers::sqrt2);
  // The current's variance moved (E[z_2^2] + 2 E[z_1 z_3] + 2 E[z_1 dz_1], dz_1 = T * (2 p2 <theta> theta_1)).
  const double z2 = p2 * p2 * (m.z2_var + m.current_z3) + 4 * p2 * mean_angle * m.current_slope;
  out.shift[plant::k1_asym] = delta * 0.5 * (2 * Phi - 1) + p2 * m.J * (-u * phi / s2);
  out.shift[plant::k2] = delta * 2 * a + z2;
  out.shift[plant::k3] = delta * 3 * (a * a + s2) + p2 * m.J * 6 + 3 * a * z2;
  out.shift[plant::k4] = delta * 4 * (a * a * a + 3 * a * s2) + p2 * m.J * 24 * a + 6 * ((a * a + s2) * z2 + 8 * p2 * p2 * (m.K + m.K2));
  // A term in the loop: its oscillation torques the pendulum, E[f'(a + Z)] z_1 to first order
  // (Stein's lemma: E[theta_1 f(a + Z')] = E[theta_1 Z'] E[f']), and moves the pickoff's mean
  // by 2 p2 E[theta_1 theta_f] = 2 p2 E[f'] E[theta_1 (H_thetaF * z_1)].
  const std::array<double, 4> mean_slope{0.5 * (2 * Phi - 1), 2 * a, 3 * (a * a + s2), 4 * (a * a * a + 3 * a * s2)};
  for (int c = plant::k1_asym; c <= plant::k4; ++c)
    out.loop_shift[c] = stiffness * p2 * 2 * mean_slope[static_cast<std::size_t>(c - plant::k1_asym)] * m.angle_force;
  return out;
}

}  // namespace vrelab::rectification
