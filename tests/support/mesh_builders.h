// Closed triangle meshes of simple solids for tests and benchmarks, built
// here (not by odemag): outward, counter-clockwise seen from outside.
#pragma once

#include <array>
#include <cmath>
#include <map>
#include <utility>
#include <vector>

#include "odemag/constants.h"
#include "odemag/shape.h"
#include "odemag/vec3.h"

namespace odemag::test {

using Triangles = std::vector<std::array<int, 3>>;

// The octahedron |x| + |y| + |z| <= a.
inline Mesh octahedron_mesh(double a) {
  std::vector<Vec3> v = {{a, 0, 0}, {-a, 0, 0}, {0, a, 0}, {0, -a, 0}, {0, 0, a}, {0, 0, -a}};
  Triangles t = {{0, 2, 4}, {2, 1, 4}, {1, 3, 4}, {3, 0, 4}, {2, 0, 5}, {1, 2, 5}, {3, 1, 5}, {0, 3, 5}};
  return Mesh(std::move(v), std::move(t));
}

// The box of full edges size centred on the origin, each face split into
// n x n squares of two triangles.
inline Mesh box_surface_mesh(const Vec3& size, int n = 1) {
  std::vector<Vec3> v;
  Triangles t;
  std::map<std::array<long, 3>, int> index;
  auto vertex = [&](const Vec3& p) {
    const std::array<long, 3> key = {std::lround(p.x / size.x * 2 * n), std::lround(p.y / size.y * 2 * n),
                                     std::lround(p.z / size.z * 2 * n)};
    auto [it, added] = index.try_emplace(key, static_cast<int>(v.size()));
    if (added) v.push_back(p);
    return it->second;
  };
  for (int axis = 0; axis < 3; ++axis)
    for (int side : {-1, 1}) {
      const int u = (axis + 1) % 3, w = (axis + 2) % 3;
      for (int i = 0; i < n; ++i)
        for (int j = 0; j < n; ++j) {
          auto corner = [&](int di, int dj) {
            Vec3 p;
            p[axis] = 0.5 * side * size[axis];
            p[u] = (-0.5 + static_cast<double>(i + di) / n) * size[u];
            p[w] = (-0.5 + static_cast<double>(j + dj) / n) * size[w];
            return vertex(p);
          };
          const int a = corner(0, 0), b = corner(1, 0), c = corner(1, 1), d = corner(0, 1);
          // (u, w, axis) is right-handed: a b c d runs counter-clockwise seen from +axis.
          if (side > 0) t.push_back({a, b, c}), t.push_back({a, c, d});
          else t.push_back({a, c, b}), t.push_back({a, d, c});
        }
    }
  return Mesh(std::move(v), std::move(t));
}

// The icosahedron subdivided `levels` times, its vertices on the ellipsoid of
// semi-axes (a, b, c) (a sphere for a = b = c).
inline Mesh ellipsoid_mesh(double a, double b, double c, int levels) {
  const double p = (1.0 + std::sqrt(5.0)) / 2.0;
  std::vector<Vec3> v = {{-1, p, 0}, {1, p, 0}, {-1, -p, 0}, {1, -p, 0}, {0, -1, p}, {0, 1, p},
                         {0, -1, -p}, {0, 1, -p}, {p, 0, -1}, {p, 0, 1}, {-p, 0, -1}, {-p, 0, 1}};
  Triangles t = {{0, 11, 5}, {0, 5, 1}, {0, 1, 7}, {0, 7, 10}, {0, 10, 11}, {1, 5, 9}, {5, 11, 4},
                 {11, 10, 2}, {10, 7, 6}, {7, 1, 8}, {3, 9, 4}, {3, 4, 2}, {3, 2, 6}, {3, 6, 8},
                 {3, 8, 9}, {4, 9, 5}, {2, 4, 11}, {6, 2, 10}, {8, 6, 7}, {9, 8, 1}};
  for (Vec3& x : v) x = normalized(x);
  for (int l = 0; l < levels; ++l) {
    std::map<std::pair<int, int>, int> mid;
    auto middle = [&](int i, int j) {
      const auto key = std::minmax(i, j);
      auto [it, added] = mid.try_emplace(key, static_cast<int>(v.size()));
      if (added) v.push_back(normalized(v[i] + v[j]));
      return it->second;
    };
    Triangles next;
    for (const auto& f : t) {
      const int ab = middle(f[0], f[1]), bc = middle(f[1], f[2]), ca = middle(f[2], f[0]);
      next.push_back({f[0], ab, ca});
      next.push_back({f[1], bc, ab});
      next.push_back({f[2], ca, bc});
      next.push_back({ab, bc, ca});
    }
    t = std::move(next);
  }
  for (Vec3& x : v) x = {a * x.x, b * x.y, c * x.z};
  return Mesh(std::move(v), std::move(t));
}

// A prism of the given cross-section (counter-clockwise polygon in x, y),
// from z = -length / 2 to length / 2, with `rings` layers along z.
inline Mesh prism_mesh(const std::vector<std::array<double, 2>>& polygon, double length, int rings = 1) {
  const int n = static_cast<int>(polygon.size());
  std::vector<Vec3> v;
  for (int r = 0; r <= rings; ++r)
    for (const auto& q : polygon) v.push_back({q[0], q[1], -0.5 * length + length * r / rings});
  const int bottom = static_cast<int>(v.size()), top = bottom + 1;
  double cx = 0.0, cy = 0.0;
  for (const auto& q : polygon) cx += q[0] / n, cy += q[1] / n;
  v.push_back({cx, cy, -0.5 * length});
  v.push_back({cx, cy, 0.5 * length});
  Triangles t;
  for (int r = 0; r < rings; ++r)
    for (int k = 0; k < n; ++k) {
      const int a = r * n + k, b = r * n + (k + 1) % n;
      t.push_back({a, b, a + n});
      t.push_back({b, b + n, a + n});
    }
  for (int k = 0; k < n; ++k) {
    t.push_back({bottom, (k + 1) % n, k});
    t.push_back({top, rings * n + k, rings * n + (k + 1) % n});
  }
  return Mesh(std::move(v), std::move(t));
}

// A cylinder (axis z) as a prism of `sides` sides whose polygon has the
// circle's area, so that its volume is the cylinder's.
inline Mesh cylinder_mesh(double radius, double length, int sides, int rings = 1) {
  const double pi = 3.14159265358979323846;
  const double r = radius * std::sqrt(2.0 * pi / (sides * std::sin(2.0 * pi / sides)));
  std::vector<std::array<double, 2>> polygon;
  for (int k = 0; k < sides; ++k) polygon.push_back({r * std::cos(2.0 * pi * k / sides), r * std::sin(2.0 * pi * k / sides)});
  return prism_mesh(polygon, length, rings);
}

// H of the uniformly magnetized polyhedron at p from its face charges
// sigma = M . n, H = (1/4 pi) sum_f sigma_f int_f (p - x') / |p - x'|^3 dA',
// each face split into 64 triangles with 8 x 8 Gauss-Legendre points each
// (collapsed square): for points at least a tenth of an edge from the
// surface.
inline Vec3 face_charge_H(const Mesh& m, const Vec3& M, const Vec3& p) {
  static const double gx[8] = {-0.960289856497536, -0.796666477413627, -0.525532409916329, -0.183434642495650,
                               0.183434642495650,  0.525532409916329,  0.796666477413627,  0.960289856497536};
  static const double gw[8] = {0.101228536290376, 0.222381034453374, 0.313706645877887, 0.362683783378362,
                               0.362683783378362, 0.313706645877887, 0.222381034453374, 0.101228536290376};
  Vec3 H;
  for (const auto& f : m.triangles()) {
    const Vec3 a = m.vertices()[f[0]], b = m.vertices()[f[1]], c = m.vertices()[f[2]];
    const Vec3 nn = cross(b - a, c - a);
    const double sigma = dot(M, nn / norm(nn));
    // Each triangle split into 16 by its edges' quarter points, 8 x 8 Gauss
    // points on the square mapped onto each (collapsed coordinates).
    const int s = 8;
    for (int i = 0; i < s; ++i)
      for (int j = 0; j < s - i; ++j)
        for (int up = 0; up < 2; ++up) {
          if (up && j == s - i - 1) continue;
          Vec3 A, B, C;
          auto at = [&](double u, double v) { return a + (u / s) * (b - a) + (v / s) * (c - a); };
          if (!up) A = at(i, j), B = at(i + 1, j), C = at(i, j + 1);
          else A = at(i + 1, j), B = at(i + 1, j + 1), C = at(i, j + 1);
          const double area2 = norm(cross(B - A, C - A));
          for (int q = 0; q < 8; ++q)
            for (int r = 0; r < 8; ++r) {
              const double xi = 0.5 * (gx[q] + 1.0), eta = 0.5 * (gx[r] + 1.0);
              const Vec3 x = A + xi * (B - A) + xi * eta * (C - B);
              const double w = 0.25 * gw[q] * gw[r] * xi * area2;
              const Vec3 d = p - x;
              H = H + (w * sigma / (4.0 * kPi * std::pow(norm(d), 3))) * d;
            }
        }
  }
  return H;
}

}  // namespace odemag::test
