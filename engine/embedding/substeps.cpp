#include "engine/embedding/substeps.h"

#include <algorithm>
#include <cmath>
#include <variant>

#include "odemag/constants.h"

namespace odemag {
namespace {
// Largest travel in one substep, in units of the body's size (smallest half
// extent): in free flight, and for a body that touched something.
constexpr double kFreeTravel = 0.1;
constexpr double kContactTravel = 0.3;
}  // namespace

SubstepBody substep_body(const MagneticBody& body, const dMass& mass) {
  SubstepBody s;
  const Vec3 half = shape_half_extents(body.shape);
  s.size = std::min({half.x, half.y, half.z});
  // A sphere's surface does not move when it turns about its centre.
  s.reach = std::holds_alternative<Sphere>(body.shape) ? 0.0 : norm(half);
  s.inertia = std::min({mass.I[0], mass.I[5], mass.I[10]});
  s.turns_in_field = !body.inert() && !(body.kind == CellKind::soft && body.cell_count() == 1 && body.soft.H_K == 0.0);
  return s;
}

double SubstepRule::longest_substep(int b, double shortest, const SubstepMotion& s, double gravity,
                                    double external_field, const std::function<double(int)>& clearance) const {
  if (!s.free) return shortest;
  const double f = norm(s.force), m = s.mass, size = bodies_[b].size;
  const double reach = bodies_[b].reach, inertia = bodies_[b].inertia;
  // Rotational stiffness: |tau| for the torque of the other bodies (it
  // turns a body about an orientation of equilibrium), and mu0 |m| |H_E|
  // for the uniform field, whose torque vanishes at equilibrium while its
  // stiffness does not (docs/hard-cases.md "Substeps").
  double k_rot = norm(s.torque);
  if (bodies_[b].turns_in_field) k_rot += kMu0 * norm(s.moment) * external_field;
  // Collision: the travel v h + a h^2 / 2 in one substep of the body's
  // farthest point, at the current velocity (translation plus rotation
  // times the bounding radius) and the full acceleration (gravity, magnetic
  // force, and the angular acceleration times the bounding radius), at most
  // L: a tenth of the body's size, three tenths for a body that was in
  // contact (which most likely still holds it; it may have lifted off by a
  // hair, so its acceleration still counts). Solved for h. The contact
  // allowance is for what the contact holds back (the acceleration): the
  // velocity's own travel v h stays within a tenth of the size, or a body
  // that moves fast while touching another (two lattice magnets started at
  // one centre spin apart) meets the floor up to 0.3 of its size deep
  // (docs/hard-cases.md "Substeps").
  const double v = norm(s.velocity) + norm(s.angular_velocity) * reach;
  const double a = f / m + gravity + (inertia > 0.0 ? norm(s.torque) / inertia * reach : 0.0);
  double L = (s.in_contact ? kContactTravel : kFreeTravel) * size;
  auto travel_time = [&] { return 2.0 * L / (v + std::sqrt(v * v + 2.0 * a * L)); };
  // In free flight, half the clearance as well: nothing is nearer, and a
  // body that comes the other way covers at most the other half (a ball
  // falling from the crane needs no substeps until it nears the heap).
  // Not while the magnetic force exceeds the body's weight: it grows
  // steeply as the body nears a magnet, which the constant acceleration of
  // the bound does not see (a ball dropped onto a magnet sank 0.34 of its
  // size into it with the clearance counted at any force).
  if (!s.in_contact && clearance && f <= m * gravity && travel_time() < shortest) L += 0.5 * clearance(b);
  shortest = std::min(shortest, travel_time());
  if (s.in_contact && v > 0.0) shortest = std::min(shortest, kFreeTravel * size / v);
  // Time scale of the magnetic force: it varies over distances of the
  // body's size, so it oscillates a body about an equilibrium at
  // omega^2 ~ |F| / (m size); and the torque about an orientation at
  // omega^2 ~ k_rot / I. The explicit update needs omega h <= limit.
  if (f > 0.0) shortest = std::min(shortest, settings_.stiffness_limit / std::sqrt(f / (m * size)));
  if (k_rot > 0.0 && inertia > 0.0)
    shortest = std::min(shortest, settings_.stiffness_limit / std::sqrt(k_rot / inertia));
  return shortest;
}

namespace {
int substeps_for(double dt, double longest) {
  const double k = std::ceil(dt / longest * (1.0 - 1e-12));
  return std::isfinite(k) ? std::max(1, static_cast<int>(std::min(k, 1e9))) : 1000000000;
}
}  // namespace

int SubstepRule::needed(double dt, const std::vector<SubstepMotion>& motion, double gravity, double external_field,
                        const std::function<double(int)>& clearance) const {
  double shortest = dt;  // longest admissible substep
  for (int b = 0; b < body_count(); ++b)
    shortest = longest_substep(b, shortest, motion[b], gravity, external_field, clearance);
  return substeps_for(dt, shortest);
}

int SubstepRule::needed_by(int b, double dt, const SubstepMotion& motion, double gravity, double external_field,
                           const std::function<double(int)>& clearance) const {
  return substeps_for(dt, longest_substep(b, dt, motion, gravity, external_field, clearance));
}

double SubstepRule::hold_time(double dt) const {
  return 2.0 * kPi * dt / std::max(settings_.stiffness_limit, 1e-9);
}

int SubstepRule::update(int wanted, double time, double dt, bool step_start) {
  // The count rises at once when needed but falls only at the start of a
  // step, after a lower count has sufficed for a while, to the largest count
  // needed meanwhile. A count that follows the phase of an oscillation (|v|,
  // |F| and |tau| all vary along it) makes the integration non-symplectic
  // and pumps energy into the oscillation (docs/hard-cases.md: a magnet
  // swinging in a uniform field of 1e5 A/m gained 21 times its swing energy
  // in 2 s). The hold is one period of the slowest oscillation whose
  // stiffness alone asks for more than one substep, 2 pi dt / stiffness_limit.
  const double hold = hold_time(dt);
  const int needed = std::min(wanted, std::max(1, settings_.max_substeps));
  if (needed >= count_) {
    count_ = needed;
    window_max_ = 1;
    set_time_ = time;
  } else {
    window_max_ = std::max(window_max_, needed);
    if (step_start && time - set_time_ >= hold * (1.0 - 1e-9)) {
      count_ = window_max_;
      window_max_ = 1;
      set_time_ = time;
    }
  }
  return count_;
}

}  // namespace odemag
