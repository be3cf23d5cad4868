#include "magnetics/relax/field_probe.h"

#include <variant>

namespace odemag {

std::vector<ProbeCell> probe_cells(const MagneticModel& model, const MagneticState& state) {
  std::vector<ProbeCell> cells;
  cells.reserve(model.cell_count());
  for (int b = 0; b < model.body_count(); ++b) {
    const MagneticBody& body = model.body(b);
    if (body.inert() || !state.active[b]) continue;
    ProbeCell base;
    base.rotation = state.pose[b].rotation;
    base.body_centre = state.pose[b].position;
    const double reach = kProbeNearBodies * norm(shape_half_extents(body.shape));
    base.near2 = reach * reach;
    const double h = body.cells.spacing;
    if (h > 0.0) {  // lattice cell: a cube of edge h carrying the cell's moment (a boundary
                    // cell, V < h^3: the cube at its point with the reduced magnetization mu / h^3)
      base.kind = ProbeCell::cuboid;
      base.half = {0.5 * h, 0.5 * h, 0.5 * h};
      base.volume = h * h * h;
    } else if (const auto* box = std::get_if<Box>(&body.shape)) {
      base.kind = ProbeCell::cuboid;
      base.half = 0.5 * box->size;
      base.volume = box->size.x * box->size.y * box->size.z;
    } else {  // single-cell sphere (exact) or cylinder (equal-volume sphere)
      base.kind = ProbeCell::sphere;
      const double R = body.cells.cell_radius;
      base.half = {R, R, R};
      base.volume = body.cells.cell_volume;
    }
    for (int i = 0; i < body.cell_count(); ++i) {
      const int c = body.first_cell + i;
      ProbeCell cell = base;
      if (body.cells.refined) {  // its own cube (edge h / 2^l), at its point as on the lattice
        cell.half = body.cells.cube_half(i);
        cell.volume = 8.0 * cell.half.x * cell.half.y * cell.half.z;
      }
      cell.position = state.cell_position[c];
      cell.moment = body.cells.volumes[i] * state.magnetization[c];
      cells.push_back(cell);
    }
  }
  return cells;
}

}  // namespace odemag
