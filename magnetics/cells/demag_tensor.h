// Intra-body interaction tensors between lattice cells (computed once per body).
//
// Point dipoles on a cubic lattice with the spherical self term 1/3 are
// linearly unstable for susceptibilities above ~11: columnar patterns of
// neighbouring dipoles feel a local field up to 0.43 M > M/3 and grow without
// an applied field (docs/model.md, "Intra-body tensor"). The exact average over
// cube a of the field of a uniformly magnetized cube b (Newell, Williams and
// Dunlop, J. Geophys. Res. 98, 1993) keeps the self term 1/3, tends to the
// point dipole far away, and makes the demagnetising energy positive
// semi-definite, so soft bodies relax to their induced magnetization.
#pragma once

#include <array>
#include <vector>

#include "odemag/settings.h"

namespace odemag {


// Demagnetising tensor N of two cubes of edge h at lattice offset (i, j, k):
// the mean field over cube a of cube b is -N M_b. Six components
// (xx, xy, xz, yy, yz, zz). N(0, 0, 0) = I / 3. Beyond kNewellRange cells the
// point dipole h^3 D(r) is used (its relative error there is below 2e-5,
// while the 27-term sums lose digits to cancellation).
void cube_demag_tensor(int i, int j, int k, double h, double n[6]);

inline constexpr int kNewellRange = 16;

// The same tensor at a real-valued offset d = centre of a - centre of b (m),
// for cubes that are aligned but need not share a lattice (cells of two
// bodies whose lattices are parallel), and, when dn is not null, its gradient
// dn[k][c] = dN_c / dd_k (1/m) from the derivatives of Newell's f and g. At
// integer offsets it equals cube_demag_tensor to round-off (1e-14). N is continuous
// everywhere, even for overlapping cubes, and N(-d) = N(d); its gradient is
// continuous except where faces of the two cubes pass through each other
// (|d_k| = h with overlapping projections, and d_k = 0 for overlapping cubes),
// where the two-sided mean is returned. Beyond kNewellRange cells: the point dipole.
void cube_demag_tensor_at(const double d[3], double h, double n[6], double (*dn)[6] = nullptr);

// Demagnetising tensor of two aligned cuboids of half extents half_a (the
// target) and half_b (the source) at offset d = centre of a - centre of b: the
// mean field over cuboid a of cuboid b uniformly magnetized is -N M_b
// (docs/model.md "Graded cells"). Newell's f and g at the corner differences
// d_k + {-(a_k + b_k), -(a_k - b_k), a_k - b_k, a_k + b_k} per axis with
// weights {-1, 1, 1, -1} (64 terms), over 4 pi V_a. For equal cubes of edge h
// it is cube_demag_tensor; V_a N_ab = V_b N_ba; N(-d) = N(d); d = 0 and
// half_a = half_b gives the cuboid's own demagnetising tensor. Beyond
// kNewellRange times the larger edge of the two: the point dipole V_b D(d).
// When dn is not null, also its gradient dn[k][c] = dN_c / dd_k (1/m), from
// the derivatives of Newell's f and g (every corner difference moves with
// d_k); odd in d, V_a dN_ab/dd = V_b dN_ba/dd at the same d; at faces that
// pass through each other the two-sided mean, as cube_demag_tensor_at.
void cuboid_demag_tensor(const double half_a[3], const double half_b[3], const double d[3], double n[6],
                         double (*dn)[6] = nullptr);

// The cuboid-cuboid tensors between the cells of a tensor-product grid
// (graded cells), faces[a] the n_a + 1 face positions along axis a: the
// corner differences of any two cells are differences F_p - F_q of two
// faces, so Newell's f and g are tabulated once at every |F_p - F_q| per
// axis and each pair costs 64 table reads instead of 64 evaluations.
// tensor(a, b) equals cuboid_demag_tensor of cells a and b (per-axis cell
// indices) to round-off, the point dipole included beyond kNewellRange
// times the larger edge; the 64-term sums are exactly symmetric in (a, b).
class GridDemagTable {
 public:
  explicit GridDemagTable(const std::array<std::vector<double>, 3>& faces);
  void tensor(const std::array<int, 3>& a, const std::array<int, 3>& b, double n[6]) const;

 private:
  std::array<std::vector<double>, 3> faces_;
  std::array<std::vector<int>, 3> index_;  // per axis, (n + 1)^2: p (n + 1) + q -> index of |F_p - F_q|
  std::array<int, 3> count_{0, 0, 0};      // distinct |F_p - F_q| per axis
  std::vector<double> table_;              // the six functions at every (u_x, u_y, u_z)
};

}  // namespace odemag
