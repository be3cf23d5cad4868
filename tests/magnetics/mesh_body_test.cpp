// Mesh and compound bodies against independent references written in the
// tests (docs/model.md "Meshes"): meshed balls, boxes and cylinders against
// the primitives and their closed forms, a soft ellipsoid against Osborn's
// demagnetising factors, a prism magnet against the field of its face
// charges, and two half boxes against the whole box.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <vector>

#include "magnetics/cells/cells.h"
#include "magnetics/model/backend.h"
#include "magnetics/model/model.h"
#include "magnetics/model/state.h"
#include "magnetics/relax/relax.h"
#include "odemag/constants.h"
#include "tests/support/contact_references.h"
#include "tests/support/mesh_builders.h"
#include "tests/support/reference_fields.h"

namespace odemag {
namespace {

SoftMaterial linear_soft(double chi) {
  SoftMaterial m;
  m.saturation = 1e12;  // linear
  m.susceptibility = chi;
  return m;
}

// The moment of a soft body in the uniform field H0 (relaxed to 1e-6: a mesh
// body's residual stalls between 1e-7 and 1e-8, docs/model.md "Meshes").
Vec3 soft_moment(const Shape& shape, double chi, double h, const Vec3& H0, int* cells = nullptr) {
  MagneticModel model;
  model.add_body("body", shape, linear_soft(chi), h);
  MagneticState state = make_state(model, 7);
  state.external_field = H0;
  RelaxOptions o;
  o.tolerance = 1e-6;
  o.max_iterations = 500;
  auto backend = make_cpu_backend(2);
  EXPECT_TRUE(relax(model, state, o, *backend).converged);
  if (cells) *cells = model.cell_count();
  return body_moment(model, state, 0);
}

// 1. A meshed ball (icosahedron subdivided 5 times, scaled to the ball's
// volume) in a uniform field: the continuum sphere's moment 4 pi R^3 chi /
// (chi + 3) H0 and the primitive ball's, at the same cell size, within 1%.
TEST(MeshBody, MeshedBallHasTheSphereMoment) {
  const double R = 0.01;
  Mesh ball = test::ellipsoid_mesh(R, R, R, 5);
  const double k = std::cbrt(4.0 / 3.0 * kPi * R * R * R / shape_volume(ball));
  ball = test::ellipsoid_mesh(k * R, k * R, k * R, 5);
  const Vec3 H0{0.0, 3e3, 4e3};
  for (double chi : {10.0, 1000.0}) {
    for (double h : {R / 3.0, R / 4.0}) {
      int cells = 0;
      const Vec3 m = soft_moment(ball, chi, h, H0, &cells);
      const Vec3 p = soft_moment(Sphere{R}, chi, h, H0);
      const double exact = 4.0 * kPi * R * R * R * chi / (chi + 3.0) * norm(H0);
      std::printf("[odemag] meshed ball chi %g R/h %.0f: %d cells, moment %.3e (sphere %.3e, primitive %.3e)\n", chi,
                  R / h, cells, norm(m), exact, norm(p));
      EXPECT_NEAR(dot(m, normalized(H0)) / exact, 1.0, 0.01) << chi << " " << h;
      EXPECT_NEAR(norm(m - p) / norm(p), 0.0, 0.01) << chi << " " << h;
    }
  }
}

// 2. A meshed box magnet: its field outside against the closed form of the
// uniformly magnetized cuboid (reference_fields.h) within 1%, with the box's
// faces on the lattice's planes and off them; and the primitive box's where
// its edges are multiples of h. (Off the planes, at h = 1.7 mm, the
// primitive's centre-inside cells were 2.2% to 4.7% off the closed form at
// these points and the mesh's volume shares within 0.3%.)
TEST(MeshBody, MeshedBoxMagnetHasTheCuboidField) {
  const Vec3 size{0.012, 0.008, 0.006};
  const Vec3 M{2e5, -1e5, 8e5};
  for (double h : {0.002, 0.0017}) {
    MagneticModel model;
    model.add_body("mesh", test::box_surface_mesh(size, 3), PermanentMaterial{M, 0.0}, h);
    model.add_body("box", Box{size}, PermanentMaterial{M, 0.0}, h);
    MagneticState state = make_state(model);
    state.pose[1].position = {1.0, 0.0, 0.0};  // far apart: each one's own field
    auto backend = make_cpu_backend(1);
    RelaxOptions o;
    magnetic_step(model, state, o, *backend);
    for (const Vec3& p : {Vec3{0.0, 0.0, 0.009}, Vec3{0.012, 0.003, 0.0}, Vec3{-0.004, -0.011, 0.005}}) {
      std::vector<Vec3> B, H;
      field_at_points(model, state, *backend, {p, p + state.pose[1].position}, B, H);
      const reference::FieldHB ref = reference::cuboid_field_local(size, M, p);
      EXPECT_LT(norm(H[0] - ref.H) / norm(ref.H), 0.01) << "h " << h << " at " << p.x << " " << p.y << " " << p.z;
      if (h == 0.002) {
        EXPECT_LT(norm(H[0] - H[1]) / norm(ref.H), 0.01) << "h " << h;
      }
      std::printf("[odemag] meshed box h %g mm: error %.2e, primitive box %.2e\n", h * 1e3,
                  norm(H[0] - ref.H) / norm(ref.H), norm(H[1] - ref.H) / norm(ref.H));
    }
    EXPECT_NEAR(body_moment(model, state, 0).z, M.z * size.x * size.y * size.z, 1e-9 * M.z * size.x * size.y * size.z);
  }
}

// 3. Meshed cylinders (prisms of 256 sides of the cylinder's area): the force
// between two coaxial magnets against the Bessel-integral reference
// (contact_references.h) and the primitive cylinders', within 1%.
TEST(MeshBody, MeshedCylindersHaveTheCoaxialForce) {
  const double a = 0.005, L = 0.01, M = 1e6, gap = 0.002;
  const double F_ref = reference::coaxial_cylinder_force(a, L, L, M, M, gap);
  const Mesh cyl = test::cylinder_mesh(a, L, 256, 4);
  for (double k : {4.0, 5.0}) {
    double force[2] = {};
    int cells = 0;
    for (int primitive = 0; primitive < 2; ++primitive) {
      MagneticModel model;
      for (const char* name : {"lower", "upper"}) {
        if (primitive) model.add_body(name, Cylinder{a, L}, PermanentMaterial{{0, 0, M}, 0.0}, a / k);
        else model.add_body(name, cyl, PermanentMaterial{{0, 0, M}, 0.0}, a / k);
      }
      MagneticState state = make_state(model);
      state.pose[1].position = {0.0, 0.0, L + gap};
      RelaxOptions o;
      o.near_field = false;
      auto backend = make_cpu_backend(1);
      magnetic_step(model, state, o, *backend);
      force[primitive] = state.force[1].z;
      if (!primitive) cells = model.body(0).cell_count();
    }
    std::printf("[odemag] meshed cylinders R/h %g: %d cells each, force %.4f N (reference %.4f, primitive %.4f)\n", k,
                cells, force[0], F_ref, force[1]);
    EXPECT_NEAR(force[0] / F_ref, 1.0, 0.01) << k;
    EXPECT_NEAR(force[0] / force[1], 1.0, 0.01) << k;
  }
}

// 3b. The same cylinders 0.2 mm apart with the near field on (the aligned
// lattices' close cells coupled as cubes): the Bessel-integral force within
// 1%, as the primitive cylinders.
TEST(MeshBody, MeshedCylindersNearContactWithTheNearField) {
  const double a = 0.005, L = 0.01, M = 1e6, gap = 0.0002;
  const double F_ref = reference::coaxial_cylinder_force(a, L, L, M, M, gap);
  const Mesh cyl = test::cylinder_mesh(a, L, 256, 4);
  MagneticModel model;
  model.add_body("lower", cyl, PermanentMaterial{{0, 0, M}, 0.0}, a / 5);
  model.add_body("upper", cyl, PermanentMaterial{{0, 0, M}, 0.0}, a / 5);
  MagneticState state = make_state(model);
  state.pose[1].position = {0.0, 0.0, L + gap};
  auto backend = make_cpu_backend(1);
  magnetic_step(model, state, RelaxOptions{}, *backend);
  std::printf("[odemag] meshed cylinders 0.2 mm apart, near field: force %.4f N (reference %.4f)\n",
              state.force[1].z, F_ref);
  EXPECT_NEAR(state.force[1].z / F_ref, 1.0, 0.01);
}

// 3c. Refined zones on a mesh body (make_refined_cells): the sub-cubes'
// shares still add up to the mesh's volume, and a soft meshed ball refined
// towards a magnet gets the refined primitive ball's force within 1%.
TEST(MeshBody, RefinedZonesOnAMeshBall) {
  const double R = 0.005, h = R / 3;
  const Mesh ball = test::ellipsoid_mesh(R, R, R, 5);
  const std::vector<RefinedZone> zones = {{{0, 0, -R}, default_refinement_radii(h)}};
  const CellSet cells = make_refined_cells(ball, h, zones);
  double v = 0.0;
  for (double x : cells.volumes) v += x;
  EXPECT_NEAR(v / shape_volume(ball), 1.0, 1e-9);
  EXPECT_GT(cells.size(), make_cells(ball, h).size());
  double force[2] = {};
  for (int primitive = 0; primitive < 2; ++primitive) {
    MagneticModel model;
    model.add_body("magnet", Cylinder{0.006, 0.01}, PermanentMaterial{{0, 0, 9e5}, 0.0}, 0.002);
    const Shape shape = primitive ? Shape{Sphere{R}} : Shape{ball};
    model.add_body("ball", shape, linear_soft(1000.0), h, zones);
    MagneticState state = make_state(model, 7);
    state.pose[1].position = {0.0, 0.0, 0.005 + R + 0.0002};
    RelaxOptions o;
    o.tolerance = 1e-6;
    o.max_iterations = 500;
    auto backend = make_cpu_backend(2);
    EXPECT_TRUE(relax(model, state, o, *backend).converged);
    magnetic_step(model, state, o, *backend);
    force[primitive] = state.force[1].z;
  }
  std::printf("[odemag] refined meshed ball on a magnet: force %.4f N (primitive %.4f)\n", force[0], force[1]);
  EXPECT_NEAR(force[0] / force[1], 1.0, 0.01);
}

// Osborn (1945): demagnetising factors of the ellipsoid of semi-axes a >= b
// >= c, with cos theta = c / a, cos phi = b / a, sin alpha = sin phi / sin
// theta, and F, E the incomplete elliptic integrals of amplitude theta and
// modulus sin alpha:
//   N_a = cos phi cos theta / (sin^3 theta sin^2 alpha) (F - E)
//   N_b = cos phi cos theta / (sin^3 theta sin^2 alpha cos^2 alpha)
//         (E - cos^2 alpha F - sin^2 alpha sin theta cos theta / cos phi)
//   N_c = cos phi cos theta / (sin^3 theta cos^2 alpha) (sin theta cos phi / cos theta - E)
// F and E by 64-point Gauss-Legendre on [0, theta] (smooth integrands).
void osborn_factors(double a, double b, double c, double N[3]) {
  const double ct = c / a, cp = b / a, st = std::sqrt(1.0 - ct * ct), sp = std::sqrt(1.0 - cp * cp);
  const double sa = sp / st, ca2 = 1.0 - sa * sa, theta = std::acos(ct);
  std::vector<double> x, w;
  reference::gauss_legendre(64, x, w);
  double F = 0.0, E = 0.0;
  for (size_t i = 0; i < x.size(); ++i) {
    const double t = 0.5 * theta * (x[i] + 1.0), wt = 0.5 * theta * w[i];
    const double d = std::sqrt(1.0 - sa * sa * std::sin(t) * std::sin(t));
    F += wt / d;
    E += wt * d;
  }
  const double pre = cp * ct / (st * st * st);
  N[0] = pre / (sa * sa) * (F - E);
  N[1] = pre / (sa * sa * ca2) * (E - ca2 * F - sa * sa * st * ct / cp);
  N[2] = pre / ca2 * (st * cp / ct - E);
}

// The same factors as the integral N_i = (abc / 2) int_0^inf ds / ((s + a_i^2)
// sqrt((s + a^2)(s + b^2)(s + c^2))), by the substitution s = c^2 (1 / v^2 -
// 1) (a smooth integrand on (0, 1]) and 20000 midpoints: a check of the
// transcription.
double ellipsoid_factor_integral(double a, double b, double c, int axis) {
  const double ai[3] = {a, b, c};
  const int n = 20000;
  double sum = 0.0;
  for (int k = 0; k < n; ++k) {
    const double v = (k + 0.5) / n, s = c * c * (1.0 / (v * v) - 1.0), ds = 2.0 * c * c / (v * v * v) / n;
    sum += ds / ((s + ai[axis] * ai[axis]) * std::sqrt((s + a * a) * (s + b * b) * (s + c * c)));
  }
  return 0.5 * a * b * c * sum;
}

TEST(MeshBody, OsbornFactorsAreTranscribedRight) {
  double N[3];
  osborn_factors(0.012, 0.008, 0.005, N);
  EXPECT_NEAR(N[0] + N[1] + N[2], 1.0, 1e-12);
  for (int i = 0; i < 3; ++i) EXPECT_NEAR(N[i], ellipsoid_factor_integral(0.012, 0.008, 0.005, i), 1e-6) << i;
}

// 4. A soft ellipsoid mesh (semi-axes 12, 8, 5 mm; the icosahedron
// subdivided 5 times) in a uniform field along each axis: M = chi / (1 +
// chi N_i) H0 with Osborn's N_i, within 2%, at most 3000 cells.
TEST(MeshBody, SoftEllipsoidHasOsbornsMoment) {
  const double a = 0.012, b = 0.008, c = 0.005;
  const Mesh e = test::ellipsoid_mesh(a, b, c, 5);
  double N[3];
  osborn_factors(a, b, c, N);
  const double V = 4.0 / 3.0 * kPi * a * b * c;
  for (double chi : {10.0, 1000.0})
    for (int axis = 0; axis < 3; ++axis) {
      Vec3 H0;
      H0[axis] = 1e3;
      int cells = 0;
      const Vec3 m = soft_moment(e, chi, 0.0011, H0, &cells);
      const double ref = V * chi / (1.0 + chi * N[axis]) * 1e3;
      std::printf("[odemag] soft ellipsoid chi %g axis %d: %d cells, moment %.4e (Osborn %.4e, N %.4f)\n", chi, axis,
                  cells, m[axis], ref, N[axis]);
      EXPECT_LE(cells, 3000);
      EXPECT_NEAR(m[axis] / ref, 1.0, 0.02) << "chi " << chi << " axis " << axis;
    }
}

// 5. A uniformly magnetized triangular prism (edge 10 mm, length 15 mm):
// the field one edge away from it against the field of its face charges by
// quadrature (test::face_charge_H), within 1%.
TEST(MeshBody, PrismMagnetHasTheFieldOfItsFaceCharges) {
  const double e = 0.01;
  const Mesh prism = mesh_centred(test::prism_mesh({{0.0, 0.0}, {e, 0.0}, {0.3 * e, 0.8 * e}}, 1.5 * e));
  const Vec3 M{3e5, -1e5, 6e5};
  MagneticModel model;
  model.add_body("prism", prism, PermanentMaterial{M, 0.0}, e / 5.0);
  MagneticState state = make_state(model);
  auto backend = make_cpu_backend(1);
  magnetic_step(model, state, RelaxOptions{}, *backend);
  const std::vector<Vec3> points = {{0.0, 0.0, 0.75 * e + e}, {0.0, 0.0, -1.75 * e}, {1.6 * e, 0.3 * e, 0.1 * e},
                                    {-0.3 * e, -1.3 * e, 0.2 * e}};
  std::vector<Vec3> B, H;
  field_at_points(model, state, *backend, points, B, H);
  for (size_t i = 0; i < points.size(); ++i) {
    const Vec3 ref = test::face_charge_H(prism, M, points[i]);
    std::printf("[odemag] prism magnet at point %zu: |H| %.1f A/m, error %.2e\n", i, norm(ref),
                norm(H[i] - ref) / norm(ref));
    EXPECT_LT(norm(H[i] - ref) / norm(ref), 0.01) << i;
  }
}

// 6. Two half boxes as one compound against the whole box: a soft box's
// moment in a uniform field and a magnet's force on it, within 0.5%, with
// the seam on a lattice plane and off it.
TEST(MeshBody, CompoundOfTwoHalfBoxesIsTheBox) {
  const Vec3 size{0.010, 0.006, 0.004};
  for (double seam : {0.0, 0.0013}) {
    const double left = 0.5 * size.x + seam, right = 0.5 * size.x - seam;
    std::vector<CompoundPart> parts(2);
    parts[0].shape = Box{{left, size.y, size.z}};
    parts[0].position = {-0.5 * size.x + 0.5 * left, 0.0, 0.0};
    parts[1].shape = test::box_surface_mesh({right, size.y, size.z}, 1);
    parts[1].position = {0.5 * size.x - 0.5 * right, 0.0, 0.0};
    const Compound compound(parts);
    EXPECT_NEAR(shape_volume(compound), size.x * size.y * size.z, 1e-12 * size.x * size.y * size.z);
    const Vec3 H0{2e3, 1e3, -1e3};
    const Vec3 mc = soft_moment(compound, 1000.0, 0.001, H0), mb = soft_moment(Box{size}, 1000.0, 0.001, H0);
    std::printf("[odemag] two half boxes, seam %g mm: moment %.5e (box %.5e)\n", seam * 1e3, norm(mc), norm(mb));
    EXPECT_LT(norm(mc - mb) / norm(mb), 0.005) << seam;
  }
}

}  // namespace
}  // namespace odemag
