// The compressed operator (magnetics/static/hmatrix.h, CuboidDemag::compress):
// its field against the dense sum on cells far enough apart for low-rank
// blocks, the tolerance controlling the error, the blocks in single
// precision, the same field bit for bit on one and two threads, and a B-H
// solve on it against the same solve on the dense operator.
#include <gtest/gtest.h>

#include <omp.h>

#include <cmath>
#include <vector>

#include "magnetics/materials/bh_curve.h"
#include "magnetics/static/bh_lattice_solve.h"
#include "magnetics/static/cuboid_demag.h"
#include "magnetics/kernels/rng.h"

namespace odemag {
namespace {

// Two bars of 1 mm cells in x, y >= 0, an L of 12 x 3 x 3 and 3 x 3 x 12
// cells with a 2 mm gap between them, and a slab of 8 x 8 x 1 cells
// above: 280 cells, many pairs far apart against their clusters.
std::vector<CuboidCell> bars() {
  auto faces = [](double lo, int n) {
    std::vector<double> f;
    for (int k = 0; k <= n; ++k) f.push_back(1e-3 * (lo + k));
    return f;
  };
  std::vector<CuboidCell> cells = grid_cells(faces(0.0, 12), faces(0.0, 3), faces(0.0, 3));
  for (const auto& part : {grid_cells(faces(14.0, 3), faces(0.0, 3), faces(0.0, 12)),
                           grid_cells(faces(0.0, 8), faces(0.0, 8), faces(15.0, 1))})
    cells.insert(cells.end(), part.begin(), part.end());
  return cells;
}

double relative_error(const std::vector<Vec3>& a, const std::vector<Vec3>& b) {
  double e = 0.0, n = 0.0;
  for (size_t i = 0; i < a.size(); ++i) {
    e += squared_norm(a[i] - b[i]);
    n += squared_norm(b[i]);
  }
  return std::sqrt(e / n);
}

TEST(HMatrix, CompressedFieldEqualsTheDenseSum) {
  const std::vector<CuboidCell> cells = bars();
  const int n = static_cast<int>(cells.size());
  std::vector<Vec3> M(n), dense, compressed;
  for (int i = 0; i < n; ++i) M[i] = 1e6 * random_unit_vector(hash_key(11, i, 0, 0));
  const CuboidDemag exact(cells, true, true);
  exact.field(M, dense);
  double previous = 1.0;
  for (const double tolerance : {1e-3, 1e-5, 1e-7}) {
    CuboidDemag demag(cells, true, true);
    HMatrixOptions options;
    options.tolerance = tolerance;
    demag.compress(options);
    ASSERT_NE(demag.compressed(), nullptr);
    EXPECT_GT(demag.compressed()->low_rank_blocks(), 0);
    EXPECT_LT(demag.compressed()->stored(), 9L * n * n / 2) << "not compressed";
    demag.field(M, compressed);
    const double error = relative_error(compressed, dense);
    EXPECT_LT(error, tolerance) << tolerance;
    EXPECT_LT(error, previous) << tolerance;
    previous = error;
    for (int i = 0; i < n; i += 37) {  // the cells' own blocks are kept exactly
      double a[6], b[6];
      demag.self_block(i, a);
      exact.self_block(i, b);
      for (int c = 0; c < 6; ++c) EXPECT_EQ(a[c], b[c]) << i;
    }
  }
}

TEST(HMatrix, SinglePrecisionKeepsTheBlockTolerance) {
  // The same blocks rounded to single precision: the field within the
  // blocks' tolerance 1e-5 of the dense sum (about 1e-7 more than in double).
  const std::vector<CuboidCell> cells = bars();
  const int n = static_cast<int>(cells.size());
  std::vector<Vec3> M(n), dense, single, twice;
  for (int i = 0; i < n; ++i) M[i] = 1e6 * random_unit_vector(hash_key(17, i, 0, 0));
  const CuboidDemag exact(cells, true, true);
  exact.field(M, dense);
  CuboidDemag demag(cells, true, true), in_double(cells, true, true);
  HMatrixOptions options;
  in_double.compress(options);
  options.single_precision = true;
  demag.compress(options);
  EXPECT_EQ(demag.compressed()->stored(), in_double.compressed()->stored());
  demag.field(M, single);
  in_double.field(M, twice);
  EXPECT_LT(relative_error(single, dense), 1e-5);
  const double rounding = relative_error(single, twice);
  EXPECT_GT(rounding, 0.0);    // it is single precision
  EXPECT_LT(rounding, 1e-6);
}

TEST(HMatrix, SameFieldOnOneAndTwoThreads) {
  const std::vector<CuboidCell> cells = bars();
  const int n = static_cast<int>(cells.size());
  std::vector<Vec3> M(n), one, two;
  for (int i = 0; i < n; ++i) M[i] = 1e6 * random_unit_vector(hash_key(13, i, 0, 0));
  for (const bool single : {false, true}) {
    CuboidDemag demag(cells, true, true);
    HMatrixOptions options;
    options.single_precision = single;
    demag.compress(options);
    const int threads = omp_get_max_threads();
    omp_set_num_threads(1);
    demag.field(M, one);
    omp_set_num_threads(2);
    demag.field(M, two);
    omp_set_num_threads(threads);
    for (int i = 0; i < n; ++i)
      for (int a = 0; a < 3; ++a) EXPECT_EQ(one[i][a], two[i][a]) << single << " " << i;
  }
}

TEST(HMatrix, BhSolveOnTheCompressedOperatorEqualsTheDenseOne) {
  const std::vector<CuboidCell> cells = bars();
  const int n = static_cast<int>(cells.size());
  // A steel-like curve: mu_r about 2000 at first, saturating near 2 T.
  const BhCurve curve({{0.0, 0.0}, {100.0, 0.25}, {300.0, 1.0}, {1000.0, 1.4}, {1e4, 1.8}, {1e5, 2.1}});
  std::vector<Vec3> source(n, Vec3{0.0, 0.0, 3e4});
  const std::vector<double> fill(n, 1.0);
  BhSolveOptions options;
  options.tolerance = 1e-8;
  const CuboidDemag dense(cells, true, true);
  CuboidDemag compressed(cells, true, true);
  compressed.compress();
  std::vector<Vec3> Md(n), Mc(n);
  ASSERT_TRUE(solve_bh_lattice(dense, curve, fill, source, Md, options).converged);
  ASSERT_TRUE(solve_bh_lattice(compressed, curve, fill, source, Mc, options).converged);
  EXPECT_LT(relative_error(Mc, Md), 1e-5);
}

}  // namespace
}  // namespace odemag
