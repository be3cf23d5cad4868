// Mesh geometry (magnetics/cells/mesh.h): the checks of a mesh, its exact
// integrals, the inside test, the part of a box inside it and the field of
// its face charges, each against a reference written here.
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

#include "magnetics/cells/mesh.h"
#include "odemag/constants.h"
#include "tests/support/mesh_builders.h"

namespace odemag {
namespace {

using test::Triangles;

// The octahedron |x| + |y| + |z| <= a: volume 4 a^3 / 3, integral of x^2
// 8 * a^5 / 60 (Dirichlet's integral over the corner simplex, times 8).
TEST(MeshIntegrals, OctahedronVolumeAndInertia) {
  const double a = 0.03;
  const Vec3 shift{0.01, -0.02, 0.005};
  std::vector<Vec3> v = test::octahedron_mesh(a).vertices();
  for (Vec3& x : v) x = x + shift;
  const Mesh m(v, test::octahedron_mesh(a).triangles());
  const MassIntegrals I = mesh_mass_integrals(m);
  const double V = 4.0 * a * a * a / 3.0;
  EXPECT_NEAR(I.volume, V, 1e-14 * V);
  EXPECT_NEAR(norm(I.centroid - shift), 0.0, 1e-15);
  // About the centroid: integral x^2 = 2 a^5 / 15, no products.
  const Mesh c = mesh_centred(m);
  const Mat3 J = inertia_from_second_moments(mesh_mass_integrals(c).second);
  const double ixx = 2.0 * 2.0 * std::pow(a, 5) / 15.0;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) EXPECT_NEAR(J.m[i][j], i == j ? ixx : 0.0, 1e-12 * ixx) << i << j;
}

// A box mesh's inertia is the box's, (m / 12)(b^2 + c^2).
TEST(MeshIntegrals, BoxMeshInertiaIsTheBoxes) {
  const Vec3 s{0.02, 0.03, 0.05};
  const Mesh m = test::box_surface_mesh(s, 3);
  const double V = s.x * s.y * s.z;
  const Mat3 J = shape_unit_inertia(m);
  EXPECT_NEAR(shape_volume(m), V, 1e-14 * V);
  EXPECT_NEAR(J.m[0][0], V * (s.y * s.y + s.z * s.z) / 12.0, 1e-12 * V * 1e-3);
  EXPECT_NEAR(J.m[1][1], V * (s.x * s.x + s.z * s.z) / 12.0, 1e-12 * V * 1e-3);
  EXPECT_NEAR(J.m[2][2], V * (s.x * s.x + s.y * s.y) / 12.0, 1e-12 * V * 1e-3);
  EXPECT_NEAR(J.m[0][1], 0.0, 1e-20);
}

TEST(MeshIntegrals, SubdividedIcosahedronApproachesTheSphere) {
  const double R = 0.01;
  for (int levels : {3, 4}) {
    const Mesh m = test::ellipsoid_mesh(R, R, R, levels);
    const double V = shape_volume(m), ball = 4.0 / 3.0 * kPi * R * R * R;
    EXPECT_GT(V, 0.0);
    EXPECT_LT(V, ball);
    EXPECT_GT(V, (levels == 3 ? 0.98 : 0.995) * ball);
  }
}

TEST(MeshInside, WindingMatchesTheOctahedron) {
  const double a = 1.0;
  const Mesh m = test::octahedron_mesh(a);
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(-1.2, 1.2);
  int inside = 0;
  for (int k = 0; k < 20000; ++k) {
    const Vec3 p{u(rng), u(rng), u(rng)};
    const double s = std::fabs(p.x) + std::fabs(p.y) + std::fabs(p.z);
    if (std::fabs(s - a) < 1e-9) continue;
    const bool in = s < a;
    inside += in;
    ASSERT_EQ(mesh_winding(m, p), in ? 1 : 0) << p.x << " " << p.y << " " << p.z;
    ASSERT_EQ(shape_contains(m, p), in);
  }
  EXPECT_GT(inside, 1000);
  // Rays through the octahedron's vertices and edges: points on the axes and
  // on the coordinate planes, whose +x rays run along edges and through vertices.
  EXPECT_EQ(mesh_winding(m, {-0.5, 0.0, 0.0}), 1);
  EXPECT_EQ(mesh_winding(m, {-1.5, 0.0, 0.0}), 0);
  EXPECT_EQ(mesh_winding(m, {-0.2, 0.3, 0.0}), 1);
  EXPECT_EQ(mesh_winding(m, {-2.0, 0.3, 0.0}), 0);
  EXPECT_EQ(mesh_winding(m, {-2.0, 0.0, 0.3}), 0);
}

// The part of a box inside the octahedron against a midpoint sum written
// here (inside: |x| + |y| + |z| < a), on 240^3 points of the box.
TEST(MeshBoxShare, MatchesAMidpointSumInTheOctahedron) {
  const double a = 1.0;
  const Mesh m = test::octahedron_mesh(a);
  const Vec3 boxes[][2] = {{{0.1, 0.2, -0.3}, {0.5, 0.6, 0.1}}, {{-0.9, -0.1, -0.2}, {-0.4, 0.4, 0.3}},
                           {{0.0, 0.0, 0.0}, {0.5, 0.5, 0.5}}, {{-0.25, -0.25, -0.25}, {0.25, 0.25, 0.25}},
                           {{0.6, 0.6, 0.6}, {1.0, 1.0, 1.0}}};
  for (const auto& b : boxes) {
    const Vec3 lo = b[0], hi = b[1];
    const int n = 240;
    const Vec3 step = (hi - lo) / static_cast<double>(n);
    double v = 0.0;
    Vec3 f;
    for (int k = 0; k < n; ++k)
      for (int j = 0; j < n; ++j)
        for (int i = 0; i < n; ++i) {
          const Vec3 p = lo + Vec3{(i + 0.5) * step.x, (j + 0.5) * step.y, (k + 0.5) * step.z};
          if (std::fabs(p.x) + std::fabs(p.y) + std::fabs(p.z) < a) v += 1.0, f = f + p;
        }
    const double dv = step.x * step.y * step.z;
    const VolumeMoments m2 = mesh_box_moments(m, lo, hi);
    const double box = (hi.x - lo.x) * (hi.y - lo.y) * (hi.z - lo.z);
    EXPECT_NEAR(m2.v, v * dv, 2e-3 * box) << lo.x;
    if (v > 0) {
      EXPECT_NEAR(m2.x / m2.v, f.x / v, 2e-3) << lo.x;
      EXPECT_NEAR(m2.y / m2.v, f.y / v, 2e-3) << lo.x;
      EXPECT_NEAR(m2.z / m2.v, f.z / v, 2e-3) << lo.x;
    }
  }
}

// The parts of a lattice of cubes inside a mesh add up to its volume and
// first moments, also where the mesh's faces lie on the lattice's planes
// (a box mesh of edges that are multiples of the spacing).
TEST(MeshBoxShare, LatticeSharesAddUpToTheMesh) {
  const Mesh ball = test::ellipsoid_mesh(0.011, 0.009, 0.01, 3);
  const Mesh box = test::box_surface_mesh({0.008, 0.006, 0.004}, 2);
  for (const Mesh* m : {&ball, &box}) {
    const double h = 0.001;
    double v = 0.0, fx = 0.0;
    for (int k = -14; k < 14; ++k)
      for (int j = -14; j < 14; ++j)
        for (int i = -14; i < 14; ++i) {
          const Vec3 lo{i * h + 0.0003, j * h, k * h};
          const VolumeMoments c = mesh_box_moments(*m, lo, lo + Vec3{h, h, h});
          ASSERT_GE(c.v, -1e-18);
          ASSERT_LE(c.v, h * h * h * (1.0 + 1e-9));
          v += c.v, fx += c.x;
        }
    const MassIntegrals I = mesh_mass_integrals(*m);
    EXPECT_NEAR(v, I.volume, 1e-10 * I.volume);
    EXPECT_NEAR(fx, I.volume * I.centroid.x, 1e-9 * I.volume * 0.01);
  }
  // Box mesh against the box's own overlap, cube by cube, on its planes:
  // exact up to the shift of the cubes by 1e-10 of the mesh's size.
  for (int i = -5; i < 5; ++i) {
    const Vec3 lo{i * 0.001, -0.003, 0.001}, hi = lo + Vec3{0.001, 0.001, 0.001};
    const double ox = std::max(0.0, std::min(hi.x, 0.004) - std::max(lo.x, -0.004));
    EXPECT_NEAR(mesh_box_moments(box, lo, hi).v, ox * 1e-6, 1e-9 * 1e-9) << i;
  }
}

Mesh with_triangles(const Mesh& m, Triangles t) { return Mesh(m.vertices(), std::move(t)); }

TEST(MeshChecks, ReportEachDefect) {
  const Mesh cube = test::box_surface_mesh({1, 1, 1}, 1);
  EXPECT_EQ(validate_mesh(cube), "");
  Triangles open = cube.triangles();
  open.pop_back();
  EXPECT_NE(validate_mesh(with_triangles(cube, open)).find("not closed: 3 boundary edges"), std::string::npos)
      << validate_mesh(with_triangles(cube, open));
  Triangles flipped = cube.triangles();
  std::swap(flipped[0][1], flipped[0][2]);
  std::swap(flipped[1][1], flipped[1][2]);
  EXPECT_NE(validate_mesh(with_triangles(cube, flipped)).find("not consistently oriented"), std::string::npos)
      << validate_mesh(with_triangles(cube, flipped));
  Triangles out_of_range = cube.triangles();
  out_of_range[3][1] = 8;
  EXPECT_NE(validate_mesh(with_triangles(cube, out_of_range)).find("triangle 3 has vertex index 8 out of range"),
            std::string::npos);
  std::vector<Vec3> bad = cube.vertices();
  bad[2].y = std::nan("");
  EXPECT_NE(validate_mesh(Mesh(bad, cube.triangles())).find("vertex 2 has a coordinate that is not finite"),
            std::string::npos);
  Triangles shared = cube.triangles();
  shared.push_back(shared[0]);
  shared.push_back({shared[0][0], shared[0][2], shared[0][1]});
  EXPECT_NE(validate_mesh(with_triangles(cube, shared)).find("not manifold"), std::string::npos)
      << validate_mesh(with_triangles(cube, shared));
  // A flat closed "tetrahedron": four coplanar points.
  const Mesh flat({{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0.3, 0.3, 0}}, {{0, 2, 1}, {0, 1, 3}, {1, 2, 3}, {2, 0, 3}});
  EXPECT_NE(validate_mesh(flat).find("encloses no volume"), std::string::npos) << validate_mesh(flat);
  // Two cubes of one mesh, the second crossing the first.
  std::vector<Vec3> v = cube.vertices();
  Triangles t = cube.triangles();
  for (const Vec3& x : cube.vertices()) v.push_back(x + Vec3{0.5, 0.3, 0.2});
  for (const auto& f : cube.triangles()) t.push_back({f[0] + 8, f[1] + 8, f[2] + 8});
  EXPECT_NE(validate_mesh(Mesh(v, t)).find("intersects itself"), std::string::npos) << validate_mesh(Mesh(v, t));
  // Two separate cubes are fine.
  for (size_t i = 8; i < v.size(); ++i) v[i] = v[i] + Vec3{2.0, 0.0, 0.0};
  EXPECT_EQ(validate_mesh(Mesh(v, t)), "");
}

TEST(MeshChecks, InvertedMeshIsTurnedOutward) {
  const Mesh cube = test::box_surface_mesh({1, 2, 3}, 1);
  Triangles t = cube.triangles();
  for (auto& f : t) std::swap(f[1], f[2]);
  const Mesh inverted(cube.vertices(), t);
  EXPECT_EQ(validate_mesh(inverted), "");
  EXPECT_NEAR(mesh_mass_integrals(inverted).volume, -6.0, 1e-12);
  bool flipped = false;
  const Mesh out = mesh_outward(inverted, &flipped);
  EXPECT_TRUE(flipped);
  EXPECT_NEAR(shape_volume(out), 6.0, 1e-12);
  mesh_outward(cube, &flipped);
  EXPECT_FALSE(flipped);
}

// The field of a uniformly magnetized prism against its face charges
// integrated by quadrature in the test support (test::face_charge_H).
TEST(MeshFaceField, PrismMatchesQuadratureOfItsFaceCharges) {
  const double e = 0.01;
  const Mesh prism = test::prism_mesh({{0.0, 0.0}, {e, 0.0}, {0.3 * e, 0.8 * e}}, 1.5 * e);
  const Mesh m = mesh_centred(prism);
  const Vec3 M{3e5, -1e5, 6e5};
  for (const Vec3& p : {Vec3{0.0, 0.0, 1.75 * e}, Vec3{1.6 * e, 0.3 * e, 0.2 * e}, Vec3{-0.9 * e, -1.1 * e, -0.4 * e}}) {
    double n[6];
    mesh_demag_tensor(m, p, n);
    const Vec3 H{-(n[0] * M.x + n[1] * M.y + n[2] * M.z), -(n[1] * M.x + n[3] * M.y + n[4] * M.z),
                 -(n[2] * M.x + n[4] * M.y + n[5] * M.z)};
    const Vec3 ref = test::face_charge_H(m, M, p);
    EXPECT_LT(norm(H - ref), 1e-6 * norm(ref)) << p.x << " " << p.y << " " << p.z;
  }
  // Inside, the trace is 1; far away, the dipole's.
  double n[6];
  mesh_demag_tensor(m, {0.0, 0.0, 0.0}, n);
  EXPECT_NEAR(n[0] + n[3] + n[5], 1.0, 1e-12);
  mesh_demag_tensor(m, {0.0, 0.0, 40 * e}, n);
  const double V = shape_volume(m), r = 40 * e;
  EXPECT_NEAR(n[5], -2.0 * V / (4.0 * kPi * r * r * r), 2e-3 * 2.0 * V / (4.0 * kPi * r * r * r));
}

// The far field of triangle clusters (meshes of more than
// kMeshExactFieldTriangles triangles) against the exact sum.
TEST(MeshFaceField, ClustersKeepTheFieldOfAFineSphere) {
  const Mesh fine = test::ellipsoid_mesh(0.01, 0.01, 0.01, 6);  // 81920 triangles
  ASSERT_GT(fine.triangles().size(), kMeshExactFieldTriangles);
  double worst = 0.0;
  for (const Vec3& p : {Vec3{0.003, 0.002, -0.004}, Vec3{0.0085, 0.001, 0.0}, Vec3{0.0, 0.0, 0.0}}) {
    double n[6];
    mesh_demag_tensor(fine, p, n);
    // A ball's tensor inside is I/3 (the polyhedron is within 0.03% of it).
    for (int a = 0; a < 6; ++a) worst = std::max(worst, std::fabs(n[a] - ((a == 0 || a == 3 || a == 5) ? 1.0 / 3.0 : 0.0)));
  }
  EXPECT_LT(worst, 3e-3);
}

}  // namespace
}  // namespace odemag
