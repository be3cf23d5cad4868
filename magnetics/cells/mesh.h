// Closed triangle meshes as body shapes (docs/model.md "Meshes"): checks,
// exact polyhedron integrals, the inside test, the part of a lattice cube
// inside the mesh, and the field of the uniformly magnetized polyhedron.
#pragma once

#include <array>
#include <cstddef>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "odemag/shape.h"
#include "odemag/vec3.h"

namespace odemag {

// Volume and first moments (integrals of 1, x, y, z) of a region.
struct VolumeMoments {
  double v = 0.0, x = 0.0, y = 0.0, z = 0.0;
};

// Volume, centre of mass and second moments (integral of x x^T) of a solid of
// unit density.
struct MassIntegrals {
  double volume = 0.0;
  Vec3 centroid;
  Mat3 second;  // integral of x_i x_j dV about the origin, m^5
};

// The inertia tensor of unit density about the origin: tr(C) I - C.
Mat3 inertia_from_second_moments(const Mat3& second);

// A uniform grid over the mesh's bounding box whose bins list the triangles
// whose bounding boxes reach into them: the search structure of every query.
struct MeshGrid {
  Vec3 origin;                    // lower corner, m
  double bin = 0.0;               // bin edge, m
  std::array<int, 3> dims{1, 1, 1};
  std::vector<int> start;         // per bin, into items (dims product + 1)
  std::vector<int> items;         // triangle indices
  int bin_of(int axis, double x) const;
};

// Far-field summary of the triangles binned in one grid bin (by centroid):
// the area-weighted normal and its first moment about the bin's centroid
// (mesh_demag_tensor).
struct FaceCluster {
  Vec3 centre;       // area-weighted centroid of the cluster's triangles
  Vec3 area_normal;  // sum of A_f n_f
  Mat3 moment;       // sum of A_f (c_f - centre) n_f^T
  double radius = 0.0;
  std::vector<int> faces;
};

// Meshes of more triangles than this take the far field of clusters of
// triangles farther than kMeshClusterOpening cluster radii in
// mesh_demag_tensor (docs/model.md "Meshes").
inline constexpr size_t kMeshExactFieldTriangles = 5000;
inline constexpr double kMeshClusterOpening = 4.0;

struct MeshData {
  std::vector<Vec3> vertices;
  std::vector<std::array<int, 3>> triangles;
  // Built on first use (mesh_index); guarded by its own once flag.
  struct Index;
  mutable std::shared_ptr<Index> index;
  mutable std::once_flag index_once;
  // validate_mesh's answer, found once (the loader and the model both ask).
  mutable std::string check;
  mutable std::once_flag check_once;
};

struct MeshData::Index {
  MeshGrid grid;
  Vec3 lo, hi;                      // bounding box, m
  // Every query of the share of a cube moves the cube by this offset (a
  // fraction 1e-10 of the mesh's size, along no lattice direction), so that no
  // vertex, edge or face lies exactly on a lattice plane (docs/model.md "Meshes").
  Vec3 jitter;
  std::vector<FaceCluster> clusters;
};

const MeshData::Index& mesh_index(const Mesh& mesh);

// The checks a mesh must pass (docs/scene-format.md "Meshes"), in this order:
// at least 4 triangles, finite coordinates, indices in range, no triangle
// repeating a vertex, closed (every edge shared by exactly two triangles),
// consistently oriented (the two triangles of an edge traverse it in
// opposite directions), non-zero volume, no two triangles crossing. Empty
// when valid, else one message (found once per mesh). The sign of the
// volume is not checked: an inverted mesh (every triangle clockwise) is
// valid here and turned by mesh_outward.
std::string validate_mesh(const Mesh& mesh);

// Closed mesh whose triangles are all clockwise seen from outside (negative
// signed volume): returned with every triangle reversed; flipped (if not
// null) says whether it was.
Mesh mesh_outward(const Mesh& mesh, bool* flipped = nullptr);

// Exact integrals of the polyhedron (sums over the tetrahedra spanned by the
// origin and each triangle); signed: negative for an inverted mesh.
MassIntegrals mesh_mass_integrals(const Mesh& mesh);

// Winding number of the closed mesh about p (1 inside an outward mesh, 0
// outside), counted along the +x ray through the search grid; edges shared by
// two triangles are decided once, so a ray through an edge counts once.
int mesh_winding(const Mesh& mesh, const Vec3& p);

// Distance from p to the mesh's surface, or max_distance when no triangle
// comes within it.
double mesh_surface_distance(const Mesh& mesh, const Vec3& p, double max_distance);

// The point of the mesh's surface nearest p.
Vec3 mesh_closest_point(const Mesh& mesh, const Vec3& p);

// Volume and first moments of the box [lo, hi] inside the mesh, exact up to
// rounding (divergence theorem: the triangles clipped to the box, the box's
// far faces' areas inside the mesh from the section of the mesh in them, those
// faces' far edges' lengths inside from the crossings along them).
VolumeMoments mesh_box_moments(const Mesh& mesh, const Vec3& lo, const Vec3& hi);

// True when the box lies wholly inside the mesh: no triangle reaches into it
// and its centre is inside.
bool mesh_box_inside(const Mesh& mesh, const Vec3& lo, const Vec3& hi);

// The demagnetising tensor of the uniformly magnetized polyhedron at p (H =
// -N M; inside or outside; six components xx, xy, xz, yy, yz, zz) from its
// face charges sigma = M . n:
//   H(p) = (1/4pi) sum_f (M . n_f) I_f(p),  I_f(p) = int_f (p - x') / |p - x'|^3 dA'
// with I_f in closed form: its normal part the signed solid angle of the
// triangle (Van Oosterom and Strackee 1983), its in-plane part sum over the
// edges of the edge's outward in-plane normal times int_edge dl / |p - x'| =
// ln((R1 + R2 + L) / (R1 + R2 - L)). Clusters of triangles farther than 3
// cluster radii take the monopole and dipole terms of their charges.
void mesh_demag_tensor(const Mesh& mesh, const Vec3& p, double n[6]);

// A box (full edge lengths) as a closed outward mesh of 12 triangles.
Mesh box_mesh(const Vec3& size);
// A ball as the icosahedron subdivided `levels` times (20 4^levels
// triangles), its vertices on the sphere (for pictures).
Mesh ball_mesh(double radius, int levels);

}  // namespace odemag
