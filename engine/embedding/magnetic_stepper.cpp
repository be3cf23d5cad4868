#include "engine/embedding/magnetic_stepper.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace odemag {

namespace {

Vec3 vec(const dReal* v) { return {v[0], v[1], v[2]}; }

// Whether a contact joint is attached to the body.
bool has_contact(dBodyID body) {
  const int n = dBodyGetNumJoints(body);
  for (int j = 0; j < n; ++j)
    if (dJointGetType(dBodyGetJoint(body, j)) == dJointTypeContact) return true;
  return false;
}

}  // namespace

MagneticStepper::MagneticStepper(MagneticForces& magnetics, dWorldID world, dSpaceID space,
                                 dNearCallback* near_callback, void* near_data, dJointGroupID contacts,
                                 const StepperSettings& settings)
    : magnetics_(magnetics),
      world_(world),
      space_(space),
      near_callback_(near_callback),
      near_data_(near_data),
      contacts_(contacts),
      settings_(settings),
      rule_(settings.substeps) {
  const char* missing = !world           ? "world"
                        : !space         ? "space"
                        : !near_callback ? "near_callback"
                        : !contacts      ? "contacts"
                                         : nullptr;
  if (missing) throw std::invalid_argument(std::string("MagneticStepper: ") + missing + " is null");
}

void MagneticStepper::add_new_bodies() {
  for (int b = rule_.body_count(); b < magnetics_.body_count(); ++b) {
    dMass mass;
    dMassSetZero(&mass);
    if (dBodyID body = magnetics_.ode_body(b)) dBodyGetMass(body, &mass);
    rule_.add_body(substep_body(magnetics_.model().body(b), mass));
  }
  motion_.resize(static_cast<size_t>(rule_.body_count()));
  in_contact_.resize(static_cast<size_t>(rule_.body_count()), 0);
}

void MagneticStepper::update_forces(bool relax) {
  if (!relax) {
    magnetics_.recompute_forces();
    return;
  }
  const RelaxReport& r = magnetics_.compute();
  ++report_.relaxations;
  report_.iterations += r.iterations;
  report_.skipped += r.skipped ? 1 : 0;
  report_.converged = report_.converged && r.converged;
  report_.residual = std::max(report_.residual, r.residual);
}

int MagneticStepper::substeps_needed(double dt) {
  for (int b = 0; b < rule_.body_count(); ++b) {
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
    if (rule_.body(b).turns_in_field) m.moment = magnetics_.moment(b);
    m.in_contact = in_contact_[b] != 0;
  }
  dVector3 g;
  dWorldGetGravity(world_, g);
  return rule_.needed(dt, motion_, norm(vec(g)), norm(magnetics_.external_field()));
}

void MagneticStepper::rigid_substep(double h) {
  magnetics_.add_forces();
  dSpaceCollide(space_, near_data_, near_callback_);
  for (int b = 0; b < rule_.body_count(); ++b) {
    dBodyID body = magnetics_.ode_body(b);
    in_contact_[b] = body && has_contact(body) ? 1 : 0;
  }
  if (settings_.exact_solver) {
    dWorldStep(world_, h);
  } else {
    dWorldQuickStep(world_, h);
  }
  dJointGroupEmpty(contacts_);
}

const StepReport& MagneticStepper::step(double dt) {
  if (!(dt > 0.0) || !std::isfinite(dt))
    throw std::invalid_argument("MagneticStepper::step: the time step " + std::to_string(dt) +
                                " is not positive and finite");
  add_new_bodies();
  report_ = StepReport{};
  const bool relax_every_substep = settings_.magnetic_solve == MagneticSolve::substep;
  auto update_substeps = [&](bool step_start) {
    const int wanted = substeps_needed(dt);
    report_.substeps_wanted = std::max(report_.substeps_wanted, wanted);
    rule_.update(wanted, time_, dt, step_start);
  };
  // As Simulation::step (docs/simulation.md "Substeps"): forces, then the
  // count; after every substep the forces again (relaxed or at the held
  // magnetization) and the count, raised at once for the rest of the step
  // when a body sped up or came closer to a magnet.
  update_forces(true);
  update_substeps(true);
  double done = 0.0;
  while (true) {
    const double h = std::min(dt / rule_.count(), dt - done);
    rigid_substep(h);
    done += h;
    ++report_.substeps;
    if (dt - done <= 1e-9 * dt) break;
    update_forces(relax_every_substep);
    update_substeps(false);
  }
  time_ += dt;
  return report_;
}

}  // namespace odemag
