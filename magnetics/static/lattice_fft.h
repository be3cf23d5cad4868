// The demagnetizing field of lattice bodies by FFT convolution
// (docs/model.md "FFT convolution on lattices").
//
// Cells are uniformly magnetized cuboids, axis aligned, on regular lattices
// of one spacing (hx, hy, hz): lattice l has n[l] cells per axis with cell
// (i, j, k) centred at origin + (i hx, j hy, k hz); the cells of a body are a
// mask on its lattice; a cell's edges are the spacing unless the lattice
// says otherwise (layers, below). Lattices share the spacing and the
// orientation but their origins differ arbitrarily (not by multiples of h). The mean field over
// cell i of lattice t is
//   H_i = -sum_s sum_j N(r_i - r_j) M_j                                  (1)
// with N the cell-averaged cuboid-cuboid tensor (cuboid_demag_tensor, the
// self term N(0) included), which depends on lattice indices only through
// i - j for each (target, source) pair: a convolution, evaluated with
// zero-padded FFTs. One kernel per pair (t, s) at the pair's real offset
// origin_t - origin_s, transformed once; a matvec is 3 forward FFTs per
// source lattice, the products summed per target in the frequency domain, and
// 3 inverse FFTs per target lattice (real-to-complex along x, and the
// transforms pruned to the lines that hold data).
//
// A lattice's cells may be smaller than its spacing (LatticeGrid::extent):
// along an axis with one cell any extent, so that a layer of cells one cell
// thick fits a body's face between the spacing's planes (cells that straddle
// no face: every cell all steel). The pair tensor is then that of unequal
// cuboids (cuboid_demag_tensor), still a function of i - j on each pair, and
// (1) keeps its convolution; V_t N_ts(d) = V_s N_st(-d) gives (s, t)'s kernel
// from (t, s)'s.
//
// The force on the cells of lattice t from those of lattice s:
//   F = mu0 V_t sum_i M_i . grad (M_i . H_i^(s)) = -mu0 V_t sum_ij M_i^T dN_ts/dd (r_i - r_j) M_j   (2)
// exact for uniformly magnetized cuboids (the mean of (M . grad) H over cell
// i is the derivative of its mean field by translation, curl H = 0 outside
// lattice s); dN/dd from cube_demag_tensor_at (equal cubes) or
// cuboid_demag_tensor, is odd in d with V_t dN_ts/dd = V_s dN_st/dd, so F_ts =
// -F_st to round-off.
#pragma once

#include <array>
#include <complex>
#include <vector>

#include "magnetics/static/demag_operator.h"
#include "odemag/vec3.h"

namespace odemag {

struct LatticeGrid {
  Vec3 origin;                      // centre of cell (0, 0, 0), m
  std::array<int, 3> n{0, 0, 0};    // cells per axis
  std::vector<char> mask;           // n0 n1 n2 entries, x fastest: 1 where the body has a cell
  // The cells' edges, m; zero: the spacing (LatticeDemag's cell). At most
  // the spacing along an axis with more than one cell.
  Vec3 extent{0.0, 0.0, 0.0};
};

class LatticeDemag : public DemagOperator {
 public:
  // cell: the spacing (hx, hy, hz) of every lattice, m, and the edges of
  // its cells unless LatticeGrid::extent says otherwise. force_pairs: the
  // (target, source) lattice pairs whose force (2) is wanted.
  LatticeDemag(const Vec3& cell, std::vector<LatticeGrid> lattices,
               const std::vector<std::array<int, 2>>& force_pairs = {});

  // Active cells, all lattices in order, each in its mask's order (x fastest).
  int cells() const override { return static_cast<int>(cell_index_.size()); }
  int cells_of(int lattice) const { return first_[lattice + 1] - first_[lattice]; }
  int first_cell(int lattice) const { return first_[lattice]; }
  Vec3 centre(int cell) const;
  int lattice_of(int cell) const;
  const Vec3& cell_size() const { return cell_; }
  // A lattice's cell edges (m) and volume (m^3).
  Vec3 extent(int lattice) const { return 2.0 * half_[lattice]; }
  double volume(int lattice) const { return volume_[lattice]; }
  int lattice_count() const { return static_cast<int>(lattices_.size()); }

  // (1): H (size cells()) from M (size cells()), A/m.
  void field(const std::vector<Vec3>& M, std::vector<Vec3>& H) const override;
  // (2): force (N) on lattice `target` from lattice `source` (a force pair).
  Vec3 force(int target, int source, const std::vector<Vec3>& M) const;
  // The self tensor N(0) of a cell (six components xx, xy, xz, yy, yz, zz).
  const std::array<double, 6>& self_tensor() const { return self_; }
  // The self tensor of a lattice's cells (its extent's).
  const std::array<double, 6>& self_tensor(int lattice) const { return self_of_[lattice]; }
  void self_block(int cell, double n[6]) const override {
    for (int c = 0; c < 6; ++c) n[c] = self_of_[lattice_of(cell)][c];
  }

  // The same sums pair by pair (O(N^2)), the reference the FFT is checked against.
  void dense_field(const std::vector<Vec3>& M, std::vector<Vec3>& H) const;
  Vec3 dense_force(int target, int source, const std::vector<Vec3>& M) const;

 private:
  using Spectrum = std::vector<std::complex<double>>;
  void forward(const std::vector<double>& in, const std::array<int, 3>& used, Spectrum& out) const;
  void inverse(Spectrum& in, const std::array<int, 3>& used, std::vector<double>& out) const;
  void scatter(int lattice, const std::vector<Vec3>& M, int component, std::vector<double>& grid) const;
  Vec3 offset(int target, int source, const std::array<int, 3>& d) const;
  // Threads only for grids large enough to pay for the parallel regions'
  // start (a matvec opens a dozen of them).
  bool parallel() const { return static_cast<long>(pad_[0]) * pad_[1] * pad_[2] >= (1L << 18); }
  void source_spectra(const std::vector<Vec3>& M, std::vector<std::array<Spectrum, 3>>& out) const;

  Vec3 cell_;
  std::vector<LatticeGrid> lattices_;
  std::vector<int> first_;                      // first active cell of each lattice, and the total
  std::vector<std::array<int, 4>> cell_index_;  // (lattice, i, j, k) of each active cell
  std::array<int, 3> pad_{0, 0, 0};             // padded FFT grid (even, 2-3-5 smooth)
  int half_x_ = 0;                              // pad_x / 2 + 1 (the real-to-complex half spectrum)
  std::vector<std::array<Spectrum, 6>> kernel_;  // per pair t <= s at t * L + s: spectra of N's six components
  std::vector<std::array<int, 2>> force_pairs_;
  std::vector<std::array<Spectrum, 10>> gradient_;  // per force pair: spectra of dN_ij/dd_k (symmetric, 10)
  std::array<double, 6> self_{};
  std::vector<Vec3> half_;                      // per lattice: the cells' half edges
  std::vector<double> volume_;                  // per lattice: a cell's volume
  std::vector<std::array<double, 6>> self_of_;  // per lattice: N(0) of its cells
};

}  // namespace odemag
