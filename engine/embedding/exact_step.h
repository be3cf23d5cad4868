// ODE's exact solver without ending the process on its internal errors
// (docs/hard-cases.md "ODE's exact solver can fail").
//
// ODE reports an internal error (a failed assertion, such as a zero pivot in
// the Dantzig LCP's factorization on a degenerate contact set) through its
// error or debug handler and then ends the process. With the handlers of
// throw_ode_internal_errors the failing call throws OdeInternalError
// instead, and ExactStep takes such a step again with QuickStep.
#pragma once

#include <ode/ode.h>

#include <stdexcept>
#include <string>
#include <vector>

namespace odemag {

struct OdeInternalError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

// Sets ODE's error and debug handlers (process-wide) to throw
// OdeInternalError with ODE's message.
void throw_ode_internal_errors();

// Steps one world with dWorldStep. The world gets its own threading
// implementation: a step that fails inside ODE leaves jobs in it, and ODE
// checks on destroying one that none are left, so a failed one is replaced
// and kept (never freed) until the process ends.
class ExactStep {
 public:
  explicit ExactStep(dWorldID world);
  ~ExactStep();
  ExactStep(const ExactStep&) = delete;
  ExactStep& operator=(const ExactStep&) = delete;

  // dWorldStep(world, h). If ODE fails inside it, the bodies (every dynamic
  // body of the world; islands stepped before the failing one have moved)
  // are put back as they were, forces and torques included, and the step is
  // taken by dWorldQuickStep on the same joints. Returns whether the exact
  // step succeeded.
  bool step(const std::vector<dBodyID>& bodies, double h);

  // Steps that failed and QuickStep took, and the last one's message.
  long failures() const { return failures_; }
  const std::string& last_failure() const { return last_failure_; }

 private:
  void use_new_threading();

  dWorldID world_;
  dThreadingImplementationID threading_ = nullptr;
  long failures_ = 0;
  std::string last_failure_;
};

}  // namespace odemag
