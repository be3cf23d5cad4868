// Field probes next to bodies whose cells are not cubes of edge h
// (magnetics/relax/field_probe.cpp, CellSet::solid_half): graded cells,
// refined zones and a box's boundary cells, each evaluated as the solid it
// stands for, so that probes agree with the forces. References: the
// face-charge field of a uniformly magnetized box and the field of a
// uniformly magnetized sphere (tests/support/reference_fields.h), for weak
// soft bodies (chi = 1e-3) whose magnetization is uniform to 1e-3 of itself.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <vector>

#include "magnetics/model/backend.h"
#include "magnetics/model/model.h"
#include "magnetics/model/state.h"
#include "magnetics/relax/relax.h"
#include "tests/support/reference_fields.h"

namespace odemag {
namespace {

constexpr double kChi = 1e-3;
const Vec3 kH0{0.0, 0.0, 1e4};

SoftMaterial weak() {
  SoftMaterial s;
  s.saturation = 1e9;
  s.susceptibility = kChi;
  return s;
}

// B - mu0 H0 (T) at the points, the body relaxed in H0.
std::vector<Vec3> induced_field(MagneticModel& model, const std::vector<Vec3>& points) {
  MagneticState state = make_state(model);
  state.external_field = kH0;
  auto backend = make_cpu_backend(1);
  RelaxOptions o;
  o.tolerance = 1e-10;
  EXPECT_TRUE(relax(model, state, o, *backend).converged);
  std::vector<Vec3> B, H;
  field_at_points(model, state, *backend, points, B, H);
  for (Vec3& b : B) b -= reference::kRefMu0 * kH0;
  return B;
}

// A 10 mm cube of graded cells, and one of a lattice whose h leaves boundary
// slabs: 0.5 mm above its top face, across the face, the induced field within
// 1% of the uniformly magnetized cube's (M = chi H0 / (1 + N chi), N = 1/3
// to the accuracy needed here; its sign is that of H0 above the face).
TEST(FieldProbe, NextToGradedAndPartialBoxCellsAsTheUniformCube) {
  const double c = 0.01;
  const Vec3 M = (kChi / (1.0 + kChi / 3.0)) * kH0;
  const reference::CuboidMagnet uniform{{c, c, c}, M, Mat3{}, {}};
  std::vector<Vec3> points;
  for (double x : {0.0, 0.002, 0.0045}) points.push_back({x, 0.001, 0.5 * c + 0.0005});
  for (const bool graded : {true, false}) {
    MagneticModel model;
    model.set_graded_cells(graded);
    model.add_body("cube", Box{{c, c, c}}, weak(), graded ? c / 8.0 : c / 5.4);
    ASSERT_EQ(model.body(0).cells.graded, graded);
    const std::vector<Vec3> B = induced_field(model, points);
    for (std::size_t p = 0; p < points.size(); ++p) {
      const Vec3 exact = uniform.field(points[p]).B;
      std::printf("%s: B_z %.4e T, exact %.4e T\n", graded ? "graded" : "boundary slabs", B[p].z, exact.z);
      EXPECT_GT(exact.z, 0.0);
      EXPECT_LT(norm(B[p] - exact), 0.01 * norm(exact)) << (graded ? "graded" : "slabs") << " point " << p;
    }
  }
}

// A lattice ball with a refined zone at its top: beside the zone the induced
// field within 1% of the uniformly magnetized sphere's (M = 3 chi / (chi + 3) H0).
TEST(FieldProbe, NextToARefinedZoneAsTheUniformSphere) {
  const double R = 0.005, h = R / 4.5;
  MagneticModel model;
  model.add_body("ball", Sphere{R}, weak(), h, {{{0.0, 0.0, R}, default_refinement_radii(h)}});
  ASSERT_TRUE(model.body(0).cells.refined);
  const Vec3 M = (3.0 * kChi / (kChi + 3.0)) * kH0;
  std::vector<Vec3> points = {{0.0, 0.0, 1.1 * R}, {0.0008, 0.0003, 1.05 * R}, {0.002, 0.0, 1.0 * R}};
  const std::vector<Vec3> B = induced_field(model, points);
  for (std::size_t p = 0; p < points.size(); ++p) {
    const Vec3 exact = reference::sphere_field(R, M, {}, points[p]).B;
    std::printf("refined: |B| %.4e T, exact %.4e T\n", norm(B[p]), norm(exact));
    EXPECT_LT(norm(B[p] - exact), 0.01 * norm(exact)) << "point " << p;
  }
}

}  // namespace
}  // namespace odemag
