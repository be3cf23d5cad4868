// Field probes: the sources of `odemag field` and field lines.
#pragma once

#include <vector>

#include "magnetics/kernels/cell_field.h"
#include "magnetics/model/model.h"
#include "magnetics/model/state.h"

namespace odemag {

// Every cell of an active magnetic body as the uniformly magnetized solid it
// stands for: a lattice cell's solid (CellSet::solid_half: a box's part, a
// graded cell's cuboid, a refined cell's cube, otherwise the cube of edge h
// with magnetization mu / h^3, reduced for a curved body's boundary cells),
// the body's box or sphere for single-cell boxes and spheres, the sphere of
// equal volume for a single-cell cylinder (an approximation inside and near it).
// A lattice ball's mean magnetization is its own uniformly magnetized sphere,
// its cells carrying only the rest.
std::vector<ProbeCell> probe_cells(const MagneticModel& model, const MagneticState& state);

}  // namespace odemag
