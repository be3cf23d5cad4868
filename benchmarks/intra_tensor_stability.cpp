// Why the intra-body tensor is the cube-cube average (docs/model.md): the
// largest eigenvalue of the linear response map M -> H_intra(M) / gamma_D of
// soft iron bodies (chi = 5000). Above 1 the body magnetizes itself in
// patterns without any applied field. Output: CSV on stdout.
#include <Eigen/Dense>
#include <cmath>
#include <cstdio>

#include "magnetics/model.h"

using namespace odemag;

// H_i = sum_j F_ij V_j M_j with F symmetric: the lattice tensors, and for
// bodies with boundary cells the boundary correction (self and uniform-mode
// tensors, magnetics/model.cpp). The map is similar to W^1/2 F W^1/2 / gamma_D
// (W = diag V), which is symmetric.
double largest_eigenvalue(IntraBodyTensor kind, const Shape& shape, double h, double chi) {
  MagneticModel model(kind);
  SoftMaterial iron;
  iron.saturation = 1.7e6;
  iron.susceptibility = chi;
  model.add_body("body", shape, iron, h);
  const MagneticBody& b = model.body(0);
  const int n = b.cell_count();
  auto mat = [](const double* t) {
    Eigen::Matrix3d m;
    m << t[0], t[1], t[2], t[1], t[3], t[4], t[2], t[4], t[5];
    return m;
  };
  const bool corrected = !b.self_tensors.empty();
  Eigen::Matrix3d Gpi = Eigen::Matrix3d::Zero(), Gbeta = Eigen::Matrix3d::Zero();
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) Gpi(r, c) = b.uniform_inverse[0].m[r][c], Gbeta(r, c) = b.uniform_inverse[1].m[r][c];
  Eigen::MatrixXd G = Eigen::MatrixXd::Zero(3 * n, 3 * n);
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) {
      Eigen::Matrix3d F = Eigen::Matrix3d::Zero();
      if (i != j) F = mat(&b.offset_tensors[6u * b.offset_index(b.cells.lattice_index[i], b.cells.lattice_index[j])]);
      if (corrected) {
        if (i == j) F += mat(&b.self_tensors[6u * i]);
        F += mat(&b.uniform_tensors[12u * i]) * Gpi * mat(&b.uniform_tensors[12u * j]) -
             mat(&b.uniform_tensors[12u * i + 6]) * Gbeta * mat(&b.uniform_tensors[12u * j + 6]);
      }
      G.block<3, 3>(3 * i, 3 * j) = std::sqrt(b.cells.volumes[i] * b.cells.volumes[j]) / b.soft.gamma_D * F;
    }
  G = 0.5 * (G + G.transpose());
  return Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(G, Eigen::EigenvaluesOnly).eigenvalues().maxCoeff();
}

int main() {
  struct Case {
    const char* name;
    Shape shape;
    double h;
  };
  const Case cases[] = {{"plate_5x5x1", Box{{0.02, 0.02, 0.004}}, 0.004},
                        {"plate_10x10x1", Box{{0.04, 0.04, 0.004}}, 0.004},
                        {"plate_10x10x2", Box{{0.02, 0.02, 0.004}}, 0.002},
                        {"cube_5x5x5", Box{{0.02, 0.02, 0.02}}, 0.004},
                        {"bar_20x2x2", Box{{0.1, 0.01, 0.01}}, 0.005},
                        {"sphere_R3h", Sphere{0.012}, 0.004}};
  std::printf("body,cells,chi,point_dipole,cell_average\n");
  for (const Case& c : cases)
    for (double chi : {10.0, 100.0, 5000.0}) {
      MagneticModel probe;
      SoftMaterial iron;
      iron.saturation = 1.7e6;
      probe.add_body("b", c.shape, iron, c.h);
      std::printf("%s,%d,%g,%.4f,%.4f\n", c.name, probe.cell_count(), chi,
                  largest_eigenvalue(IntraBodyTensor::point_dipole, c.shape, c.h, chi),
                  largest_eigenvalue(IntraBodyTensor::cell_average, c.shape, c.h, chi));
    }
  return 0;
}
