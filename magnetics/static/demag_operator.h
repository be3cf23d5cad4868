// What the nonlinear static solve (magnetics/static/bh_lattice_solve.h) needs of a
// demagnetizing-field operator: the cell-averaged field H = -N M of the
// cells' mean magnetizations, and each cell's own block of N (the
// preconditioner's). Implemented by the FFT convolution on lattices
// (magnetics/static/lattice_fft.h) and by the dense sum over cuboids of any sizes
// with mirror planes (magnetics/static/cuboid_demag.h).
#pragma once

#include <vector>

#include "odemag/vec3.h"

namespace odemag {

class DemagOperator {
 public:
  virtual ~DemagOperator() = default;
  virtual int cells() const = 0;
  // H (size cells()) from M (size cells()), A/m.
  virtual void field(const std::vector<Vec3>& M, std::vector<Vec3>& H) const = 0;
  // The field of a cell's own magnetization on itself is -n M: n's six
  // components (xx, xy, xz, yy, yz, zz).
  virtual void self_block(int cell, double n[6]) const = 0;
};

}  // namespace odemag
