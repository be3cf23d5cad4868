// FFT convolution of the demagnetizing tensor on lattices (magnetics/static/lattice_fft.h)
// against the dense pairwise sums of the same tensors, and the Newton-Krylov
// B-H solve (magnetics/static/bh_lattice_solve.h) on a soft cube against the curve.
#include <gtest/gtest.h>

#include <cmath>
#include <stdexcept>

#include "magnetics/static/bh_lattice_solve.h"
#include "odemag/constants.h"
#include "magnetics/kernels/kernels.h"
#include "magnetics/static/lattice_fft.h"
#include "magnetics/kernels/rng.h"

namespace odemag {
namespace {

// An irregular mask: about 70% of the cells, chosen by hash.
LatticeGrid random_lattice(const Vec3& origin, std::array<int, 3> n, int seed) {
  LatticeGrid g;
  g.origin = origin;
  g.n = n;
  g.mask.resize(static_cast<size_t>(n[0]) * n[1] * n[2]);
  for (size_t c = 0; c < g.mask.size(); ++c) g.mask[c] = unit_interval(hash_key(seed, static_cast<int>(c), 0, 0)) < 0.7;
  return g;
}

std::vector<Vec3> random_magnetization(int cells, double scale) {
  std::vector<Vec3> M(cells);
  for (int i = 0; i < cells; ++i) M[i] = scale * random_unit_vector(hash_key(9, i, 0, 0));
  return M;
}

double max_relative_difference(const std::vector<Vec3>& a, const std::vector<Vec3>& b) {
  double d = 0.0, s = 0.0;
  for (size_t i = 0; i < a.size(); ++i) {
    d = std::max(d, norm(a[i] - b[i]));
    s = std::max(s, norm(b[i]));
  }
  return d / s;
}

// Two masked lattices, the second at a non-integer offset (in every axis) and
// of another shape; the cells cuboids or cubes.
LatticeDemag two_bodies(const Vec3& cell, bool forces) {
  std::vector<LatticeGrid> g{random_lattice({0.0, 0.0, 0.0}, {5, 4, 3}, 1),
                             random_lattice({0.37 * cell.x, -1.61 * cell.y, 3.3 * cell.z}, {3, 6, 4}, 2)};
  std::vector<std::array<int, 2>> pairs;
  if (forces) pairs = {{0, 1}, {1, 0}};
  return LatticeDemag(cell, g, pairs);
}

TEST(LatticeFft, FieldEqualsTheDenseSumOfCuboidTensors) {
  for (const Vec3 cell : {Vec3{1e-3, 1e-3, 1e-3}, Vec3{1e-3, 0.7e-3, 1.6e-3}}) {
    const LatticeDemag demag = two_bodies(cell, false);
    ASSERT_GT(demag.cells_of(0), 20);
    ASSERT_GT(demag.cells_of(1), 20);
    const auto M = random_magnetization(demag.cells(), 1e6);
    std::vector<Vec3> fft, dense;
    demag.field(M, fft);
    demag.dense_field(M, dense);
    EXPECT_LT(max_relative_difference(fft, dense), 1e-12) << cell.y;
  }
}

TEST(LatticeFft, ForceEqualsTheDenseSumAndBalances) {
  const LatticeDemag demag = two_bodies({2e-3, 2e-3, 2e-3}, true);
  const auto M = random_magnetization(demag.cells(), 1e6);
  const Vec3 F01 = demag.force(0, 1, M), F10 = demag.force(1, 0, M);
  const Vec3 dense = demag.dense_force(0, 1, M);
  EXPECT_LT(norm(F01 - dense), 1e-11 * norm(dense));
  EXPECT_LT(norm(F01 + F10), 1e-11 * norm(F01));  // momentum balance F_01 = -F_10
}

// Cells smaller than the spacing (LatticeGrid::extent): a layer one cell
// thick in z of flat cells and one in x of thin cells next to a lattice of
// cuboids, all at non-integer offsets. The FFT field (unequal-cuboid kernels,
// the (s, t) kernel by reciprocity) and the forces equal the dense sums, and
// the forces balance.
TEST(LatticeFft, LayersOfSmallerCellsEqualTheDenseSums) {
  const Vec3 cell{1e-3, 0.8e-3, 1.2e-3};
  LatticeGrid flat = random_lattice({0.2e-3, -0.55e-3, 4.1e-3}, {4, 5, 1}, 3);
  flat.extent = {1e-3, 0.8e-3, 0.35e-3};
  LatticeGrid thin = random_lattice({5.3e-3, 0.4e-3, 0.7e-3}, {1, 4, 3}, 4);
  thin.extent = {0.25e-3, 0.6e-3, 1.2e-3};
  const std::vector<LatticeGrid> g{random_lattice({0.0, 0.0, 0.0}, {5, 4, 3}, 1), flat, thin};
  const LatticeDemag demag(cell, g, {{0, 1}, {1, 0}, {1, 2}, {2, 1}, {0, 2}, {2, 0}});
  for (int l = 0; l < 3; ++l) ASSERT_GT(demag.cells_of(l), 5);
  EXPECT_NEAR(demag.volume(1), 1e-3 * 0.8e-3 * 0.35e-3, 1e-24);
  const auto M = random_magnetization(demag.cells(), 1e6);
  std::vector<Vec3> fft, dense;
  demag.field(M, fft);
  demag.dense_field(M, dense);
  EXPECT_LT(max_relative_difference(fft, dense), 1e-12);
  for (const auto& p : std::vector<std::array<int, 2>>{{0, 1}, {1, 2}, {0, 2}}) {
    const Vec3 F = demag.force(p[0], p[1], M), back = demag.force(p[1], p[0], M);
    const Vec3 ref = demag.dense_force(p[0], p[1], M);
    // 1e-10: the unequal cuboids' 64-term sums cancel more digits than the cubes' 27.
    EXPECT_LT(norm(F - ref), 1e-10 * norm(ref)) << p[0] << p[1];
    EXPECT_LT(norm(F + back), 1e-10 * norm(F)) << p[0] << p[1];  // momentum balance
  }
  // A cell larger than the spacing along an axis with several cells would overlap its neighbours.
  LatticeGrid bad = random_lattice({0.0, 0.0, 9e-3}, {2, 2, 2}, 5);
  bad.extent = {1e-3, 0.8e-3, 1.5e-3};
  EXPECT_THROW(LatticeDemag(cell, {bad}), std::invalid_argument);
}

// The cell law in b = H + M (bh_lattice_solve.h (5)) inverts b = H + w f(H):
// from H, b = H + w f(H) gives back H and M = w f(H), and dM/db is the
// derivative of M(b) (central differences), at cells cut to w = 0.6 too.
TEST(BhLatticeSolve, FluxDensityCellLawInvertsTheCurve) {
  const BhCurve curve({{0.0, 0.0}, {100.0, 0.5}, {300.0, 1.2}, {1000.0, 1.5}, {1e4, 1.8}});
  for (const double w : {1.0, 0.6}) {
    for (const Vec3& H : {Vec3{0, 0, 20.0}, Vec3{150.0, -80.0, 40.0}, Vec3{-700.0, 300.0, 900.0}, Vec3{0, 3e4, 1e5}}) {
      double unused[6], J[6];
      const Vec3 M = bh_cell_law(curve, w, H, unused);
      Vec3 H_back;
      const Vec3 M_back = bh_flux_cell_law(curve, w, H + M, H_back, J);
      EXPECT_LT(norm(H_back - H), 1e-12 * norm(H + M)) << w << " " << H.x << " " << H.y << " " << H.z;
      EXPECT_LT(norm(M_back - M), 1e-12 * norm(H + M)) << w << " " << H.x << " " << H.y << " " << H.z;
      for (int k = 0; k < 3; ++k) {
        Vec3 db{};
        (&db.x)[k] = 1e-6 * norm(H + M);
        Vec3 Hp, Hm;
        const Vec3 dM = (bh_flux_cell_law(curve, w, H + M + db, Hp, unused) -
                         bh_flux_cell_law(curve, w, H + M - db, Hm, unused)) / (2.0 * (&db.x)[k]);
        const Vec3 column = symmetric_times(J, k == 0 ? Vec3{1, 0, 0} : k == 1 ? Vec3{0, 1, 0} : Vec3{0, 0, 1});
        EXPECT_LT(norm(dM - column), 1e-6) << w << " " << H.x << " " << H.y << " " << H.z << " column " << k;
      }
    }
  }
}

// One soft cube of 4^3 cells in a uniform field: the solve converges, and the
// mean M sits on the curve at the mean internal field (a cube's mean field is
// H_A - N M with N about 1/3; checked as M = M(|H|) cell by cell), in both
// Newton variables (the field H and the default b = H + M).
TEST(BhLatticeSolve, SoftCubeConvergesOntoTheCurve) {
  const BhCurve curve({{0.0, 0.0}, {100.0, 0.5}, {300.0, 1.2}, {1000.0, 1.5}, {1e4, 1.8}});
  LatticeGrid g;
  g.n = {4, 4, 4};
  g.mask.assign(64, 1);
  const LatticeDemag demag({1e-3, 1e-3, 1e-3}, {g});
  for (const BhNewtonVariable variable : {BhNewtonVariable::field, BhNewtonVariable::flux_density})
  for (const double Ha : {1e3, 3e5, 2e6}) {
    const std::vector<double> fill(64, 1.0);
    const std::vector<Vec3> source(64, Vec3{0.0, 0.0, Ha});
    std::vector<Vec3> M(64);
    BhSolveOptions options;
    options.variable = variable;
    const BhSolveReport report = solve_bh_lattice(demag, curve, fill, source, M, options);
    EXPECT_TRUE(report.converged) << Ha;
    // Field evaluations: one per GMRES iteration, at least one residual per
    // Newton step and the initial one; at most one more per GMRES restart
    // cycle and ten more halvings per step.
    EXPECT_GE(report.matvecs, report.krylov_iterations + report.newton_iterations + 1) << Ha;
    EXPECT_LE(report.matvecs, 2 * report.krylov_iterations + 11 * report.newton_iterations + 1) << Ha;
    std::vector<Vec3> Hd;
    demag.field(M, Hd);
    for (int i = 0; i < 64; ++i) {
      const Vec3 H = source[i] + Hd[i];
      EXPECT_NEAR(norm(M[i]), curve.magnetization(norm(H)), 1e-6 * curve.saturation()) << Ha;
    }
  }
}

}  // namespace
}  // namespace odemag
