#pragma once
// plant/ode_solver.hpp -- SUNDIALS CVODE behind RAII owners.
//
// Takes: an OdeSystem (size, right-hand side), initial time and state, and SolverSettings
//        (relative tolerance, absolute tolerance per state, maximum step).
// Gives: the state at requested output times (CVODE's interpolation in CV_NORMAL mode),
//        step statistics. Every SUNDIALS flag is checked; a failure throws SolverError
//        naming the call, the flag and the simulation time, never a crash. An exception
//        thrown by the right-hand side is carried across CVODE and rethrown.
//
// CVODE's BDF method with a dense direct linear solver: the servo loop makes the system
// stiff (closed-loop poles at kHz) while a low-frequency vibration allows steps of ms;
// the systems here have at most a few tens of states, so a dense Jacobian by difference
// quotients is cheap (docs/plant.md).
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include "core/settings_description.hpp"

namespace vrelab::plant {

class OdeSystem {
 public:
  virtual ~OdeSystem() = default;
  virtual int size() const = 0;
  virtual void rhs(double t_s, const double* x, double* dx) const = 0;
  // The Jacobian d(dx)/dx at (t, x), column-major n x n into j; false (the default): CVODE
  // forms it by difference quotients.
  virtual bool has_jacobian() const { return false; }
  virtual void jacobian(double /*t_s*/, const double* /*x*/, double* /*j*/) const {}
};

// CVODE's settings. Describe lists each field once (core/settings_description.hpp): IsValid
// checks the described ranges and the JSON record of the settings used iterates it. The
// runs set them in code (from ShakeSettings), so no case table or flag holds them.
struct SolverSettings {
  double relative_tolerance = 1e-10;
  std::vector<double> absolute_tolerance;  // one per state
  double max_step_s = 0.0;                 // 0: no limit
  long max_steps = 50'000'000;
  // Give CVODE the system's own Jacobian when it has one (OdeSystem::has_jacobian); false:
  // CVODE's difference quotients always (a check of the analytic one).
  bool analytic_jacobian = true;

  template <class V>
  static void Describe(V& v) {
    using S = SolverSettings;
    using core::field;
    v(field("relative_tolerance", &S::relative_tolerance, "", core::open(0, 1), "CVODE's relative tolerance"));
    v(field("absolute_tolerance", &S::absolute_tolerance, "state units", core::above(0),
            "CVODE's absolute tolerance, one per state"));
    v(field("max_step_s", &S::max_step_s, "s", core::at_least(0), "Longest step; 0: no limit"));
    v(field("max_steps", &S::max_steps, "steps", core::at_least(1), "Steps allowed in one advance"));
    v(field("analytic_jacobian", &S::analytic_jacobian, "", core::any_value(),
            "The system's own Jacobian where it has one; false: difference quotients"));
  }
  bool IsValid(std::string* error) const { return core::validate(*this, error); }
};

struct SolverError : std::runtime_error {
  SolverError(const std::string& call, int flag, double t_s, const std::string& detail);
  std::string call;
  int flag;
  double t_s;
};

class OdeSolver {
 public:
  OdeSolver(const OdeSystem& system, double t0_s, const std::vector<double>& x0, const SolverSettings& s);
  ~OdeSolver();
  OdeSolver(const OdeSolver&) = delete;
  OdeSolver& operator=(const OdeSolver&) = delete;

  // Integrates to t_out (>= the last output time) and returns the state there.
  const std::vector<double>& advance(double t_out_s);
  const std::vector<double>& state() const { return x_; }
  double time() const { return t_; }
  long steps() const;
  long rhs_evaluations() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
  std::vector<double> x_;
  double t_;
};

}  // namespace vrelab::plant
