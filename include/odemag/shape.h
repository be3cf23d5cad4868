// Body shapes, centred on the body's centre of mass (body frame).
#pragma once

#include <string>
#include <variant>

#include "odemag/vec3.h"

namespace odemag {

struct Sphere {
  double radius = 0.0;
};
// Full edge lengths along the body x, y, z axes.
struct Box {
  Vec3 size;
};
// Axis along the body z axis.
struct Cylinder {
  double radius = 0.0;
  double length = 0.0;
};

using Shape = std::variant<Sphere, Box, Cylinder>;

// One lambda per shape for std::visit: std::visit(Overloaded{[](const Sphere&)
// {...}, [](const Box&) {...}, [](const Cylinder&) {...}}, shape).
template <class... Ts>
struct Overloaded : Ts... {
  using Ts::operator()...;
};
template <class... Ts>
Overloaded(Ts...) -> Overloaded<Ts...>;

double shape_volume(const Shape& shape);
// Half extents of the axis-aligned bounding box in the body frame.
Vec3 shape_half_extents(const Shape& shape);
// True when the body-frame point lies inside the shape (boundary included up to tol).
bool shape_contains(const Shape& shape, const Vec3& local, double tol = 0.0);
// The point of the shape (boundary included) nearest the body-frame point p:
// p itself when inside.
Vec3 closest_point_in_shape(const Shape& shape, const Vec3& p);
// Empty when valid, else a message naming the offending key.
std::string validate_shape(const Shape& shape);
const char* shape_kind(const Shape& shape);

}  // namespace odemag
