// The intra-body tensors (magnetics/demag_tensor.h): exact properties of the
// cube-cube demagnetising tensor, and the stability that motivates it.
#include "magnetics/demag_tensor.h"

#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <cmath>

#include "magnetics/kernels.h"
#include "magnetics/model.h"
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
double largest_response_eigenvalue(IntraBodyTensor kind, const Shape& shape, double h, double chi) {
  const MagneticModel model = test_support::soft_body_model(kind, shape, h, chi);
  const MagneticBody& b = model.body(0);
  const int n = b.cell_count();
  Eigen::MatrixXd G = Eigen::MatrixXd::Zero(3 * n, 3 * n);
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) {
      if (i == j) continue;
      const double* t = &b.offset_tensors[6u * b.offset_index(b.cells.lattice_index[i], b.cells.lattice_index[j])];
      const double T[3][3] = {{t[0], t[1], t[2]}, {t[1], t[3], t[4]}, {t[2], t[4], t[5]}};
      for (int p = 0; p < 3; ++p)
        for (int q = 0; q < 3; ++q) G(3 * i + p, 3 * j + q) = T[p][q] * b.cells.cell_volume / b.soft.gamma_D;
    }
  return Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(G).eigenvalues().maxCoeff();
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

}  // namespace
}  // namespace odemag
