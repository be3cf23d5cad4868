#include "engine/simulation/timeline.h"

#include <algorithm>
#include <cmath>

#include <Eigen/Geometry>

namespace odemag {

namespace {

// Spherical linear interpolation from a (u = 0) to b (u = 1) along the shorter arc.
Quaternion slerp(const Quaternion& a, const Quaternion& b, double u) {
  const Eigen::Quaterniond q =
      Eigen::Quaterniond(a.w, a.x, a.y, a.z).slerp(u, Eigen::Quaterniond(b.w, b.x, b.y, b.z));
  return {q.w(), q.x(), q.y(), q.z()};
}

}  // namespace

// The increment R = B A^T has R - R^T = 2 sin(angle) [n]x and trace
// 1 + 2 cos(angle); atan2 keeps the angle accurate where it is tiny (a
// resting body's step), where acos of the trace loses it.
Vec3 angular_velocity_between(const Mat3& A, const Mat3& B, double dt) {
  const Mat3 R = B * A.transposed();  // world-frame increment
  const Vec3 axis{R.m[2][1] - R.m[1][2], R.m[0][2] - R.m[2][0], R.m[1][0] - R.m[0][1]};
  const double two_sin = norm(axis);
  if (two_sin == 0.0) return {};  // no turn (or exactly half a turn: no shorter way)
  const double angle = std::atan2(0.5 * two_sin, 0.5 * (R.m[0][0] + R.m[1][1] + R.m[2][2] - 1.0));
  return (angle / (dt * two_sin)) * axis;
}

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

Timeline::Timeline(const SceneDescription& scene) : events_(scene.timeline) {
  for (const TimelineEvent& e : events_) {
    const int body = e.body.empty() ? -1 : scene.find_body(e.body);
    body_.push_back(body);
    fixed_.push_back(body >= 0 && scene.bodies[body].fixed ? 1 : 0);
  }
  state_.assign(events_.size(), kPending);
  ramp_start_scale_.assign(events_.size(), 1.0);
  ramp_start_field_.assign(events_.size(), Vec3{});
}

void Timeline::apply(double t, double dt, TimelineTarget& target) {
  for (size_t e = 0; e < events_.size(); ++e) {
    const TimelineEvent& ev = events_[e];
    const int body = body_[e];
    if (ev.kind == TimelineEvent::Kind::keyframes) {
      // Scripted motion: the body where the track says, with the velocity
      // that takes it to the next step's pose. A body that is not fixed is
      // kinematic while its track runs (held at the first key before it) and
      // dynamic again after the last key; a fixed body stays at the last key.
      const bool on_track = fixed_[e] || t + 0.5 * dt < ev.keys.back().time;
      const BodyPose now = keyframe_pose(ev.keys, t);
      const BodyPose next = keyframe_pose(ev.keys, t + dt);
      target.follow_track(body, on_track, now, (1.0 / dt) * (next.position - now.position),
                          angular_velocity_between(now.rotation, next.rotation, dt));
      continue;
    }
    if (t + 0.5 * dt < ev.time || state_[e] == kDone) continue;  // not due, or over
    const bool first = state_[e] == kPending;
    state_[e] = kRunning;
    const double span = ev.end_time - ev.time;
    const double u = span > 0.0 ? std::clamp((t - ev.time) / span, 0.0, 1.0) : 1.0;
    if (u >= 1.0) state_[e] = kDone;  // this application is the last
    switch (ev.kind) {
      case TimelineEvent::Kind::add_body:
        target.set_present(body, true);
        break;
      case TimelineEvent::Kind::remove_body:
        target.set_present(body, false);
        break;
      case TimelineEvent::Kind::mutual_induction:
        target.set_mutual_induction(ev.enabled);
        break;
      case TimelineEvent::Kind::scale_magnetization:
        if (first) ramp_start_scale_[e] = target.magnetization_scale(body);
        target.set_magnetization_scale(body, ramp_start_scale_[e] + u * (ev.value - ramp_start_scale_[e]));
        break;
      case TimelineEvent::Kind::external_field:
        if (first) ramp_start_field_[e] = target.external_field();
        target.set_external_field(ramp_start_field_[e] + u * (ev.field - ramp_start_field_[e]));
        break;
      case TimelineEvent::Kind::keyframes:
        break;
    }
  }
}

}  // namespace odemag
