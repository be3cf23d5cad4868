#include "engine/embedding/exact_step.h"

#include <algorithm>
#include <cstdarg>
#include <cstdio>

namespace odemag {

namespace {

[[noreturn]] void throw_ode_error(int number, const char* message, va_list arguments) {
  char text[512];
  std::vsnprintf(text, sizeof text, message, arguments);
  throw OdeInternalError("ODE internal error " + std::to_string(number) + ": " + text);
}

// Threading implementations left with a failed step's jobs (ExactStep),
// kept for the whole process: the list is never destroyed, so that they, and
// the step memory their jobs still point to, stay reachable.
std::vector<dThreadingImplementationID>& failed_threading() {
  static auto* kept = new std::vector<dThreadingImplementationID>;
  return *kept;
}

struct BodyState {
  dReal position[3], orientation[4], velocity[3], angular_velocity[3], force[3], torque[3];
};

}  // namespace

void throw_ode_internal_errors() {
  dSetErrorHandler(throw_ode_error);
  dSetDebugHandler(throw_ode_error);
}

ExactStep::ExactStep(dWorldID world) : world_(world) {
  throw_ode_internal_errors();
  use_new_threading();
}

ExactStep::~ExactStep() {
  dWorldSetStepThreadingImplementation(world_, nullptr, nullptr);
  dThreadingFreeImplementation(threading_);
}

void ExactStep::use_new_threading() {
  threading_ = dThreadingAllocateSelfThreadedImplementation();
  dWorldSetStepThreadingImplementation(world_, dThreadingImplementationGetFunctions(threading_), threading_);
}

bool ExactStep::step(const std::vector<dBodyID>& bodies, double h) {
  std::vector<BodyState> saved(bodies.size());
  for (size_t i = 0; i < bodies.size(); ++i) {
    const dBodyID b = bodies[i];
    BodyState& s = saved[i];
    std::copy_n(dBodyGetPosition(b), 3, s.position);
    std::copy_n(dBodyGetQuaternion(b), 4, s.orientation);
    std::copy_n(dBodyGetLinearVel(b), 3, s.velocity);
    std::copy_n(dBodyGetAngularVel(b), 3, s.angular_velocity);
    std::copy_n(dBodyGetForce(b), 3, s.force);
    std::copy_n(dBodyGetTorque(b), 3, s.torque);
  }
  try {
    dWorldStep(world_, h);
    return true;
  } catch (const OdeInternalError& e) {
    ++failures_;
    last_failure_ = e.what();
  }
  failed_threading().push_back(threading_);
  use_new_threading();
  for (size_t i = 0; i < bodies.size(); ++i) {
    const dBodyID b = bodies[i];
    const BodyState& s = saved[i];
    dBodySetPosition(b, s.position[0], s.position[1], s.position[2]);
    dBodySetQuaternion(b, s.orientation);
    dBodySetLinearVel(b, s.velocity[0], s.velocity[1], s.velocity[2]);
    dBodySetAngularVel(b, s.angular_velocity[0], s.angular_velocity[1], s.angular_velocity[2]);
    dBodySetForce(b, s.force[0], s.force[1], s.force[2]);
    dBodySetTorque(b, s.torque[0], s.torque[1], s.torque[2]);
  }
  dWorldQuickStep(world_, h);
  return false;
}

}  // namespace odemag
