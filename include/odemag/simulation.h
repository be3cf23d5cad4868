// A scene in motion: the ODE world, the magnetic force accumulator and the
// time line, stepped with a fixed rigid time step (docs/simulation.md).
#pragma once

#include <map>
#include <memory>
#include <string>
#include <vector>

#include "odemag/magnetic_forces.h"
#include "odemag/scene.h"
#include "odemag/stepper.h"

namespace odemag {

// The ODE world of a scene (engine/simulation/rigid_world.h): opaque here.
class RigidWorld;

class Simulation {
 public:
  // The scene's magnetics on the backend its solver.backend and
  // solver.threads ask for (std::invalid_argument when "cuda" is asked for
  // and no device is usable, or the scene needs what only the CPU backend
  // has); a SceneError for a body whose shape or material is refused.
  explicit Simulation(const SceneDescription& scene);
  // On a backend of the library's own (nullptr: the CPU backend with the
  // scene's thread count).
  Simulation(const SceneDescription& scene, std::unique_ptr<MagneticBackend> backend);
  ~Simulation();
  Simulation(const Simulation&) = delete;
  Simulation& operator=(const Simulation&) = delete;

  // One rigid step of scene.simulation.time_step: time-line events due at
  // the current time, then the step loop (MagneticStepper: magnetic forces
  // timed as T_m, collision and integration as T_r, in substeps). A substep
  // that leaves a body's state non-finite ends the step (ODE's collision
  // aborts the process on NaN positions); the next call throws
  // std::runtime_error with non_finite_message().
  void step();
  // Steps until time() >= t (within half a step).
  void advance_to(double t);

  double time() const { return stepper_->time(); }
  long steps() const { return stepper_->steps(); }
  const SceneDescription& scene() const { return scene_; }
  // Body b's pose and velocities (scene order; m, m/s, rad/s, world frame).
  BodyPose pose(int body) const;
  Vec3 velocity(int body) const;
  Vec3 angular_velocity(int body) const;
  // The ODE world of the scene (engine/simulation/rigid_world.h): for code
  // built with odemag's sources.
  RigidWorld& world() { return *world_; }
  const RigidWorld& world() const { return *world_; }
  MagneticForces& magnetics() { return *magnetics_; }
  const MagneticForces& magnetics() const { return *magnetics_; }
  const MagneticStepper& stepper() const { return *stepper_; }
  // One report per step taken (wall_ms: the whole step(), time line,
  // outcomes and contact zones included).
  const std::vector<StepReport>& records() const { return records_; }

  // Scene outcome numbers (SceneDescription::outcomes, engine/simulation/outcomes.h):
  // each is taken the first time the simulation reaches its time (t = 0 with
  // the magnetization relaxed, then after every rigid step), statistics over
  // every step; end-of-run ones by finish().
  const std::map<std::string, double>& outcomes() const;
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
  // once): bodies whose cells are known to be poor (scene_notices,
  // engine/simulation/magnetic_system.h); a lattice ball whose refined
  // contact zones could not follow its contacts (follow_contact_zones).
  const std::vector<std::string>& notices() const;

 private:
  // The time line and its target, the outcomes, the refined contact zones.
  struct Parts;

  // solver.contact_refinement: after a step, every lattice ball with a
  // contact point (contact_points at the step's end poses) farther than
  // kContactZoneFollowDistance h from every zone point gets new zones at its
  // contact points (MagneticForces::refine_body), the zones the scene would
  // place at these poses (docs/model.md "Refined contact zones"). A body
  // whose zones cannot be built (beyond kMaxRefinedCells) keeps its cells
  // and gets one notice.
  void follow_contact_zones(StepReport& record);
  SceneDescription scene_;
  std::unique_ptr<RigidWorld> world_;
  std::unique_ptr<MagneticForces> magnetics_;
  std::unique_ptr<MagneticStepper> stepper_;
  std::vector<StepReport> records_;
  std::unique_ptr<Parts> parts_;
};

}  // namespace odemag
