#include "odemag/shape.h"

#include <algorithm>
#include <cmath>

#include "magnetics/cells/cells.h"
#include "magnetics/cells/compound.h"
#include "magnetics/cells/mesh.h"
#include "odemag/constants.h"

namespace odemag {

namespace {
bool positive(double v) { return std::isfinite(v) && v > 0.0; }
}  // namespace

double shape_volume(const Shape& shape) {
  return std::visit(Overloaded{
                        [](const Sphere& s) { return 4.0 / 3.0 * kPi * s.radius * s.radius * s.radius; },
                        [](const Box& b) { return b.size.x * b.size.y * b.size.z; },
                        [](const Cylinder& c) { return kPi * c.radius * c.radius * c.length; },
                        [](const Mesh& m) { return mesh_mass_integrals(m).volume; },
                        [](const Compound& c) { return compound_mass_integrals(c).volume; },
                    },
                    shape);
}

Mat3 shape_unit_inertia(const Shape& shape) {
  auto diagonal = [](double a, double b, double c) {
    Mat3 j;
    j.m[0][0] = a, j.m[1][1] = b, j.m[2][2] = c;
    return j;
  };
  const double v = shape_volume(shape);
  return std::visit(
      Overloaded{
          [&](const Sphere& s) {
            const double i = 0.4 * v * s.radius * s.radius;
            return diagonal(i, i, i);
          },
          [&](const Box& b) {
            const Vec3 e = b.size;
            return diagonal(v * (e.y * e.y + e.z * e.z) / 12.0, v * (e.x * e.x + e.z * e.z) / 12.0,
                            v * (e.x * e.x + e.y * e.y) / 12.0);
          },
          [&](const Cylinder& c) {
            const double r2 = c.radius * c.radius, side = v * (3.0 * r2 + c.length * c.length) / 12.0;
            return diagonal(side, side, 0.5 * v * r2);
          },
          [](const Mesh& m) { return inertia_from_second_moments(mesh_mass_integrals(m).second); },
          [](const Compound& c) { return inertia_from_second_moments(compound_mass_integrals(c).second); },
      },
      shape);
}

Vec3 shape_half_extents(const Shape& shape) {
  return std::visit(Overloaded{
                        [](const Sphere& s) { return Vec3{s.radius, s.radius, s.radius}; },
                        [](const Box& b) { return 0.5 * b.size; },
                        [](const Cylinder& c) { return Vec3{c.radius, c.radius, 0.5 * c.length}; },
                        [](const Mesh& m) {
                          const MeshData::Index& ix = mesh_index(m);
                          return Vec3{std::max(-ix.lo.x, ix.hi.x), std::max(-ix.lo.y, ix.hi.y),
                                      std::max(-ix.lo.z, ix.hi.z)};
                        },
                        [](const Compound& c) { return compound_half_extents(c); },
                    },
                    shape);
}

bool shape_contains(const Shape& shape, const Vec3& p, double tol) {
  return std::visit(
      Overloaded{
          [&](const Sphere& s) { return norm(p) <= s.radius + tol; },
          [&](const Box& b) {
            return std::abs(p.x) <= 0.5 * b.size.x + tol && std::abs(p.y) <= 0.5 * b.size.y + tol &&
                   std::abs(p.z) <= 0.5 * b.size.z + tol;
          },
          [&](const Cylinder& c) {
            return std::hypot(p.x, p.y) <= c.radius + tol && std::abs(p.z) <= 0.5 * c.length + tol;
          },
          [&](const Mesh& m) {
            return mesh_winding(m, p) != 0 || (tol > 0.0 && mesh_surface_distance(m, p, tol) < tol);
          },
          [&](const Compound& c) { return compound_contains(c, p, tol); },
      },
      shape);
}

Vec3 closest_point_in_shape(const Shape& shape, const Vec3& p) {
  return std::visit(Overloaded{
                        [&](const Sphere& s) {
                          const double r = norm(p);
                          return r <= s.radius ? p : (s.radius / r) * p;
                        },
                        [&](const Box& b) {
                          const Vec3 e = 0.5 * b.size;
                          return Vec3{std::clamp(p.x, -e.x, e.x), std::clamp(p.y, -e.y, e.y),
                                      std::clamp(p.z, -e.z, e.z)};
                        },
                        [&](const Cylinder& c) {
                          const double rho = std::hypot(p.x, p.y), s = rho <= c.radius ? 1.0 : c.radius / rho;
                          return Vec3{s * p.x, s * p.y, std::clamp(p.z, -0.5 * c.length, 0.5 * c.length)};
                        },
                        [&](const Mesh& m) { return mesh_winding(m, p) != 0 ? p : mesh_closest_point(m, p); },
                        [&](const Compound& c) { return compound_closest_point(c, p); },
                    },
                    shape);
}

std::string validate_shape(const Shape& shape) {
  return std::visit(Overloaded{
                        [](const Sphere& s) -> std::string {
                          return positive(s.radius) ? "" : "sphere radius must be finite and > 0";
                        },
                        [](const Box& b) -> std::string {
                          return positive(b.size.x) && positive(b.size.y) && positive(b.size.z)
                                     ? ""
                                     : "box edge lengths must be finite and > 0";
                        },
                        [](const Cylinder& c) -> std::string {
                          if (!positive(c.radius)) return "cylinder radius must be finite and > 0";
                          if (!positive(c.length)) return "cylinder length must be finite and > 0";
                          return "";
                        },
                        [](const Mesh& m) { return validate_mesh(m); },
                        [](const Compound& c) { return validate_compound(c); },
                    },
                    shape);
}

const char* shape_kind(const Shape& shape) {
  return std::visit(Overloaded{[](const Sphere&) { return "sphere"; },
                               [](const Box&) { return "box"; },
                               [](const Cylinder&) { return "cylinder"; },
                               [](const Mesh&) { return "mesh"; },
                               [](const Compound&) { return "compound"; }},
                    shape);
}

}  // namespace odemag
