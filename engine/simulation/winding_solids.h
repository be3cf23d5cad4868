// The collision solids of a coil's winding (docs/simulation.md "Coil
// windings"): the copper of a finite-section coil is a solid that other
// bodies collide with, like the carrying body's own shape. Off the
// conductors the coil's field is curl-free, which the force on a cell
// relies on (magnetics/relax/relax.cpp add_coil_forces); a body inside the copper
// would be where it is not.
#pragma once

#include <vector>

#include "magnetics/sources/coil.h"
#include "odemag/vec3.h"

namespace odemag {

// A box or a cylinder in the carrying body's frame.
struct CollisionSolid {
  enum class Kind { box, cylinder };
  Kind kind = Kind::box;
  Vec3 centre;  // m, body frame
  Mat3 axes;    // columns: the solid's x, y, z in the body frame (a cylinder along z)
  Vec3 size;    // m: a box's full sides; a cylinder's {radius, radius, length}
};

// Round parts of a winding are covered by boxes of at most 15 degrees of
// arc each: a box covers its annular sector and reaches at most 1 - cos(7.5
// deg) = 0.86% of the radius beyond it (into the bore, and past the outer
// surface), never less than the copper.
inline constexpr int kWindingSectorsPerTurn = 24;

// The solids that cover the winding of a finite-section coil (a
// circular_coil: 24 boxes about its bore, or one cylinder without a bore; a
// rounded_rectangle: a box per straight side and 6 per quarter-round corner).
// Filaments and current sheets (loop, segment, arc, solenoid) have no
// volume: none.
std::vector<CollisionSolid> winding_solids(const CoilSource& coil);

}  // namespace odemag
