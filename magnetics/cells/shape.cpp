#include "odemag/shape.h"

#include <algorithm>
#include <cmath>

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
                    },
                    shape);
}

Vec3 shape_half_extents(const Shape& shape) {
  return std::visit(Overloaded{
                        [](const Sphere& s) { return Vec3{s.radius, s.radius, s.radius}; },
                        [](const Box& b) { return 0.5 * b.size; },
                        [](const Cylinder& c) { return Vec3{c.radius, c.radius, 0.5 * c.length}; },
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
                    },
                    shape);
}

const char* shape_kind(const Shape& shape) {
  return std::visit(Overloaded{[](const Sphere&) { return "sphere"; },
                               [](const Box&) { return "box"; },
                               [](const Cylinder&) { return "cylinder"; }},
                    shape);
}

}  // namespace odemag
