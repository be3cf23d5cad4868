#include "magnetics/cells.h"

#include <algorithm>
#include <cmath>

#include "magnetics/constants.h"

namespace odemag {

CellSet make_cells(const Shape& shape, double cell_size) {
  CellSet cells;
  const double volume = shape_volume(shape);
  if (cell_size > 0.0) {
    const Vec3 half = shape_half_extents(shape);
    std::array<int, 3> n{};
    for (int a = 0; a < 3; ++a)
      n[a] = std::max(1, static_cast<int>(std::floor(2.0 * half[a] / cell_size + 1e-9)));
    const double tol = 1e-9 * cell_size;
    for (int k = 0; k < n[2]; ++k)
      for (int j = 0; j < n[1]; ++j)
        for (int i = 0; i < n[0]; ++i) {
          const Vec3 p{(i - 0.5 * (n[0] - 1)) * cell_size, (j - 0.5 * (n[1] - 1)) * cell_size,
                       (k - 0.5 * (n[2] - 1)) * cell_size};
          if (!shape_contains(shape, p, tol)) continue;
          cells.local_positions.push_back(p);
          cells.lattice_index.push_back({i, j, k});
        }
    cells.lattice_extent = n;
    cells.spacing = cell_size;
  }
  if (cells.local_positions.empty()) {
    cells.local_positions.push_back({0.0, 0.0, 0.0});
    cells.lattice_index.push_back({0, 0, 0});
    cells.lattice_extent = {1, 1, 1};
    cells.spacing = 0.0;
  }
  cells.cell_volume = volume / static_cast<double>(cells.size());
  cells.cell_radius = std::cbrt(3.0 * cells.cell_volume / (4.0 * kPi));
  if (cells.spacing > 0.0) {
    cells.contact_radius = 0.5 * cells.spacing;
  } else {
    const Vec3 half = shape_half_extents(shape);
    cells.contact_radius = std::min({half.x, half.y, half.z});
  }
  return cells;
}

}  // namespace odemag
