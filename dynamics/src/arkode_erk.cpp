/// ARKODE ERKStep (default 4th-order adaptive explicit Runge-Kutta): the explicit reference. Its
/// step is bounded by stability, so on a stiff case it exhausts its per-output step budget and
/// returns ARK_TOO_MUCH_WORK; steerPass reports that as SolverFailed instead of a wrong path.
#include <memory>

#include <arkode/arkode_erkstep.h>

#include "sundials_support.h"

namespace fieldpath::dynamics::detail {
namespace {

class ArkodeErk final : public Integrator {
 public:
  ArkodeErk(OdeSystem& system, int size, double t0, const double* y0,
            const IntegratorSettings& settings)
      : Integrator(system, size, y0, settings.atol) {
    mem_.reset(ERKStepCreate(rhsTrampoline, t0, y_, ctx_));
    FIELDPATH_SUNDIALS_NOT_NULL(mem_, "ERKStepCreate");
    void* mem = mem_.get();
    FIELDPATH_SUNDIALS_CHECK(ERKStepSetErrHandlerFn(mem, keepErrorMessage, &last_error_));
    FIELDPATH_SUNDIALS_CHECK(ERKStepSVtolerances(mem, settings.rtol, atol_));
    FIELDPATH_SUNDIALS_CHECK(ERKStepSetUserData(mem, &system_));
    FIELDPATH_SUNDIALS_CHECK(ERKStepSetMaxNumSteps(mem, settings.max_steps));
    if (settings.max_step_s > 0.0)
      FIELDPATH_SUNDIALS_CHECK(ERKStepSetMaxStep(mem, settings.max_step_s));
  }

  std::string flagName(int flag) const override {
    return takeFlagName(ERKStepGetReturnFlagName(flag));
  }

 private:
  int evolve(double t_out, double& t_reached) override {
    return ERKStepEvolve(mem_.get(), t_out, y_, &t_reached, ARK_NORMAL);
  }

  void reinit(double t) override {
    FIELDPATH_SUNDIALS_CHECK(ERKStepReInit(mem_.get(), rhsTrampoline, t, y_));
  }

  SolverStats counters() const override {
    void* mem = mem_.get();
    SolverStats s;
    FIELDPATH_SUNDIALS_CHECK(ERKStepGetNumSteps(mem, &s.steps));
    FIELDPATH_SUNDIALS_CHECK(ERKStepGetNumRhsEvals(mem, &s.rhs_evals));
    FIELDPATH_SUNDIALS_CHECK(ERKStepGetNumErrTestFails(mem, &s.error_test_failures));
    return s;
  }

  std::unique_ptr<void, FreeByAddress<ERKStepFree>> mem_;
};

}  // namespace

std::unique_ptr<Integrator> makeArkodeErk(OdeSystem& system, int size, double t0, const double* y0,
                                          const IntegratorSettings& settings) {
  return std::make_unique<ArkodeErk>(system, size, t0, y0, settings);
}

}  // namespace fieldpath::dynamics::detail
