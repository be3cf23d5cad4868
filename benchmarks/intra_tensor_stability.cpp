// Why the intra-body tensor is the cube-cube average (docs/model.md): the
// largest eigenvalue of the linear response map M -> H_intra(M) / gamma_D of
// soft iron bodies (chi = 5000). Above 1 the body magnetizes itself in
// patterns without any applied field. Output: CSV on stdout.
#include <cstdio>

#include "magnetics/model/model.h"
#include "tests/support/magnetic_checks.h"

using namespace odemag;

// The corrected operator where the body has boundary cells
// (tests/support/magnetic_checks.h).
double largest_eigenvalue(IntraBodyTensor kind, const Shape& shape, double h, double chi) {
  const MagneticModel model = test_support::soft_body_model(kind, shape, h, chi);
  return test_support::largest_response_eigenvalue(model.body(0));
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
