// The collision solids of a coil's winding (docs/simulation.md "Coil
// windings"): the copper of a finite-section coil, or a filament's wire, is a
// solid that other bodies collide with, like the carrying body's own shape. Off the
// conductors the coil's field is curl-free, which the force on a cell
// relies on (magnetics/relax/relax.cpp add_coil_forces); a body inside the copper
// would be where it is not.
#pragma once

#include <vector>

#include "magnetics/sources/coil.h"
#include "odemag/vec3.h"

namespace odemag {

// A box, a cylinder or a capsule in the carrying body's frame.
struct CollisionSolid {
  enum class Kind { box, cylinder, capsule };
  Kind kind = Kind::box;
  Vec3 centre;  // m, body frame
  Mat3 axes;    // columns: the solid's x, y, z in the body frame (a cylinder or capsule along z)
  // m: a box's full sides; a cylinder's {radius, radius, length}; a capsule's
  // {radius, radius, length of its cylinder} (half spheres beyond both ends)
  Vec3 size;
};

// Round parts of a winding are covered by boxes of at most 15 degrees of
// arc each: a box covers its annular sector and reaches at most 1 - cos(7.5
// deg) = 0.86% of the radius beyond it (into the bore, and past the outer
// surface), never less than the copper.
inline constexpr int kWindingSectorsPerTurn = 24;

// A filament's wire (magnetics/sources/coil.h filament_wire_radius, radius a)
// is covered by capsules along chords of its centre line: a segment by one, a
// loop by n = pi / acos(1 - a / (4 R)) (at least 24, at most
// kMaxWireCapsulesPerTurn) per turn, an arc by its share of them. A chord of
// a circle of radius R over the angle 2 pi / n lies up to s = R (1 - cos(pi / n))
// inside the arc, so the capsules take the radius a + s: never less than the
// copper, reaching at most 2 s (half the wire radius, while n is not capped)
// beyond it on the inside of the bend.
inline constexpr int kMaxWireCapsulesPerTurn = 256;

// The solids that cover the copper of a coil (a circular_coil: 24 boxes
// about its bore, or one cylinder without a bore; a rounded_rectangle: a box
// per straight side and 6 per quarter-round corner; a loop, segment or arc:
// capsules along its wire). A solenoid's current sheet has no volume: none.
std::vector<CollisionSolid> winding_solids(const CoilSource& coil);

}  // namespace odemag
