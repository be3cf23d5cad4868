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
#include "engine/embedding/force_accumulator.h"
#include "engine/scene/scene.h"
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

// The rolling resistance of one contact about the axis its bodies roll about
// (ContactSettings::rolling_axes "rolling"): omega_rel = omega_a - omega_b at
// the substep's start; where its part in the contact plane, omega_t, is
// above kRollingAxisMinimum, the contact's first tangent direction (fdir1,
// the first friction and rolling axis) is omega_t / |omega_t| and it keeps
// one rolling row, about that axis: one row fewer, and the torque rho N
// whatever the direction of rolling. Below it (bodies at rest relative to
// each other) the contact keeps both rows of `contact`'s surface. A surface
// without rolling resistance is left as it is.
constexpr double kRollingAxisMinimum = 1e-9;  // rad/s
void align_rolling_row(dContact& contact, const Vec3& relative_omega);

class RigidWorld {
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

  // The two halves of a rigid step, timed separately by the simulation:
  // update_forces() recomputes every accumulator's forces; integrate(h) adds
  // them to the bodies, collides, runs dWorldQuickStep(h) and empties the
  // contacts. A step may integrate several substeps with one update.
  // move_kinematic = false: the kinematic bodies end where they began (their
  // velocities still act on the contacts), for a step that covers a time the
  // kinematic bodies cover in other integrate() calls (the whole step of
  // rigid_substeps "moving").
  void update_forces(double time, double dt);
  void integrate(double h, bool move_kinematic = true);

  // Riding bodies (simulation.rigid_substeps "moving", docs/simulation.md
  // "Substeps"): bodies that took the rigid step whole and follow a given
  // path, kinematic in ODE, through the substeps of the others: contacts
  // with them see their velocity but do not move them. by_body: 1 for each
  // body to ride, one entry per body, or empty: none (they are dynamic
  // again, each with the velocity it was last given). Only free dynamic
  // bodies (not kinematic, disabled, asleep or jointed) ride, others are
  // ignored. The pairs of riders that touched in the last integrate() stay
  // in touching() (they are not collided while both ride). A rider that a
  // dynamic body runs into, which it did not touch when the riding began,
  // rides no more from that substep on (riding() false): dynamic, with the
  // velocity of its path, as a sleeping body that a faster one hits wakes.
  void ride(const std::vector<uint8_t>& by_body);
  bool riding(int i) const { return bodies_[i].rides; }
  bool can_ride(int i) const;

  // A body's pose and velocities as ODE holds them, to put it back.
  struct Motion {
    dReal position[3], orientation[4];
    Vec3 velocity, angular_velocity;
  };
  Motion motion(int i) const;
  void set_motion(int i, const Motion& m);

  // Whether the body sleeps (docs/simulation.md "Sleeping bodies"): taken
  // out of ODE's step, at rest, until its applied force or torque moves by
  // SleepSettings::wake_force of its weight, a faster or kinematic body
  // touches it, it touches nothing, or the time line acts.
  bool sleeping(int i) const { return bodies_[i].sleeping; }
  int sleeping_count() const;
  // Pairs of dynamic bodies that touched in the last integrate(); and pairs
  // (dynamic, kinematic) that did.
  const std::vector<std::pair<int, int>>& touching() const { return touching_; }
  const std::vector<std::pair<int, int>>& touching_kinematic() const { return touching_kinematic_; }

  // Whether the body touched something in the last integrate().
  bool in_contact(int i) const { return bodies_[i].in_contact; }
  // Its contact points in the last integrate() (ODE's dCollide gives up to 8 per pair).
  int contact_count(int i) const { return bodies_[i].contacts; }

  // A lower bound of the distance (m) from body i's collision geometry to
  // every other geometry of the world, the ground included: the gap between
  // their axis-aligned bounding boxes; 0 where they overlap.
  double clearance(int i) const;

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
    std::vector<dGeomID> windings;  // the solids of its coils' windings (winding_solids.h)
    bool kinematic = false;
    bool enabled = true;
    double mass = 0.0;
    bool in_contact = false;
    int contacts = 0;
    double skin = 0.0;  // collision geometry enlarged by this much, m
    // Sleeping bodies (docs/simulation.md "Sleeping bodies").
    double radius = 0.0;       // bounding radius of the shape, m
    bool jointed = false;      // held by a scene joint: never sleeps
    bool sleeping = false;
    bool touches_kinematic = false;  // in the last integrate()
    bool rides = false;        // kinematic in ODE along a given path (ride)
    bool leaves_ride = false;  // a dynamic body ran into it in this collision pass
    int recollide_rank = -1;   // its place among those (stop_riding_where_hit)
    double idle = 0.0;         // s below the sleep speed, in contact
    Vec3 force, torque;        // applied (accumulators) in the last integrate()
    Vec3 rest_force, rest_torque;  // applied when it fell asleep
  };
  // An ODE joint of the scene (docs/scene-format.md "joints"), in the world frame.
  void add_joint(const SceneDescription& scene, const JointDescription& joint);
  int index_of(dBodyID body) const;
  // Collects the contacts of a geom pair (found_); create_contact_joints
  // then wakes the sleeping bodies a faster body runs into and makes ODE's
  // contact joints.
  static void near_callback(void* data, dGeomID a, dGeomID b);
  void create_contact_joints();
  // After the collision pass: the riders a dynamic body ran into that it did
  // not touch when they began to ride (leaving_ride_) are dynamic from this
  // substep on, with their forces, and are collided with what the pass
  // skipped for them (recollided_).
  void stop_riding_where_hit();
  double speed(int i) const;  // |v| + |omega| r, m/s
  void wake(int i);
  // Before the step: wakes sleeping bodies whose applied force or torque moved.
  void wake_on_force_change();
  // After the step: wakes sleeping bodies with a faster partner, and puts to
  // sleep each body slow for SleepSettings::time among slow partners.
  void update_sleep(double h);
  double skin_of(dGeomID geom) const;

  dWorldID world_ = nullptr;
  dSpaceID space_ = nullptr;
  dJointGroupID contacts_ = nullptr;
  dGeomID ground_ = nullptr;
  bool has_joints_ = false;
  std::vector<Body> bodies_;
  std::vector<ForceAccumulator*> accumulators_;
  dSurfaceParameters surface_;  // of every contact (contact_surface)
  bool rolling_axis_aligned_ = false;  // ContactSettings::rolling_axes "rolling": align_rolling_row
  SleepSettings sleep_;
  double gravity_ = 0.0;  // |g|, m/s^2
  // Pairs of dynamic bodies in contact in the last integrate().
  std::vector<std::pair<int, int>> touching_;
  std::vector<std::pair<int, int>> touching_kinematic_;  // (dynamic, kinematic)
  // While bodies ride: the pairs above of riders only, and riders in contact,
  // from the integrate() before they rode.
  std::vector<std::pair<int, int>> rider_touching_, rider_touching_kinematic_;
  std::vector<int> riders_in_contact_;
  // The touching() pairs (lower index first, sorted) when they began to ride.
  std::vector<std::pair<int, int>> ride_start_touching_;
  std::vector<int> leaving_ride_;  // riders hit in this collision pass
  int recollided_ = -1;            // the body stop_riding_where_hit collides, or -1
  struct FoundContact {
    dContact contact;
    dBodyID a, b;  // nullptr: the ground
  };
  std::vector<FoundContact> found_;  // by near_callback, until create_contact_joints
  bool exact_solver_ = false;
  std::unique_ptr<ExactStep> exact_step_;  // with the exact solver
  std::vector<dBodyID> ode_bodies_;        // every body, for ExactStep
  // The scene's damping factors per rigid step of time_step_ s (integrate
  // spreads them over the substeps).
  double linear_damping_ = 0.0, angular_damping_ = 0.0, time_step_ = 1.0;
  double damped_step_ = 0.0;  // the substep the bodies' damping was last set for
  // This world's state of ODE's random number generator (integrate); ODE's
  // initial seed, so that the first world of a process steps as before.
  unsigned long random_seed_ = 0;
};

}  // namespace odemag
