#include "engine/simulation/simulation.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <stdexcept>

#include <Eigen/Geometry>

#include "engine/simulation/magnetic_system.h"

namespace odemag {

namespace {

double elapsed_ms(std::chrono::steady_clock::time_point since) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - since).count();
}

// Spherical linear interpolation from a (u = 0) to b (u = 1) along the shorter arc.
Quaternion slerp(const Quaternion& a, const Quaternion& b, double u) {
  const Eigen::Quaterniond q =
      Eigen::Quaterniond(a.w, a.x, a.y, a.z).slerp(u, Eigen::Quaterniond(b.w, b.x, b.y, b.z));
  return {q.w(), q.x(), q.y(), q.z()};
}

// Angular velocity that turns rotation A into rotation B in time dt, the
// shorter way. The increment R = B A^T has R - R^T = 2 sin(angle) [n]x and
// trace 1 + 2 cos(angle); atan2 keeps the angle accurate where it is tiny
// (a resting body's step), where acos of the trace loses it.
Vec3 angular_velocity_between(const Mat3& A, const Mat3& B, double dt) {
  const Mat3 R = B * A.transposed();  // world-frame increment
  const Vec3 axis{R.m[2][1] - R.m[1][2], R.m[0][2] - R.m[2][0], R.m[1][0] - R.m[0][1]};
  const double two_sin = norm(axis);
  if (two_sin == 0.0) return {};  // no turn (or exactly half a turn: no shorter way)
  const double angle = std::atan2(0.5 * two_sin, 0.5 * (R.m[0][0] + R.m[1][1] + R.m[2][2] - 1.0));
  return (angle / (dt * two_sin)) * axis;
}

// Clears the flag of both bodies of every touching pair in which one is
// moving: a body touching one that takes the substeps takes them too.
void clear_touching_moving(const std::vector<std::pair<int, int>>& touching, const std::vector<uint8_t>& moving,
                           std::vector<uint8_t>& flags) {
  for (const auto& [a, b] : touching)
    if (moving[a] || moving[b]) flags[a] = flags[b] = 0;
}

}  // namespace

BodyPose keyframe_pose(const std::vector<Keyframe>& keys, double t) {
  auto pose_of = [](const Vec3& p, const Quaternion& q) {
    BodyPose pose;
    pose.position = p;
    pose.rotation = rotation_from_quaternion(q.w, q.x, q.y, q.z);
    return pose;
  };
  if (t <= keys.front().time) return pose_of(keys.front().position, keys.front().orientation);
  if (t >= keys.back().time) return pose_of(keys.back().position, keys.back().orientation);
  size_t i = 1;
  while (keys[i].time < t) ++i;
  const Keyframe& a = keys[i - 1];
  const Keyframe& b = keys[i];
  const double u = (t - a.time) / (b.time - a.time);
  return pose_of(a.position + u * (b.position - a.position), slerp(a.orientation, b.orientation, u));
}

Simulation::Simulation(const SceneDescription& scene, std::unique_ptr<MagneticBackend> backend)
    : scene_(scene), outcomes_(scene_) {
  world_ = std::make_unique<RigidWorld>(scene_);
  // The magnetic model of the scene, built as for solve and field
  // (build_magnetic_system), then tied to the ODE bodies.
  MagneticSystem ms = build_magnetic_system(scene_);
  contact_zones_ = std::move(ms.contact_zones);
  contact_zones_failed_.assign(scene_.bodies.size(), 0);
  magnetics_ = std::make_unique<MagneticForces>(
      std::move(ms.model), std::move(ms.state), scene_.solver.relax,
      backend ? std::move(backend) : make_cpu_backend(scene_.solver.threads));
  for (size_t b = 0; b < scene_.bodies.size(); ++b) magnetics_->bind(static_cast<int>(b), world_->body(static_cast<int>(b)));
  world_->add_accumulator(magnetics_.get());
  // The substep rule's view of each body: shape, material, ODE inertia.
  substep_rule_ = SubstepRule({scene_.simulation.max_substeps, scene_.simulation.stiffness_limit});
  for (size_t b = 0; b < scene_.bodies.size(); ++b) {
    dMass mass;
    dBodyGetMass(world_->body(static_cast<int>(b)), &mass);
    substep_rule_.add_body(substep_body(magnetics_->model().body(static_cast<int>(b)), mass));
  }
  substep_motion_.resize(scene_.bodies.size());
  event_state_.assign(scene_.timeline.size(), kPending);
  ramp_start_scale_.assign(scene_.timeline.size(), 1.0);
  ramp_start_field_.assign(scene_.timeline.size(), Vec3{});
  // Events at t = 0 hold already in the state at t = 0 (frame 0, the first
  // state line), as in `odemag solve` (apply_events_at_start); the first
  // step() applies them again, which changes nothing.
  apply_timeline(scene_.simulation.time_step);
}

void Simulation::apply_timeline(double dt) {
  for (size_t e = 0; e < scene_.timeline.size(); ++e) {
    const TimelineEvent& ev = scene_.timeline[e];
    const int body = ev.body.empty() ? -1 : scene_.find_body(ev.body);
    if (ev.kind == TimelineEvent::Kind::keyframes) {
      // Scripted motion: place the body where the track says and give it the
      // velocity that takes it to the next step's pose. A body that is not
      // fixed is kinematic while its track runs (held at the first key before
      // it) and dynamic again after the last key, with the velocity of the
      // track's last step (a hand that lets go); a fixed body stays at the
      // last key.
      if (!scene_.bodies[body].fixed) {
        const bool released = time_ + 0.5 * dt >= ev.keys.back().time;
        world_->set_kinematic(body, !released);
        if (released) continue;
      }
      const BodyPose now = keyframe_pose(ev.keys, time_);
      const BodyPose next = keyframe_pose(ev.keys, time_ + dt);
      world_->set_kinematic_state(body, now, (1.0 / dt) * (next.position - now.position),
                                  angular_velocity_between(now.rotation, next.rotation, dt));
      continue;
    }
    if (time_ + 0.5 * dt < ev.time || event_state_[e] == kDone) continue;  // not due, or over
    const bool first = event_state_[e] == kPending;
    event_state_[e] = kRunning;
    const double span = ev.end_time - ev.time;
    const double u = span > 0.0 ? std::clamp((time_ - ev.time) / span, 0.0, 1.0) : 1.0;
    if (u >= 1.0) event_state_[e] = kDone;  // this application is the last
    switch (ev.kind) {
      case TimelineEvent::Kind::add_body:
        world_->set_enabled(body, true);
        magnetics_->set_active(body, true);
        break;
      case TimelineEvent::Kind::remove_body:
        world_->set_enabled(body, false);
        magnetics_->set_active(body, false);
        break;
      case TimelineEvent::Kind::mutual_induction:
        magnetics_->options().mutual_induction = ev.enabled;
        break;
      case TimelineEvent::Kind::scale_magnetization:
        if (first) ramp_start_scale_[e] = magnetics_->magnetization_scale(body);
        magnetics_->set_magnetization_scale(body, ramp_start_scale_[e] + u * (ev.value - ramp_start_scale_[e]));
        break;
      case TimelineEvent::Kind::external_field:
        if (first) ramp_start_field_[e] = magnetics_->external_field();
        magnetics_->set_external_field(ramp_start_field_[e] + u * (ev.field - ramp_start_field_[e]));
        break;
      case TimelineEvent::Kind::keyframes:
        break;
    }
  }
}

void Simulation::update_substep_motion() {
  for (int b = 0; b < world_->body_count(); ++b) {
    SubstepMotion& m = substep_motion_[b];
    // A sleeping body does not move (docs/simulation.md "Sleeping bodies"),
    // a riding one moves on a given path ("Substeps").
    m.free = !world_->kinematic(b) && world_->enabled(b) && !world_->sleeping(b) && !world_->riding(b);
    if (!m.free) continue;
    m.mass = world_->mass(b);
    m.velocity = world_->velocity(b);
    m.angular_velocity = world_->angular_velocity(b);
    m.force = magnetics_->force(b);
    m.torque = magnetics_->torque(b);
    if (substep_rule_.body(b).turns_in_field) m.moment = magnetics_->moment(b);
    m.in_contact = world_->in_contact(b);
  }
}

int Simulation::substeps_needed(double dt) {
  update_substep_motion();
  return substep_rule_.needed(dt, substep_motion_, norm(scene_.gravity), norm(magnetics_->external_field()),
                              [this](int b) { return world_->clearance(b); });
}

std::vector<uint8_t> Simulation::bodies_to_hold(double dt) {
  update_substep_motion();
  const int n = world_->body_count();
  std::vector<uint8_t> moving(n, 0);
  for (int b = 0; b < n; ++b)
    moving[b] = substep_motion_[b].free &&
                substep_rule_.needed_by(b, dt, substep_motion_[b], norm(scene_.gravity),
                                        norm(magnetics_->external_field()),
                                        [this](int i) { return world_->clearance(i); }) > 1;
  std::vector<uint8_t> held(n, 1);
  for (int b = 0; b < n; ++b)
    if (moving[b]) held[b] = 0;
  clear_touching_moving(world_->touching(), moving, held);
  for (const auto& [a, k] : world_->touching_kinematic())
    if (moving[a]) held[k] = 0;
  return held;
}

std::vector<uint8_t> Simulation::bodies_to_step_whole(double dt, std::vector<uint8_t>& moving) {
  update_substep_motion();
  const int n = world_->body_count();
  moving_until_.resize(n, -1.0);
  moving.assign(n, 0);
  bool any_moving = false;
  for (int b = 0; b < n; ++b) {
    if (!substep_motion_[b].free) continue;
    const int needed = substep_rule_.needed_by(b, dt, substep_motion_[b], norm(scene_.gravity),
                                               norm(magnetics_->external_field()),
                                               [this](int i) { return world_->clearance(i); });
    if (needed > 1)
      moving_until_[b] = time_ + substep_rule_.hold_time(dt);
    // Held in the substeps for a hold time, so that a body's step does not
    // follow the phase of its oscillation (SubstepRule::update).
    moving[b] = time_ < moving_until_[b] * (1.0 - 1e-12) || !world_->can_ride(b);
    any_moving = any_moving || moving[b];
  }
  if (!any_moving) return {};
  std::vector<uint8_t> whole(n, 0);
  for (int b = 0; b < n; ++b) whole[b] = substep_motion_[b].free && !moving[b];
  clear_touching_moving(world_->touching(), moving, whole);
  return whole;
}

void Simulation::step_slow_bodies_whole(double dt, StepRecord& record) {
  std::vector<uint8_t> moving;
  std::vector<uint8_t> whole = bodies_to_step_whole(dt, moving);
  if (std::count(whole.begin(), whole.end(), 1) == 0) return;
  const auto t0 = std::chrono::steady_clock::now();
  // One step of dt for every body, as with one substep: the bodies that take
  // it whole keep theirs, the others go back to the step's start.
  const int n = world_->body_count();
  std::vector<RigidWorld::Motion> start(n);
  std::vector<BodyPose> start_pose(n);
  for (int b = 0; b < n; ++b)
    if (substep_motion_[b].free) start[b] = world_->motion(b), start_pose[b] = world_->pose(b);
  world_->integrate(dt, false);
  note_non_finite(time_ + dt);
  // Its contacts, found at the step's start positions, count too: those
  // bodies_to_step_whole read were the last substep's.
  clear_touching_moving(world_->touching(), moving, whole);
  whole_.assign(n, 0);
  whole_end_.assign(n, {});
  for (int b = 0; b < n && non_finite_body_ < 0; ++b) {
    if (!substep_motion_[b].free) continue;
    if (!whole[b]) {
      world_->set_motion(b, start[b]);
      continue;
    }
    // Through the substeps it rides from its start to its end on a straight
    // path at constant velocities (kinematic: the substeps' contacts see its
    // motion), and it ends the step with the state of its own step.
    whole_end_[b] = world_->motion(b);
    const BodyPose end_pose = world_->pose(b);
    RigidWorld::Motion path = start[b];
    path.velocity = (1.0 / dt) * (end_pose.position - start_pose[b].position);
    path.angular_velocity = angular_velocity_between(start_pose[b].rotation, end_pose.rotation, dt);
    world_->set_motion(b, path);
    whole_[b] = 1;
    ++record.whole_step;
  }
  world_->ride(whole_);
  record.rigid_ms += elapsed_ms(t0);
}

void Simulation::update_substeps(double dt, bool step_start, StepRecord& record) {
  const int wanted = substeps_needed(dt);
  record.substeps_wanted = std::max(record.substeps_wanted, wanted);
  substeps_ = substep_rule_.update(wanted, time_, dt, step_start);
}

void Simulation::step() {
  if (non_finite_body_ >= 0) throw std::runtime_error(non_finite_message());
  const auto started = std::chrono::steady_clock::now();
  const double dt = scene_.simulation.time_step;
  apply_timeline(dt);
  StepRecord record;
  record.time = time_;
  const bool relax_every_substep = scene_.simulation.magnetic_solve != "step";
  const bool hold_slow_bodies = scene_.simulation.magnetic_solve == "moving";
  auto update_forces = [&](double t, double h, bool relax) {
    // T_m: relaxation, forces and torques; or, with magnetic_solve "step"
    // after the first substep, the forces at the held magnetization.
    const auto t0 = std::chrono::steady_clock::now();
    if (!relax) {
      magnetics_->recompute_forces();
      record.magnetic_ms += elapsed_ms(t0);
      return;
    }
    world_->update_forces(t, h);
    record.magnetic_ms += elapsed_ms(t0);
    ++record.relaxations;
    const RelaxReport& report = magnetics_->last_report();
    record.iterations += report.iterations;
    record.llg_steps += report.llg_steps;
    record.newton_steps += report.newton_steps;
    record.skipped += report.skipped ? 1 : 0;
    record.converged = record.converged && report.converged;
    record.residual = std::max(record.residual, report.residual);
  };
  update_forces(time_, dt, true);
  if (steps_ == 0) outcomes_.sample(scene_, time_, dt, *world_, *magnetics_);  // t = 0, relaxed
  update_substeps(dt, true, record);
  if (scene_.simulation.rigid_substeps == "moving" && substeps_ > 1) step_slow_bodies_whole(dt, record);
  // Substeps, each with its own forces: holding one step's forces over
  // several substeps is not symplectic and makes resting contacts unstable
  // (docs/simulation.md "Substeps"). The count is checked again after every
  // substep's forces and raised for the rest of the step when a body sped
  // up or came closer to a magnet (docs/hard-cases.md: a 0.3 mm ball
  // falling onto a magnet reached it within one 4 ms step and was thrown out).
  double done = 0.0;
  record.substeps = 0;
  while (non_finite_body_ < 0) {
    const double h = std::min(dt / substeps_, dt - done);
    // T_r: collision, dWorldQuickStep, contacts.
    const auto t0 = std::chrono::steady_clock::now();
    world_->integrate(h);
    record.rigid_ms += elapsed_ms(t0);
    done += h;
    ++record.substeps;
    // A NaN stops the step: ODE's collision would abort on it.
    note_non_finite(time_ + done);
    if (dt - done <= 1e-9 * dt || non_finite_body_ >= 0) break;
    if (hold_slow_bodies || record.whole_step > 0) {
      // A riding body's magnetization is held too, and its force kept: it is
      // not used before the next step.
      std::vector<uint8_t>& held = magnetics_->options().held_bodies =
          hold_slow_bodies ? bodies_to_hold(dt) : std::vector<uint8_t>(world_->body_count(), 0);
      for (size_t b = 0; b < held.size(); ++b) {
        if (world_->riding(static_cast<int>(b))) held[b] = RelaxOptions::kHeldKeepForce;
        record.held += held[b] && magnetics_->model().body(static_cast<int>(b)).responsive();
      }
    }
    update_forces(time_ + done, dt / substeps_, relax_every_substep);
    magnetics_->options().held_bodies.clear();
    update_substeps(dt, false, record);
  }
  if (!whole_.empty()) {
    // The bodies that rode to the end end the step in the state of their own
    // step; those that a body ran into were stepped from there on.
    for (int b = 0; b < world_->body_count(); ++b)
      if (whole_[b] && !world_->riding(b)) whole_[b] = 0, --record.whole_step;
    world_->ride({});
    for (int b = 0; b < world_->body_count(); ++b)
      if (whole_[b]) world_->set_motion(b, whole_end_[b]);
    whole_.clear();
  }
  record.sleeping = world_->sleeping_count();
  records_.push_back(record);
  time_ += dt;
  ++steps_;
  outcomes_.sample(scene_, time_, dt, *world_, *magnetics_);
  if (scene_.solver.contact_refinement) follow_contact_zones(records_.back());
  records_.back().wall_ms = elapsed_ms(started);
}

void Simulation::follow_contact_zones(StepRecord& record) {
  const auto t0 = std::chrono::steady_clock::now();
  // The poses at the step's end (the magnetic state holds the last substep's).
  std::vector<BodyPose> poses(scene_.bodies.size());
  for (size_t b = 0; b < poses.size(); ++b) poses[b] = world_->pose(static_cast<int>(b));
  const std::vector<uint8_t>& active = magnetics_->state().active;
  for (size_t b = 0; b < scene_.bodies.size(); ++b) {
    if (contact_zones_failed_[b] || !active[b]) continue;
    // The zones the scene would place at these poses (scene_contact_zones).
    std::vector<RefinedZone> zones = contact_zones(scene_, poses, active, static_cast<int>(b));
    const double h = scene_.body_cell_size(static_cast<int>(b));
    bool covered = true;
    for (const RefinedZone& wanted : zones) {
      bool near_zone = false;
      for (const RefinedZone& zone : contact_zones_[b])
        near_zone = near_zone || norm(wanted.point - zone.point) <= kContactZoneFollowDistance * h;
      covered = covered && near_zone;
    }
    if (covered) continue;
    try {
      magnetics_->refine_body(static_cast<int>(b), zones);
      contact_zones_[b] = std::move(zones);
      ++record.rezoned;
    } catch (const std::invalid_argument& e) {  // more than kMaxRefinedCells cells
      contact_zones_failed_[b] = 1;
      char t[32];
      std::snprintf(t, sizeof t, "%.4f", time_);
      notices_.push_back(scene_.file + ": body '" + scene_.bodies[b].name + "' (bodies[" +
                         std::to_string(b) + "]): at t = " + t +
                         " s its refined contact zones could not follow its contacts (" + e.what() +
                         "), so its force there has the plain lattice's error");
    }
  }
  if (record.rezoned > 0) record.magnetic_ms += elapsed_ms(t0);
}

void Simulation::advance_to(double t) {
  const double dt = scene_.simulation.time_step;
  while (time_ + 0.5 * dt < t) step();
}

void Simulation::finish() { outcomes_.finish(scene_, *world_, *magnetics_); }

bool Simulation::finite_state(int b) const {
  const BodyPose p = world_->pose(b);
  return is_finite(p.position) && is_finite(world_->velocity(b)) &&
         is_finite(world_->angular_velocity(b)) && is_finite(magnetics_->force(b)) &&
         is_finite(magnetics_->torque(b)) && is_finite(magnetics_->moment(b));
}

void Simulation::note_non_finite(double t) {
  if (non_finite_body_ >= 0) return;
  for (int b = 0; b < world_->body_count(); ++b) {
    if (finite_state(b)) continue;
    non_finite_body_ = b;
    non_finite_step_ = steps_ + 1;
    non_finite_time_ = t;
    return;
  }
}

std::string Simulation::non_finite_message() const {
  int body = non_finite_body_;
  long step = non_finite_step_;
  double t = non_finite_time_;
  for (int b = 0; body < 0 && b < world_->body_count(); ++b)
    if (!finite_state(b)) body = b, step = steps_, t = time_;
  if (body < 0) return {};
  return scene_.file + ": body '" + scene_.bodies[body].name + "' has a non-finite state at step " +
         std::to_string(step) + " (t = " + std::to_string(t) + " s); stopped";
}

}  // namespace odemag
