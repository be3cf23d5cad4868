// Compound bodies (docs/model.md "Compounds"): the union of parts placed in
// one body frame, its integrals, inside test and lattice-cube shares.
#pragma once

#include <memory>
#include <mutex>
#include <vector>

#include "magnetics/cells/mesh.h"
#include "odemag/shape.h"

namespace odemag {

// One part in the body frame: a sphere, or an axis-aligned box or cylinder
// (its orientation a signed permutation) with its own shape and pose, or a
// body-frame mesh (meshes, turned boxes, and turned cylinders as prisms of
// kCompoundCylinderSides sides of the cylinder's volume).
struct BodyFramePart {
  Shape primitive;   // part frame; Sphere, Box or Cylinder, or a Mesh in the body frame
  Vec3 position;     // primitives: the part's origin in the body frame
  Mat3 orientation;  // primitives: a signed permutation (part -> body)
  Vec3 lo, hi;       // bounding box in the body frame, m
  Mesh field_mesh;   // boxes, cylinders and meshes in the body frame, for the field (mesh_demag_tensor)
  double sphere_radius = 0.0;  // spheres (their field is a dipole's outside)
};

inline constexpr int kCompoundCylinderSides = 256;

struct CompoundData {
  std::vector<CompoundPart> parts;
  mutable std::vector<BodyFramePart> body_parts;  // built on first use (compound_parts)
  mutable std::once_flag once;
};

const std::vector<BodyFramePart>& compound_parts(const Compound& compound);

// Exact for parts that do not overlap (the sums of the parts' integrals);
// where parts overlap, the overlap is subtracted as counted on a grid of
// kCompoundOverlapSamples^3 points over the box holding every pair's overlap.
MassIntegrals compound_mass_integrals(const Compound& compound);
inline constexpr int kCompoundOverlapSamples = 48;

Vec3 compound_half_extents(const Compound& compound);
bool compound_contains(const Compound& compound, const Vec3& p, double tol);
Vec3 compound_closest_point(const Compound& compound, const Vec3& p);
// Largest depth of p inside a part (0 outside every part).
double compound_depth(const Compound& compound, const Vec3& p);

// Volume and first moments of the box inside the union of the parts: exact
// where at most one part meets the box or the parts meeting it have disjoint
// bounding boxes there; else the sum less the overlap counted at 6^3 points.
VolumeMoments compound_box_moments(const Compound& compound, const Vec3& lo, const Vec3& hi);
bool compound_box_inside(const Compound& compound, const Vec3& lo, const Vec3& hi);

// The demagnetising tensor of the uniformly magnetized union at p: the sum of
// the parts' tensors (exact for parts that do not overlap).
void compound_demag_tensor(const Compound& compound, const Vec3& p, double n[6]);

std::string validate_compound(const Compound& compound);

// A cylinder (axis z) as a closed prism of the given sides and the
// cylinder's volume.
Mesh cylinder_prism_mesh(double radius, double length, int sides);

}  // namespace odemag
