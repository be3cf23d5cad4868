// Things that add forces and torques to ODE bodies before each rigid step
// (docs/embedding.md "The API in one loop", 4: dBodyAddForce / dBodyAddTorque).
#pragma once

#include <ode/ode.h>

namespace odemag {

class ForceAccumulator {
 public:
  virtual ~ForceAccumulator() = default;
  // Recomputes the forces for the rigid step starting at `time` (s) of length dt.
  virtual void update(double time, double dt) = 0;
  // Adds the current forces and torques to the ODE bodies. ODE clears its
  // force accumulators after every dWorldQuickStep, so this runs before each
  // (sub)step; the forces stay those computed by the last update().
  virtual void add_forces() = 0;
  // Adds the forces of one body that add_forces() skipped because it was
  // kinematic then and is dynamic now, within the same (sub)step (a rider
  // that a body ran into: RigidWorld::ride). Bodies it does not know: nothing.
  virtual void add_forces_to(dBodyID /*body*/) {}
};

}  // namespace odemag
