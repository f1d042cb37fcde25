#include "plant/ode_solver.hpp"

#include <cmath>
#include <exception>
#include <sstream>

#include <cvode/cvode.h>
#include <nvector/nvector_serial.h>
#include <sundials/sundials_context.h>
#include <sunlinsol/sunlinsol_dense.h>
#include <sunmatrix/sunmatrix_dense.h>

#include "core/cancel.hpp"

namespace vrelab::plant {
namespace {

std::string describe_flag(int flag) {
  char* name = CVodeGetReturnFlagName(flag);
  std::string s = name ? name : "unknown flag";
  free(name);  // CVodeGetReturnFlagName returns malloc'ed memory
  return s;
}

}  // namespace

SolverError::SolverError(const std::string& c, int f, double t, const std::string& detail)
    : std::runtime_error([&] {
        std::ostringstream s;
        s << "solver failure in " << c << " at simulated time t = " << t << " s";
        if (f != 0) s << " (" << describe_flag(f) << ")";
        if (!detail.empty()) s << ": " << detail;
        return s.str();
      }()),
      call(c),
      flag(f),
      t_s(t) {}

struct OdeSolver::Impl {
  const OdeSystem& system;
  SUNContext ctx = nullptr;
  N_Vector y = nullptr;
  N_Vector abstol = nullptr;
  SUNMatrix a = nullptr;
  SUNLinearSolver ls = nullptr;
  void* mem = nullptr;
  std::exception_ptr rhs_error;
  std::string last_message;

  explicit Impl(const OdeSystem& s) : system(s) {}
  ~Impl() {
    if (mem) CVodeFree(&mem);
    if (ls) SUNLinSolFree(ls);
    if (a) SUNMatDestroy(a);
    if (abstol) N_VDestroy(abstol);
    if (y) N_VDestroy(y);
    if (ctx) SUNContext_Free(&ctx);
  }

  void check(int flag, const char* call, double t) const {
    if (flag < 0) throw SolverError(call, flag, t, last_message);
  }

  static int rhs(realtype t, N_Vector y, N_Vector ydot, void* user) {
    auto* self = static_cast<Impl*>(user);
    try {
      self->system.rhs(t, N_VGetArrayPointer(y), N_VGetArrayPointer(ydot));
      for (sunindextype i = 0; i < N_VGetLength(ydot); ++i)
        if (!std::isfinite(N_VGetArrayPointer(ydot)[i])) return 1;  // recoverable: CVODE cuts the step
      return 0;
    } catch (...) {
      self->rhs_error = std::current_exception();
      return -1;
    }
  }

  static int jac(realtype t, N_Vector y, N_Vector, SUNMatrix j, void* user, N_Vector, N_Vector, N_Vector) {
    auto* self = static_cast<Impl*>(user);
    try {
      self->system.jacobian(t, N_VGetArrayPointer(y), SUNDenseMatrix_Data(j));  // column-major
      return 0;
    } catch (...) {
      self->rhs_error = std::current_exception();
      return -1;
    }
  }

  static void on_error(int, const char*, const char* function, char* msg, void* user) {
    auto* self = static_cast<Impl*>(user);
    self->last_message = std::string(function) + ": " + msg;
  }
};

OdeSolver::OdeSolver(const OdeSystem& system, double t0, const std::vector<double>& x0, const SolverSettings& s)
    : impl_(std::make_unique<Impl>(system)), x_(x0), t_(t0) {
  const int n = system.size();
  std::string why;
  if (!s.IsValid(&why)) throw SolverError("SolverSettings::IsValid", 0, t0, why);
  if (static_cast<int>(x0.size()) != n || static_cast<int>(s.absolute_tolerance.size()) != n)
    throw SolverError("OdeSolver", 0, t0, "state and tolerance sizes must equal the system size");
  Impl& m = *impl_;
  if (SUNContext_Create(nullptr, &m.ctx) != 0) throw SolverError("SUNContext_Create", 0, t0, "");
  m.y = N_VNew_Serial(n, m.ctx);
  m.abstol = N_VNew_Serial(n, m.ctx);
  if (!m.y || !m.abstol) throw SolverError("N_VNew_Serial", 0, t0, "allocation failed");
  for (int i = 0; i < n; ++i) {
    N_VGetArrayPointer(m.y)[i] = x0[static_cast<std::size_t>(i)];
    N_VGetArrayPointer(m.abstol)[i] = s.absolute_tolerance[static_cast<std::size_t>(i)];
  }
  m.mem = CVodeCreate(CV_BDF, m.ctx);
  if (!m.mem) throw SolverError("CVodeCreate", 0, t0, "");
  m.check(CVodeSetErrHandlerFn(m.mem, &Impl::on_error, &m), "CVodeSetErrHandlerFn", t0);
  m.check(CVodeInit(m.mem, &Impl::rhs, t0, m.y), "CVodeInit", t0);
  m.check(CVodeSetUserData(m.mem, &m), "CVodeSetUserData", t0);
  m.check(CVodeSVtolerances(m.mem, s.relative_tolerance, m.abstol), "CVodeSVtolerances", t0);
  m.a = SUNDenseMatrix(n, n, m.ctx);
  m.ls = SUNLinSol_Dense(m.y, m.a, m.ctx);
  if (!m.a || !m.ls) throw SolverError("SUNLinSol_Dense", 0, t0, "allocation failed");
  m.check(CVodeSetLinearSolver(m.mem, m.ls, m.a), "CVodeSetLinearSolver", t0);
  if (s.analytic_jacobian && system.has_jacobian()) m.check(CVodeSetJacFn(m.mem, &Impl::jac), "CVodeSetJacFn", t0);
  m.check(CVodeSetMaxNumSteps(m.mem, s.max_steps), "CVodeSetMaxNumSteps", t0);
  if (s.max_step_s > 0) m.check(CVodeSetMaxStep(m.mem, s.max_step_s), "CVodeSetMaxStep", t0);
}

OdeSolver::~OdeSolver() = default;

const std::vector<double>& OdeSolver::advance(double t_out) {
  Impl& m = *impl_;
  if (t_out < t_) throw SolverError("OdeSolver::advance", 0, t_, "output times must not decrease");
  core::throw_if_cancelled();  // a caller's cancel flag (core/cancel.hpp): Ctrl-C in Python
  if (t_out > t_) {
    realtype t_reached = t_;
    const int flag = CVode(m.mem, t_out, m.y, &t_reached, CV_NORMAL);
    if (m.rhs_error) std::rethrow_exception(m.rhs_error);
    if (flag < 0) {
      realtype t_cur = t_reached;
      CVodeGetCurrentTime(m.mem, &t_cur);
      throw SolverError("CVode", flag, t_cur, m.last_message);
    }
    t_ = t_out;
  }
  for (std::size_t i = 0; i < x_.size(); ++i) x_[i] = N_VGetArrayPointer(m.y)[i];
  return x_;
}

long OdeSolver::steps() const {
  long n = 0;
  CVodeGetNumSteps(impl_->mem, &n);
  return n;
}

long OdeSolver::rhs_evaluations() const {
  long n = 0;
  CVodeGetNumRhsEvals(impl_->mem, &n);
  return n;
}

}  // namespace vrelab::plant
