// Per-body cell sets on a cubic lattice (MODEL.md "Cells").
#pragma once

#include <array>
#include <vector>

#include "magnetics/shape.h"
#include "magnetics/vec3.h"

namespace odemag {

// The cells of one body, in the body frame. Every cell stands for the same
// volume: the body's volume divided by the cell count, so that the body's
// total moment is M times its volume exactly (h^3 for boxes whose edges are
// multiples of h; (4/3) pi R^3 for a single-cell ball).
struct CellSet {
  std::vector<Vec3> local_positions;            // body frame, m
  std::vector<std::array<int, 3>> lattice_index;  // integer lattice coordinates, 0-based
  std::array<int, 3> lattice_extent{1, 1, 1};   // lattice points per axis of the bounding lattice
  double spacing = 0.0;                         // h, m; 0 for a single cell
  double cell_volume = 0.0;                     // V, m^3
  double cell_radius = 0.0;                     // radius of the sphere of volume V, m
  // Radius of the sphere inscribed in the solid a cell stands for: h/2 for a
  // lattice cell (centre to the face of its cube), R for a one-cell ball, the
  // smallest half extent for another one-cell body. Two cells of different
  // bodies interact through the exact dipole kernel while their centres are
  // farther apart than the sum of their contact radii, so bodies that touch
  // never reach the bounded core (magnetics/kernels.h).
  double contact_radius = 0.0;

  int size() const { return static_cast<int>(local_positions.size()); }
};

// Cells of a shape on a lattice of spacing h = cell_size. With cell_size <= 0
// (or a lattice coarser than the shape) the body is one cell at its centre.
// Per axis the lattice has max(1, floor(extent / h)) points spaced h apart and
// centred on the body, so no cell's cube reaches beyond the body; points
// inside the shape become cells.
CellSet make_cells(const Shape& shape, double cell_size);

}  // namespace odemag
