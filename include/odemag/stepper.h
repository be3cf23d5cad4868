// The step loop: one rigid step of an ODE world in substeps, each with its
// own magnetic forces, collision check and ODE step (docs/simulation.md
// "Substeps"). `odemag run`, Python's Simulation and embedders all step
// through it:
//
//   odemag::MagneticStepper stepper(magnetics, world, space, near_callback, nullptr, contacts);
//   loop { stepper.step(0.001); }  // replaces apply(); dSpaceCollide; dWorldQuickStep; dJointGroupEmpty
//
// The scene simulation (engine/simulation/simulation.h) hands it its own
// RigidWorld as the rigid side.
#pragma once

#include <ode/ode.h>

#include <memory>
#include <utility>
#include <vector>

#include "odemag/magnetic_forces.h"
#include "odemag/settings.h"

namespace odemag {

// The substep rule (engine/embedding/substeps.h): opaque here.
class SubstepRule;
struct SubstepMotion;

// What one rigid step did and cost.
struct StepReport {
  double time = 0.0;         // at the start of the step, s
  double magnetic_ms = 0.0;  // T_m: relaxation, forces and torques
  double rigid_ms = 0.0;     // T_r: collision, the ODE step, contacts
  double wall_ms = 0.0;      // the whole step, the caller's work around it included where it says so
  int substeps = 0;          // substeps taken, each with its own forces and collision check
  // The most substeps the substep rule asked for during the step; above
  // StepperSettings::substeps.max_substeps its travel and stiffness bounds
  // did not hold (docs/hard-cases.md: 1 mm objects at 4 ms steps).
  int substeps_wanted = 1;
  int relaxations = 0;       // substeps that relaxed the magnetization
  int skipped = 0;           // relaxations skipped, nothing having changed (RelaxOptions::skip_unchanged)
  int iterations = 0;        // outer relaxation iterations, summed
  long llg_steps = 0;        // per-cell LLG steps of those relaxations, summed over cells
  long newton_steps = 0;     // per-cell Newton steps of those relaxations, summed over cells
  int held = 0;              // magnetic_solve moving: induced bodies held, summed over the later substeps
  // Bodies whose refined contact zones moved to their contacts after the
  // step (the scene simulation's solver.contact_refinement); counted in magnetic_ms.
  int rezoned = 0;
  bool converged = true;
  double residual = 0.0;     // largest over the relaxations
  // The first body whose state (pose, velocities, magnetic force, torque or
  // moment) was found non-finite after a substep, which ended the step; -1: none.
  int non_finite_body = -1;
};

// The rigid side of the step loop: one substep of the ODE world and what the
// substep rule and magnetic_solve moving ask of its bodies. Body indices are
// the MagneticForces' body indices.
class RigidSubsteps {
 public:
  virtual ~RigidSubsteps() = default;
  // Recomputes the forces for a substep starting at `time` (s) of length h:
  // the magnetics' relaxation and forces, and any other accumulator's.
  virtual void update_forces(double time, double h) = 0;
  // One substep of h seconds: the forces added to the bodies, collision, the
  // ODE step, the contact joints emptied.
  virtual void integrate(double h) = 0;
  // Whether body b touched something in the last integrate().
  virtual bool in_contact(int b) const = 0;
  // Pairs of dynamic bodies that touched in the last integrate(); pairs
  // (dynamic, kinematic) that did.
  virtual const std::vector<std::pair<int, int>>& touching() const = 0;
  virtual const std::vector<std::pair<int, int>>& touching_kinematic() const = 0;
  // A lower bound (m) of the distance from body b to everything it may hit,
  // where knows_clearance() (SubstepRule::needed).
  virtual bool knows_clearance() const { return false; }
  virtual double clearance(int /*b*/) const { return 0.0; }
};

class MagneticStepper {
 public:
  // The embedder's world and collision: per substep, the magnetic forces
  // added, dSpaceCollide(space, near_data, near_callback) (which makes
  // contact joints in contacts), the ODE step, contacts emptied. Nothing is
  // owned; all must outlive the stepper. Throws std::invalid_argument on a
  // null world, space, near_callback or contacts.
  MagneticStepper(MagneticForces& magnetics, dWorldID world, dSpaceID space, dNearCallback* near_callback,
                  void* near_data, dJointGroupID contacts, const StepperSettings& settings = {});
  // The same loop over a rigid side of one's own (the scene simulation's
  // RigidWorld): the magnetics' bodies must be bound to the world's ODE
  // bodies (MagneticForces::bind); neither is owned.
  MagneticStepper(MagneticForces& magnetics, dWorldID world, RigidSubsteps& rigid,
                  const StepperSettings& settings = {});
  ~MagneticStepper();
  MagneticStepper(const MagneticStepper&) = delete;
  MagneticStepper& operator=(const MagneticStepper&) = delete;

  // One rigid step of dt seconds in substeps: begin_step(dt), finish_step().
  // Bodies attached to the MagneticForces since the last step join the rule
  // here (their shape, material and ODE mass; bodies never attached are not
  // counted: attach them with InertMaterial to have them counted). Throws
  // std::invalid_argument when dt is not positive and finite, and
  // std::runtime_error naming the body when the last step stopped at a
  // non-finite state; the MagneticForces' checks (std::domain_error on a
  // non-finite pose) apply.
  const StepReport& step(double dt);
  // The step in two halves, for a caller that looks at the state between
  // them: begin_step relaxes the magnetization at the step's start and sets
  // the substep count; finish_step takes the substeps. A substep that leaves
  // a body's state non-finite ends the step (ODE's collision aborts the
  // process on NaN positions): report.non_finite_body names it.
  void begin_step(double dt);
  const StepReport& finish_step();

  double time() const { return time_; }              // s, summed over the steps
  long steps() const { return steps_; }              // steps finished
  int substeps() const;                              // count in use
  const StepReport& last_report() const { return report_; }
  const SubstepRule& rule() const { return *rule_; }
  const StepperSettings& settings() const { return settings_; }
  // The body found non-finite (-1: none), the step (counted from 1) and the
  // time at the end of the substep it was found after.
  int non_finite_body() const { return non_finite_body_; }
  long non_finite_step() const { return non_finite_step_; }
  double non_finite_time() const { return non_finite_time_; }

 private:
  void add_new_bodies();
  void update_forces(double t, double h);
  void update_motion();
  int substeps_needed(double dt);
  void update_substeps(double dt, bool step_start);
  // magnetic_solve moving: by body, 1 for every body whose magnetization a
  // later substep holds: all but the free bodies that alone need more than
  // one substep of dt and the free bodies touching them.
  std::vector<uint8_t> bodies_to_hold(double dt);
  bool finite_state(int b) const;
  void note_non_finite(double t);

  MagneticForces& magnetics_;
  dWorldID world_;
  std::unique_ptr<RigidSubsteps> own_rigid_;  // the embedder's world (first constructor)
  RigidSubsteps& rigid_;
  StepperSettings settings_;
  std::unique_ptr<SubstepRule> rule_;
  std::vector<SubstepMotion> motion_;
  StepReport report_;
  double dt_ = 0.0;  // of the step begun
  double time_ = 0.0;
  long steps_ = 0;
  int non_finite_body_ = -1;
  long non_finite_step_ = 0;
  double non_finite_time_ = 0.0;
};

}  // namespace odemag
