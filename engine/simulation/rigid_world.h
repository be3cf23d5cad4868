// The ODE side of a scene: world, collision space, contact joints, one ODE
// body and geom per scene body, a ground plane (docs/simulation.md "Bodies",
// "Contacts").
#pragma once

#include <ode/ode.h>

#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "engine/embedding/exact_step.h"
#include "odemag/stepper.h"
#include "odemag/magnetic_forces.h"
#include "odemag/scene.h"
#include "magnetics/model/state.h"

namespace odemag {

// The surface of every contact joint. ODE gives a contact with
// dContactRolling three rows of rolling and spinning resistance whatever their
// coefficients, and without dContactAxisDep all three take rho; a row costs
// as much as a normal or friction row in the quick step (docs/simulation.md
// "Contacts"). So the rows are asked for only where their coefficients are
// nonzero: none when both are 0, per axis (dContactAxisDep, a negative
// coefficient: no row) when rolling and spinning differ.
dSurfaceParameters contact_surface(const ContactSettings& c);

class RigidWorld : public RigidSubsteps {
 public:
  // Bodies are created in scene order; "fixed" bodies are kinematic (they
  // move only by keyframes); bodies with present = false start disabled.
  explicit RigidWorld(const SceneDescription& scene);
  ~RigidWorld();
  RigidWorld(const RigidWorld&) = delete;
  RigidWorld& operator=(const RigidWorld&) = delete;

  dWorldID world() const { return world_; }
  dSpaceID space() const { return space_; }
  int body_count() const { return static_cast<int>(bodies_.size()); }
  dBodyID body(int i) const { return bodies_[i].body; }
  bool kinematic(int i) const { return bodies_[i].kinematic; }
  double mass(int i) const { return bodies_[i].mass; }

  // Disabled bodies neither move nor collide (removed from the scene).
  void set_enabled(int i, bool enabled);
  bool enabled(int i) const { return bodies_[i].enabled; }

  // Makes a body kinematic (moved only by set_kinematic_state: a keyframed
  // dynamic body while its track runs) or dynamic again, keeping its velocity.
  void set_kinematic(int i, bool kinematic);

  // Places a kinematic body and gives it the velocities it moves with during
  // the next step (so contacts see the motion).
  void set_kinematic_state(int i, const BodyPose& pose, const Vec3& velocity, const Vec3& angular_velocity);

  // Accumulators, in order (not owned).
  void add_accumulator(ForceAccumulator* accumulator) { accumulators_.push_back(accumulator); }

  // RigidSubsteps, the two halves of a substep that the step loop
  // (MagneticStepper) times apart: update_forces() recomputes every
  // accumulator's forces; integrate(h) adds them to the bodies, collides,
  // runs the ODE step and empties the contacts.
  void update_forces(double time, double dt) override;
  void integrate(double h) override;

  // Pairs of dynamic bodies that touched in the last integrate(); and pairs
  // (dynamic, kinematic) that did.
  const std::vector<std::pair<int, int>>& touching() const override { return touching_; }
  const std::vector<std::pair<int, int>>& touching_kinematic() const override { return touching_kinematic_; }

  // Whether the body touched something in the last integrate().
  bool in_contact(int i) const override { return bodies_[i].in_contact; }
  // Its contact points in the last integrate() (ODE's dCollide gives up to 8 per pair).
  int contact_count(int i) const { return bodies_[i].contacts; }

  // A lower bound of the distance (m) from body i's collision geometry to
  // every other geometry of the world, the ground included: the gap between
  // their axis-aligned bounding boxes; 0 where they overlap.
  double clearance(int i) const override;
  bool knows_clearance() const override { return true; }

  // Substeps that ODE's exact solver failed on and QuickStep took instead
  // (docs/simulation.md "Contacts"), and the last failure's message.
  long exact_solver_failures() const { return exact_step_ ? exact_step_->failures() : 0; }
  std::string last_exact_solver_failure() const { return exact_step_ ? exact_step_->last_failure() : ""; }

  BodyPose pose(int i) const;
  Vec3 velocity(int i) const;
  Vec3 angular_velocity(int i) const;

 private:
  struct Body {
    dBodyID body = nullptr;
    dGeomID geom = nullptr;
    // Its other geoms: a compound's parts after the first, the solids of its
    // coils' windings (winding_solids.h).
    std::vector<dGeomID> windings;
    bool kinematic = false;
    bool enabled = true;
    double mass = 0.0;
    bool in_contact = false;
    int contacts = 0;
    double skin = 0.0;  // collision geometry enlarged by this much, m
  };
  // An ODE joint of the scene (docs/scene-format.md "joints"), in the world frame.
  void add_joint(const SceneDescription& scene, const JointDescription& joint);
  int index_of(dBodyID body) const;
  // Makes ODE's contact joints for the contacts of a geom pair.
  static void near_callback(void* data, dGeomID a, dGeomID b);
  double skin_of(dGeomID geom) const;

  // A trimesh geom of the mesh (body frame), its data kept in trimeshes_.
  dGeomID trimesh_geom(const Mesh& mesh);
  // The geom of a primitive or a mesh.
  dGeomID part_geom(const PartShape& shape, double skin);

  // A trimesh's vertices and indices, which ODE reads in place.
  struct TriMeshStore {
    std::vector<double> vertices;  // x y z per vertex (ODE's dVector3 stride: 4)
    std::vector<dTriIndex> indices;
    dTriMeshDataID data = nullptr;
  };
  std::vector<std::unique_ptr<TriMeshStore>> trimeshes_;

  dWorldID world_ = nullptr;
  dSpaceID space_ = nullptr;
  dJointGroupID contacts_ = nullptr;
  dGeomID ground_ = nullptr;
  bool has_joints_ = false;
  std::vector<Body> bodies_;
  std::vector<ForceAccumulator*> accumulators_;
  dSurfaceParameters surface_;  // of every contact (contact_surface)
  // Pairs of dynamic bodies in contact in the last integrate().
  std::vector<std::pair<int, int>> touching_;
  std::vector<std::pair<int, int>> touching_kinematic_;  // (dynamic, kinematic)
  bool exact_solver_ = false;
  std::unique_ptr<ExactStep> exact_step_;  // with the exact solver
  std::vector<dBodyID> ode_bodies_;        // every body, for ExactStep
  // The scene's damping factors per rigid step of time_step_ s (integrate
  // spreads them over the substeps).
  double linear_damping_ = 0.0, angular_damping_ = 0.0, time_step_ = 1.0;
  double damped_step_ = 0.0;  // the substep the bodies' damping was last set for
  // This world's state of ODE's random number generator (integrate), from
  // ODE's initial seed, so that every world steps as the first of a process.
  unsigned long random_seed_ = 0;
};

}  // namespace odemag
