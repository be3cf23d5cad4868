// Field probes: the sources of `odemag field` and field lines.
#pragma once

#include <vector>

#include "magnetics/kernels/cell_field.h"
#include "magnetics/model/model.h"
#include "magnetics/model/state.h"

namespace odemag {

// Every cell of an active magnetic body as the uniformly magnetized solid it
// stands for: a cube of edge h for lattice cells (centred on the cell point,
// magnetization mu / h^3: reduced for boundary cells), the body's box or sphere
// for single-cell boxes and spheres, the sphere of equal volume for a
// single-cell cylinder (an approximation inside and near it).
std::vector<ProbeCell> probe_cells(const MagneticModel& model, const MagneticState& state);

}  // namespace odemag
