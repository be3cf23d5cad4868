// The time line of a scene (docs/scene-format.md "timeline"): its events
// applied at a time, to the rigid world and magnetics of a run
// (Simulation) or to the magnetic system that `odemag solve` and
// `odemag field` relax at t = 0, through one applier.
#pragma once

#include <vector>

#include "odemag/scene.h"
#include "magnetics/model/state.h"

namespace odemag {

// What the time line acts on. Body indices are scene body indices.
class TimelineTarget {
 public:
  virtual ~TimelineTarget() = default;
  // add / remove: the body is present (collides, makes and feels fields) or not.
  virtual void set_present(int body, bool present) = 0;
  virtual double magnetization_scale(int body) const = 0;
  virtual void set_magnetization_scale(int body, double scale) = 0;
  virtual Vec3 external_field() const = 0;
  virtual void set_external_field(const Vec3& H) = 0;
  virtual void set_mutual_induction(bool enabled) = 0;
  // A keyframed body: on its track, at `pose`, moving with the velocities
  // that take it to the track's pose one step later; or (on_track false) a
  // body that is not fixed, released after its last key (dynamic again,
  // with the velocity it was last given: a hand that lets go).
  virtual void follow_track(int body, bool on_track, const BodyPose& pose, const Vec3& velocity,
                            const Vec3& angular_velocity) = 0;
};

class Timeline {
 public:
  explicit Timeline(const SceneDescription& scene);

  // Applies what is due at time t (s) of a run with steps of dt: every event
  // whose time lies within half a step of t or before and is not over, a
  // ramp at its share (t - time) / (end_time - time), clamped to [0, 1],
  // of the way from the value it found when it began; every keyframe track
  // at t. Call it at t = 0 and at the start of every step; at the same time
  // twice it changes nothing.
  void apply(double t, double dt, TimelineTarget& target);

 private:
  std::vector<TimelineEvent> events_;
  std::vector<int> body_;       // per event: scene body index, -1 for none
  std::vector<char> fixed_;     // per event: its body is fixed (stays on its track)
  // Per event: pending, running (a ramp), done. Ramps start from the value
  // the quantity had when the event began.
  enum EventState : char { kPending, kRunning, kDone };
  std::vector<char> state_;
  std::vector<double> ramp_start_scale_;
  std::vector<Vec3> ramp_start_field_;
};

// Pose on a keyframe track at time t: positions linearly interpolated,
// orientations by spherical linear interpolation; held before the first and
// after the last key.
BodyPose keyframe_pose(const std::vector<Keyframe>& keys, double t);

// Angular velocity that turns rotation A into rotation B in time dt, the
// shorter way.
Vec3 angular_velocity_between(const Mat3& A, const Mat3& B, double dt);

}  // namespace odemag
