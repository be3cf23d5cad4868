// Body shapes, centred on the body's centre of mass (body frame).
#pragma once

#include <array>
#include <memory>
#include <string>
#include <variant>
#include <vector>

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

// A closed triangle mesh (docs/model.md "Meshes"): vertices in the body
// frame (m), triangles as vertex indices, counter-clockwise seen from outside
// (outward normals). The body frame's origin is the mesh's centre of mass
// (mesh_centred moves a mesh there). Immutable: copies share the vertices,
// the triangles and the search grid the library builds on first use.
struct MeshData;  // the library's (magnetics/cells/mesh.h)
class Mesh {
 public:
  Mesh();
  Mesh(std::vector<Vec3> vertices, std::vector<std::array<int, 3>> triangles);
  const std::vector<Vec3>& vertices() const;
  const std::vector<std::array<int, 3>>& triangles() const;
  const MeshData& data() const { return *data_; }

 private:
  std::shared_ptr<const MeshData> data_;
};

// The mesh moved so that its centre of mass (uniform density) lies at the
// origin; offset (if not null) receives the centre of mass it had.
Mesh mesh_centred(const Mesh& mesh, Vec3* offset = nullptr);

// The shapes a compound is made of: primitives and meshes, no compounds.
using PartShape = std::variant<Sphere, Box, Cylinder, Mesh>;
// One part of a compound, placed in the compound's body frame.
struct CompoundPart {
  PartShape shape;
  Vec3 position;     // the part's origin in the body frame, m
  Mat3 orientation;  // part frame -> body frame
};
// One rigid body made of parts (docs/model.md "Compounds"): overlapping parts
// count once. The body frame's origin is the compound's centre of mass
// (compound_centred moves it there). Immutable, like Mesh: copies share the
// parts and what the library derives from them on first use.
struct CompoundData;  // the library's (magnetics/cells/compound.h)
class Compound {
 public:
  Compound();
  explicit Compound(std::vector<CompoundPart> parts);
  const std::vector<CompoundPart>& parts() const;
  const CompoundData& data() const { return *data_; }

 private:
  std::shared_ptr<const CompoundData> data_;
};

// The compound moved so that its centre of mass lies at the origin; offset
// (if not null) receives the centre of mass it had.
Compound compound_centred(const Compound& compound, Vec3* offset = nullptr);

using Shape = std::variant<Sphere, Box, Cylinder, Mesh, Compound>;

// One lambda per shape for std::visit: std::visit(Overloaded{[](const Sphere&)
// {...}, [](const Box&) {...}, [](const Cylinder&) {...}, [](const Mesh&)
// {...}, [](const Compound&) {...}}, shape).
template <class... Ts>
struct Overloaded : Ts... {
  using Ts::operator()...;
};
template <class... Ts>
Overloaded(Ts...) -> Overloaded<Ts...>;

// Volume, m^3 (a compound's: of the union of its parts).
double shape_volume(const Shape& shape);
// The inertia tensor of the shape at unit density about the body origin
// (kg m^2 per kg/m^3): exact polyhedron integrals for meshes.
Mat3 shape_unit_inertia(const Shape& shape);
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
