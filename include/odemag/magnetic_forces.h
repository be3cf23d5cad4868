// Magnetics for ODE bodies: the public API for embedding odemag in an ODE
// program (docs/embedding.md), and the force accumulator that the scene
// simulation registers:
//
//   odemag::MagneticForces magnetics;
//   magnetics.attach(magnet_body, odemag::Box{{0.1, 0.02, 0.02}},
//                    odemag::PermanentMaterial{{1e6, 0, 0}}, 0.005);
//   magnetics.attach(ball_body, odemag::Sphere{0.006}, iron);
//   loop { magnetics.apply(); dSpaceCollide(...); dWorldQuickStep(...); dJointGroupEmpty(...); }
//
// or that loop in the substeps of `odemag run`: MagneticStepper
// (odemag/stepper.h, docs/embedding.md "Substeps").
//
// The moments persist from step to step (warm start), which is what makes
// remanence possible.
#pragma once

#include <ode/ode.h>

#include <cstdint>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "odemag/constants.h"
#include "odemag/material.h"
#include "odemag/settings.h"
#include "odemag/shape.h"
#include "odemag/vec3.h"

namespace odemag {

// The library's own types behind the API (magnetics/): opaque here.
class MagneticBackend;
class MagneticModel;
struct MagneticState;
struct RefinedZone;

// Things that add forces and torques to ODE bodies before each rigid step
// (docs/embedding.md "The API in one loop", 4: dBodyAddForce / dBodyAddTorque).
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

// A copy of the magnetic state (MagneticForces::save_state): every cell's
// moments and magnetization and what they belong to. A value: copies are
// independent.
class SavedMagneticState {
 public:
  struct Data;  // engine/embedding/saved_state.h
  SavedMagneticState();
  ~SavedMagneticState();
  SavedMagneticState(const SavedMagneticState& other);
  SavedMagneticState& operator=(const SavedMagneticState& other);
  SavedMagneticState(SavedMagneticState&&) noexcept;
  SavedMagneticState& operator=(SavedMagneticState&&) noexcept;
  // The relaxation report when it was saved.
  const RelaxReport& report() const;
  Data& data() { return *data_; }
  const Data& data() const { return *data_; }

 private:
  std::unique_ptr<Data> data_;
};

class MagneticForces : public ForceAccumulator {
 public:
  // On the CPU backend with `threads` threads (0: all cores). seed: the
  // moments' initial directions and the noise.
  explicit MagneticForces(const RelaxOptions& options = {}, int threads = 0, uint64_t seed = 1,
                          IntraBodyTensor intra_tensor = IntraBodyTensor::cell_average);
  // On the backend of that kind: cpu, cuda, or automatic (CUDA where a
  // device is usable, docs/gpu.md). Defined in odemag::gpu: link it (or
  // odemag::odemag) to use this one. Throws std::invalid_argument when cuda
  // is asked for and no device is usable.
  MagneticForces(const RelaxOptions& options, BackendKind backend, int threads = 0, uint64_t seed = 1,
                 IntraBodyTensor intra_tensor = IntraBodyTensor::cell_average);
  // A backend of the library's own (the tests' and benchmarks'; nullptr:
  // the CPU backend with all cores).
  MagneticForces(const RelaxOptions& options, std::unique_ptr<MagneticBackend> backend, uint64_t seed = 1,
                 IntraBodyTensor intra_tensor = IntraBodyTensor::cell_average);
  // Magnetics built elsewhere (a scene's, engine/simulation/magnetic_system.h): the
  // model and its state as they are; bind() then ties bodies to ODE bodies.
  MagneticForces(MagneticModel model, MagneticState state, const RelaxOptions& options,
                 std::unique_ptr<MagneticBackend> backend);
  ~MagneticForces() override;
  MagneticForces(const MagneticForces&) = delete;
  MagneticForces& operator=(const MagneticForces&) = delete;
  // Ties magnetic body index to an ODE body (nullptr: static, set_pose) and
  // takes its pose. Throws std::out_of_range on a bad index.
  void bind(int index, dBodyID body);

  // Attaches a shape (centred on the body's centre of mass, in its frame) and
  // a material to an ODE body and returns the magnetic body index. body may be
  // nullptr for a static body placed with set_pose. cell_size <= 0: one cell.
  // Throws std::invalid_argument naming the call and the body (the index and
  // name it would get) on a bad shape or material, or a lattice of more than
  // kMaxBodyLatticePoints points (magnetics/model/model.h), before any cell is
  // made.
  int attach(dBodyID body, const Shape& shape, const Material& material, double cell_size = 0.0,
             const std::string& name = "");
  // The same with the material named `material` of a set of named materials,
  // a scene file's (SceneDescription::materials, engine/scene/scene.h;
  // docs/embedding.md "Materials from a scene file"). Throws
  // std::invalid_argument naming the material and the known ones when there
  // is none of that name.
  int attach(dBodyID body, const Shape& shape, const std::map<std::string, Material>& materials,
             const std::string& material, double cell_size = 0.0, const std::string& name = "");

  // Reads the poses of the ODE bodies, relaxes the magnetization from the
  // previous step's moments, computes forces and torques and adds them to the
  // (non-kinematic, enabled or woken) ODE bodies. Returns the relaxation report.
  const RelaxReport& apply();

  // ForceAccumulator: update() relaxes and computes, add_forces() adds.
  // compute() and recompute_forces() throw std::domain_error, naming the
  // body (name and index), when an active body's pose (its ODE body's, or
  // the one set_pose or state() gave it), its magnetization scale or the
  // external field is not finite; they check before relaxing, the state
  // keeps the last step's forces.
  void update(double, double) override { compute(); }
  // Adds the forces and torques to the active, magnetic, non-kinematic ODE
  // bodies that are enabled. A body ODE put to sleep (disabled, its
  // auto-disable flag set) is woken (dBodyEnable) when its magnetic force
  // or torque has changed, since the last add_forces() that found it awake
  // (or the first that found it asleep, for a body never seen awake), by
  // more than wake_tolerance() times the load that holds it at rest:
  //   |F - F_0| > tol (|F_0| + m |g|)  or  |T - T_0| > tol (|T_0| + r (|F_0| + m |g|)),
  // m its ODE mass, g the world's gravity, r half the diagonal of the
  // shape's bounding box. A body resting in a steady field stays asleep; one a magnet
  // approaches is woken. Bodies whose auto-disable flag is off (disabled by
  // the program, as the scene simulation removes bodies) are never woken.
  void add_forces() override;
  // The same for one body, if it is one of the model's (ForceAccumulator).
  void add_forces_to(dBodyID body) override;
  const RelaxReport& compute();
  // Forces and torques at the bodies' current poses with the magnetization of
  // the last compute() held (magnetic_forces_at_held_magnetization): no
  // relaxation. add_forces() then adds them.
  void recompute_forces();

  // Throws std::invalid_argument when H is not finite or stronger than
  // ranges::kFieldStrength (odemag/constants.h).
  void set_external_field(const Vec3& H);
  Vec3 external_field() const;
  // Relative change of force or torque that wakes a sleeping body
  // (add_forces); default 1e-3, infinity never wakes. Throws
  // std::invalid_argument when negative or NaN.
  void set_wake_tolerance(double tolerance);
  double wake_tolerance() const { return wake_tolerance_; }
  // Every call taking a body index throws std::out_of_range naming the call
  // and the index when it is not 0 .. body_count() - 1.
  // A body that is not active neither makes nor feels a field (removed).
  void set_active(int index, bool active);
  bool active(int index) const;
  // Scales a permanent magnet's remanent magnetization, or an electromagnet's
  // coil field and coil currents (the crane). Throws std::invalid_argument,
  // naming the body, when scale is not finite or takes the magnetization
  // beyond ranges::kFieldStrength or a coil's ampere-turns beyond
  // ranges::kAmpereTurns (ranges::largest_magnetization_scale, the scene's
  // rule for scale_magnetization events).
  void set_magnetization_scale(int index, double scale);
  double magnetization_scale(int index) const;
  // Pose of a static (body == nullptr) magnetic body. Throws
  // std::invalid_argument, naming the body, when it is not finite, the
  // position is farther than ranges::kLength from the origin, or the rotation
  // is not one (R^T R = I within ranges::kRotationTolerance, det R > 0).
  void set_pose(int index, const BodyPose& pose);

  RelaxOptions& options() { return options_; }
  const RelaxOptions& options() const { return options_; }
  const RelaxReport& last_report() const { return report_; }

  int body_count() const;
  dBodyID ode_body(int index) const { return bodies_[body_index(index, "ode_body")]; }
  // A m^2, world; zero for a body that is not active.
  Vec3 moment(int index) const;
  Vec3 force(int index) const;   // N, world
  Vec3 torque(int index) const;  // N m, about the CoM
  // B (T) and H (A/m) at world points (m) with the magnetization of the last
  // compute(); inside a magnetic body B = mu0 (H + M) with M of its nearest
  // cell. Throws std::invalid_argument naming the index of a point that is
  // not finite or farther than ranges::kLength from the origin.
  void field_at_points(const std::vector<Vec3>& points, std::vector<Vec3>& B, std::vector<Vec3>& H);

  // Gives a body new refined contact zones (MagneticModel::refine_body,
  // docs/model.md "Refined contact zones"; none: its plain cells again): its
  // cells are built anew and take the magnetization the old cells held there
  // (transfer_refined_state); the next compute() relaxes. A state saved
  // before no longer restores (restore_state refuses it). Throws std::out_of_range on a bad index
  // and std::invalid_argument, changing nothing, for zones add_body refuses.
  void refine_body(int index, const std::vector<RefinedZone>& zones);

  // Saving and restoring the magnetic state (docs/embedding.md "Saving and
  // restoring"): every cell's moments and magnetization, the warm-start and
  // skip data, poses, forces, active flags, magnetization scales, the
  // external field, the noise counters and the last relaxation report.
  // restore_state() throws std::invalid_argument, changing nothing, when the
  // state was saved from magnetics with other bodies or cells.
  SavedMagneticState save_state() const;
  void restore_state(const SavedMagneticState& saved);

  // The library's model and state (magnetics/model/): for code built with
  // odemag's sources (tests, benchmarks, the scene simulation).
  const MagneticModel& model() const { return *model_; }
  const MagneticState& state() const { return *state_; }
  MagneticState& state() { return *state_; }
  MagneticBackend& backend() { return *backend_; }

 private:
  // index, or std::out_of_range naming the call when it is not a body index.
  int body_index(int index, const char* call) const;
  void read_poses();
  // std::domain_error, naming call and body, on a non-finite input of a step.
  void check_inputs(const char* call) const;
  // add_forces: whether sleeping body b is to be woken.
  bool wakes(int b) const;
  // add_forces: the body's force and torque become its F_0, T_0.
  void note_reference(int b);
  void add_forces_of(int b);  // add_forces() for body b

  std::unique_ptr<MagneticModel> model_;
  std::unique_ptr<MagneticState> state_;
  std::vector<dBodyID> bodies_;
  std::unique_ptr<MagneticBackend> backend_;
  RelaxOptions options_;
  RelaxReport report_;
  double wake_tolerance_ = 1e-3;
  // Per body: F_0, T_0 of the wake-up rule (add_forces), and whether set.
  std::vector<Vec3> reference_force_, reference_torque_;
  std::vector<uint8_t> reference_known_;
  std::vector<int> refinements_;  // per body: refine_body calls (save_state, restore_state)
};

// Pose of an ODE body as a magnetics BodyPose.
BodyPose ode_pose(dBodyID body);

}  // namespace odemag
