// Current sources (coils): the magnetic field of conductors carrying a steady
// current, and the force and torque that an external field exerts on them
// (docs/model.md "Current sources (coils)").
//
// Conventions. SI units. Every source carries `current` (A) in each of its
// `turns` conductors; only the ampere-turns N I enter the field and the force.
// Positive current circulates counter-clockwise about `axis` (right-handed),
// so that the field inside a loop points along +axis. Axes and directions need
// not be unit vectors (they are normalised here). A source's geometry is given
// in one frame (a body frame, say) and its field is evaluated at points of the
// same frame; the posed overloads take a body pose (rotation body -> world,
// position of the body frame's origin) and world points.
//
// Filaments have a wire. A loop, segment or arc stands for a round wire of
// radius `wire_radius` (0: kDefaultWireRadius times the loop's or arc's radius
// or the segment's length) carrying the current uniformly over its section.
// Off the wire the field is the filament's, exact; inside it (distance d from
// the wire's centre line below the wire radius a) it is the filament's times
// (d / a)^2, the fraction of the current within d: for a straight wire
// exactly the round conductor's H = N I d / (2 pi a^2), for loops and arcs the
// same near the wire, with the curvature's smaller part scaled too
// (docs/model.md "Current sources (coils)" gives the error against a thick
// ring). So the field is continuous at the wire's surface and bounded
// everywhere (at most about N I / (2 pi a)), and so is its gradient, which
// the force on a magnetic body takes. A scene's filaments collide as
// capsules of that radius (docs/simulation.md "Coil windings"). On a solenoid
// sheet itself the field is the mean of its two sides; at points closer to
// a sheet's edge ring than kOnConductor times its radius it is 0. Finite-section
// coils are finite everywhere, also inside the copper.
#pragma once

#include <string>
#include <variant>

#include "odemag/vec3.h"

namespace odemag {

// Distance from a solenoid sheet's edge ring, relative to its radius, below
// which its field is 0.
inline constexpr double kOnConductor = 1e-10;

// A filament's wire radius when its wire_radius is 0, relative to the loop's
// or arc's radius or the segment's length.
inline constexpr double kDefaultWireRadius = 0.01;

// A circular filament of radius `radius` about `centre`, in the plane normal to `axis`.
struct CircularLoop {
  Vec3 centre;
  Vec3 axis{0.0, 0.0, 1.0};
  double radius = 0.0;   // m
  double current = 0.0;  // A
  double turns = 1.0;
  double wire_radius = 0.0;  // m; 0: kDefaultWireRadius * radius
};

// A straight filament; positive current flows from a to b.
struct StraightSegment {
  Vec3 a, b;
  double current = 0.0;
  double turns = 1.0;
  double wire_radius = 0.0;  // m; 0: kDefaultWireRadius * |b - a|
};

// A circular arc: from centre + radius * start (start projected onto the
// plane normal to axis), `angle` radians about axis (right-handed; negative:
// the other way round). Current flows from the start along the arc.
struct Arc {
  Vec3 centre;
  Vec3 axis{0.0, 0.0, 1.0};
  double radius = 0.0;
  Vec3 start{1.0, 0.0, 0.0};
  double angle = 0.0;  // rad, any value (|angle| > 2 pi winds more than once)
  double current = 0.0;
  double turns = 1.0;
  double wire_radius = 0.0;  // m; 0: kDefaultWireRadius * radius
};

// A thin cylindrical current sheet (an ideal solenoid): `turns` turns spread
// uniformly over `length` along axis, centred on `centre`; surface current
// density K = turns * current / length.
struct Solenoid {
  Vec3 centre;
  Vec3 axis{0.0, 0.0, 1.0};
  double radius = 0.0;
  double length = 0.0;  // 0: a circular loop
  double current = 0.0;
  double turns = 1.0;
};

// A circular coil of rectangular cross-section: inner_radius <= r <=
// outer_radius, |z| <= length / 2 about centre along axis, with uniform
// azimuthal current density J = turns * current / ((outer - inner) * length).
// Field: Gauss-Legendre quadrature over the radius of exact solenoid sheets,
// `quadrature_order` points per panel on panels graded towards the point.
struct CircularCoil {
  Vec3 centre;
  Vec3 axis{0.0, 0.0, 1.0};
  double inner_radius = 0.0;
  double outer_radius = 0.0;
  double length = 0.0;
  double current = 0.0;
  double turns = 1.0;
  int quadrature_order = 8;
};

// A rounded-rectangle coil of rectangular cross-section (the TEAM 20 coil):
// the points at distance inner_corner_radius..outer_corner_radius (in the
// plane normal to axis) from the core rectangle |u| <= core_half_width,
// |v| <= core_half_depth, and |w| <= height / 2, where u runs along
// width_direction (projected onto the plane), w along axis and v along
// axis x width_direction. Uniform current density J = turns * current /
// ((outer - inner) * height), counter-clockwise about axis. So the winding has
// outer sides 2 (core_half_width + outer_corner_radius) with corner radius
// outer_corner_radius and inner sides 2 (core_half_width +
// inner_corner_radius) with corner radius inner_corner_radius
// (inner_corner_radius = 0: sharp inner corners). The four straight sides are
// exact (current-carrying cuboids, closed form); the four corners are
// integrated along the axis in closed form and over (radius, angle) by
// Gauss-Legendre quadrature, `quadrature_order` squared points per panel on
// panels graded towards the point.
struct RoundedRectangleCoil {
  Vec3 centre;
  Vec3 axis{0.0, 0.0, 1.0};
  Vec3 width_direction{1.0, 0.0, 0.0};
  double core_half_width = 0.0;
  double core_half_depth = 0.0;
  double inner_corner_radius = 0.0;
  double outer_corner_radius = 0.0;
  double height = 0.0;
  double current = 0.0;
  double turns = 1.0;
  int quadrature_order = 8;
};

using CoilSource = std::variant<CircularLoop, StraightSegment, Arc, Solenoid, CircularCoil, RoundedRectangleCoil>;

// Why a source is not a valid geometry ("" when it is): non-positive radius,
// zero axis, inner radius above outer, quadrature order outside 1..64, ...
std::string coil_source_error(const CoilSource& source);

// N I of a source (A).
double ampere_turns(const CoilSource& source);

// The wire radius of a filament (loop, segment, arc: its wire_radius, or the
// default), m; 0 for the other sources.
double filament_wire_radius(const CoilSource& source);

// Field H (A/m) of a source at a point (same frame); B = mu0 H in vacuum.
Vec3 coil_field_H(const CoilSource& source, const Vec3& point);
Vec3 coil_field_B(const CoilSource& source, const Vec3& point);  // mu0 H, T

}  // namespace odemag
