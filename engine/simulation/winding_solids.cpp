#include "engine/simulation/winding_solids.h"

#include <algorithm>
#include <cmath>
#include <type_traits>
#include <variant>

#include "odemag/constants.h"

namespace odemag {
namespace {

Mat3 from_columns(const Vec3& x, const Vec3& y, const Vec3& z) {
  Mat3 m;
  for (int i = 0; i < 3; ++i) {
    m.m[i][0] = x[i];
    m.m[i][1] = y[i];
    m.m[i][2] = z[i];
  }
  return m;
}

CollisionSolid box(const Vec3& centre, const Mat3& axes, const Vec3& size) {
  return {CollisionSolid::Kind::box, centre, axes, size};
}

// A capsule of `radius` about the segment p0 p1.
CollisionSolid capsule(const Vec3& p0, const Vec3& p1, double radius) {
  const CoilFrame f = frame_from_axis(p1 - p0);
  return {CollisionSolid::Kind::capsule, 0.5 * (p0 + p1), from_columns(f.e1, f.e2, f.e3),
          {radius, radius, norm(p1 - p0)}};
}

// Boxes that cover the annular sector r_in <= r <= r_out, theta0 <= theta <=
// theta1 about `centre` in the plane of u and v (theta from u towards v),
// |w| <= height / 2: per box of half angle delta, along its mid direction
// from r_in cos(delta) to r_out, across +-r_out sin(delta).
void add_sector_boxes(const Vec3& centre, const Vec3& u, const Vec3& v, const Vec3& w, double r_in,
                      double r_out, double theta0, double theta1, double height,
                      std::vector<CollisionSolid>& out) {
  const double sector = 2.0 * kPi / kWindingSectorsPerTurn;
  const int n = static_cast<int>(std::ceil((theta1 - theta0) / sector - 1e-9));
  const double delta = 0.5 * (theta1 - theta0) / n;
  const double inner = r_in * std::cos(delta);
  for (int k = 0; k < n; ++k) {
    const double theta = theta0 + (2 * k + 1) * delta;
    const Vec3 radial = std::cos(theta) * u + std::sin(theta) * v;
    const Vec3 across = -std::sin(theta) * u + std::cos(theta) * v;
    out.push_back(box(centre + (0.5 * (inner + r_out)) * radial, from_columns(radial, across, w),
                      {r_out - inner, 2.0 * r_out * std::sin(delta), height}));
  }
}

// Capsules of radius `wire` (widened by the chords' sagitta) along the arc
// of radius r about `centre` in the plane of u and v, from theta0 through
// `angle` (either sign); angle 2 pi: a loop. kMaxWireCapsulesPerTurn.
void add_wire_arc(const Vec3& centre, const Vec3& u, const Vec3& v, double r, double theta0, double angle,
                  double wire, std::vector<CollisionSolid>& out) {
  const double per_turn = std::clamp(std::ceil(kPi / std::acos(std::max(-1.0, 1.0 - wire / (4.0 * r)))), 24.0,
                                     static_cast<double>(kMaxWireCapsulesPerTurn));
  const int n = std::max(1, static_cast<int>(std::ceil(per_turn * std::abs(angle) / (2.0 * kPi) - 1e-9)));
  const double step = angle / n, radius = wire + r * (1.0 - std::cos(0.5 * std::abs(step)));
  for (int k = 0; k < n; ++k) {
    const double t0 = theta0 + k * step, t1 = t0 + step;
    const Vec3 p0 = centre + r * (std::cos(t0) * u + std::sin(t0) * v);
    const Vec3 p1 = centre + r * (std::cos(t1) * u + std::sin(t1) * v);
    out.push_back(capsule(p0, p1, radius));
  }
}

}  // namespace

std::vector<CollisionSolid> winding_solids(const CoilSource& coil) {
  std::vector<CollisionSolid> out;
  std::visit(
      [&](const auto& c) {
        using T = std::decay_t<decltype(c)>;
        if constexpr (std::is_same_v<T, CircularCoil>) {
          const CoilFrame f = frame_from_axis(c.axis);
          const Vec3 &u = f.e1, &v = f.e2, &w = f.e3;
          if (c.inner_radius == 0.0) {
            out.push_back({CollisionSolid::Kind::cylinder,
                           c.centre,
                           from_columns(u, v, w),
                           {c.outer_radius, c.outer_radius, c.length}});
          } else {
            add_sector_boxes(c.centre, u, v, w, c.inner_radius, c.outer_radius, 0.0, 2.0 * kPi,
                             c.length, out);
          }
        } else if constexpr (std::is_same_v<T, CircularLoop>) {
          const CoilFrame f = frame_from_axis(c.axis);
          add_wire_arc(c.centre, f.e1, f.e2, c.radius, 0.0, 2.0 * kPi, filament_wire_radius(c), out);
        } else if constexpr (std::is_same_v<T, Arc>) {
          // Arc's frame (magnetics/sources/coil.cpp): e1 along start, turning about axis.
          const CoilFrame f = frame_from_axis_and(c.axis, c.start);
          add_wire_arc(c.centre, f.e1, f.e2, c.radius, 0.0, c.angle, filament_wire_radius(c), out);
        } else if constexpr (std::is_same_v<T, StraightSegment>) {
          out.push_back(capsule(c.a, c.b, filament_wire_radius(c)));
        } else if constexpr (std::is_same_v<T, RoundedRectangleCoil>) {
          // The coil's own frame (magnetics/sources/coil.h): u along width_direction, w along the axis.
          const CoilFrame f = frame_from_axis_and(c.axis, c.width_direction);
          const Vec3 &u = f.e1, &v = f.e2, &w = f.e3;
          const Mat3 axes = from_columns(u, v, w);
          const double a = c.core_half_width, b = c.core_half_depth,
                       build = c.outer_corner_radius - c.inner_corner_radius;
          const double mid = 0.5 * (c.inner_corner_radius + c.outer_corner_radius);
          for (double s : {-1.0, 1.0}) {
            out.push_back(box(c.centre + (s * (a + mid)) * u, axes, {build, 2.0 * b, c.height}));
            out.push_back(box(c.centre + (s * (b + mid)) * v, axes, {2.0 * a, build, c.height}));
          }
          // The quarter-round corners about the core rectangle's corners, counter-clockwise from
          // (+a, +b).
          const double cu[4] = {1, -1, -1, 1}, cv[4] = {1, 1, -1, -1};
          for (int k = 0; k < 4; ++k)
            add_sector_boxes(c.centre + (cu[k] * a) * u + (cv[k] * b) * v, u, v, w,
                             c.inner_corner_radius, c.outer_corner_radius, 0.5 * kPi * k,
                             0.5 * kPi * (k + 1), c.height, out);
        }
      },
      coil);
  return out;
}

}  // namespace odemag
