// The dense cuboid-cell demagnetizing field with mirror planes
// (magnetics/static/cuboid_demag.h): the quarter with its images against the whole
// problem built cell by cell, a uniformly magnetized cube of unequal cells
// against its demagnetizing factor 1/3 (exact for the volume-averaged
// field), and the B-H solve on a quarter against the same solve on the whole.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <stdexcept>

#include "magnetics/materials/bh_curve.h"
#include "magnetics/static/bh_lattice_solve.h"
#include "odemag/constants.h"
#include "magnetics/static/cuboid_demag.h"
#include "magnetics/cells/demag_tensor.h"
#include "magnetics/kernels/kernels.h"
#include "magnetics/kernels/rng.h"

namespace odemag {
namespace {

Vec3 reflect(const Vec3& s, const Vec3& v) { return {s.x * v.x, s.y * v.y, s.z * v.z}; }

// Cells of unequal sizes in x, y >= 0, some with a face on a mirror plane,
// some overlapping none: a tensor-product grid of uneven faces (mm) plus a
// detached block.
std::vector<CuboidCell> quarter_cells() {
  std::vector<CuboidCell> cells = grid_cells({0.0, 0.7e-3, 2.0e-3, 2.4e-3}, {0.0, 1.1e-3, 1.5e-3}, {-1.0e-3, 0.3e-3, 1.9e-3});
  cells.push_back({1e-3 * Vec3{3.5, 0.9, 2.6}, 1e-3 * Vec3{0.6, 0.4, 0.3}});  // apart, 0.3 mm above the grid's corner
  return cells;
}

TEST(CuboidDemag, MirrorPlanesEqualTheWholeProblem) {
  const std::vector<CuboidCell> quarter = quarter_cells();
  const int n = static_cast<int>(quarter.size());
  std::vector<Vec3> M(n);
  for (int i = 0; i < n; ++i) M[i] = 1e6 * random_unit_vector(hash_key(3, i, 0, 0));
  for (int planes = 1; planes <= 3; ++planes) {
    const bool mx = planes & 1, my = planes & 2;
    const CuboidDemag folded(quarter, mx, my);
    // The whole problem: every cell and its images with their reflected magnetizations.
    std::vector<CuboidCell> whole;
    std::vector<Vec3> M_whole;
    for (const Vec3& s : folded.images())
      for (int i = 0; i < n; ++i) {
        whole.push_back({reflect(s, quarter[i].centre), quarter[i].half});
        M_whole.push_back(reflect(s, M[i]));
      }
    const CuboidDemag full(whole, false, false);
    std::vector<Vec3> H, H_whole;
    folded.field(M, H);
    full.field(M_whole, H_whole);
    double scale = 0.0;
    for (const Vec3& h : H_whole) scale = std::max(scale, norm(h));
    for (int i = 0; i < n; ++i) EXPECT_LT(norm(H[i] - H_whole[i]), 1e-12 * scale) << planes << " cell " << i;
    // The force on all images of the detached block from all images of the grid.
    const int images = static_cast<int>(folded.images().size());
    Vec3 F_whole{};
    for (int s = 0; s < images; ++s)
      for (int t = 0; t < images; ++t) F_whole += full.force(s * n + n - 1, s * n + n, t * n, t * n + n - 1, M_whole);
    const Vec3 F = folded.force(n - 1, n, 0, n - 1, M);
    EXPECT_LT(norm(F - F_whole), 1e-12 * norm(F_whole)) << planes;
    // Momentum: the grid's images feel the opposite (to round-off: the pair terms are larger than their sum).
    EXPECT_LT(norm(F + folded.force(0, n - 1, n - 1, n, M)), 1e-10 * norm(F)) << planes;
    const Vec3 p = 1e-3 * Vec3{1.3, 2.2, 2.5};
    EXPECT_LT(norm(folded.field_at(p, M) - full.field_at(p, M_whole)), 1e-12 * norm(full.field_at(p, M_whole))) << planes;
  }
}

TEST(CuboidDemag, UniformCubeOfUnequalCellsHasTheMeanFieldMinusMOverThree) {
  // The cube |x|, |y|, |z| <= 1 mm: its quarter in uneven cells, M along z
  // (symmetric under both planes). The mean of H over any uniformly
  // magnetized cube is -M / 3.
  const std::vector<double> f = {0.0, 0.15e-3, 0.45e-3, 1.0e-3};
  const std::vector<CuboidCell> cells = grid_cells(f, f, {-1.0e-3, -0.8e-3, -0.1e-3, 0.5e-3, 0.9e-3, 1.0e-3});
  const CuboidDemag demag(cells, true, true);
  const double Ms = 1e6;
  const std::vector<Vec3> M(cells.size(), Vec3{0.0, 0.0, Ms});
  std::vector<Vec3> H;
  demag.field(M, H);
  Vec3 mean{};
  double volume = 0.0;
  for (int i = 0; i < demag.cells(); ++i) {
    mean += demag.volume(i) * H[i];
    volume += demag.volume(i);
  }
  mean = mean / volume;
  EXPECT_NEAR(mean.z, -Ms / 3.0, 1e-12 * Ms);
  EXPECT_LT(std::hypot(mean.x, mean.y), 1e-12 * Ms);
}

TEST(CuboidDemag, BhSolveOnTheQuarterEqualsTheSolveOnTheWhole) {
  // A soft steel block (linear-to-saturation curve) in a field along z
  // that grows with x^2 + y^2 (symmetric in both planes), the B-H
  // Newton-GMRES on the quarter and on the whole.
  const std::vector<CuboidCell> quarter = quarter_cells();
  const int n = static_cast<int>(quarter.size());
  const BhCurve curve({{0.0, 0.0}, {100.0, 0.2}, {400.0, 1.0}, {2000.0, 1.5}, {20000.0, 1.9}});
  auto source = [](const Vec3& c) { return Vec3{0.0, 0.0, 300.0 * (1.0 + 1e5 * (c.x * c.x + c.y * c.y))}; };
  const CuboidDemag folded(quarter, true, true);
  std::vector<CuboidCell> whole;
  for (const Vec3& s : folded.images())
    for (const CuboidCell& c : quarter) whole.push_back({reflect(s, c.centre), c.half});
  const CuboidDemag full(whole, false, false);
  BhSolveOptions options;
  options.tolerance = 1e-10;
  std::vector<Vec3> Hq(n), Hw(whole.size());
  for (int i = 0; i < n; ++i) Hq[i] = source(quarter[i].centre);
  for (size_t i = 0; i < whole.size(); ++i) Hw[i] = source(whole[i].centre);
  std::vector<Vec3> Mq(n), Mw(whole.size());
  const BhSolveReport rq = solve_bh_lattice(folded, curve, std::vector<double>(n, 1.0), Hq, Mq, options);
  const BhSolveReport rw = solve_bh_lattice(full, curve, std::vector<double>(whole.size(), 1.0), Hw, Mw, options);
  ASSERT_TRUE(rq.converged);
  ASSERT_TRUE(rw.converged);
  double scale = 0.0;
  for (const Vec3& m : Mw) scale = std::max(scale, norm(m));
  for (int i = 0; i < n; ++i) EXPECT_LT(norm(Mq[i] - Mw[i]), 1e-8 * scale) << i;
}

TEST(CuboidDemag, RepeatedPairsEqualTheDirectSum) {
  // A uniform grid of 1/3 mm cells (centres with rounding: the pairs at one
  // lattice offset share a tensor only through the keys' tolerance) beside
  // a block of another size: the field and the force from the stored
  // distinct pairs against the sum of cuboid_demag_tensor over every cell
  // and image, written here.
  std::vector<double> fx, fy, fz;
  for (int k = 0; k <= 4; ++k) fx.push_back(k * 1e-3 / 3.0);
  for (int k = 0; k <= 3; ++k) fy.push_back(k * 1e-3 / 3.0);
  for (int k = 0; k <= 5; ++k) fz.push_back(-1e-3 + k * 1e-3 / 3.0);
  std::vector<CuboidCell> cells = grid_cells(fx, fy, fz);
  const int grid = static_cast<int>(cells.size());
  cells.push_back({1e-3 * Vec3{0.5, 0.4, 0.9}, 1e-3 * Vec3{0.3, 0.2, 0.15}});  // above the grid
  const int n = static_cast<int>(cells.size());
  const CuboidDemag demag(cells, true, true);
  std::vector<Vec3> M(n);
  for (int i = 0; i < n; ++i) M[i] = 1e6 * random_unit_vector(hash_key(5, i, 0, 0));
  std::vector<Vec3> H;
  demag.field(M, H);
  auto pair = [&](int i, int j, const Vec3& s, double t[6], double (*dt)[6]) {
    const double ha[3] = {cells[i].half.x, cells[i].half.y, cells[i].half.z};
    const double hb[3] = {cells[j].half.x, cells[j].half.y, cells[j].half.z};
    const Vec3 d = cells[i].centre - reflect(s, cells[j].centre);
    const double dd[3] = {d.x, d.y, d.z};
    cuboid_demag_tensor(ha, hb, dd, t, dt);
  };
  double scale = 0.0;
  for (const Vec3& h : H) scale = std::max(scale, norm(h));
  for (int i = 0; i < n; ++i) {
    Vec3 direct{};
    for (int j = 0; j < n; ++j)
      for (const Vec3& s : demag.images()) {
        double t[6];
        pair(i, j, s, t, nullptr);
        direct -= symmetric_times(t, reflect(s, M[j]));
      }
    EXPECT_LT(norm(H[i] - direct), 1e-12 * scale) << "cell " << i;
  }
  // Forces, (2) of cuboid_demag.h: on the grid's two lower layers from its
  // three upper ones (pairs that repeat: the table) and on the grid from the
  // block (every pair distinct: evaluated one by one).
  auto direct_force = [&](int t0, int t1, int s0, int s1) {
    Vec3 quarter{};
    for (int i = t0; i < t1; ++i)
      for (int j = s0; j < s1; ++j)
        for (const Vec3& s : demag.images()) {
          double t[6], dt[3][6];
          pair(i, j, s, t, dt);
          for (int k = 0; k < 3; ++k)
            quarter[k] -= kMu0 * demag.volume(i) * dot(M[i], symmetric_times(dt[k], reflect(s, M[j])));
        }
    Vec3 total{};
    for (const Vec3& s : demag.images()) total += reflect(s, quarter);
    return total;
  };
  const int layer = 4 * 3;
  for (const std::array<int, 4>& r : {std::array<int, 4>{0, 2 * layer, 2 * layer, grid}, {0, grid, grid, n}}) {
    const Vec3 F_direct = direct_force(r[0], r[1], r[2], r[3]);
    EXPECT_LT(norm(demag.force(r[0], r[1], r[2], r[3], M) - F_direct), 1e-12 * norm(F_direct)) << r[1];
    EXPECT_LT(norm(demag.force_operator(r[0], r[1], r[2], r[3])(M) - F_direct), 1e-12 * norm(F_direct)) << r[1];
  }
}

TEST(CuboidDemag, ForceOperatorEqualsTheForce) {
  // One mirror plane or none (components the images do not cancel), for two
  // magnetizations on one operator.
  const std::vector<CuboidCell> cells = quarter_cells();
  const int n = static_cast<int>(cells.size());
  for (const bool mirror : {false, true}) {
    const CuboidDemag demag(cells, mirror, false);
    const CuboidDemag::ForceOperator on_block = demag.force_operator(n - 1, n, 0, n - 1);
    for (int seed = 0; seed < 2; ++seed) {
      std::vector<Vec3> M(n);
      for (int i = 0; i < n; ++i) M[i] = 1e6 * random_unit_vector(hash_key(7, i, seed, 0));
      const Vec3 F = demag.force(n - 1, n, 0, n - 1, M);
      const Vec3 G = on_block(M);
      EXPECT_GT(norm(F), 0.0);
      EXPECT_LT(norm(G - F), 1e-12 * norm(F)) << mirror << " " << seed;
      if (mirror) {
        EXPECT_EQ(G.x, 0.0);
      }
    }
  }
}

TEST(CuboidDemag, RefusesCellsAcrossAMirrorPlane) {
  EXPECT_THROW(CuboidDemag({{Vec3{0.0, 1.0, 0.0}, Vec3{0.5, 0.5, 0.5}}}, true, false), std::invalid_argument);
  EXPECT_THROW(CuboidDemag({{Vec3{1.0, 1.0, 0.0}, Vec3{0.5, 0.0, 0.5}}}, false, false), std::invalid_argument);
}

}  // namespace
}  // namespace odemag
