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
// On a conductor. The field of a filament (loop, segment, arc, the edge rings
// of a solenoid sheet) diverges at the wire; at points closer to the wire than
// kOnConductor times the source's size (radius, or segment length) the field
// is returned as 0, the mean of the singular azimuthal field over a small
// circle around the wire. On a solenoid sheet itself the field is the mean of
// its two sides. Finite-section coils are finite everywhere, also inside the
// copper.
#pragma once

#include <functional>
#include <string>
#include <variant>
#include <vector>

#include "odemag/vec3.h"

namespace odemag {

// Distance from a filament, relative to its size, below which its field is 0.
inline constexpr double kOnConductor = 1e-10;

// A circular filament of radius `radius` about `centre`, in the plane normal to `axis`.
struct CircularLoop {
  Vec3 centre;
  Vec3 axis{0.0, 0.0, 1.0};
  double radius = 0.0;   // m
  double current = 0.0;  // A
  double turns = 1.0;
};

// A straight filament; positive current flows from a to b.
struct StraightSegment {
  Vec3 a, b;
  double current = 0.0;
  double turns = 1.0;
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

// The orthonormal frame of a source (e1, e2, e3 = e3 x e1): e3 along `axis`;
// e1 along the part of `first` normal to it (a rounded rectangle's
// width_direction: its u, v, w), or a fixed choice normal to the axis.
struct CoilFrame {
  Vec3 e1, e2, e3;
};
CoilFrame frame_from_axis(const Vec3& axis);
CoilFrame frame_from_axis_and(const Vec3& axis, const Vec3& first);

// Why a source is not a valid geometry ("" when it is): non-positive radius,
// zero axis, inner radius above outer, quadrature order outside 1..64, ...
std::string coil_source_error(const CoilSource& source);

// N I of a source (A).
double ampere_turns(const CoilSource& source);

// Field H (A/m) of a source at a point (same frame); B = mu0 H in vacuum.
Vec3 coil_field_H(const CircularLoop& loop, const Vec3& point);
Vec3 coil_field_H(const StraightSegment& segment, const Vec3& point);
Vec3 coil_field_H(const Arc& arc, const Vec3& point);
Vec3 coil_field_H(const Solenoid& solenoid, const Vec3& point);
Vec3 coil_field_H(const CircularCoil& coil, const Vec3& point);
Vec3 coil_field_H(const RoundedRectangleCoil& coil, const Vec3& point);
Vec3 coil_field_H(const CoilSource& source, const Vec3& point);
Vec3 coil_field_H(const std::vector<CoilSource>& sources, const Vec3& point);
Vec3 coil_field_B(const CoilSource& source, const Vec3& point);  // mu0 H, T

// A source given in a body frame, evaluated at a world point: H_world =
// R H_body(R^T (x - position)).
Vec3 coil_field_H(const CoilSource& source, const Mat3& rotation, const Vec3& position, const Vec3& world_point);
// The source moved from the body frame to the world frame.
CoilSource transformed(const CoilSource& source, const Mat3& rotation, const Vec3& position);

// The current distribution as weighted current elements: the source's
// J dV (or I dl) lumped at quadrature points; sum of moment = 0 for closed
// sources. What a force, a torque or a mutual inductance is integrated over.
struct CurrentElement {
  Vec3 position;  // m
  Vec3 moment;    // current element I dl (A m)
};

// Quadrature orders of current_elements (docs/model.md "Current sources (coils)").
struct ElementOptions {
  // Full circles (loops, solenoids, circular coils): equally spaced angles
  // (the trapezoidal rule, exponentially convergent for periodic integrands).
  int per_turn = 64;
  // Gauss-Legendre points along each segment, arc, straight side or corner.
  int along = 16;
  // Gauss-Legendre points across a winding, per direction (radius, length).
  int across = 4;
};

std::vector<CurrentElement> current_elements(const CoilSource& source, const ElementOptions& options = {});

// Force (N) on a source in an external field B(x) (T), F = sum I dl x B, and
// torque (N m) about `about`, sum (x - about) x (I dl x B).
struct Wrench {
  Vec3 force;
  Vec3 torque;
};
Wrench coil_wrench(const CoilSource& source, const std::function<Vec3(const Vec3&)>& field_B, const Vec3& about,
                   const ElementOptions& options = {});
Wrench coil_wrench(const std::vector<CurrentElement>& elements, const std::function<Vec3(const Vec3&)>& field_B,
                   const Vec3& about);

// Magnetic dipole moment (A m^2) of the source about the origin of its frame,
// m = 1/2 integral x x J dV (closed sources: independent of the origin; a loop:
// N I pi R^2 along axis).
Vec3 dipole_moment(const CoilSource& source, const ElementOptions& options = {});

// Special functions used above, double precision.
// Complete elliptic integrals of the first and second kind, modulus k (|k| < 1),
// by the arithmetic-geometric mean.
double elliptic_K(double k);
double elliptic_E(double k);
// Bulirsch's general complete elliptic integral
// cel(kc, p, a, b) = int_0^{pi/2} (a cos^2 t + b sin^2 t) / ((cos^2 t + p sin^2 t) sqrt(cos^2 t + kc^2 sin^2 t)) dt,
// kc != 0 (p <= 0: the Cauchy principal value).
double bulirsch_cel(double kc, double p, double a, double b);
// Carlson's symmetric elliptic integrals R_F(x, y, z) and R_D(x, y, z)
// (at most one of x, y zero; z > 0 for R_D), by duplication.
double carlson_RF(double x, double y, double z);
double carlson_RD(double x, double y, double z);

}  // namespace odemag
