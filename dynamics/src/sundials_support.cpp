#include "sundials_support.h"

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <stdexcept>
#include <utility>

namespace fieldpath::dynamics::detail {

void throwSundials(const char* call, long flag, const char* file, int line) {
  throw std::runtime_error(std::string(call) + " failed with flag " + std::to_string(flag) +
                           " at " + std::filesystem::path(file).filename().string() + ":" +
                           std::to_string(line));
}

Context::Context() { FIELDPATH_SUNDIALS_CHECK(SUNContext_Create(nullptr, &ctx_)); }
Context::~Context() { SUNContext_Free(&ctx_); }

Vector::Vector(sunindextype size, SUNContext ctx) : v_(N_VNew_Serial(size, ctx)) {
  FIELDPATH_SUNDIALS_NOT_NULL(v_, "N_VNew_Serial");
}
Vector::~Vector() { N_VDestroy(v_); }

void OdeSystem::rethrowPending() {
  if (pending) std::rethrow_exception(std::exchange(pending, nullptr));
}

int rhsTrampoline(sunrealtype t, N_Vector y, N_Vector ydot, void* user_data) {
  auto* system = static_cast<OdeSystem*>(user_data);
  try {
    return system->rhs(t, N_VGetArrayPointer(y), N_VGetArrayPointer(ydot));
  } catch (...) {
    system->pending = std::current_exception();
    return -1;
  }
}

void keepErrorMessage(int /*error_code*/, const char* module, const char* function, char* msg,
                      void* eh_data) {
  *static_cast<std::string*>(eh_data) = std::string(module) + "/" + function + ": " + msg;
}

Integrator::Integrator(OdeSystem& system, int size, const double* y0,
                       const std::vector<double>& atol)
    : system_(system), y_(size, ctx_), atol_(size, ctx_) {
  std::copy_n(y0, size, y_.data());
  if (atol.size() != static_cast<std::size_t>(size))
    throw std::logic_error("atol: one value per component");
  std::copy_n(atol.data(), size, atol_.data());
}

int Integrator::advance(double t_out, double* y, double& t_reached) {
  t_reached = t_out;
  const int flag = evolve(t_out, t_reached);
  system_.rethrowPending();
  std::copy_n(y_.data(), N_VGetLength_Serial(y_), y);
  return flag;
}

void Integrator::restart(double t, const double* y) {
  before_restart_ = stats();
  ++before_restart_.restarts;
  std::copy_n(y, N_VGetLength_Serial(y_), y_.data());
  reinit(t);
}

SolverStats Integrator::stats() const {
  const SolverStats now = counters();
  SolverStats s = before_restart_;
  s.steps += now.steps;
  s.rhs_evals += now.rhs_evals;
  s.jacobian_evals += now.jacobian_evals;
  s.error_test_failures += now.error_test_failures;
  s.convergence_failures += now.convergence_failures;
  return s;
}

std::string takeFlagName(char* name) {
  std::string out = name ? name : "?";
  std::free(name);
  return out;
}

}  // namespace fieldpath::dynamics::detail
