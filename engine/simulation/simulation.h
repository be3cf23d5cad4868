// A scene in motion: the ODE world, the magnetic force accumulator and the
// time line, stepped with a fixed rigid time step (docs/simulation.md).
#pragma once

#include <map>
#include <memory>
#include <string>
#include <vector>

#include "engine/embedding/magnetic_forces.h"
#include "engine/embedding/substeps.h"
#include "engine/simulation/outcomes.h"
#include "engine/simulation/rigid_world.h"
#include "engine/scene/scene.h"
#include "magnetics/cells/cells.h"

namespace odemag {

// What one rigid step cost and how the relaxation went.
struct StepRecord {
  double time = 0.0;         // at the start of the step, s
  double magnetic_ms = 0.0;  // T_m: relaxation, forces and torques
  double rigid_ms = 0.0;     // T_r: collision, dWorldQuickStep, contacts
  double wall_ms = 0.0;      // the whole step(): time line, T_m, T_r, substep rule, outcomes
  int substeps = 1;          // substeps, each with its own relaxation and collision check
  // The most substeps the substep rule asked for during the step; above
  // SimulationSettings::max_substeps its travel and stiffness bounds did not
  // hold (docs/hard-cases.md: 1 mm objects at 4 ms steps).
  int substeps_wanted = 1;
  int iterations = 0;        // outer relaxation iterations, summed over the substeps
  long llg_steps = 0;        // per-cell LLG steps of those relaxations, summed over cells
  long newton_steps = 0;     // per-cell Newton steps of those relaxations, summed over cells
  int relaxations = 0;       // substeps that relaxed the magnetization (SimulationSettings::magnetic_solve)
  int skipped = 0;           // substeps whose magnetic step was skipped (solver.skip_unchanged)
  int held = 0;              // magnetic_solve "moving": induced bodies held, summed over the later substeps
  int whole_step = 0;        // rigid_substeps "moving": free bodies that took the step whole
  // solver.contact_refinement: bodies whose refined contact zones moved to
  // their contacts after the step (Simulation::follow_contact_zones); the
  // time it took counts in magnetic_ms.
  int rezoned = 0;
  bool converged = true;
  double residual = 0.0;
  int sleeping = 0;          // bodies asleep at the step's end (SleepSettings)
};

class Simulation {
 public:
  // backend: nullptr for the CPU backend with the scene's thread count.
  explicit Simulation(const SceneDescription& scene, std::unique_ptr<MagneticBackend> backend = nullptr);

  // One rigid step of scene.simulation.time_step: time-line events due at the
  // current time, magnetic forces (timed as T_m), collision and integration
  // (timed as T_r). A substep that leaves a body's state non-finite ends the
  // step (ODE's collision aborts the process on NaN positions); the next
  // call throws std::runtime_error with non_finite_message().
  void step();
  // Steps until time() >= t (within half a step).
  void advance_to(double t);

  double time() const { return time_; }
  long steps() const { return steps_; }
  const SceneDescription& scene() const { return scene_; }
  RigidWorld& world() { return *world_; }
  const RigidWorld& world() const { return *world_; }
  MagneticForces& magnetics() { return *magnetics_; }
  const MagneticForces& magnetics() const { return *magnetics_; }
  const std::vector<StepRecord>& records() const { return records_; }

  // Scene outcome numbers (SceneDescription::outcomes, engine/simulation/outcomes.h):
  // each is taken the first time the simulation reaches its time (t = 0 with
  // the magnetization relaxed, then after every rigid step), statistics over
  // every step; end-of-run ones by finish().
  const std::map<std::string, double>& outcomes() const { return outcomes_.values(); }
  void finish();
  // A body's state is finite (no NaN or infinity in pose, velocity, force).
  bool finite_state(int body) const;
  // The NaN guard of `odemag run` (docs/hard-cases.md): empty while every
  // body's state is finite, else "SCENE: body 'NAME' has a non-finite state
  // at step K (t = T s); stopped" for the body that was found non-finite
  // first (checked after every substep, so a NaN that spreads to the other
  // bodies through their fields is traced to where it began), K counting
  // steps from 1 and T the end of the substep.
  std::string non_finite_message() const;
  // Notices for the user, in the order they arose (odemag run prints each
  // once): with solver.contact_refinement, a lattice ball whose zones could
  // not follow its contacts (follow_contact_zones).
  const std::vector<std::string>& notices() const { return notices_; }

 private:
  void apply_timeline(double dt);
  // Substeps the rule (engine/embedding/substeps.h) wants now, before the cap
  // SimulationSettings::max_substeps.
  void update_substep_motion();  // substep_motion_ from the world and the magnetics
  int substeps_needed(double dt);
  // magnetic_solve "moving": by body, 1 for every body whose magnetization a
  // later substep holds: all but the free bodies that alone need more than
  // one substep of dt and the free bodies touching them.
  std::vector<uint8_t> bodies_to_hold(double dt);
  // rigid_substeps "moving": by body, 1 for every free body that takes the
  // rigid step whole: all but those that needed more than one substep of dt
  // within the last hold time (SubstepRule::hold_time) and those touching
  // them. Empty when no body would take the substeps. moving: 1 for each
  // body that needed the substeps within the hold time.
  std::vector<uint8_t> bodies_to_step_whole(double dt, std::vector<uint8_t>& moving);
  // With rigid_substeps "moving" and more than one substep: one step of dt
  // for every free body; the bodies_to_step_whole that touched no moving
  // body in it either keep it (whole_end_) and ride through the substeps from
  // their start to there, the others go back to the step's start for their
  // substeps.
  void step_slow_bodies_whole(double dt, StepRecord& record);
  // Sets substeps_ from substeps_needed through the rule (capped: raised at
  // once, lowered only at a step's start after a hold time); notes the
  // uncapped need in record.substeps_wanted.
  void update_substeps(double dt, bool step_start, StepRecord& record);
  // Records the first body whose state is not finite (non_finite_message).
  void note_non_finite(double t);

  SceneDescription scene_;
  std::unique_ptr<RigidWorld> world_;
  std::unique_ptr<MagneticForces> magnetics_;
  double time_ = 0.0;
  long steps_ = 0;
  std::vector<StepRecord> records_;
  OutcomeRecorder outcomes_;
  // Per event: pending, running (a ramp), done. Ramps start from the value
  // the quantity had when the event began.
  enum EventState : char { kPending, kRunning, kDone };
  std::vector<char> event_state_;
  std::vector<double> ramp_start_scale_;
  std::vector<Vec3> ramp_start_field_;
  // The substep rule (docs/simulation.md "Substeps"), one body per scene
  // body, its hold state, and the count in use.
  SubstepRule substep_rule_;
  std::vector<SubstepMotion> substep_motion_;
  int substeps_ = 1;
  // rigid_substeps "moving": by body, the time until which it counts as
  // needing the substeps (the last time it needed them plus the hold time).
  std::vector<double> moving_until_;
  // In a rigid step: by body, 1 for a body that took it whole (empty: none),
  // and the state it ends the step in.
  std::vector<uint8_t> whole_;
  std::vector<RigidWorld::Motion> whole_end_;
  // solver.contact_refinement: after a step, every lattice ball with a
  // contact point (contact_points at the step's end poses) farther than
  // kContactZoneFollowDistance h from every zone point gets new zones at its
  // contact points (MagneticForces::refine_body), the zones the scene would
  // place at these poses (docs/model.md "Refined contact zones"). A body
  // whose zones cannot be built (beyond kMaxRefinedCells) keeps its cells
  // and gets one notice.
  void follow_contact_zones(StepRecord& record);
  std::vector<std::vector<RefinedZone>> contact_zones_;
  std::vector<uint8_t> contact_zones_failed_;  // by body: its notice was given
  std::vector<std::string> notices_;
  // The first body found non-finite (-1 while none), its step and time.
  int non_finite_body_ = -1;
  long non_finite_step_ = 0;
  double non_finite_time_ = 0.0;
};

// Pose on a keyframe track at time t: positions linearly interpolated,
// orientations by spherical linear interpolation; held before the first and
// after the last key.
BodyPose keyframe_pose(const std::vector<Keyframe>& keys, double t);

}  // namespace odemag
