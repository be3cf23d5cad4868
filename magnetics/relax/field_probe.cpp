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
    if (h > 0.0) {  // lattice cells: their solids (CellSet::solid_half), per cell below
      base.kind = ProbeCell::cuboid;
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
    // A lattice ball: its uniform part, the mean magnetization over the whole
    // ball, is the exact uniformly magnetized sphere; the cells carry the rest
    // (their solids are cubes, near the curved surface not the parts they
    // stand for). Uniform magnetization is then exact at every point.
    Vec3 uniform_part;
    if (const auto* ball = std::get_if<Sphere>(&body.shape); ball && h > 0.0) {
      double volume = 0.0;
      Vec3 moment;
      for (int i = 0; i < body.cell_count(); ++i) {
        volume += body.cells.volumes[i];
        moment += body.cells.volumes[i] * state.magnetization[body.first_cell + i];
      }
      uniform_part = moment / volume;
      ProbeCell sphere = base;
      sphere.kind = ProbeCell::sphere;
      sphere.position = state.pose[b].position;
      sphere.half = {ball->radius, ball->radius, ball->radius};
      sphere.volume = volume;
      sphere.moment = moment;
      cells.push_back(sphere);
    }
    for (int i = 0; i < body.cell_count(); ++i) {
      const int c = body.first_cell + i;
      ProbeCell cell = base;
      if (h > 0.0) {
        cell.half = body.cells.solid_half(i);
        cell.volume = body.cells.solid_volume(i);
      }
      cell.position = state.cell_position[c];
      cell.moment = body.cells.volumes[i] * (state.magnetization[c] - uniform_part);
      cells.push_back(cell);
    }
  }
  return cells;
}

}  // namespace odemag
