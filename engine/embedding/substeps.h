// The substep rule (docs/simulation.md "Substeps"): into how many substeps,
// each with its own magnetic forces and collision check, a rigid step of
// length dt is split so that no free body tunnels and the magnetic force and
// torque are resolved in time. One rule for the scene simulation
// (engine/simulation/simulation.h) and for embedders (MagneticStepper,
// engine/embedding/magnetic_stepper.h; docs/embedding.md "Substeps").
#pragma once

#include <ode/ode.h>

#include <functional>
#include <vector>

#include "magnetics/model/model.h"
#include "odemag/settings.h"
#include "odemag/vec3.h"

namespace odemag {

// What the rule knows of a body that does not change while it moves.
struct SubstepBody {
  double size = 0.0;     // smallest half-extent of the shape, m
  double reach = 0.0;    // farthest surface point that a rotation moves (0 for a sphere), m
  double inertia = 0.0;  // smallest principal moment of inertia, kg m^2
  bool turns_in_field = false;  // a uniform field exerts a torque on it
};

// From the magnetic body's shape and material and its ODE mass (body-frame
// inertia, diagonal for the centred, axis-aligned shapes). A uniform field
// turns every magnetic body but an isotropic one-cell soft body (a plain
// iron ball), whose moment simply follows the field.
SubstepBody substep_body(const MagneticBody& body, const dMass& mass);

// A body's state when the rule is asked (after a substep's magnetic forces).
struct SubstepMotion {
  bool free = false;    // dynamic and enabled: kinematic and disabled bodies do not count
  double mass = 0.0;    // kg
  Vec3 velocity;        // m/s, world
  Vec3 angular_velocity;  // rad/s, world
  Vec3 force;           // magnetic, N, world
  Vec3 torque;          // magnetic, N m, world
  Vec3 moment;          // A m^2, world; read only for bodies that turn in a field
  bool in_contact = false;  // touched something in the last substep
};

class SubstepRule {
 public:
  explicit SubstepRule(const SubstepSettings& settings = {}) : settings_(settings) {}

  // Bodies, in the order of the motions passed to needed().
  void add_body(const SubstepBody& body) { bodies_.push_back(body); }
  int body_count() const { return static_cast<int>(bodies_.size()); }
  const SubstepBody& body(int b) const { return bodies_[b]; }
  const SubstepSettings& settings() const { return settings_; }

  // Substeps of dt needed for collision (travel) and for the magnetic force's
  // time scale (stiffness), before the cap max_substeps. motion: one per
  // body; gravity: |g|, m/s^2; external_field: |H_E|, A/m. clearance, when
  // given: a lower bound of the distance (m) from body b to every other
  // body and the ground, asked only for a body in free flight, pulled by a
  // magnetic force no larger than its weight, whose travel bound would
  // shorten the substep; it may then cover half of it as well.
  int needed(double dt, const std::vector<SubstepMotion>& motion, double gravity, double external_field,
             const std::function<double(int)>& clearance = {}) const;
  // What body b alone needs (needed() is the largest over the bodies).
  int needed_by(int b, double dt, const SubstepMotion& motion, double gravity, double external_field,
                const std::function<double(int)>& clearance = {}) const;

  // The count in use after the rule wanted `wanted` (needed()) at `time`,
  // s: raised at once, lowered only at a step's start (step_start) after a
  // hold time, to the largest count needed meanwhile; always within
  // 1 .. max(1, max_substeps).
  int update(int wanted, double time, double dt, bool step_start);
  int count() const { return count_; }
  // The hold time of update(), s: one period of the slowest oscillation whose
  // stiffness alone asks for more than one substep of dt.
  double hold_time(double dt) const;

 private:
  // The longest admissible substep of body b, at most `shortest` (s): the
  // clearance is asked for only when b's travel bound would shorten it.
  double longest_substep(int b, double shortest, const SubstepMotion& motion, double gravity,
                         double external_field, const std::function<double(int)>& clearance) const;
  SubstepSettings settings_;
  std::vector<SubstepBody> bodies_;
  // Count in use, and the largest count needed since it was last set (at
  // set_time_; it falls only after a hold time, see update).
  int count_ = 1;
  int window_max_ = 1;
  double set_time_ = 0.0;
};

}  // namespace odemag
