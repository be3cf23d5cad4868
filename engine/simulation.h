// A scene in motion: the ODE world, the magnetic force accumulator and the
// time line, stepped with a fixed rigid time step (docs/simulation.md).
#pragma once

#include <map>
#include <memory>
#include <string>
#include <vector>

#include "engine/magnetic_forces.h"
#include "engine/rigid_world.h"
#include "engine/scene.h"

namespace odemag {

// What one rigid step cost and how the relaxation went.
struct StepRecord {
  double time = 0.0;         // at the start of the step, s
  double magnetic_ms = 0.0;  // T_m: relaxation, forces and torques
  double rigid_ms = 0.0;     // T_r: collision, dWorldQuickStep, contacts
  int substeps = 1;          // substeps, each with its own relaxation and collision check
  int iterations = 0;        // outer relaxation iterations, summed over the substeps
  bool converged = true;
  double residual = 0.0;
};

class Simulation {
 public:
  // backend: nullptr for the CPU backend with the scene's thread count.
  explicit Simulation(const SceneDescription& scene, std::unique_ptr<MagneticBackend> backend = nullptr);

  // One rigid step of scene.simulation.time_step: time-line events due at the
  // current time, magnetic forces (timed as T_m), collision and integration
  // (timed as T_r).
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

  // Scene outcome numbers (SceneDescription::outcomes): each is evaluated the
  // first time the simulation reaches its time, end-of-run ones by finish().
  const std::map<std::string, double>& outcomes() const { return outcomes_; }
  void finish();
  // Bodies whose names start with prefix and whose centre is above height.
  int count_above(const std::string& prefix, double height) const;
  // A body's state is finite (no NaN or infinity in pose, velocity, force).
  bool finite_state(int body) const;

 private:
  void apply_timeline(double dt);
  // Substeps needed for collision (travel) and for the magnetic force's time
  // scale (stiffness); see SimulationSettings::max_substeps.
  int substeps_needed(double dt) const;
  void evaluate_outcomes(bool end);

  SceneDescription scene_;
  std::unique_ptr<RigidWorld> world_;
  std::unique_ptr<MagneticForces> magnetics_;
  double time_ = 0.0;
  long steps_ = 0;
  std::vector<StepRecord> records_;
  std::map<std::string, double> outcomes_;
  // Per event: pending, running (a ramp), done. Ramps start from the value
  // the quantity had when the event began.
  enum EventState : char { kPending, kRunning, kDone };
  std::vector<char> event_state_;
  std::vector<double> ramp_start_scale_;
  std::vector<Vec3> ramp_start_field_;
  std::vector<double> body_size_;  // smallest half-extent of each body, m
};

// Pose on a keyframe track at time t: positions linearly interpolated,
// orientations by spherical linear interpolation; held before the first and
// after the last key.
BodyPose keyframe_pose(const std::vector<Keyframe>& keys, double t);

}  // namespace odemag
