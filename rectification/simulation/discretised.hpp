#pragma once
// rectification/simulation/discretised.hpp -- the plant under random vibration stepped once
// per output sample: an exact discretisation of the linear loop for the excitation's own
// interpolant, the small nonlinear terms as an exponential-integrator correction.
//
// Takes: the shaken plant (plant/accelerometer.hpp; its Input is not used), its linearisation
//        and equilibrium, a RandomExcitation (vibration/sampled.hpp) and the rate of the grid
//        the run is sampled on (the readout's, or the excitation's own sample rate).
// Gives: at each grid point t_m = m / rate the plant's output U/K1 (g), the companion's
//        linear output (the plant's linearisation driven by the same input, as
//        shake_excitation defines it), the input (g) and the residual quadrature
//        Q - z_Q (the integral of what the linear dynamics do not explain).
//
// Method (docs/performance.md, "Random runs"). The state deviation from the equilibrium is
// split x - x_eq = z + y: z the linear companion, z' = A z + B a(t); y the rest,
// y' = A y + N(t), N = f(x) - A (x - x_eq) - B a exactly (nothing is linearised).
//  - a(t) is the quintic B-spline through the excitation's samples (knots at 1/fs): on each
//    knot interval a polynomial of degree 5, so z is propagated exactly over a grid step by
//    e^{A h} z + K_j c, with c the 7 spline coefficients around the step and K_j from the
//    exponential of the plant augmented by the polynomial's derivative chain (one matrix per
//    phase j of the grid against the knots: the grid rate must be a small rational multiple
//    p/q of fs, q <= 256, and at least fs).
//  - y by the second-order exponential integrator (ETD2): y_{m+1} = e^{Ah} y_m +
//    h phi1(Ah) N_m + h phi2(Ah) (N_{m+1} - N_m), N linear between grid points, N_{m+1}
//    evaluated at the predicted y (its dependence on y is of second order in the small
//    terms) and the output corrected by C (y_{m+1} - y_pred). The mean of N over a grid
//    step is its trapezoid, so the measured mean carries N's content at multiples of the
//    grid rate only (none for smooth terms of a band-limited drive).
//  - one plant evaluation per grid point (Accelerometer::rhs_output).
// Non-smooth effects (current saturation, readout clipping) make N neither small nor smooth,
// and the pickoff nonlinearity's correction was measured 0.3 % off CVODE under GEVS (the
// squeeze film is not checked): `unsupported` says so and shake_excitation runs CVODE instead.
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "plant/accelerometer.hpp"
#include "vibration/sampled.hpp"

namespace vrelab::rectification {

// Pointers into a DiscretisedRandomPlant's matrices and vectors for one step (internal).
struct StepData {
  int n = 0, w = 0, k_axes = 0;
  const double *e = nullptr, *p1 = nullptr, *ep2 = nullptr, *a = nullptr, *b = nullptr, *k = nullptr,
               *c_p2 = nullptr, *window = nullptr, *a_k = nullptr, *f = nullptr, *q_row = nullptr, *q_input = nullptr;
  const int* act = nullptr;
  double *z = nullptr, *sigma = nullptr, *g = nullptr, *n_prev = nullptr, *dn = nullptr, *linear = nullptr;
};

class DiscretisedRandomPlant {
 public:
  // Why the discretised path cannot run this case, or "" when it can.
  static std::string unsupported(const plant::PlantConfig& config, const vibration::RandomExcitation& ex,
                                 double grid_rate_Hz);

  // quadrature = false: residual_quadrature() is not wanted (a sampled record reads the
  // output and the linear output only), and the quadrature state is not stepped (it feeds
  // nothing back: one state fewer in every per-step product).
  DiscretisedRandomPlant(const plant::Accelerometer& plant, const plant::Accelerometer::Linear& lin,
                         const std::vector<double>& x_eq, const vibration::RandomExcitation& ex, double grid_rate_Hz,
                         bool quadrature = true);
  ~DiscretisedRandomPlant();

  // From grid point m to m + 1 (the object starts at m = 0, t = 0, at rest).
  void advance();
  std::int64_t index() const { return m_; }
  double time_s() const { return static_cast<double>(m_) / rate_; }
  double output_g() const { return out_; }
  double linear_output_g() const { return linear_; }
  const Vec3& input_g() const { return a_; }
  double residual_quadrature() const;  // y_Q = Q - z_Q (needs quadrature = true)
  long plant_evaluations() const { return evaluations_; }

 private:
  struct Coefficients;
  void evaluate_at_grid_point();  // a, N, output, linear output at m (y holds the prediction)
  StepData step_data();

  const plant::Accelerometer& plant_;
  const std::vector<double>& x_eq_;
  double rate_;
  int n_;                       // plant states
  std::vector<int> act_, inert_;  // states stepped (the loop's, then the quadrature if kept) / held still
  int na_ = 0, q_index_ = -1;   // act_'s size, the quadrature's place in it (-1: not stepped)
  std::vector<int> axes_;       // excited axes
  int k_ = 0;                   // their number
  std::int64_t p_ = 1, q_ = 1;  // grid step = p/q knot intervals
  std::int64_t m_ = 0;          // grid point
  std::int64_t knot_ = 0, phase_ = 0;  // m p = knot_ q + phase_ (no division per step)
  // Per phase j (grid point m at knot position floor + j/q): input weights (6) and the input
  // contribution over the step (na x 7k).
  std::vector<std::vector<double>> weights_;
  std::vector<Eigen::MatrixXd> k_step_;
  // On the stepped states: e^{Ah}, h phi1(Ah), e^{Ah} h phi2(Ah), A, B (excited axes).
  Eigen::MatrixXd e_, p1_, ep2_, a_mat_, b_mat_;
  // z: the companion; sigma: the deviation x - x_eq where the plant is evaluated (the ETD2
  // prediction; the corrected state is sigma + P2 dN); g = f - B a; N_prev; dN.
  Eigen::VectorXd z_, sigma_, g_, n_prev_, dn_, a_k_, c_p2_, p2_q_, q_row_, q_input_;
  std::vector<double> x_, f_;  // full plant state and derivative
  StepData data_;
  void (*propagate_)(const StepData&) = nullptr;
  double (*correct_)(const StepData&, bool first) = nullptr;
  Vec3 a_ = Vec3::Zero();
  double out_ = 0, linear_ = 0;
  long evaluations_ = 0;
  std::unique_ptr<Coefficients> coef_;
};

}  // namespace vrelab::rectification
