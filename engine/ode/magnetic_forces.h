// Magnetics for ODE bodies: the force accumulator that the scene simulation
// registers, and the public API for embedding odemag in an ODE program
// (docs/embedding.md):
//
//   odemag::MagneticForces magnetics;
//   magnetics.attach(magnet_body, odemag::Box{{0.1, 0.02, 0.02}},
//                    odemag::PermanentMaterial{{1e6, 0, 0}}, 0.005);
//   magnetics.attach(ball_body, odemag::Sphere{0.006}, iron);
//   loop { magnetics.apply(); dSpaceCollide(...); dWorldQuickStep(...); dJointGroupEmpty(...); }
//
// The moments persist from step to step (warm start), which is what makes
// remanence possible.
#pragma once

#include <ode/ode.h>

#include <memory>
#include <string>
#include <vector>

#include "engine/ode/force_accumulator.h"
#include "magnetics/backend.h"
#include "magnetics/model.h"
#include "magnetics/relax.h"
#include "magnetics/state.h"

namespace odemag {

class MagneticForces : public ForceAccumulator {
 public:
  // backend: nullptr for the CPU backend with all cores.
  explicit MagneticForces(const RelaxOptions& options = {},
                          std::unique_ptr<MagneticBackend> backend = nullptr, uint64_t seed = 1,
                          IntraBodyTensor intra_tensor = IntraBodyTensor::cell_average);

  // Magnetics built elsewhere (a scene's, engine/sim/magnetic_system.h): the
  // model and its state as they are; bind() then ties bodies to ODE bodies.
  MagneticForces(MagneticModel model, MagneticState state, const RelaxOptions& options,
                 std::unique_ptr<MagneticBackend> backend);
  // Ties magnetic body index to an ODE body (nullptr: static, set_pose) and
  // takes its pose. Throws std::out_of_range on a bad index.
  void bind(int index, dBodyID body);

  // Attaches a shape (centred on the body's centre of mass, in its frame) and
  // a material to an ODE body and returns the magnetic body index. body may be
  // nullptr for a static body placed with set_pose. cell_size <= 0: one cell.
  // Throws std::invalid_argument on a bad shape or material.
  int attach(dBodyID body, const Shape& shape, const Material& material, double cell_size = 0.0,
             const std::string& name = "");

  // Reads the poses of the ODE bodies, relaxes the magnetization from the
  // previous step's moments, computes forces and torques and adds them to the
  // (non-kinematic, enabled) ODE bodies. Returns the relaxation report.
  const RelaxReport& apply();

  // ForceAccumulator: update() relaxes and computes, add_forces() adds.
  void update(double, double) override { compute(); }
  void add_forces() override;
  const RelaxReport& compute();
  // Forces and torques at the bodies' current poses with the magnetization of
  // the last compute() held (magnetic_forces_at_held_magnetization): no
  // relaxation. add_forces() then adds them.
  void recompute_forces();

  void set_external_field(const Vec3& H) { state_.external_field = H; }
  Vec3 external_field() const { return state_.external_field; }
  // Every call taking a body index throws std::out_of_range when it is not
  // 0 .. body_count() - 1.
  // A body that is not active neither makes nor feels a field (removed).
  void set_active(int index, bool active) { state_.active[body_index(index, "set_active")] = active ? 1 : 0; }
  bool active(int index) const { return state_.active[body_index(index, "active")] != 0; }
  // Scales a permanent magnet's remanent magnetization (electromagnets, the crane).
  void set_magnetization_scale(int index, double scale) {
    state_.magnetization_scale[body_index(index, "set_magnetization_scale")] = scale;
  }
  double magnetization_scale(int index) const {
    return state_.magnetization_scale[body_index(index, "magnetization_scale")];
  }
  // Pose of a static (body == nullptr) magnetic body.
  void set_pose(int index, const BodyPose& pose) { state_.pose[body_index(index, "set_pose")] = pose; }

  RelaxOptions& options() { return options_; }
  const RelaxOptions& options() const { return options_; }
  const RelaxReport& last_report() const { return report_; }

  int body_count() const { return model_.body_count(); }
  dBodyID ode_body(int index) const { return bodies_[body_index(index, "ode_body")]; }
  // A m^2, world; zero for a body that is not active.
  Vec3 moment(int index) const { return active(index) ? body_moment(model_, state_, index) : Vec3{}; }
  Vec3 force(int index) const { return state_.force[body_index(index, "force")]; }                  // N, world
  Vec3 torque(int index) const { return state_.torque[body_index(index, "torque")]; }                // N m, about the CoM

  const MagneticModel& model() const { return model_; }
  const MagneticState& state() const { return state_; }
  MagneticState& state() { return state_; }
  MagneticBackend& backend() { return *backend_; }

 private:
  // index, or std::out_of_range naming the call when it is not a body index.
  int body_index(int index, const char* call) const;
  void read_poses();

  MagneticModel model_;
  MagneticState state_;
  std::vector<dBodyID> bodies_;
  std::unique_ptr<MagneticBackend> backend_;
  RelaxOptions options_;
  RelaxReport report_;
};

// Pose of an ODE body as a magnetics BodyPose.
BodyPose ode_pose(dBodyID body);

}  // namespace odemag
