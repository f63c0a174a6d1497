/// CVODE BDF with a dense Newton solver and CVODE's difference-quotient Jacobian (no user Jacobian:
/// the moment of a sampled field has no cheap analytic derivative).
#include <memory>

#include <cvode/cvode.h>
#include <sunlinsol/sunlinsol_dense.h>
#include <sunmatrix/sunmatrix_dense.h>

#include "sundials_support.h"

namespace fieldpath::dynamics::detail {
namespace {

struct MatrixDeleter {
  void operator()(SUNMatrix m) const { SUNMatDestroy(m); }
};
struct LinearSolverDeleter {
  void operator()(SUNLinearSolver s) const { SUNLinSolFree(s); }
};

class CvodeBdf final : public Integrator {
 public:
  CvodeBdf(OdeSystem& system, int size, double t0, const double* y0,
           const IntegratorSettings& settings)
      : Integrator(system, size, y0, settings.atol) {
    mem_.reset(CVodeCreate(CV_BDF, ctx_));
    FIELDPATH_SUNDIALS_NOT_NULL(mem_, "CVodeCreate");
    void* mem = mem_.get();
    FIELDPATH_SUNDIALS_CHECK(CVodeSetErrHandlerFn(mem, keepErrorMessage, &last_error_));
    FIELDPATH_SUNDIALS_CHECK(CVodeInit(mem, rhsTrampoline, t0, y_));
    FIELDPATH_SUNDIALS_CHECK(CVodeSVtolerances(mem, settings.rtol, atol_));
    FIELDPATH_SUNDIALS_CHECK(CVodeSetUserData(mem, &system_));
    matrix_.reset(SUNDenseMatrix(size, size, ctx_));
    FIELDPATH_SUNDIALS_NOT_NULL(matrix_, "SUNDenseMatrix");
    solver_.reset(SUNLinSol_Dense(y_, matrix_.get(), ctx_));
    FIELDPATH_SUNDIALS_NOT_NULL(solver_, "SUNLinSol_Dense");
    FIELDPATH_SUNDIALS_CHECK(CVodeSetLinearSolver(mem, solver_.get(), matrix_.get()));
    FIELDPATH_SUNDIALS_CHECK(CVodeSetMaxNumSteps(mem, settings.max_steps));
    if (settings.max_step_s > 0.0)
      FIELDPATH_SUNDIALS_CHECK(CVodeSetMaxStep(mem, settings.max_step_s));
  }

  std::string flagName(int flag) const override {
    return takeFlagName(CVodeGetReturnFlagName(flag));
  }

 private:
  int evolve(double t_out, double& t_reached) override {
    return CVode(mem_.get(), t_out, y_, &t_reached, CV_NORMAL);
  }

  void reinit(double t) override { FIELDPATH_SUNDIALS_CHECK(CVodeReInit(mem_.get(), t, y_)); }

  SolverStats counters() const override {
    void* mem = mem_.get();
    long jac_rhs = 0;
    SolverStats s;
    FIELDPATH_SUNDIALS_CHECK(CVodeGetNumSteps(mem, &s.steps));
    FIELDPATH_SUNDIALS_CHECK(CVodeGetNumRhsEvals(mem, &s.rhs_evals));
    FIELDPATH_SUNDIALS_CHECK(CVodeGetNumJacEvals(mem, &s.jacobian_evals));
    FIELDPATH_SUNDIALS_CHECK(CVodeGetNumLinRhsEvals(mem, &jac_rhs));
    FIELDPATH_SUNDIALS_CHECK(CVodeGetNumErrTestFails(mem, &s.error_test_failures));
    FIELDPATH_SUNDIALS_CHECK(CVodeGetNumNonlinSolvConvFails(mem, &s.convergence_failures));
    s.rhs_evals += jac_rhs;  // the difference-quotient Jacobian's evaluations count too
    return s;
  }

  // Destroyed in reverse order: the CVODE memory first, then the solver and matrix it uses.
  std::unique_ptr<std::remove_pointer_t<SUNMatrix>, MatrixDeleter> matrix_;
  std::unique_ptr<std::remove_pointer_t<SUNLinearSolver>, LinearSolverDeleter> solver_;
  std::unique_ptr<void, FreeByAddress<CVodeFree>> mem_;
};

}  // namespace

std::unique_ptr<Integrator> makeCvodeBdf(OdeSystem& system, int size, double t0, const double* y0,
                                         const IntegratorSettings& settings) {
  return std::make_unique<CvodeBdf>(system, size, t0, y0, settings);
}

}  // namespace fieldpath::dynamics::detail
