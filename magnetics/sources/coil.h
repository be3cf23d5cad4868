// Current sources (coils), the computations behind include/odemag/coil.h:
// the field of each kind of source, posed sources, current elements, the
// force and torque that a field exerts on a source, and the elliptic
// integrals they use (docs/model.md "Current sources (coils)").
#pragma once

#include <functional>
#include <string>
#include <variant>
#include <vector>

#include "odemag/coil.h"
#include "odemag/vec3.h"

namespace odemag {

// The orthonormal frame of a source (e1, e2, e3 = e3 x e1): e3 along `axis`;
// e1 along the part of `first` normal to it (a rounded rectangle's
// width_direction: its u, v, w), or a fixed choice normal to the axis.
struct CoilFrame {
  Vec3 e1, e2, e3;
};
CoilFrame frame_from_axis(const Vec3& axis);
CoilFrame frame_from_axis_and(const Vec3& axis, const Vec3& first);

// Field H (A/m) of a source at a point (same frame); B = mu0 H in vacuum.
Vec3 coil_field_H(const CircularLoop& loop, const Vec3& point);
Vec3 coil_field_H(const StraightSegment& segment, const Vec3& point);
Vec3 coil_field_H(const Arc& arc, const Vec3& point);
Vec3 coil_field_H(const Solenoid& solenoid, const Vec3& point);
Vec3 coil_field_H(const CircularCoil& coil, const Vec3& point);
Vec3 coil_field_H(const RoundedRectangleCoil& coil, const Vec3& point);
Vec3 coil_field_H(const std::vector<CoilSource>& sources, const Vec3& point);

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
