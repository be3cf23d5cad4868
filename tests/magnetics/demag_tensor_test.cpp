// The intra-body tensors (magnetics/cells/demag_tensor.h): exact properties of the
// cube-cube demagnetising tensor, and the stability that motivates it.
#include "magnetics/cells/demag_tensor.h"

#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <limits>
#include <vector>

#include "magnetics/model/backend.h"
#include "magnetics/kernels/kernels.h"
#include "magnetics/model/model.h"
#include "tests/support/magnetic_checks.h"

namespace odemag {
namespace {

TEST(CubeDemagTensor, SelfTermIsOneThirdIdentity) {
  double n[6];
  cube_demag_tensor(0, 0, 0, 2e-3, n);
  EXPECT_NEAR(n[0], 1.0 / 3.0, 1e-14);
  EXPECT_NEAR(n[3], 1.0 / 3.0, 1e-14);
  EXPECT_NEAR(n[5], 1.0 / 3.0, 1e-14);
  EXPECT_NEAR(n[1], 0.0, 1e-15);
  EXPECT_NEAR(n[2], 0.0, 1e-15);
  EXPECT_NEAR(n[4], 0.0, 1e-15);
}

TEST(CubeDemagTensor, OffDiagonalCellsAreTracelessAndSymmetricUnderReflection) {
  for (int i = -3; i <= 3; ++i)
    for (int j = -3; j <= 3; ++j)
      for (int k = -3; k <= 3; ++k) {
        if (i == 0 && j == 0 && k == 0) continue;
        double n[6], m[6];
        cube_demag_tensor(i, j, k, 1e-3, n);
        EXPECT_NEAR(n[0] + n[3] + n[5], 0.0, 1e-13);  // Laplace: div of H vanishes outside (27-term sums lose ~3 digits)
        cube_demag_tensor(-i, -j, -k, 1e-3, m);      // N(-d) = N(d)
        for (int a = 0; a < 6; ++a) EXPECT_EQ(n[a], m[a]);
        cube_demag_tensor(-i, j, k, 1e-3, m);        // xy, xz odd in x
        EXPECT_EQ(n[1], -m[1]);
        EXPECT_EQ(n[2], -m[2]);
      }
}

TEST(CubeDemagTensor, TendsToPointDipoleFarAway) {
  const double h = 1e-3;
  // The first correction of a cube's field is of order (h / r)^4 (cubic symmetry).
  for (int d : {4, 8, 12, 16}) {
    double n[6], t[6];
    cube_demag_tensor(d, d / 2, -d / 4, h, n);
    dipole_tensor({d * h, (d / 2) * h, -(d / 4) * h}, 0.0, t);
    double err = 0.0, scale = 0.0;
    for (int a = 0; a < 6; ++a) {
      err = std::max(err, std::abs(n[a] + t[a] * h * h * h));
      scale = std::max(scale, std::abs(t[a] * h * h * h));
    }
    const double r = std::sqrt(d * d + (d / 2) * (d / 2) + (d / 4) * (d / 4));
    EXPECT_LT(err / scale, 2.0 * std::pow(1.0 / r, 4)) << "d=" << d;
  }
}

// A body of L^3 cubes magnetized uniformly is a uniformly magnetized cube:
// its mean demagnetising tensor is exactly I/3 (sum rule over all pairs).
TEST(CubeDemagTensor, CubeOfCubesHasDemagFactorOneThird) {
  for (int L : {2, 3, 5}) {
    double sum[6] = {};
    for (int a = 0; a < L * L * L; ++a)
      for (int b = 0; b < L * L * L; ++b) {
        double n[6];
        cube_demag_tensor(a % L - b % L, (a / L) % L - (b / L) % L, a / (L * L) - b / (L * L), 1.0, n);
        for (int c = 0; c < 6; ++c) sum[c] += n[c];
      }
    const double cells = L * L * L;
    EXPECT_NEAR(sum[0] / cells, 1.0 / 3.0, 1e-10) << L;
    EXPECT_NEAR(sum[3] / cells, 1.0 / 3.0, 1e-10) << L;
    EXPECT_NEAR(sum[5] / cells, 1.0 / 3.0, 1e-10) << L;
    EXPECT_NEAR(sum[1] / cells, 0.0, 1e-10) << L;
  }
}

// Largest eigenvalue of the linear response map M -> H_intra(M) / gamma_D of
// a soft body: above 1 the body magnetizes itself without any applied field.
// Graded bodies (per-pair tensors, the diagonal included): the map is
// similar to W^1/2 T W^1/2 / gamma_D, W = diag V.
double largest_response_eigenvalue(const MagneticBody& b) {
  const int n = b.cell_count();
  Eigen::MatrixXd G = Eigen::MatrixXd::Zero(3 * n, 3 * n);
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) {
      const double* t = nullptr;
      if (b.cells.graded) {
        t = &b.pair_tensors[6u * (static_cast<size_t>(i) * n + j)];
      } else {
        if (i == j) continue;
        t = &b.offset_tensors[6u * b.offset_index(b.cells.lattice_index[i], b.cells.lattice_index[j])];
      }
      const double T[3][3] = {{t[0], t[1], t[2]}, {t[1], t[3], t[4]}, {t[2], t[4], t[5]}};
      const double w = std::sqrt(b.cells.volumes[i] * b.cells.volumes[j]);
      for (int p = 0; p < 3; ++p)
        for (int q = 0; q < 3; ++q) G(3 * i + p, 3 * j + q) = T[p][q] * w / b.soft.gamma_D;
    }
  G = 0.5 * (G + G.transpose());
  return Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(G, Eigen::EigenvaluesOnly).eigenvalues().maxCoeff();
}

double largest_response_eigenvalue(IntraBodyTensor kind, const Shape& shape, double h, double chi,
                                   bool graded = false) {
  MagneticModel model(kind);
  model.set_graded_cells(graded);
  SoftMaterial iron;
  iron.saturation = 1.7e6;
  iron.susceptibility = chi;
  model.add_body("body", shape, iron, h);
  EXPECT_EQ(model.body(0).cells.graded, graded);
  return largest_response_eigenvalue(model.body(0));
}

TEST(IntraBodyTensor, CellAverageKeepsSoftBodiesStable) {
  // Plates, cubes and bars of iron (chi = 5000): the point-dipole lattice is
  // unstable (eigenvalue > 1); the cube-cube tensor is not.
  struct Case {
    Shape shape;
    double h;
  };
  const Case cases[] = {{Box{{0.02, 0.02, 0.004}}, 0.004},   // 5 x 5 x 1 plate
                        {Box{{0.02, 0.02, 0.02}}, 0.004},    // 5 x 5 x 5 cube
                        {Box{{0.1, 0.01, 0.01}}, 0.005}};    // 20 x 2 x 2 bar
  for (const Case& c : cases) {
    EXPECT_LT(largest_response_eigenvalue(IntraBodyTensor::cell_average, c.shape, c.h, 5000.0), 1.0);
    EXPECT_GT(largest_response_eigenvalue(IntraBodyTensor::point_dipole, c.shape, c.h, 5000.0), 1.0);
  }
  EXPECT_LT(largest_response_eigenvalue(IntraBodyTensor::cell_average, Sphere{0.012}, 0.004, 5000.0), 1.0);
}

// Graded cells (docs/model.md "Graded cells") keep the operator the Galerkin
// energy of a tiling by cuboids: soft bodies relax, even at chi = infinity
// (gamma_D = 1/3), for cubes and bars of 4 .. 6 cells per axis.
TEST(IntraBodyTensor, GradedCellsKeepSoftBodiesStable) {
  const double inf = std::numeric_limits<double>::infinity();
  for (double chi : {inf, 5000.0}) {
    const double cube4 = largest_response_eigenvalue(IntraBodyTensor::cell_average, Box{{0.02, 0.02, 0.02}}, 0.005,
                                                     chi, true);
    const double cube6 = largest_response_eigenvalue(IntraBodyTensor::cell_average, Box{{0.03, 0.03, 0.03}}, 0.005,
                                                     chi, true);
    const double bar = largest_response_eigenvalue(IntraBodyTensor::cell_average, Box{{0.04, 0.02, 0.02}}, 0.005,
                                                   chi, true);
    std::printf("[odemag] graded cells, largest response eigenvalue at chi %g: cube 4^3 %.6f, 6^3 %.6f, bar 8x4x4 %.6f\n",
                chi, cube4, cube6, bar);
    EXPECT_LT(cube4, 1.0);
    EXPECT_LT(cube6, 1.0);
    EXPECT_LT(bar, 1.0);
  }
}

// Which bodies are graded (when the model asks for graded cells; off by
// default): responsive boxes of at least 4 cells per axis and at most
// kMaxGradedCells cells, with the cell-average tensor. Plates, rods,
// permanent magnets without recoil, balls and the point-dipole model keep
// the uniform lattice.
TEST(IntraBodyTensor, GradedCellsOnlyForResponsiveBoxesFourCellsAcross) {
  SoftMaterial iron;
  iron.saturation = 1.7e6;
  iron.susceptibility = 1000.0;
  const PermanentMaterial fixed{{0, 0, 1e6}, 0.0}, recoil{{0, 0, 1e6}, 0.05};
  MagneticModel model;
  EXPECT_FALSE(model.body(model.add_body("default", Box{{0.02, 0.02, 0.02}}, iron, 0.005)).cells.graded);  // off
  model.set_graded_cells(true);
  EXPECT_TRUE(model.body(model.add_body("cube", Box{{0.02, 0.02, 0.02}}, iron, 0.005)).cells.graded);
  EXPECT_TRUE(model.body(model.add_body("recoil", Box{{0.02, 0.02, 0.02}}, recoil, 0.005)).cells.graded);
  EXPECT_FALSE(model.body(model.add_body("fixed", Box{{0.02, 0.02, 0.02}}, fixed, 0.005)).cells.graded);
  EXPECT_FALSE(model.body(model.add_body("core", Box{{0.05, 0.05, 0.01}}, iron, 0.005)).cells.graded);  // 10 x 10 x 2
  EXPECT_FALSE(model.body(model.add_body("ball", Sphere{0.01}, iron, 0.004)).cells.graded);
  EXPECT_FALSE(model.body(model.add_body("big", Box{{0.055, 0.05, 0.05}}, iron, 0.005)).cells.graded);  // 1100 cells
  MagneticModel paper(IntraBodyTensor::point_dipole);
  paper.set_graded_cells(true);
  EXPECT_FALSE(paper.body(paper.add_body("cube", Box{{0.02, 0.02, 0.02}}, iron, 0.005)).cells.graded);
  // The graded cells tile the box: volumes add up, faces at the
  // Chebyshev-Lobatto points -cos(pi k / n) (here n = 4: 0, 1 - 1/sqrt 2, 1).
  const CellSet& c = model.body(1).cells;
  double total = 0.0;
  for (int i = 0; i < c.size(); ++i) total += c.volumes[i];
  EXPECT_NEAR(total, 8e-6, 1e-18);
  EXPECT_NEAR(c.local_positions[0].x - c.half_extents[0].x, -0.01, 1e-15);
  EXPECT_NEAR(c.local_positions[0].x + c.half_extents[0].x, -0.01 * std::sqrt(0.5), 1e-15);
  EXPECT_NEAR(c.local_positions[1].x + c.half_extents[1].x, 0.0, 1e-15);
}

// Cuboid-cuboid tensor (cuboid_demag_tensor): equal cubes give Newell's
// cube-cube tensor.
TEST(CuboidDemagTensor, EqualCubesGiveTheCubeTensor) {
  const double h = 1e-3, half[3] = {0.5 * h, 0.5 * h, 0.5 * h};
  for (int i = -4; i <= 4; ++i)
    for (int j = -3; j <= 3; ++j)
      for (int k = -2; k <= 5; ++k) {
        double n[6], m[6];
        const double d[3] = {i * h, j * h, k * h};
        cuboid_demag_tensor(half, half, d, n);
        cube_demag_tensor(i, j, k, h, m);
        for (int a = 0; a < 6; ++a) EXPECT_NEAR(n[a], m[a], 1e-12) << i << " " << j << " " << k << " " << a;
      }
}

// Superposition, exact for any placement (touching, overlapping, self): a
// cuboid made of two or four cubes acts, as a source, as the sum of its cubes
// and, as a target, takes the mean of the fields over its cubes.
TEST(CuboidDemagTensor, CompositeCuboidsAreSuperpositionsOfCubes) {
  const double h = 1.0, cube[3] = {0.5, 0.5, 0.5}, bar[3] = {1.0, 0.5, 0.5}, slab[3] = {1.0, 1.0, 0.5};
  // The bar's cubes sit at x = -/+ h/2 of its centre; the slab's at (+-h/2, +-h/2).
  for (const auto& d : std::vector<std::array<double, 3>>{
           {0.0, 0.0, 0.0}, {1.5, 0.0, 0.0}, {0.5, 1.0, 0.0}, {2.5, -1.0, 1.0}, {0.25, 0.3, 0.7}, {-3.5, 2.0, -1.0}}) {
    double n[6], ref[6] = {}, m[6];
    // Source bar, target cube: the sum over the bar's two cubes.
    cuboid_demag_tensor(cube, bar, d.data(), n);
    for (double sx : {-0.5, 0.5}) {
      const double e[3] = {d[0] - sx, d[1], d[2]};
      cube_demag_tensor_at(e, h, m);
      for (int a = 0; a < 6; ++a) ref[a] += m[a];
    }
    for (int a = 0; a < 6; ++a) EXPECT_NEAR(n[a], ref[a], 1e-12) << d[0] << " " << d[1] << " " << d[2] << " " << a;
    // Source cube, target slab: the mean over the slab's four cubes.
    cuboid_demag_tensor(slab, cube, d.data(), n);
    std::fill(ref, ref + 6, 0.0);
    for (double sx : {-0.5, 0.5})
      for (double sy : {-0.5, 0.5}) {
        const double e[3] = {d[0] + sx, d[1] + sy, d[2]};
        cube_demag_tensor_at(e, h, m);
        for (int a = 0; a < 6; ++a) ref[a] += 0.25 * m[a];
      }
    for (int a = 0; a < 6; ++a) EXPECT_NEAR(n[a], ref[a], 1e-12) << d[0] << " " << d[1] << " " << d[2] << " " << a;
  }
  // The bar's own tensor: trace 1, and its four cube pairs over its two cubes.
  double n[6];
  const double zero[3] = {0, 0, 0};
  cuboid_demag_tensor(bar, bar, zero, n);
  EXPECT_NEAR(n[0] + n[3] + n[5], 1.0, 1e-13);
  double self[6], pair[6];
  cube_demag_tensor(0, 0, 0, h, self);
  cube_demag_tensor(1, 0, 0, h, pair);
  for (int a = 0; a < 6; ++a) EXPECT_NEAR(n[a], self[a] + pair[a], 1e-13) << a;
}

// Reciprocity V_a N_ab = V_b N_ba, N(-d) = N(d), trace 0 apart.
TEST(CuboidDemagTensor, ReciprocityAndSymmetry) {
  const double a[3] = {0.3e-3, 0.5e-3, 0.2e-3}, b[3] = {0.7e-3, 0.25e-3, 0.4e-3};
  const double va = 8 * a[0] * a[1] * a[2], vb = 8 * b[0] * b[1] * b[2];
  for (const auto& d : std::vector<std::array<double, 3>>{
           {1.0e-3, 0.0, 0.0}, {0.3e-3, 0.75e-3, 0.1e-3}, {0.0, 0.0, 0.0}, {2e-3, -1e-3, 3e-3}, {-0.2e-3, 0.1e-3, 0.6e-3}}) {
    double nab[6], nba[6], neg[6];
    const double md[3] = {-d[0], -d[1], -d[2]};
    cuboid_demag_tensor(a, b, d.data(), nab);
    cuboid_demag_tensor(b, a, md, nba);
    cuboid_demag_tensor(a, b, md, neg);
    for (int c = 0; c < 6; ++c) {
      EXPECT_NEAR(va * nab[c], vb * nba[c], 1e-13 * va) << c;
      EXPECT_NEAR(nab[c], neg[c], 1e-13) << c;
    }
  }
  const double d[3] = {2e-3, -1e-3, 3e-3};  // apart: div H = 0
  double n[6];
  cuboid_demag_tensor(a, b, d, n);
  EXPECT_NEAR(n[0] + n[3] + n[5], 0.0, 1e-12);
}

// Unequal cuboids apart against brute-force quadrature of the dipole kernel
// over both volumes (Gauss-Legendre, 8 points per axis per cuboid), and far
// away against the point dipole V_b D(d) (first correction (size / r)^2).
TEST(CuboidDemagTensor, MatchesQuadratureAndThePointDipole) {
  static const double gx[8] = {-0.9602898564975363, -0.7966664774136267, -0.5255324099163290, -0.1834346424956498,
                               0.1834346424956498,  0.5255324099163290,  0.7966664774136267,  0.9602898564975363};
  static const double gw[8] = {0.1012285362903763, 0.2223810344533745, 0.3137066458778873, 0.3626837833783620,
                               0.3626837833783620, 0.3137066458778873, 0.2223810344533745, 0.1012285362903763};
  const double a[3] = {0.3, 0.5, 0.2}, b[3] = {0.7, 0.25, 0.4};
  for (const auto& d : std::vector<std::array<double, 3>>{{3.0, 0.5, 0.2}, {0.4, 2.5, -0.3}, {1.0, -1.0, 2.0}}) {
    double ref[6] = {};
    // Mean over a of the field of b with M = e_q: H = V_b-average of D(x - y) M.
    for (int i = 0; i < 8; ++i)
      for (int j = 0; j < 8; ++j)
        for (int k = 0; k < 8; ++k)
          for (int p = 0; p < 8; ++p)
            for (int q = 0; q < 8; ++q)
              for (int r = 0; r < 8; ++r) {
                const Vec3 x{d[0] + a[0] * gx[i], d[1] + a[1] * gx[j], d[2] + a[2] * gx[k]};
                const Vec3 y{b[0] * gx[p], b[1] * gx[q], b[2] * gx[r]};
                const double w = gw[i] * gw[j] * gw[k] * gw[p] * gw[q] * gw[r] / 64.0;
                double t[6];
                dipole_tensor(x - y, 0.0, t);
                for (int c = 0; c < 6; ++c) ref[c] -= w * t[c];
              }
    const double vb = 8 * b[0] * b[1] * b[2];
    double n[6], scale = 0.0;
    cuboid_demag_tensor(a, b, d.data(), n);
    for (int c = 0; c < 6; ++c) scale = std::max(scale, std::fabs(ref[c] * vb));
    for (int c = 0; c < 6; ++c) EXPECT_NEAR(n[c], ref[c] * vb, 1e-6 * scale) << d[0] << " " << c;
  }
  for (double r : {5.0, 10.0, 20.0, 40.0}) {
    const double d[3] = {r, 0.4 * r, -0.3 * r};
    double n[6], t[6], err = 0.0, scale = 0.0;
    cuboid_demag_tensor(a, b, d, n);
    dipole_tensor({d[0], d[1], d[2]}, 0.0, t);
    const double vb = 8 * b[0] * b[1] * b[2];
    for (int c = 0; c < 6; ++c) {
      err = std::max(err, std::fabs(n[c] + t[c] * vb));
      scale = std::max(scale, std::fabs(t[c] * vb));
    }
    const double dist = std::sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
    EXPECT_LT(err / scale, 2.0 / (dist * dist)) << r;  // edges ~ 1: (size / r)^2
  }
}

// The gradient of the unequal-cuboid tensor (cuboid_demag_tensor's dn, the
// lattice force's dN/dd): against central differences of the tensor (itself
// checked against quadrature above), near (overlapping projections, faces
// apart) and far (point dipole); odd in d; V_a dN_ab = V_b dN_ba; for equal
// cubes it is cube_demag_tensor_at's.
TEST(CuboidDemagTensor, GradientMatchesCentralDifferencesAndIsReciprocal) {
  const double a[3] = {0.3e-3, 0.5e-3, 0.2e-3}, b[3] = {0.7e-3, 0.25e-3, 0.4e-3};
  const double va = 8 * a[0] * a[1] * a[2], vb = 8 * b[0] * b[1] * b[2];
  for (const auto& d : std::vector<std::array<double, 3>>{{1.3e-3, 0.2e-3, 0.1e-3},
                                                          {0.3e-3, 0.9e-3, -0.15e-3},
                                                          {-0.2e-3, 0.1e-3, 0.75e-3},
                                                          {2e-3, -1e-3, 3e-3},
                                                          {30e-3, 12e-3, -9e-3}}) {
    double n[6], g[3][6], gba[3][6], gneg[3][6], unused[6];
    cuboid_demag_tensor(a, b, d.data(), n, g);
    const double md[3] = {-d[0], -d[1], -d[2]};
    cuboid_demag_tensor(b, a, d.data(), unused, gba);
    cuboid_demag_tensor(a, b, md, unused, gneg);
    double scale = 0.0;
    for (int k = 0; k < 3; ++k)
      for (int c = 0; c < 6; ++c) scale = std::max(scale, std::fabs(g[k][c]));
    ASSERT_GT(scale, 0.0);
    for (int k = 0; k < 3; ++k) {
      const double step = 1e-6 * std::sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
      double p[3] = {d[0], d[1], d[2]}, m[3] = {d[0], d[1], d[2]}, np[6], nm[6];
      p[k] += step, m[k] -= step;
      cuboid_demag_tensor(a, b, p, np);
      cuboid_demag_tensor(a, b, m, nm);
      for (int c = 0; c < 6; ++c) {
        // The difference quotient's round-off: the 64-term sums cancel digits a few edges apart.
        EXPECT_NEAR(g[k][c], (np[c] - nm[c]) / (2 * step), 1e-5 * scale) << d[0] << " " << k << " " << c;
        EXPECT_NEAR(g[k][c], -gneg[k][c], 1e-12 * scale) << k << " " << c;
        EXPECT_NEAR(va * g[k][c], vb * gba[k][c], 1e-10 * va * scale) << k << " " << c;
      }
    }
  }
  const double h = 1e-3, half[3] = {0.5e-3, 0.5e-3, 0.5e-3};
  for (const auto& d : std::vector<std::array<double, 3>>{{1.2e-3, 0.3e-3, -0.4e-3}, {0.0, 2e-3, 1e-3}}) {
    double n[6], g[3][6], nc[6], gc[3][6];
    cuboid_demag_tensor(half, half, d.data(), n, g);
    cube_demag_tensor_at(d.data(), h, nc, gc);
    for (int k = 0; k < 3; ++k)
      for (int c = 0; c < 6; ++c) EXPECT_NEAR(g[k][c], gc[k][c], 1e-12 / h) << k << " " << c;
  }
}

// The tabulated grid tensors (GridDemagTable, used for graded bodies) give
// cuboid_demag_tensor of the two cells, near and far (point dipole), on an
// uneven grid.
TEST(CuboidDemagTensor, GridTableMatchesTheCuboidTensor) {
  // Chebyshev-Lobatto faces (as graded cells) along x and y, and along z a
  // grid with a gap, so that some pairs are beyond kNewellRange edges.
  std::array<std::vector<double>, 3> faces;
  for (int k = 0; k <= 10; ++k) faces[0].push_back(-std::cos(kPi * k / 10));
  for (int k = 0; k <= 4; ++k) faces[1].push_back(-0.5 * std::cos(kPi * k / 4));
  faces[2] = {0.0, 0.1, 0.3, 0.35, 6.0, 6.2};
  const GridDemagTable table(faces);
  double worst = 0.0;
  int far = 0;
  for (int ax = 0; ax < 10; ++ax)
    for (int ay = 0; ay < 4; ++ay)
      for (int az = 0; az < 5; ++az)
        for (int bx = 0; bx < 10; ++bx)
          for (int by = 0; by < 4; ++by)
            for (int bz = 0; bz < 5; ++bz) {
              const int a[3] = {ax, ay, az}, b[3] = {bx, by, bz};
              double ha[3], hb[3], d[3], n[6], m[6], r2 = 0.0, edge = 0.0;
              for (int k = 0; k < 3; ++k) {
                const auto& F = faces[k];
                ha[k] = 0.5 * (F[a[k] + 1] - F[a[k]]), hb[k] = 0.5 * (F[b[k] + 1] - F[b[k]]);
                d[k] = 0.5 * (F[a[k]] + F[a[k] + 1]) - 0.5 * (F[b[k]] + F[b[k] + 1]);
                r2 += d[k] * d[k];
                edge = std::max({edge, 2 * ha[k], 2 * hb[k]});
              }
              if (r2 > kNewellRange * kNewellRange * edge * edge) ++far;
              table.tensor({ax, ay, az}, {bx, by, bz}, n);
              cuboid_demag_tensor(ha, hb, d, m);
              double scale = 0.0, diff = 0.0;
              for (int c = 0; c < 6; ++c) scale = std::max(scale, std::fabs(m[c])), diff = std::max(diff, std::fabs(n[c] - m[c]));
              worst = std::max(worst, diff / scale);
            }
  std::printf("[odemag] grid table against cuboid_demag_tensor: largest difference %.2e of the tensor\n", worst);
  EXPECT_GT(far, 0);
  // Both lose digits to the cancellation of the 64-term sums towards
  // kNewellRange edges, the table summing the same terms from differently
  // rounded arguments (measured 9.3e-8 of the tensor, at 16 edges).
  EXPECT_LT(worst, 2e-7);
}

// The CPU backend's intra-body field of a turned graded body with a
// non-uniform magnetization: -sum_j N_ij M_j without the cube's I/3 self term
// (the local relaxation's), the sum written out here from cuboid_demag_tensor
// of the cells' cuboids (positions and half extents of the cell set).
TEST(CuboidDemagTensor, CpuBackendSumsGradedCells) {
  MagneticModel model;
  model.set_graded_cells(true);
  SoftMaterial iron;
  iron.saturation = 1.7e6;
  iron.susceptibility = 1000.0;
  model.add_body("bar", Box{{0.02, 0.015, 0.01}}, iron, 0.0025);  // 8 x 6 x 4 graded cells
  const MagneticBody& body = model.body(0);
  ASSERT_TRUE(body.cells.graded);
  MagneticState state = make_state(model);
  state.pose[0].rotation = rotation_from_quaternion(0.9, 0.2, -0.3, 0.25);
  state.pose[0].position = {0.1, -0.05, 0.02};
  place_cells(model, state);
  const int n = body.cell_count();
  std::vector<Vec3> M_body(n);  // body frame
  for (int i = 0; i < n; ++i) {
    const Vec3& p = body.cells.local_positions[i];
    M_body[i] = Vec3{1e5 + 3e6 * p.y, -2e5 + 5e6 * p.z * p.x / 0.01, 4e5 - 2e7 * p.x};
    state.magnetization[i] = state.pose[0].rotation * M_body[i];
  }
  auto backend = make_cpu_backend(1);
  backend->begin_step(model, state);
  std::vector<Vec3> H(model.cell_count());
  backend->responsive_field(model, state, H);
  double worst = 0.0, scale = 0.0;
  for (int i = 0; i < n; ++i) {
    Vec3 h;
    for (int j = 0; j < n; ++j) {
      const Vec3 &a = body.cells.half_extents[i], &b = body.cells.half_extents[j];
      const Vec3 r = body.cells.local_positions[i] - body.cells.local_positions[j];
      const double ha[3] = {a.x, a.y, a.z}, hb[3] = {b.x, b.y, b.z}, d[3] = {r.x, r.y, r.z};
      double N[6];
      cuboid_demag_tensor(ha, hb, d, N);
      if (i == j) N[0] -= 1.0 / 3.0, N[3] -= 1.0 / 3.0, N[5] -= 1.0 / 3.0;
      const Vec3& m = M_body[j];
      h -= Vec3{N[0] * m.x + N[1] * m.y + N[2] * m.z, N[1] * m.x + N[3] * m.y + N[4] * m.z,
                N[2] * m.x + N[4] * m.y + N[5] * m.z};
    }
    const Vec3 expected = state.pose[0].rotation * h;
    worst = std::max(worst, norm(H[i] - expected));
    scale = std::max(scale, norm(expected));
  }
  EXPECT_LT(worst, 1e-10 * scale);
  // The body's moment is the volume-weighted sum.
  Vec3 moment;
  for (int i = 0; i < n; ++i) moment += body.cells.volumes[i] * state.magnetization[i];
  EXPECT_LT(norm(body_moment(model, state, 0) - moment), 1e-12 * norm(moment));
}

}  // namespace
}  // namespace odemag
