#include "odemag/stepper.h"

#include "engine/embedding/substeps.h"
#include "magnetics/model/model.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <stdexcept>
#include <string>
#include <unordered_map>

namespace odemag {

namespace {

Vec3 vec(const dReal* v) { return {v[0], v[1], v[2]}; }

double elapsed_ms(std::chrono::steady_clock::time_point since) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - since).count();
}

// An embedder's world as the rigid side: the magnetic forces added, the
// embedder's collision callback, dWorldQuickStep or dWorldStep, contacts
// emptied; contacts and touching pairs read from the contact joints.
class OdeSpaceSubsteps : public RigidSubsteps {
 public:
  OdeSpaceSubsteps(MagneticForces& magnetics, dWorldID world, dSpaceID space, dNearCallback* near_callback,
                   void* near_data, dJointGroupID contacts, bool exact_solver)
      : magnetics_(magnetics),
        world_(world),
        space_(space),
        near_callback_(near_callback),
        near_data_(near_data),
        contacts_(contacts),
        exact_solver_(exact_solver) {}

  void update_forces(double, double) override { magnetics_.compute(); }

  void integrate(double h) override {
    magnetics_.add_forces();
    dSpaceCollide(space_, near_data_, near_callback_);
    read_contacts();
    if (exact_solver_) {
      dWorldStep(world_, h);
    } else {
      dWorldQuickStep(world_, h);
    }
    dJointGroupEmpty(contacts_);
  }

  bool in_contact(int b) const override { return b < static_cast<int>(in_contact_.size()) && in_contact_[b]; }
  const std::vector<std::pair<int, int>>& touching() const override { return touching_; }
  const std::vector<std::pair<int, int>>& touching_kinematic() const override { return touching_kinematic_; }

 private:
  // Per magnetic body: whether a contact joint is attached to its ODE body;
  // the pairs of magnetic bodies that such a joint connects.
  void read_contacts() {
    const int n = magnetics_.body_count();
    index_.clear();
    for (int b = 0; b < n; ++b)
      if (dBodyID body = magnetics_.ode_body(b)) index_.emplace(body, b);
    in_contact_.assign(static_cast<size_t>(n), 0);
    touching_.clear();
    touching_kinematic_.clear();
    for (int b = 0; b < n; ++b) {
      dBodyID body = magnetics_.ode_body(b);
      if (!body) continue;
      const int joints = dBodyGetNumJoints(body);
      for (int j = 0; j < joints; ++j) {
        dJointID joint = dBodyGetJoint(body, j);
        if (dJointGetType(joint) != dJointTypeContact) continue;
        in_contact_[b] = 1;
        dBodyID other = dJointGetBody(joint, 0) == body ? dJointGetBody(joint, 1) : dJointGetBody(joint, 0);
        const auto found = other ? index_.find(other) : index_.end();
        if (found == index_.end()) continue;
        const int o = found->second;
        const bool b_moves = !dBodyIsKinematic(body), o_moves = !dBodyIsKinematic(other);
        if (b_moves && o_moves && b < o) touching_.emplace_back(b, o);
        if (b_moves && !o_moves) touching_kinematic_.emplace_back(b, o);
      }
    }
  }

  MagneticForces& magnetics_;
  dWorldID world_;
  dSpaceID space_;
  dNearCallback* near_callback_;
  void* near_data_;
  dJointGroupID contacts_;
  bool exact_solver_;
  std::unordered_map<dBodyID, int> index_;
  std::vector<uint8_t> in_contact_;
  std::vector<std::pair<int, int>> touching_, touching_kinematic_;
};

// The embedder's world, checked before it is used.
dWorldID checked_world(dWorldID world, dSpaceID space, dNearCallback* near_callback, dJointGroupID contacts) {
  const char* missing = !world           ? "world"
                        : !space         ? "space"
                        : !near_callback ? "near_callback"
                        : !contacts      ? "contacts"
                                         : nullptr;
  if (missing) throw std::invalid_argument(std::string("MagneticStepper: ") + missing + " is null");
  return world;
}

// Clears the flag of both bodies of every touching pair in which one is
// moving: a body touching one that takes the substeps takes them too.
void clear_touching_moving(const std::vector<std::pair<int, int>>& touching, const std::vector<uint8_t>& moving,
                           std::vector<uint8_t>& flags) {
  for (const auto& [a, b] : touching)
    if (moving[a] || moving[b]) flags[a] = flags[b] = 0;
}

}  // namespace

MagneticStepper::MagneticStepper(MagneticForces& magnetics, dWorldID world, dSpaceID space,
                                 dNearCallback* near_callback, void* near_data, dJointGroupID contacts,
                                 const StepperSettings& settings)
    : magnetics_(magnetics),
      world_(checked_world(world, space, near_callback, contacts)),
      own_rigid_(std::make_unique<OdeSpaceSubsteps>(magnetics, world, space, near_callback, near_data, contacts,
                                                    settings.exact_solver)),
      rigid_(*own_rigid_),
      settings_(settings),
      rule_(std::make_unique<SubstepRule>(settings.substeps)) {}

MagneticStepper::MagneticStepper(MagneticForces& magnetics, dWorldID world, RigidSubsteps& rigid,
                                 const StepperSettings& settings)
    : magnetics_(magnetics),
      world_(world),
      rigid_(rigid),
      settings_(settings),
      rule_(std::make_unique<SubstepRule>(settings.substeps)) {}

MagneticStepper::~MagneticStepper() = default;

int MagneticStepper::substeps() const { return rule_->count(); }

void MagneticStepper::add_new_bodies() {
  for (int b = rule_->body_count(); b < magnetics_.body_count(); ++b) {
    dMass mass;
    dMassSetZero(&mass);
    if (dBodyID body = magnetics_.ode_body(b)) dBodyGetMass(body, &mass);
    rule_->add_body(substep_body(magnetics_.model().body(b), mass));
  }
  motion_.resize(static_cast<size_t>(rule_->body_count()));
}

void MagneticStepper::update_forces(double t, double h) {
  // T_m: relaxation (of the bodies not held), forces and torques.
  const auto t0 = std::chrono::steady_clock::now();
  rigid_.update_forces(t, h);
  report_.magnetic_ms += elapsed_ms(t0);
  const RelaxReport& r = magnetics_.last_report();
  ++report_.relaxations;
  report_.iterations += r.iterations;
  report_.llg_steps += r.llg_steps;
  report_.newton_steps += r.newton_steps;
  report_.skipped += r.skipped ? 1 : 0;
  report_.converged = report_.converged && r.converged;
  report_.residual = std::max(report_.residual, r.residual);
}

void MagneticStepper::update_motion() {
  for (int b = 0; b < rule_->body_count(); ++b) {
    SubstepMotion& m = motion_[b];
    dBodyID body = magnetics_.ode_body(b);
    m.free = body && !dBodyIsKinematic(body) && dBodyIsEnabled(body);
    if (!m.free) continue;
    dMass mass;
    dBodyGetMass(body, &mass);
    m.mass = mass.mass;
    m.velocity = vec(dBodyGetLinearVel(body));
    m.angular_velocity = vec(dBodyGetAngularVel(body));
    m.force = magnetics_.force(b);
    m.torque = magnetics_.torque(b);
    if (rule_->body(b).turns_in_field) m.moment = magnetics_.moment(b);
    m.in_contact = rigid_.in_contact(b);
  }
}

namespace {

double gravity_of(dWorldID world) {
  dVector3 g;
  dWorldGetGravity(world, g);
  return norm(vec(g));
}

}  // namespace

int MagneticStepper::substeps_needed(double dt) {
  update_motion();
  std::function<double(int)> clearance;
  if (rigid_.knows_clearance()) clearance = [this](int b) { return rigid_.clearance(b); };
  return rule_->needed(dt, motion_, gravity_of(world_), norm(magnetics_.external_field()), clearance);
}

void MagneticStepper::update_substeps(double dt, bool step_start) {
  const int wanted = substeps_needed(dt);
  report_.substeps_wanted = std::max(report_.substeps_wanted, wanted);
  rule_->update(wanted, time_, dt, step_start);
}

std::vector<uint8_t> MagneticStepper::bodies_to_hold(double dt) {
  update_motion();
  const int n = rule_->body_count();
  std::function<double(int)> clearance;
  if (rigid_.knows_clearance()) clearance = [this](int b) { return rigid_.clearance(b); };
  const double g = gravity_of(world_), H = norm(magnetics_.external_field());
  std::vector<uint8_t> moving(n, 0);
  for (int b = 0; b < n; ++b)
    moving[b] = motion_[b].free && rule_->needed_by(b, dt, motion_[b], g, H, clearance) > 1;
  std::vector<uint8_t> held(n, RelaxOptions::kHeld);
  for (int b = 0; b < n; ++b)
    if (moving[b]) held[b] = 0;
  clear_touching_moving(rigid_.touching(), moving, held);
  for (const auto& [a, k] : rigid_.touching_kinematic())
    if (moving[a]) held[k] = 0;
  return held;
}

bool MagneticStepper::finite_state(int b) const {
  if (!is_finite(magnetics_.force(b)) || !is_finite(magnetics_.torque(b)) || !is_finite(magnetics_.moment(b)))
    return false;
  dBodyID body = magnetics_.ode_body(b);
  return !body || (is_finite(vec(dBodyGetPosition(body))) && is_finite(vec(dBodyGetLinearVel(body))) &&
                   is_finite(vec(dBodyGetAngularVel(body))));
}

void MagneticStepper::note_non_finite(double t) {
  if (non_finite_body_ >= 0) return;
  for (int b = 0; b < magnetics_.body_count(); ++b) {
    if (finite_state(b)) continue;
    non_finite_body_ = b;
    non_finite_step_ = steps_ + 1;
    non_finite_time_ = t;
    report_.non_finite_body = b;
    return;
  }
}

const StepReport& MagneticStepper::step(double dt) {
  begin_step(dt);
  return finish_step();
}

void MagneticStepper::begin_step(double dt) {
  if (!(dt > 0.0) || !std::isfinite(dt))
    throw std::invalid_argument("MagneticStepper::step: the time step " + std::to_string(dt) +
                                " is not positive and finite");
  if (non_finite_body_ >= 0)
    throw std::runtime_error("MagneticStepper::step: body " + std::to_string(non_finite_body_) +
                             (magnetics_.model().body(non_finite_body_).name.empty()
                                  ? std::string()
                                  : " ('" + magnetics_.model().body(non_finite_body_).name + "')") +
                             " has a non-finite state at step " + std::to_string(non_finite_step_) +
                             " (t = " + std::to_string(non_finite_time_) + " s); stopped");
  add_new_bodies();
  report_ = StepReport{};
  report_.time = time_;
  dt_ = dt;
  // Forces relaxed at the step's start, then the count.
  update_forces(time_, dt);
  update_substeps(dt, true);
}

const StepReport& MagneticStepper::finish_step() {
  const double dt = dt_;
  const bool hold_slow_bodies = settings_.magnetic_solve == MagneticSolve::moving;
  // Substeps, each with its own forces: holding one step's forces over
  // several substeps is not symplectic and makes resting contacts unstable
  // (docs/simulation.md "Substeps"). The count is checked again after every
  // substep's forces and raised for the rest of the step when a body sped
  // up or came closer to a magnet (docs/hard-cases.md: a 0.3 mm ball
  // falling onto a magnet reached it within one 4 ms step and was thrown out).
  double done = 0.0;
  while (true) {
    const double h = std::min(dt / rule_->count(), dt - done);
    // T_r: forces added, collision, the ODE step, contacts.
    const auto t0 = std::chrono::steady_clock::now();
    rigid_.integrate(h);
    report_.rigid_ms += elapsed_ms(t0);
    done += h;
    ++report_.substeps;
    // A NaN stops the step: ODE's collision would abort on it.
    note_non_finite(time_ + done);
    if (dt - done <= 1e-9 * dt || non_finite_body_ >= 0) break;
    if (hold_slow_bodies) {
      std::vector<uint8_t>& held = magnetics_.options().held_bodies = bodies_to_hold(dt);
      for (size_t b = 0; b < held.size(); ++b)
        report_.held += held[b] && magnetics_.model().body(static_cast<int>(b)).responsive();
    }
    update_forces(time_ + done, dt / rule_->count());
    magnetics_.options().held_bodies.clear();
    update_substeps(dt, false);
  }
  time_ += dt;
  ++steps_;
  return report_;
}

}  // namespace odemag
