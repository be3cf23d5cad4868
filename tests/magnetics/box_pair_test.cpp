// Two box magnets at every cell size against closed forms (docs/validation.md
// "What a user gets"): a 20 x 10 x 5 mm bar 1 mm above a 10 mm cube, both
// magnetized along z, the bar offset sideways by (2, 1) mm. The force is
// Akoun and Yonnet's (IEEE Trans. Magn. 20(5), 1984), the interaction of the
// boxes' face charges sigma = +-M in closed form, written here; the field is
// the face-charge field of tests/support/reference_fields.h. Neither uses
// odemag's kernels.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <vector>

#include "odemag/scene.h"
#include "odemag/solve.h"
#include "tests/support/reference_fields.h"

namespace odemag {
namespace {

// The fourth antiderivative of W / R^3 (R^2 = U^2 + V^2 + W^2) twice in U and
// twice in V: d^4 Phi / dU^2 dV^2 = W / R^3 (checked below by finite differences).
double akoun_yonnet_phi(double U, double V, double W) {
  const double R = std::sqrt(U * U + V * V + W * W);
  double phi = -W * R;
  if (U != 0.0 && V != 0.0) phi += U * V * std::atan(U * V / (W * R));
  if (U != 0.0) phi += U * W * std::asinh(U / std::hypot(V, W));
  if (V != 0.0) phi += V * W * std::asinh(V / std::hypot(U, W));
  return phi;
}

// z force (N) on the rectangle [x1] x [y1] at height z1 carrying the magnetic
// charge density s1 (A/m) from the rectangle [x2] x [y2] at z2 with s2:
// mu0 s1 s2 / (4 pi) over the four-fold integral of (z1 - z2) / R^3, whose
// integral over an interval pair [a1, b1] x [a2, b2] of a function of x1 - x2
// is G(b1 - a2) - G(b1 - b2) - G(a1 - a2) + G(a1 - b2), G'' = g.
double rectangles_force_z(double s1, const double x1[2], const double y1[2], double z1, double s2,
                          const double x2[2], const double y2[2], double z2) {
  double sum = 0.0;
  for (int i = 0; i < 2; ++i)
    for (int j = 0; j < 2; ++j)
      for (int k = 0; k < 2; ++k)
        for (int l = 0; l < 2; ++l) {
          const double su = (i == 1 ? 1.0 : -1.0) * (j == 0 ? 1.0 : -1.0);
          const double sv = (k == 1 ? 1.0 : -1.0) * (l == 0 ? 1.0 : -1.0);
          sum += su * sv * akoun_yonnet_phi(x1[i] - x2[j], y1[k] - y2[l], z1 - z2);
        }
  return reference::kRefMu0 * s1 * s2 / (4.0 * reference::kRefPi) * sum;
}

struct ZMagnet {
  Vec3 centre, size;
  double M;  // A/m along z
};

// Akoun-Yonnet: the z force on a from b, both magnetized along z.
double box_force_z(const ZMagnet& a, const ZMagnet& b) {
  const double xa[2] = {a.centre.x - 0.5 * a.size.x, a.centre.x + 0.5 * a.size.x};
  const double ya[2] = {a.centre.y - 0.5 * a.size.y, a.centre.y + 0.5 * a.size.y};
  const double xb[2] = {b.centre.x - 0.5 * b.size.x, b.centre.x + 0.5 * b.size.x};
  const double yb[2] = {b.centre.y - 0.5 * b.size.y, b.centre.y + 0.5 * b.size.y};
  double F = 0.0;
  for (int fa = 0; fa < 2; ++fa)
    for (int fb = 0; fb < 2; ++fb) {
      const double za = a.centre.z + (fa ? 0.5 : -0.5) * a.size.z, zb = b.centre.z + (fb ? 0.5 : -0.5) * b.size.z;
      F += rectangles_force_z(fa ? a.M : -a.M, xa, ya, za, fb ? b.M : -b.M, xb, yb, zb);
    }
  return F;
}

const ZMagnet kCube{{0.0, 0.0, 0.0}, {0.01, 0.01, 0.01}, 1e6};
const ZMagnet kBar{{0.002, 0.001, 0.005 + 0.001 + 0.0025}, {0.02, 0.01, 0.005}, 1e6};

SceneDescription box_pair(double h) {
  SceneDescription s;
  s.file = "box_pair";
  s.gravity = {};
  s.materials["magnet"] = PermanentMaterial{{0.0, 0.0, 1e6}, 0.0};
  for (const auto& [name, m] : {std::pair{"cube", kCube}, std::pair{"bar", kBar}}) {
    BodyDescription b;
    b.name = name;
    b.shape = Box{m.size};
    b.material = "magnet";
    b.position = m.centre;
    b.fixed = true;
    b.cell_size = h;
    s.bodies.push_back(b);
  }
  s.solver.backend = BackendKind::cpu;
  s.solver.threads = 1;
  return s;
}

// The corner sum of two rectangles against the four-fold integral of
// (z1 - z2) / R^3 by 16-point Gauss-Legendre quadrature per axis (smooth:
// the rectangles are 0.4 to 0.9 of their size apart).
TEST(BoxPair, AkounYonnetCornerSumIsTheFourFoldIntegral) {
  std::vector<double> x, w;
  reference::gauss_legendre(16, x, w);
  const double x1[2] = {0.0, 1.0}, y1[2] = {0.0, 0.6};
  for (const Vec3 offset : {Vec3{0.3, -0.2, 0.4}, Vec3{-0.5, 0.1, 0.9}, Vec3{1.2, 0.5, 0.6}}) {
    const double x2[2] = {offset.x, offset.x + 0.7}, y2[2] = {offset.y, offset.y + 1.3};
    const double W = offset.z;
    double quadrature = 0.0;
    auto node = [&](const double* lim, int i) { return 0.5 * (lim[0] + lim[1]) + 0.5 * (lim[1] - lim[0]) * x[i]; };
    for (int a = 0; a < 16; ++a)
      for (int b = 0; b < 16; ++b)
        for (int c = 0; c < 16; ++c)
          for (int d = 0; d < 16; ++d) {
            const double U = node(x1, a) - node(x2, c), V = node(y1, b) - node(y2, d);
            const double R = std::sqrt(U * U + V * V + W * W);
            quadrature += w[a] * w[b] * w[c] * w[d] * W / (R * R * R);
          }
    quadrature *= 0.25 * 0.25 * 1.0 * 0.6 * 0.7 * 1.3;  // the Jacobians (lengths / 2 each)
    // rectangles_force_z with s1 = s2 = 1, z1 - z2 = W, in units of mu0 / 4 pi.
    const double closed = rectangles_force_z(1.0, x1, y1, W, 1.0, x2, y2, 0.0) /
                          (reference::kRefMu0 / (4.0 * reference::kRefPi));
    EXPECT_NEAR(closed, quadrature, 1e-9 * std::fabs(quadrature)) << offset.x << " " << offset.y << " " << W;
  }
}

// The force within 2% at every cell size up to half the smallest side (5 mm),
// within 0.5% from an eighth of it; cell sizes that divide the edges and
// cell sizes that do not.
TEST(BoxPair, ForceMatchesAkounYonnetAtEveryCellSize) {
  const double reference = box_force_z(kBar, kCube);
  ASSERT_NEAR(reference, -22.64, 0.01);  // attraction, N
  for (const double h : {0.0025, 0.01 / 3.0, 0.002, 0.005 / 3.0, 0.00125, 0.001, 0.000625}) {
    const SceneSolution s = solve_scene(box_pair(h));
    const double error = s.bodies[1].force.z / reference - 1.0;
    std::printf("h %.3f mm: %d + %d cells, F_z %.4f N, error %+.3f%%\n", h * 1e3, s.bodies[0].cells,
                s.bodies[1].cells, s.bodies[1].force.z, 100.0 * error);
    EXPECT_LT(std::fabs(error), h <= 0.005 / 8.0 + 1e-12 ? 0.005 : 0.02) << "h = " << h;
    EXPECT_NEAR(s.bodies[0].force.z, -s.bodies[1].force.z, 1e-9 * std::fabs(reference));
  }
}

// B 1 mm above the bar's top face within 1% of the two boxes' face-charge
// fields from a cell size of a quarter of the smallest side.
TEST(BoxPair, FieldAboveTheBarMatchesTheFaceCharges) {
  const reference::CuboidMagnet cube{kCube.size, {0.0, 0.0, kCube.M}, Mat3{}, kCube.centre};
  const reference::CuboidMagnet bar{kBar.size, {0.0, 0.0, kBar.M}, Mat3{}, kBar.centre};
  std::vector<Vec3> points;
  for (double x : {-0.008, 0.0, 0.005, 0.011})
    for (double y : {-0.003, 0.0, 0.0045}) points.push_back({kBar.centre.x + x, kBar.centre.y + y, kBar.centre.z + 0.0035});
  for (const double h : {0.00125, 0.001, 0.000625}) {
    const SceneField f = scene_field(box_pair(h), points);
    double worst = 0.0;
    for (std::size_t p = 0; p < points.size(); ++p) {
      const Vec3 B = cube.field(points[p]).B + bar.field(points[p]).B;
      worst = std::max(worst, norm(f.B[p] - B) / norm(B));
    }
    std::printf("h %.3f mm: largest relative error of B 1 mm above the bar %.3f%%\n", h * 1e3, 100.0 * worst);
    EXPECT_LT(worst, 0.01) << "h = " << h;
  }
}

}  // namespace
}  // namespace odemag
