// A rigid step of an embedder's ODE world with the substeps of `odemag run`
// (docs/embedding.md "Substeps"): the step is split by the substep rule
// (engine/embedding/substeps.h, docs/simulation.md "Substeps") and every substep
// gets its own magnetic forces, collision check and ODE step:
//
//   odemag::MagneticStepper stepper(magnetics, world, space, near_callback, nullptr, contacts);
//   loop { stepper.step(0.001); }  // replaces apply(); dSpaceCollide; dWorldQuickStep; dJointGroupEmpty
#pragma once

#include <ode/ode.h>

#include <vector>

#include "engine/embedding/magnetic_forces.h"
#include "engine/embedding/substeps.h"

namespace odemag {

// When the magnetization is relaxed (SimulationSettings::magnetic_solve):
// at every substep, or once per rigid step, the later substeps recomputing
// forces and torques at the new poses with the magnetization held
// (MagneticForces::recompute_forces).
enum class MagneticSolve { substep, step };

struct StepperSettings {
  SubstepSettings substeps;                          // max_substeps, stiffness_limit
  MagneticSolve magnetic_solve = MagneticSolve::substep;
  bool exact_solver = false;                         // dWorldStep instead of dWorldQuickStep
};

// What one rigid step did (cf. StepRecord of the scene simulation).
struct StepReport {
  int substeps = 0;         // substeps taken
  int substeps_wanted = 1;  // the most the rule asked for; above max_substeps its bounds did not hold
  int relaxations = 0;      // substeps that relaxed the magnetization
  int skipped = 0;          // relaxations skipped, nothing having changed (RelaxOptions::skip_unchanged)
  int iterations = 0;       // outer relaxation iterations, summed
  bool converged = true;
  double residual = 0.0;    // largest over the relaxations
};

class MagneticStepper {
 public:
  // The embedder's world and collision: per substep, dSpaceCollide(space,
  // near_data, near_callback) (which makes contact joints in contacts) and
  // then the ODE step; contacts is emptied after it. Nothing is owned; all
  // must outlive the stepper. Throws std::invalid_argument on a null world,
  // space, near_callback or contacts.
  MagneticStepper(MagneticForces& magnetics, dWorldID world, dSpaceID space, dNearCallback* near_callback,
                  void* near_data, dJointGroupID contacts, const StepperSettings& settings = {});

  // One rigid step of dt seconds in substeps. Bodies attached to the
  // MagneticForces since the last step join the rule here (their shape,
  // material and ODE mass; bodies never attached are not counted: attach
  // them with InertMaterial to have them counted). Throws
  // std::invalid_argument when dt is not positive and finite; the
  // MagneticForces' checks (std::domain_error on a non-finite pose) apply.
  const StepReport& step(double dt);

  double time() const { return time_; }              // s, summed over the steps
  int substeps() const { return rule_.count(); }     // count in use
  const StepReport& last_report() const { return report_; }
  const SubstepRule& rule() const { return rule_; }
  const StepperSettings& settings() const { return settings_; }

 private:
  void add_new_bodies();
  void update_forces(bool relax);
  int substeps_needed(double dt);
  void rigid_substep(double h);

  MagneticForces& magnetics_;
  dWorldID world_;
  dSpaceID space_;
  dNearCallback* near_callback_;
  void* near_data_;
  dJointGroupID contacts_;
  StepperSettings settings_;
  SubstepRule rule_;
  std::vector<SubstepMotion> motion_;
  std::vector<char> in_contact_;  // per body: a contact joint in the last substep
  StepReport report_;
  double time_ = 0.0;
};

}  // namespace odemag
