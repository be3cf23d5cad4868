// Why the intra-body tensor is the cube-cube average (docs/model.md): the
// largest eigenvalue of the linear response map M -> H_intra(M) / gamma_D of
// soft iron bodies (chi = 5000). Above 1 the body magnetizes itself in
// patterns without any applied field. Output: CSV on stdout.
#include <Eigen/Dense>
#include <cstdio>

#include "magnetics/model.h"

using namespace odemag;

double largest_eigenvalue(IntraBodyTensor kind, const Shape& shape, double h, double chi) {
  MagneticModel model(kind);
  SoftMaterial iron;
  iron.saturation = 1.7e6;
  iron.susceptibility = chi;
  model.add_body("body", shape, iron, h);
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
