#pragma once
/// SUNDIALS plumbing private to dynamics/: an RAII context and vector, flag checks naming the call,
/// file and line, and the typed right-hand side behind one static trampoline. Never included from a
/// public header: other modules see our own types only.
#include <exception>
#include <memory>
#include <string>
#include <vector>

#include <nvector/nvector_serial.h>
#include <sundials/sundials_context.h>

#include "fieldpath/dynamics/steering.h"

namespace fieldpath::dynamics::detail {

/// Throws std::runtime_error ("CVodeInit failed with flag -22 at cvode_bdf.cpp:41"): a failed setup
/// call is an internal error (exit 2), never a numerical outcome.
[[noreturn]] void throwSundials(const char* call, long flag, const char* file, int line);

#define FIELDPATH_SUNDIALS_CHECK(call)                                                          \
  do {                                                                                          \
    const long fieldpath_flag_ = static_cast<long>(call);                                       \
    if (fieldpath_flag_ < 0)                                                                    \
      ::fieldpath::dynamics::detail::throwSundials(#call, fieldpath_flag_, __FILE__, __LINE__); \
  } while (false)

/// Constructors return null on failure; same report as a negative flag.
#define FIELDPATH_SUNDIALS_NOT_NULL(ptr, call)                                   \
  do {                                                                           \
    if ((ptr) == nullptr)                                                        \
      ::fieldpath::dynamics::detail::throwSundials(call, 0, __FILE__, __LINE__); \
  } while (false)

/// SUNContext owner (SUNDIALS 6.4: SUNContext_Create(nullptr, &ctx)).
class Context {
 public:
  Context();
  ~Context();
  Context(const Context&) = delete;
  Context& operator=(const Context&) = delete;
  operator SUNContext() const { return ctx_; }

 private:
  SUNContext ctx_ = nullptr;
};

/// Serial N_Vector owner.
class Vector {
 public:
  Vector(sunindextype size, SUNContext ctx);
  ~Vector();
  Vector(const Vector&) = delete;
  Vector& operator=(const Vector&) = delete;
  operator N_Vector() const { return v_; }
  double* data() const { return N_VGetArrayPointer(v_); }

 private:
  N_Vector v_ = nullptr;
};

/// y' = f(t, y) with a fixed size. rhs returns 0 on success, > 0 for a recoverable failure (the
/// solver retries with a smaller step), < 0 for a fatal one.
class OdeSystem {
 public:
  virtual ~OdeSystem() = default;
  virtual int rhs(double t, const double* y, double* ydot) = 0;
  /// An exception thrown by rhs (interruption, a field error) is held here and rethrown once the
  /// solver has returned: it must not unwind through C frames.
  std::exception_ptr pending;
  void rethrowPending();
};

/// The one static trampoline (CVRhsFn and ARKRhsFn have the same signature); user_data is the
/// OdeSystem.
int rhsTrampoline(sunrealtype t, N_Vector y, N_Vector ydot, void* user_data);

/// Error handler for CVODE and ARKODE: keeps the message (for SteeringResult::message) instead of
/// printing it on stderr. eh_data is a std::string.
void keepErrorMessage(int error_code, const char* module, const char* function, char* msg,
                      void* eh_data);

/// A time integrator over an OdeSystem; CVODE BDF and ARKODE ERK derive from it. It owns the
/// context and the state vector and keeps the counters across restarts.
class Integrator {
 public:
  virtual ~Integrator() = default;
  Integrator(const Integrator&) = delete;
  Integrator& operator=(const Integrator&) = delete;

  /// Advances to t_out (s); y (size n) receives the state at t_reached (= t_out unless it failed).
  /// Returns the solver flag (< 0: failure).
  int advance(double t_out, double* y, double& t_reached);
  /// Starts again from (t, y), e.g. after a clamp; the counters keep counting.
  void restart(double t, const double* y);
  SolverStats stats() const;
  virtual std::string flagName(int flag) const = 0;
  /// The solver's last error message, if any.
  const std::string& lastError() const { return last_error_; }

 protected:
  Integrator(OdeSystem& system, int size, const double* y0, const std::vector<double>& atol);
  virtual int evolve(double t_out, double& t_reached) = 0;  ///< one CVode / ERKStepEvolve on y_
  virtual void reinit(double t) = 0;         ///< from y_; resets the solver's own counters
  virtual SolverStats counters() const = 0;  ///< since the last (re)initialisation

  OdeSystem& system_;
  Context ctx_;  ///< declared before every object created in it
  Vector y_;
  Vector atol_;  ///< absolute tolerance per component
  std::string last_error_;

 private:
  SolverStats before_restart_;
};

/// SUNDIALS' *GetReturnFlagName strings are malloc'ed: copy and free.
std::string takeFlagName(char* name);

/// unique_ptr deleter calling a SUNDIALS destroy function that takes the pointer's address.
template <auto free_fn>
struct FreeByAddress {
  void operator()(void* mem) const { free_fn(&mem); }
};

struct IntegratorSettings {
  double rtol = 1e-6;
  std::vector<double> atol;  ///< per component (angles in rad, rates in rad/s)
  double max_step_s =
      0.0;  ///< 0 = unlimited; set to the output interval so no feature is stepped over
  long max_steps = 500;  ///< per advance() call
};

std::unique_ptr<Integrator> makeCvodeBdf(OdeSystem& system, int size, double t0, const double* y0,
                                         const IntegratorSettings& settings);
std::unique_ptr<Integrator> makeArkodeErk(OdeSystem& system, int size, double t0, const double* y0,
                                          const IntegratorSettings& settings);

}  // namespace fieldpath::dynamics::detail
