// Triangle meshes from files (docs/scene-format.md "Meshes"): STL (ASCII
// and binary), OBJ, PLY and the other formats Assimp reads.
#pragma once

#include <array>
#include <cstddef>
#include <stdexcept>
#include <string>
#include <vector>

#include "odemag/vec3.h"

namespace odemag {

// A mesh file that cannot be used: missing, unreadable, of an unknown
// format, truncated or malformed, or over kMaxMeshTriangles. what() is one
// line that names the file.
class MeshFileError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

struct MeshFileContent {
  std::vector<Vec3> vertices;  // as in the file (no scale)
  std::vector<std::array<int, 3>> triangles;
};

// The largest mesh accepted, in triangles: its cells' shares and its checks
// take about kMeshSecondsPerTriangle each (benchmarks/results/mesh_body.md).
inline constexpr size_t kMaxMeshTriangles = 2'000'000;
inline constexpr double kMeshSecondsPerTriangle = 4e-6;

// "N triangles, more than the M accepted: loading and checking it would take
// about T s and B MB": the refusal of a mesh over kMaxMeshTriangles.
std::string mesh_size_refusal(size_t triangles);

// The triangles of every mesh in the file, with the nodes' transforms
// applied, polygons split into triangles, and vertices at the same position
// joined into one (so that closedness can be checked).
MeshFileContent read_mesh_file(const std::string& path);

// Vertices at exactly the same position joined into one; triangles that then
// repeat a vertex are kept (validate_mesh reports them).
void join_identical_vertices(MeshFileContent& mesh);

}  // namespace odemag
