// Fields and induced moments against independent analytic references
// (tests/support/reference_fields.h): the closed-form cuboid field checked
// against itself (far field, demag factor, quadrature, potential, Maxwell),
// then odemag's one-cell spheres (permanent, soft, recoil) and lattice bodies
// (permanent cuboids, soft sphere) against the references.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <memory>
#include <string>
#include <vector>

#include "magnetics/model/backend.h"
#include "magnetics/model/model.h"
#include "magnetics/relax/relax.h"
#include "magnetics/model/state.h"
#include "tests/support/magnetic_setup.h"
#include "tests/support/reference_fields.h"

namespace odemag {
namespace {

namespace ref = reference;

constexpr double kInf = std::numeric_limits<double>::infinity();

// A rotation that mixes all three axes (no symmetry of a box survives it).
Mat3 tilted() { return rotation_from_quaternion(0.9, 0.2, -0.3, 0.25); }

// Unit directions: the 6 axes, the 8 cube diagonals and a few generic ones.
std::vector<Vec3> directions() {
  std::vector<Vec3> d = {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}};
  for (int i = 0; i < 8; ++i)
    d.push_back(normalized(Vec3{(i & 1) ? 1.0 : -1.0, (i & 2) ? 1.0 : -1.0, (i & 4) ? 1.0 : -1.0}));
  for (const Vec3& v : {Vec3{0.3, -0.7, 0.2}, Vec3{-0.9, 0.1, 0.45}, Vec3{0.05, 0.6, -0.8}})
    d.push_back(normalized(v));
  return d;
}

double rel(const Vec3& a, const Vec3& b) { return norm(a - b) / norm(b); }

// ---------------------------------------------------------------------------
// 1. Self-checks of the closed-form cuboid field.

// (a) Far away a cuboid is a point dipole of moment M a b c. The first
// correction is O((size/r)^2) relative (the l = 3 multipole; it vanishes for a
// cube by symmetry, which leaves O((size/r)^4)). Tolerance 1e-3 at r = 30 edges
// (longest edge); the error must also fall by >= 3.5x when r doubles (2nd order).
TEST(ReferenceCuboid, FarFieldIsPointDipole) {
  const Vec3 M{3e5, -5e5, 8e5};
  for (const Vec3& size : {Vec3{0.01, 0.01, 0.01}, Vec3{0.02, 0.01, 0.01}, Vec3{0.01, 0.03, 0.005}}) {
    const double edge = std::max({size.x, size.y, size.z});
    const Vec3 m = (size.x * size.y * size.z) * M;
    double worst30 = 0, worst60 = 0;
    for (const Vec3& d : directions()) {
      const double e30 = rel(ref::cuboid_field_local(size, M, 30 * edge * d).H, ref::point_dipole_H(m, 30 * edge * d));
      const double e60 = rel(ref::cuboid_field_local(size, M, 60 * edge * d).H, ref::point_dipole_H(m, 60 * edge * d));
      worst30 = std::max(worst30, e30);
      worst60 = std::max(worst60, e60);
      EXPECT_LT(e30, 1e-3);
    }
    std::printf("[ref] far field, size %g x %g x %g: max rel err at 30 edges %.3e, at 60 edges %.3e\n",
                size.x, size.y, size.z, worst30, worst60);
    EXPECT_GT(worst30 / worst60, 3.5);
  }
}

// (b) The cube's demagnetizing factor is 1/3 along every axis: H(centre) =
// -M/3 to rounding (1e-12 |M|). Also trace N = 1 inside any box, 0 outside
// (lap G = -4 pi inside, 0 outside), to 1e-12.
TEST(ReferenceCuboid, CubeCentreAndTraceOfDemagTensor) {
  const Vec3 M{3e5, -5e5, 8e5};
  for (double a : {1e-3, 0.01, 1.0}) {
    const ref::FieldHB f = ref::cuboid_field_local({a, a, a}, M, {0, 0, 0});
    EXPECT_LT(norm(f.H + (1.0 / 3.0) * M), 1e-12 * norm(M)) << "edge " << a;
    EXPECT_LT(norm(f.B - ref::kRefMu0 * (2.0 / 3.0) * M), 1e-12 * ref::kRefMu0 * norm(M));
  }
  const Vec3 size{0.02, 0.01, 0.013};
  for (const Vec3& p : {Vec3{0, 0, 0}, Vec3{0.004, -0.002, 0.006}, Vec3{-0.0099, 0.0049, -0.0064}}) {
    const ref::SymTensor n = ref::cuboid_demag_tensor(size, p);
    EXPECT_NEAR(n.xx + n.yy + n.zz, 1.0, 1e-12);
  }
  for (const Vec3& d : directions()) {
    const ref::SymTensor n = ref::cuboid_demag_tensor(size, 0.015 * d);
    EXPECT_NEAR(n.xx + n.yy + n.zz, 0.0, 1e-12);
  }
}

// (c1) Brute-force check: direct Gauss-Legendre quadrature of the surface
// charges (16 x 16 panels, 10 x 10 nodes per face) at points outside, near
// and inside the box, at least a quarter edge from every face; relative 1e-6.
TEST(ReferenceCuboid, MatchesSurfaceChargeQuadrature) {
  const Vec3 size{0.02, 0.01, 0.013};
  const Vec3 M{3e5, -5e5, 8e5};
  const std::vector<Vec3> points = {{0.03, 0.0, 0.0},       {0.0, 0.012, 0.0},   {0.0, 0.0, -0.01},
                                    {0.014, 0.009, -0.011}, {-0.02, 0.02, 0.02}, {0.004, -0.08, 0.03},
                                    {0.0, 0.0, 0.0},        {0.006, 0.002, -0.003}};
  for (const Vec3& p : points) {
    const Vec3 H = ref::cuboid_field_local(size, M, p).H;
    const Vec3 Hq = ref::cuboid_H_quadrature(size, M, p);
    EXPECT_LT(rel(H, Hq), 1e-6) << "at " << p.x << " " << p.y << " " << p.z;
  }
}

// (c2) H = -grad phi (closed-form potential, central differences with step
// 1e-5 edge: truncation ~1e-10, rounding ~1e-10; tolerance 1e-6 |H|), and
// Maxwell: div B = 0 and curl H = 0 outside and inside (|div B| * edge and
// |curl H| * edge below 1e-6 |B|, |H|), and at a face: B_n continuous,
// H_t continuous, H_n jumps by M_n.
TEST(ReferenceCuboid, PotentialGradientAndMaxwellEquations) {
  const Vec3 size{0.02, 0.01, 0.013};
  const Vec3 M{3e5, -5e5, 8e5};
  const double edge = 0.01, d = 1e-5 * edge;
  auto H = [&](const Vec3& p) { return ref::cuboid_field_local(size, M, p).H; };
  auto B = [&](const Vec3& p) { return ref::cuboid_field_local(size, M, p).B; };
  const std::vector<Vec3> points = {{0.03, 0.0, 0.0},      {0.0, 0.012, 0.0},    {0.0, 0.0, -0.01},
                                    {0.014, 0.009, -0.011}, {-0.0105, 0.0, 0.0}, {0.011, 0.0052, 0.0068},
                                    {0.0, 0.0, 0.0},        {0.006, 0.002, -0.003}};
  for (const Vec3& p : points) {
    Vec3 grad, dB[3], dH[3];
    for (int a = 0; a < 3; ++a) {
      Vec3 e;
      e[a] = d;
      grad[a] = (ref::cuboid_potential_local(size, M, p + e) - ref::cuboid_potential_local(size, M, p - e)) / (2 * d);
      dB[a] = (B(p + e) - B(p - e)) / (2 * d);  // dB / dx_a
      dH[a] = (H(p + e) - H(p - e)) / (2 * d);
    }
    const Vec3 h = H(p);
    EXPECT_LT(rel(-1.0 * grad, h), 1e-6) << "at " << p.x << " " << p.y << " " << p.z;
    const double div_B = dB[0].x + dB[1].y + dB[2].z;
    const Vec3 curl_H{dH[1].z - dH[2].y, dH[2].x - dH[0].z, dH[0].y - dH[1].x};
    EXPECT_LT(std::abs(div_B) * edge, 1e-6 * norm(B(p)));
    EXPECT_LT(norm(curl_H) * edge, 1e-6 * norm(h));
  }
  // Across the face x = +a/2 at (y, z) = (0.002, -0.003).
  const double eps = 1e-9;
  const Vec3 in{0.01 - eps, 0.002, -0.003}, out{0.01 + eps, 0.002, -0.003};
  const ref::FieldHB fi = ref::cuboid_field_local(size, M, in), fo = ref::cuboid_field_local(size, M, out);
  EXPECT_NEAR(fo.B.x, fi.B.x, 1e-5 * ref::kRefMu0 * norm(M));
  EXPECT_NEAR(fo.H.y, fi.H.y, 1e-5 * norm(M));
  EXPECT_NEAR(fo.H.z, fi.H.z, 1e-5 * norm(M));
  EXPECT_NEAR(fo.H.x - fi.H.x, M.x, 1e-5 * norm(M));
  // On the charged face itself: the average of the two sides (the X = 0 convention).
  const Vec3 on_face = ref::cuboid_field_local(size, M, {0.01, 0.002, -0.003}).H;
  EXPECT_LT(norm(on_face - 0.5 * (fi.H + fo.H)), 1e-5 * norm(M));
  // In the plane of a face but off it, and on the line of an edge beyond its
  // end, the closed form stays finite and continuous (1e-6 relative over 1e-9 m).
  for (const Vec3& p : {Vec3{0.01, 0.007, 0.0}, Vec3{0.01, 0.005, 0.01}, Vec3{0.01, 0.005, -0.02}}) {
    const Vec3 h0 = H(p), h1 = H(p + Vec3{1e-9, 1e-9, 1e-9});
    ASSERT_TRUE(is_finite(h0));
    EXPECT_LT(rel(h1, h0), 1e-6);
  }
}

// The pose wrapper: a rotated, translated box equals the local formula in the
// body frame, rotated back (checked against the far-field dipole of the
// rotated moment, which does not use the wrapper's frames).
TEST(ReferenceCuboid, PoseWrapperRotatesAndTranslates) {
  ref::CuboidMagnet magnet{{0.02, 0.01, 0.013}, {3e5, -5e5, 8e5}, tilted(), {0.1, -0.2, 0.05}};
  for (const Vec3& d : directions()) {
    const Vec3 p = magnet.centre + 1.0 * d;  // 50 edges away
    EXPECT_LT(rel(magnet.field(p).H, ref::point_dipole_H(magnet.moment(), p - magnet.centre)), 2e-4);
  }
  const Vec3 B_local = ref::cuboid_field_local(magnet.size, magnet.M_body, {}).B;
  EXPECT_LT(norm(magnet.field(magnet.centre).B - magnet.rotation * B_local), 1e-12 * ref::kRefMu0 * 1e6);
}

// ---------------------------------------------------------------------------
// odemag against the references.

struct Scene : test_support::MagneticSetup {
  Scene() : MagneticSetup(0) {}
  void init(const Mat3& rotation = {}, const Vec3& position = {}) {
    state = make_state(model, 7);
    state.pose[0] = {rotation, position};
  }
  RelaxReport relax_in(const Vec3& H0, RelaxOptions o = {}) {
    state.external_field = H0;
    return relax(model, state, o, *backend);
  }
  std::vector<Vec3> B_at(const std::vector<Vec3>& points) {
    std::vector<Vec3> B, H;
    field_at_points(model, state, *backend, points, B, H);
    return B;
  }
};

RelaxOptions tight() { return test_support::relax_options(1e-10); }

// 2. A one-cell permanent sphere is a uniformly magnetized sphere: outside,
// exactly the dipole field (odemag's kernel is the exact dipole beyond the
// cell radius = R). Relative 1e-12 from 1.001 R to 50 R, 17 directions, in a
// tilted, translated pose (M given in the body frame).
TEST(PermanentSphere, OneCellGivesExactDipoleOutside) {
  const double R = 0.01;
  const Vec3 M_body{2e5, -6e5, 9e5};
  Scene s;
  s.model.add_body("m", Sphere{R}, PermanentMaterial{M_body, 0.0}, 0.0);
  s.init(tilted(), {0.3, -0.1, 0.2});
  s.relax_in({});
  const Vec3 M = tilted() * M_body;
  std::vector<Vec3> points;
  for (const Vec3& d : directions())
    for (double r : {1.001, 1.5, 3.0, 10.0, 50.0}) points.push_back(s.state.pose[0].position + r * R * d);
  const std::vector<Vec3> B = s.B_at(points);
  double worst = 0;
  for (size_t i = 0; i < points.size(); ++i) {
    const Vec3 Bref = ref::sphere_field(R, M, s.state.pose[0].position, points[i]).B;
    worst = std::max(worst, rel(B[i], Bref));
    EXPECT_LT(rel(B[i], Bref), 1e-12) << "point " << i;
  }
  std::printf("[odemag] one-cell permanent sphere: max rel err of B outside %.2e\n", worst);
}

// 3. A permanent box on a lattice converges to the closed-form cuboid field.
// The cells are point dipoles at the centres of h-cubes: the midpoint rule of
// a kernel that is harmonic in the source point, so its h^2 error term
// vanishes (equivalently: a uniformly magnetized cube has no l = 3 multipole),
// and the error falls as h^4, ~16x per halving of h. The error is
// max |B - B_ref| / |B_ref| over 17 directions at a distance of 2 (and 1)
// longest-edge lengths from the centre, in a tilted, translated pose.
// Required: < 0.5% at h = edge/8 at 2 edges (measured 3.1e-6 or less), at
// least 10x smaller per halving of h at 2 edges (measured 15.8-16.0x); at 1
// edge, monotone and >= 10x on the last halving (the cube's corners are close:
// measured 5.6x, 10.5x, 15.5x).
struct LatticeCase {
  std::string name;
  Vec3 size;
  Vec3 M_body;
  double edge;  // h = edge / k; the shortest edge, so the lattice fills the box
};

// Errors of a permanent box on a lattice of spacing edge / k against the
// closed form at points `distance_in_edges` longest edges from its centre:
// `dipole` is the field the relaxation uses (the point-dipole lattice sum,
// read as the applied field at tiny probe cells: recoil magnets with M_r = 0
// and chi_r = 1e-12, whose own fields are negligible); `probe` is
// field_at_points (the exact fields of the lattice cubes); `relaxation` the
// applied field at the probes with the default options, where the near field
// of a one-cell ball next to a lattice body (magnetics/near_field/ball_lattice_near_field.cpp)
// replaces the point dipoles of the cells within 3 h by their cubes' fields.
struct LatticeErrors {
  std::vector<double> dipole, probe, relaxation;
};

LatticeErrors lattice_cuboid_errors(const LatticeCase& c, const std::vector<int>& divisions,
                                    double distance_in_edges) {
  const Mat3 R = tilted();
  const Vec3 centre{0.05, 0.02, -0.03};
  const ref::CuboidMagnet exact{c.size, c.M_body, R, centre};
  const double L = std::max({c.size.x, c.size.y, c.size.z});
  std::vector<Vec3> points;
  for (const Vec3& d : directions()) {
    const Vec3 local = distance_in_edges * L * d;
    EXPECT_FALSE(ref::inside_box(c.size, local));
    points.push_back(centre + R * local);
  }
  LatticeErrors errors;
  for (int k : divisions) {
    Scene s;
    s.model.add_body("box", Box{c.size}, PermanentMaterial{c.M_body, 0.0}, c.edge / k);
    const double expect_cells = (c.size.x / c.edge) * (c.size.y / c.edge) * (c.size.z / c.edge) * k * k * k;
    EXPECT_EQ(s.model.cell_count(), static_cast<int>(std::lround(expect_cells)));
    for (size_t i = 0; i < points.size(); ++i)
      s.model.add_body("probe" + std::to_string(i), Sphere{1e-6}, PermanentMaterial{{}, 1e-12}, 0.0);
    s.init(R, centre);
    for (size_t i = 0; i < points.size(); ++i) s.state.pose[1 + i].position = points[i];
    RelaxOptions point_dipoles;
    point_dipoles.near_field = false;
    s.relax_in({}, point_dipoles);
    const std::vector<Vec3> B = s.B_at(points);
    double worst_dipole = 0, worst_probe = 0, worst_relaxation = 0;
    for (size_t i = 0; i < points.size(); ++i) {
      const Vec3 H_exact = exact.field(points[i]).H;
      const int probe_cell = s.model.body(1 + static_cast<int>(i)).first_cell;
      worst_dipole = std::max(worst_dipole, rel(s.state.applied_field[probe_cell], H_exact));
      worst_probe = std::max(worst_probe, rel(B[i], exact.field(points[i]).B));
    }
    s.relax_in({});
    for (size_t i = 0; i < points.size(); ++i) {
      const int probe_cell = s.model.body(1 + static_cast<int>(i)).first_cell;
      worst_relaxation = std::max(worst_relaxation, rel(s.state.applied_field[probe_cell], exact.field(points[i]).H));
    }
    errors.relaxation.push_back(worst_relaxation);
    errors.dipole.push_back(worst_dipole);
    errors.probe.push_back(worst_probe);
  }
  return errors;
}

TEST(PermanentCuboid, LatticeConvergesToClosedForm) {
  const std::vector<LatticeCase> cases = {
      {"cube, M along z", {0.01, 0.01, 0.01}, {0, 0, 1e6}, 0.01},
      {"cube, M oblique", {0.01, 0.01, 0.01}, {3e5, -5e5, 8e5}, 0.01},
      {"2:1:1, M oblique", {0.02, 0.01, 0.01}, {3e5, -5e5, 8e5}, 0.01},
      {"1:3:0.5, M oblique", {0.01, 0.03, 0.005}, {-7e5, 2e5, 4e5}, 0.005},
  };
  const std::vector<int> divisions = {2, 4, 8, 16};
  for (const LatticeCase& c : cases) {
    for (double distance : {2.0, 1.0}) {
      const LatticeErrors err = lattice_cuboid_errors(c, divisions, distance);
      const std::vector<double>& e = err.dipole;
      std::printf("[odemag] lattice box %-18s at %g edges:", c.name.c_str(), distance);
      for (size_t i = 0; i < e.size(); ++i) std::printf("  h=e/%-2d %.2e", divisions[i], e[i]);
      std::printf("\n[odemag]   with the near field:          ");
      for (size_t i = 0; i < e.size(); ++i) std::printf("  h=e/%-2d %.2e", divisions[i], err.relaxation[i]);
      std::printf("\n");
      // The cubes' exact fields near the probes only remove error.
      for (size_t i = 0; i < e.size(); ++i)
        EXPECT_LE(err.relaxation[i], e[i] * (1.0 + 1e-9)) << c.name << " at " << distance << " edges, h = edge/" << divisions[i];
      for (size_t i = 1; i < e.size(); ++i) {
        // Fourth order: >= 10x per halving; at 1 edge (near the corners) the
        // coarsest lattices are not yet asymptotic, so there only the last.
        const double factor = distance == 2.0 || i + 1 == e.size() ? 10.0 : 1.0;
        EXPECT_LT(factor * e[i], e[i - 1]) << c.name << " at " << distance << " edges, h = edge/" << divisions[i];
      }
      if (distance == 2.0) {
        EXPECT_LT(e[2], 5e-3) << c.name << " at h = edge/8";
      }
      // The probes sum the exact fields of the lattice cubes, which tile the
      // box: the closed form to round-off at every h.
      for (size_t i = 0; i < err.probe.size(); ++i)
        EXPECT_LT(err.probe[i], 1e-10) << c.name << " probe at h = edge/" << divisions[i];
    }
  }
}

// Field probes inside magnets: B = mu0 (H + M) with H the field of the
// uniformly magnetized solids. A one-cell sphere has B = (2/3) mu0 M inside;
// a lattice box is tiled by its cubes, so inside it the probe gives the
// closed-form cuboid field exactly.
TEST(FieldProbe, InsideMagnetsGivesTheUniformSolidsField) {
  const Vec3 M{2e5, -4e5, 7e5};
  {
    Scene s;
    s.model.add_body("sphere", Sphere{0.01}, PermanentMaterial{M, 0.0}, 0.0);
    s.init(tilted(), {0.01, 0.02, 0.03});
    s.relax_in({});
    const Vec3 M_world = tilted() * M;
    const std::vector<Vec3> inside = {{0.01, 0.02, 0.03}, {0.015, 0.02, 0.028}, {0.01, 0.027, 0.03}};
    for (const Vec3& B : s.B_at(inside)) EXPECT_LT(rel(B, (2.0 / 3.0) * ref::kRefMu0 * M_world), 1e-12);
  }
  {
    const Vec3 size{0.02, 0.01, 0.01};
    Scene s;
    s.model.add_body("box", Box{size}, PermanentMaterial{M, 0.0}, 0.0025);
    s.init(tilted(), {0.05, 0.02, -0.03});
    s.relax_in({});
    const ref::CuboidMagnet exact{size, M, tilted(), {0.05, 0.02, -0.03}};
    std::vector<Vec3> inside;
    for (const Vec3& d : directions()) inside.push_back(Vec3{0.05, 0.02, -0.03} + tilted() * Vec3{0.37 * size.x * d.x, 0.41 * size.y * d.y, 0.43 * size.z * d.z});
    const std::vector<Vec3> B = s.B_at(inside);
    for (size_t i = 0; i < inside.size(); ++i) EXPECT_LT(rel(B[i], exact.field(inside[i]).B), 1e-10) << i;
  }
}

// An electromagnet: a soft core driven by its coil field H_c (body frame)
// is magnetized as a sphere in a uniform H_c would be (one cell: M = H_c /
// gamma_D below saturation), the field turns with the body, scales with the
// body's magnetization scale, and acts on the core only: a soft ball nearby
// feels just the core's dipole field.
TEST(Electromagnet, CoilFieldMagnetizesItsOwnCoreOnly) {
  const double R = 0.01, chi = 1000.0, Ms = 1.7e6;
  SoftMaterial core;
  core.saturation = Ms;
  core.susceptibility = chi;
  core.coil_field = {0, 0, 2e5};
  SoftMaterial ball = core;
  ball.coil_field = {};
  Scene s;
  s.model.add_body("core", Sphere{R}, core, 0.0);
  s.model.add_body("ball", Sphere{0.002}, ball, 0.0);
  s.init(tilted(), {});
  s.state.pose[1].position = {0.3, 0, 0};  // far: it feels ~0 from the core
  s.relax_in({}, tight());
  const double gamma_D = 1.0 / 3.0 + 1.0 / chi;
  const Vec3 expected = (2e5 / gamma_D) * (tilted() * Vec3{0, 0, 1});
  EXPECT_LT(rel(s.state.magnetization[0], expected), 1e-9);
  // The ball feels the core's dipole field only: M = 3 R^3 ... tiny, not 2e5 / gamma_D.
  const Vec3 mu = (4.0 / 3.0 * ref::kRefPi * R * R * R) * s.state.magnetization[0];
  const Vec3 dipole = ref::point_dipole_H(mu, {0.3, 0, 0});
  EXPECT_LT(rel(s.state.applied_field[1], dipole), 1e-9);
  s.state.magnetization_scale[0] = 0.25;
  s.relax_in({}, tight());
  EXPECT_LT(rel(s.state.magnetization[0], 0.25 * expected), 1e-9);
}

// 4. A one-cell soft sphere in a uniform field: M = chi H_in, H_in = H0 - M/3,
// so moment 4 pi R^3 chi / (chi + 3) H0 below saturation and (4/3) pi R^3 Ms
// above (tolerance 1e-6 relative; two-level scheme, tolerance 1e-10).
struct SoftCase {
  double chi;
  double ratio;  // |H0| / (gamma_D Ms): < 1 below saturation
};

// Soft material of saturation Ms and susceptibility chi; gamma_D = 1/3 +
// 1/chi of a sphere of it.
SoftMaterial soft_material(double Ms, double chi) {
  SoftMaterial mat;
  mat.saturation = Ms;
  mat.susceptibility = chi;
  return mat;
}
double sphere_gamma_D(double chi) { return 1.0 / 3.0 + (std::isinf(chi) ? 0.0 : 1.0 / chi); }

Vec3 soft_field_direction(int i) {
  const Vec3 d[] = {{1, 0, 0}, {0.3, -0.7, 0.2}, {-0.9, 0.1, 0.45}, {0.05, 0.6, -0.8}};
  return normalized(d[i % 4]);
}

TEST(SoftSphere, OneCellMomentMatchesLinearSphere) {
  const double R = 0.01, Ms = 1.2e6;
  double worst_below = 0, worst_above = 0;
  int most_iterations = 0;
  int i = 0;
  for (double chi : {10.0, 1000.0, kInf}) {
    const SoftMaterial mat = soft_material(Ms, chi);
    const double gamma_D = sphere_gamma_D(chi);
    // |H0| from ~4 A/m to ~5e6 A/m.
    for (double ratio : {1e-5, 1e-3, 0.05, 0.3, 0.7, 0.95, 0.999, 1.001, 1.05, 1.5, 10.0}) {
      const Vec3 H0 = ratio * gamma_D * Ms * soft_field_direction(i++);
      Scene s;
      s.model.add_body("ball", Sphere{R}, mat, 0.0);
      s.init(tilted(), {0.1, 0.2, 0.3});
      const RelaxReport r = s.relax_in(H0, tight());
      EXPECT_TRUE(r.converged) << "chi " << chi << " ratio " << ratio;
      most_iterations = std::max(most_iterations, r.iterations);
      const Vec3 m = body_moment(s.model, s.state, 0);
      const double e = rel(m, ref::soft_sphere_moment(R, chi, Ms, H0));
      double& worst = ratio < 1 ? worst_below : worst_above;
      worst = std::max(worst, e);
      EXPECT_LT(e, 1e-6) << "chi " << chi << " ratio " << ratio;
    }
  }
  std::printf("[odemag] one-cell soft sphere, two-level: max rel moment err below saturation %.2e, above %.2e, "
              "at most %d outer iterations\n",
              worst_below, worst_above, most_iterations);
}

// The same with the paper's Algorithm 1 (one LLG step per iteration,
// RelaxScheme::paper) in strong fields, |H0| = 0.3 .. 5 gamma_D Ms.
// (a) Without the noise field and at tolerance 1e-10 (relative torque), the
//     moment is exact to 1e-6 (measured <= 5e-10). Measured iterations
//     (time_step_factor 0.5 / 3): ~330 at |H0| = 0.6 gamma_D Ms, ~760-910 at
//     0.3, ~1170 at 0.9, ~650 at 1.5, ~210 at 5 (printed by the test).
// (b) With the default noise field (|H_noise| = 1e-6 |H_eff|), the relative
//     torque cannot fall below ~1e-6 at saturation, where |H_eff| stays large:
//     at tolerance 1e-10 it runs to any iteration cap (error ~1e-7). At
//     tolerance 1e-6 it converges (measured ~130 .. 630 iterations) and the
//     moment is within 2e-5 (measured <= 4.6e-6).
void paper_scheme_cases(double noise_ratio, double tolerance, double accuracy) {
  const double R = 0.01, Ms = 1.2e6;
  int i = 0;
  for (double chi : {10.0, 1000.0, kInf}) {
    const SoftMaterial mat = soft_material(Ms, chi);
    const double gamma_D = sphere_gamma_D(chi);
    std::printf("[odemag] paper scheme, noise %g, tolerance %g, chi %g: iterations (rel err) at |H0|/(gamma_D Ms) =",
                noise_ratio, tolerance, chi);
    for (double ratio : {0.3, 0.6, 0.9, 1.5, 5.0}) {
      const Vec3 H0 = ratio * gamma_D * Ms * soft_field_direction(i++);
      Scene s;
      s.model.add_body("ball", Sphere{R}, mat, 0.0);
      s.init(tilted(), {0.1, 0.2, 0.3});
      RelaxOptions o;
      o.scheme = RelaxScheme::paper;
      o.tolerance = tolerance;
      o.max_iterations = 20000;
      o.local.noise_ratio = noise_ratio;
      const RelaxReport r = s.relax_in(H0, o);
      const Vec3 m = body_moment(s.model, s.state, 0);
      const double e = rel(m, ref::soft_sphere_moment(R, chi, Ms, H0));
      std::printf("  %g: %d (%.1e)", ratio, r.iterations, e);
      EXPECT_TRUE(r.converged) << "chi " << chi << " ratio " << ratio;
      EXPECT_LT(e, accuracy) << "chi " << chi << " ratio " << ratio;
    }
    std::printf("\n");
  }
}

TEST(SoftSphere, OneCellPaperSchemeInStrongFieldNoiseFree) { paper_scheme_cases(0.0, 1e-10, 1e-6); }

TEST(SoftSphere, OneCellPaperSchemeInStrongFieldWithNoise) {
  paper_scheme_cases(LocalRelaxOptions{}.noise_ratio, 1e-6, 2e-5);
}

// 5. A soft sphere on a cubic lattice (default intra-body tensor). Cells on a
// cubic lattice, each with gamma_D = 1/3 + 1/chi, reproduce the continuum in
// the bulk (Clausius-Mossotti / Lorentz cavity: the lattice sum of the other
// cells' fields inside a uniformly magnetized region vanishes by cubic
// symmetry), so the moment tends to 4 pi R^3 chi/(chi+3) H0; the surface is
// handled by the boundary cells (each the part of its cube inside the ball)
// and the boundary correction of the intra-body field (docs/model.md
// "Cells"), which gives a uniform magnetization the ball's exact field, so
// the lattice ball takes the continuum moment at every h (the exact solution
// is uniform). Before it (centre-inside staircase, volume shared out equally)
// the error was +10.9% / +8.57% / +5.84% (chi = inf) and +0.46% / +0.37% /
// +0.26% (chi = 1) at h = R/2, R/4, R/8, and the test asserted that it was
// positive and fell with h; now it is round-off (measured below 1e-14) and
// asserted below 1e-9. m is parallel to H0 (1e-6).
// Measured with the default intra-body tensor (IntraBodyTensor::cell_average);
// with point-dipole tensors the chi = inf lattice does not converge (residual
// 1e-4 .. 4e-2 after 1000 iterations at h = R/4 .. R/8), and this test fails.
TEST(SoftSphere, LatticeSphereApproachesContinuumMoment) {
  const double R = 0.01, Ms = 1.7e6;
  const Vec3 H0 = 1e4 * normalized(Vec3{0.3, -0.7, 0.2});  // M ~ 3e4 << Ms: linear regime
  for (double chi : {kInf, 1.0}) {
    const SoftMaterial mat = soft_material(Ms, chi);
    const Vec3 m_ref = ref::soft_sphere_moment(R, chi, Ms, H0);
    for (double k : {2.0, 4.0, 8.0}) {
      Scene s;
      s.model.add_body("ball", Sphere{R}, mat, R / k);
      s.init(tilted(), {});
      RelaxOptions o;
      o.tolerance = 1e-8;
      o.max_iterations = 1000;
      const RelaxReport r = s.relax_in(H0, o);
      EXPECT_TRUE(r.converged) << "chi " << chi << " h = R/" << k;
      const Vec3 m = body_moment(s.model, s.state, 0);
      const double excess = norm(m) / norm(m_ref) - 1.0;
      const Vec3 u = normalized(H0);
      const double transverse = norm(m - dot(m, u) * u) / norm(m);
      std::printf("[odemag] lattice soft sphere chi %g h = R/%g: %d cells, %d iterations, |m|/|m_ref| - 1 = %.3e, "
                  "transverse %.1e\n",
                  chi, k, s.model.cell_count(), r.iterations, excess, transverse);
      EXPECT_LT(std::fabs(excess), 1e-9) << "chi " << chi << " h = R/" << k;
      EXPECT_LT(transverse, 1e-6);
    }
  }
}

// 6. A one-cell recoil magnet in a uniform field: M = M_r + chi_r H_in with
// H_in = H0 - M/3 gives M = (M_r + chi_r H0) / (1 + chi_r/3). Relative 1e-10
// (the update is a closed form; the outer loop converges in a few passes).
TEST(RecoilMagnet, OneCellMatchesLinearSphere) {
  const double R = 0.01;
  const Vec3 M_r_body{2e5, -6e5, 9e5};
  for (double chi_r : {0.05, 0.3, 1.0}) {
    for (const Vec3& H0 : {Vec3{}, Vec3{1e5, 0, 0}, Vec3{-3e5, 2e5, 4e5}}) {
      Scene s;
      s.model.add_body("m", Sphere{R}, PermanentMaterial{M_r_body, chi_r}, 0.0);
      s.init(tilted(), {0.02, 0, 0});
      const RelaxReport r = s.relax_in(H0, tight());
      EXPECT_TRUE(r.converged);
      const Vec3 M_ref = ref::recoil_sphere_magnetization(tilted() * M_r_body, chi_r, H0);
      EXPECT_LT(rel(s.state.magnetization[0], M_ref), 1e-10) << "chi_r " << chi_r;
      // And its field outside is the sphere's dipole plus H0.
      const Vec3 p = s.state.pose[0].position + 0.03 * normalized(Vec3{1, 2, -2});
      const Vec3 B = s.B_at({p})[0];
      const Vec3 B_ref = ref::sphere_field(R, M_ref, s.state.pose[0].position, p).B + ref::kRefMu0 * H0;
      EXPECT_LT(rel(B, B_ref), 1e-10);
    }
  }
}

}  // namespace
}  // namespace odemag

namespace odemag {
namespace {

// RelaxOptions::progress (the progress lines of a long `odemag solve`) is
// called once after every outer iteration, with the residuals so far, for the
// two-level and the paper scheme.
TEST(Relax, ProgressIsReportedAfterEveryOuterIteration) {
  for (const RelaxScheme scheme : {RelaxScheme::two_level, RelaxScheme::paper}) {
    MagneticModel model;
    SoftMaterial iron;
    iron.saturation = 1.6e6;
    iron.susceptibility = 100.0;
    model.add_body("cube", Box{{0.01, 0.01, 0.01}}, iron, 0.0025);
    MagneticState state = make_state(model, 1);
    state.external_field = {0, 0, 1e4};
    RelaxOptions o;
    o.scheme = scheme;
    std::vector<std::vector<double>> seen;
    o.progress = [&](const RelaxReport& r) {
      EXPECT_EQ(r.residual_history.size(), seen.size() + 1);
      seen.push_back(r.residual_history);
    };
    auto backend = make_cpu_backend(1);
    o.max_iterations = 40;  // the paper scheme need not converge in these
    const RelaxReport report = relax(model, state, o, *backend);
    ASSERT_FALSE(seen.empty());
    EXPECT_EQ(seen.size(), report.residual_history.size());
    EXPECT_EQ(seen.back(), report.residual_history);
  }
}

}  // namespace
}  // namespace odemag
