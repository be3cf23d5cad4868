// Independent analytic references for the magnetics tests: fields of uniformly
// magnetized cuboids and spheres, and the magnetization of linear (soft or
// recoil) spheres in a uniform field. Written from the physics only: nothing
// here uses odemag's kernels (magnetics/kernels/kernels.h) or its relaxation code;
// only the plain Vec3 / Mat3 value types are shared. SI units throughout
// (H, M in A/m, B in T, moments in A m^2).
//
// ---------------------------------------------------------------------------
// Uniformly magnetized cuboid (magnetic surface-charge formulation)
// ---------------------------------------------------------------------------
// A body of uniform magnetization M carries the surface charge sigma = M.n on
// its faces and no volume charge (div M = 0 inside). Its scalar potential is
//   phi(r) = 1/(4 pi) oint M.n' / |r - r'| dA'
//          = -1/(4 pi) M . grad G(r),     G(r) = int_V dV' / |r - r'|,
// (divergence theorem) and H = -grad phi, so
//   H(r) = -N(r) M,   N(r) = -1/(4 pi) Hess G(r),   B = mu0 (H + M [inside]).
// N is the (position dependent) demagnetizing tensor; inside the body
// trace N = 1 because lap G = -4 pi there, outside trace N = 0.
//
// For the box [-a/2, a/2] x [-b/2, b/2] x [-c/2, c/2] write the corner offsets
//   X = x - x',  Y = y - y',  Z = z - z',  x' in {-a/2, +a/2}, ...,
//   R = sqrt(X^2 + Y^2 + Z^2),
// with the corner sign s = s_x s_y s_z, s_x = +1 for x' = -a/2 (the upper limit
// of X) and -1 for x' = +a/2. The volume integral of any f(r - r') is then
// sum_corners s F(X, Y, Z) with F a triple antiderivative of f. Needed are
// the second derivatives of the antiderivative P of 1/R:
//   d2P/dX2  = -atan(Y Z / (X R))     [d2/dYdZ atan(YZ/(XR)) = X / R^3]
//   d2P/dXdY =  log(Z + R)            [d/dZ log(Z + R) = 1 / R]
// (up to terms that lack one of the variables and cancel in the corner sum).
// Hence, with the other components by cyclic permutation,
//   N_xx(r) =  1/(4 pi) sum_corners s atan(Y Z / (X R))
//   N_xy(r) = -1/(4 pi) sum_corners s log(Z + R)
// and for the potential (H = -grad phi, used by the self-checks)
//   phi(r)  = -1/(4 pi) sum_corners s M . (P_X, P_Y, P_Z),
//   P_X     = Y log(Z + R) + Z log(Y + R) - X atan(Y Z / (X R))   (cyclic).
// Check: at the centre of a cube each of the 8 corners gives atan(1/sqrt 3)
// = pi/6 with s = +1 after the sign of YZ/X is absorbed, so N_xx = 1/3.
//
// Singular and delicate cases:
// * X = 0 (the point lies in the plane of a face normal to x): the one-sided
//   limits of atan(YZ/(XR)) are +-pi/2 sign(YZ). Outside the face's own
//   rectangle the four corners of that face cancel pairwise for either limit,
//   so the term is set to 0; on the face itself this gives the average of the
//   fields just inside and just outside (the usual value on a charged sheet).
// * log(Z + R) for Z < 0 loses all digits (R ~ -Z); it is evaluated as a
//   difference over the two z corners of the same (x', y'):
//     log((Z1 + R1) / (Z2 + R2)),  Z1 = z + c/2 > Z2 = z - c/2,
//   rewritten with Z + R = (X^2 + Y^2) / (R - Z) so that no cancellation
//   occurs; when both Z are negative the factors X^2 + Y^2 cancel exactly, so
//   points on the line of an edge but beyond its end stay finite. On an edge
//   itself (X = Y = 0 with Z1 > 0 > Z2) the off-diagonal field diverges
//   logarithmically, as it physically does; the result is then +-inf.
// * Points on a corner are singular too; the references are not meant to be
//   evaluated exactly there.
//
// ---------------------------------------------------------------------------
// Uniformly magnetized sphere (radius R, magnetization M, moment m = V M)
//   outside: H = (3 u (u . m) - m) / (4 pi r^3),  u = r / |r|, B = mu0 H
//   inside:  H = -M / 3,  B = mu0 (H + M) = 2/3 mu0 M.
//
// Linear sphere in a uniform field H0 (inside a uniformly magnetized sphere
// H_in = H0 - M / 3, uniform):
//   soft, M = chi H_in:        M = chi H0 / (1 + chi/3) = 3 chi / (chi + 3) H0,
//                              moment m = 4 pi R^3 chi / (chi + 3) H0
//                              (chi -> inf: m = 4 pi R^3 H0, M = 3 H0);
//   with saturation (the intrinsic curve M = min(chi H_in, Ms) along H_in):
//                              |M| = min(3 chi/(chi + 3) |H0|, Ms) along H0,
//                              saturated moment (4/3) pi R^3 Ms;
//   recoil, M = M_r + chi_r H_in:
//                              M = (M_r + chi_r H0) / (1 + chi_r / 3).
#pragma once

#include <algorithm>
#include <cmath>
#include <vector>

#include "odemag/vec3.h"

namespace odemag::reference {

inline constexpr double kRefPi = 3.141592653589793238462643383279502884;
inline constexpr double kRefMu0 = 4.0e-7 * kRefPi;

struct FieldHB {
  Vec3 H;  // A/m
  Vec3 B;  // T
};

// Symmetric 3x3 tensor, components xx, yy, zz, xy, yz, zx.
struct SymTensor {
  double xx = 0, yy = 0, zz = 0, xy = 0, yz = 0, zx = 0;
  Vec3 operator*(const Vec3& v) const {
    return {xx * v.x + xy * v.y + zx * v.z, xy * v.x + yy * v.y + yz * v.z,
            zx * v.x + yz * v.y + zz * v.z};
  }
};

namespace detail {

// atan(Y Z / (X R)), 0 in the plane X = 0 (see the header comment).
inline double corner_atan(double X, double Y, double Z, double R) {
  if (X == 0.0) return 0.0;
  return std::atan((Y * Z) / (X * R));
}

// Z + R computed without cancellation for Z < 0.
inline double z_plus_r(double X, double Y, double Z, double R) {
  return Z >= 0.0 ? Z + R : (X * X + Y * Y) / (R - Z);
}

// log(Z1 + R1) - log(Z2 + R2) for Z1 > Z2 at the same (X, Y).
inline double log_pair(double X, double Y, double Z1, double Z2) {
  const double R1 = std::sqrt(X * X + Y * Y + Z1 * Z1);
  const double R2 = std::sqrt(X * X + Y * Y + Z2 * Z2);
  if (Z2 >= 0.0) return std::log((Z1 + R1) / (Z2 + R2));
  if (Z1 <= 0.0) return std::log((R2 - Z2) / (R1 - Z1));  // rho^2 cancels
  return std::log((Z1 + R1) * (R2 - Z2) / (X * X + Y * Y));  // straddles: inf on the edge
}

// Y log(Z + R), 0 when Y = 0 (the log is then at worst a finite-times-zero).
inline double y_log_z_plus_r(double X, double Y, double Z, double R) {
  if (Y == 0.0) return 0.0;
  return Y * std::log(z_plus_r(X, Y, Z, R));
}

// Calls f(s, X, Y, Z, R) at the 8 corners (xs[i], ys[j], zs[k]) of a box seen
// from the field point, s = +1 or -1 the corner's sign (-1)^(i+j+k).
template <class F>
void for_each_corner(const double xs[2], const double ys[2], const double zs[2], F&& f) {
  for (int i = 0; i < 2; ++i)
    for (int j = 0; j < 2; ++j)
      for (int k = 0; k < 2; ++k) {
        const double s = ((i + j + k) % 2 == 0) ? 1.0 : -1.0;
        const double X = xs[i], Y = ys[j], Z = zs[k];
        const double R = std::sqrt(X * X + Y * Y + Z * Z);
        f(s, X, Y, Z, R);
      }
}

}  // namespace detail

// Demagnetizing tensor field N(r) of the box of full edges `size`, centred at
// the origin and axis-aligned; H = -N M. Exact closed form (header comment).
inline SymTensor cuboid_demag_tensor(const Vec3& size, const Vec3& r) {
  const double xs[2] = {r.x + 0.5 * size.x, r.x - 0.5 * size.x};  // X with s_x = +1, -1
  const double ys[2] = {r.y + 0.5 * size.y, r.y - 0.5 * size.y};
  const double zs[2] = {r.z + 0.5 * size.z, r.z - 0.5 * size.z};
  double sxx = 0, syy = 0, szz = 0;
  detail::for_each_corner(xs, ys, zs, [&](double s, double X, double Y, double Z, double R) {
    sxx += s * detail::corner_atan(X, Y, Z, R);
    syy += s * detail::corner_atan(Y, Z, X, R);
    szz += s * detail::corner_atan(Z, X, Y, R);
  });
  // Off-diagonals: sum over the corners of s log(W + R), W the third axis,
  // grouped into pairs along W (log_pair) for stability.
  double sxy = 0, syz = 0, szx = 0;
  for (int i = 0; i < 2; ++i)
    for (int j = 0; j < 2; ++j) {
      const double s = ((i + j) % 2 == 0) ? 1.0 : -1.0;
      sxy += s * detail::log_pair(xs[i], ys[j], zs[0], zs[1]);  // N_xy: log(Z + R)
      syz += s * detail::log_pair(ys[i], zs[j], xs[0], xs[1]);  // N_yz: log(X + R)
      szx += s * detail::log_pair(zs[i], xs[j], ys[0], ys[1]);  // N_zx: log(Y + R)
    }
  const double k = 1.0 / (4.0 * kRefPi);
  SymTensor n;
  n.xx = k * sxx;
  n.yy = k * syy;
  n.zz = k * szz;
  n.xy = -k * sxy;
  n.yz = -k * syz;
  n.zx = -k * szx;
  return n;
}

inline bool inside_box(const Vec3& size, const Vec3& r) {
  return std::abs(r.x) < 0.5 * size.x && std::abs(r.y) < 0.5 * size.y &&
         std::abs(r.z) < 0.5 * size.z;
}

// H and B of the axis-aligned box centred at the origin, magnetization M.
inline FieldHB cuboid_field_local(const Vec3& size, const Vec3& M, const Vec3& r) {
  const Vec3 H = -(cuboid_demag_tensor(size, r) * M);
  const Vec3 B = kRefMu0 * (inside_box(size, r) ? H + M : H);
  return {H, B};
}

// Scalar potential phi (A) of the same box, H = -grad phi.
inline double cuboid_potential_local(const Vec3& size, const Vec3& M, const Vec3& r) {
  const double xs[2] = {r.x + 0.5 * size.x, r.x - 0.5 * size.x};
  const double ys[2] = {r.y + 0.5 * size.y, r.y - 0.5 * size.y};
  const double zs[2] = {r.z + 0.5 * size.z, r.z - 0.5 * size.z};
  using detail::corner_atan;
  using detail::y_log_z_plus_r;
  double sum = 0.0;
  detail::for_each_corner(xs, ys, zs, [&](double s, double X, double Y, double Z, double R) {
    const double px = y_log_z_plus_r(X, Y, Z, R) + y_log_z_plus_r(X, Z, Y, R) - X * corner_atan(X, Y, Z, R);
    const double py = y_log_z_plus_r(Y, Z, X, R) + y_log_z_plus_r(Y, X, Z, R) - Y * corner_atan(Y, Z, X, R);
    const double pz = y_log_z_plus_r(Z, X, Y, R) + y_log_z_plus_r(Z, Y, X, R) - Z * corner_atan(Z, X, Y, R);
    sum += s * (M.x * px + M.y * py + M.z * pz);
  });
  return -sum / (4.0 * kRefPi);
}

// A box magnet in an arbitrary pose: edges `size` and magnetization M_body
// along the body axes, body frame -> world by `rotation`, centre at `centre`.
struct CuboidMagnet {
  Vec3 size;
  Vec3 M_body;
  Mat3 rotation;
  Vec3 centre;

  FieldHB field(const Vec3& world_point) const {
    const Vec3 local = rotation.transpose_times(world_point - centre);
    const FieldHB f = cuboid_field_local(size, M_body, local);
    return {rotation * f.H, rotation * f.B};
  }
  Vec3 moment() const { return (size.x * size.y * size.z) * (rotation * M_body); }
};

// Uniformly magnetized sphere of radius R and magnetization M (world) at centre.
inline FieldHB sphere_field(double R, const Vec3& M, const Vec3& centre, const Vec3& p) {
  const Vec3 r = p - centre;
  const double d = norm(r);
  if (d < R) {
    const Vec3 H = (-1.0 / 3.0) * M;
    return {H, kRefMu0 * (H + M)};
  }
  const Vec3 m = (4.0 / 3.0 * kRefPi * R * R * R) * M;
  const Vec3 u = r / d;
  const Vec3 H = (1.0 / (4.0 * kRefPi * d * d * d)) * (3.0 * dot(u, m) * u - m);
  return {H, kRefMu0 * H};
}

// Field of a point dipole m at the origin.
inline Vec3 point_dipole_H(const Vec3& m, const Vec3& r) {
  const double d = norm(r);
  const Vec3 u = r / d;
  return (1.0 / (4.0 * kRefPi * d * d * d)) * (3.0 * dot(u, m) * u - m);
}

// Moment of a soft sphere (intrinsic curve M = min(chi H_in, Ms) along H_in)
// of radius R in the uniform field H0. chi may be +infinity.
inline Vec3 soft_sphere_moment(double R, double chi, double Ms, const Vec3& H0) {
  const double V = 4.0 / 3.0 * kRefPi * R * R * R;
  const double h = norm(H0);
  if (h == 0.0) return {};
  const double linear = std::isinf(chi) ? 3.0 * h : 3.0 * chi / (chi + 3.0) * h;  // |M| unsaturated
  return (V * std::min(linear, Ms) / h) * H0;
}

// Magnetization of a sphere of linear recoil material M = M_r + chi_r H_in in
// the uniform field H0 (all world frame).
inline Vec3 recoil_sphere_magnetization(const Vec3& M_r, double chi_r, const Vec3& H0) {
  return (1.0 / (1.0 + chi_r / 3.0)) * (M_r + chi_r * H0);
}

// ---------------------------------------------------------------------------
// Brute-force check of the closed form: H from direct quadrature of the
// surface charges, H(r) = 1/(4 pi) sum_faces sigma int (r - r') / |r - r'|^3 dA',
// with composite Gauss-Legendre rules (panels x panels per face, `order`
// nodes per panel and axis). Accurate only for points well away from the
// faces (distance >> panel size / order).

// Gauss-Legendre nodes and weights on [-1, 1] (Newton on P_n).
inline void gauss_legendre(int n, std::vector<double>& x, std::vector<double>& w) {
  x.assign(n, 0.0);
  w.assign(n, 0.0);
  for (int i = 0; i < n; ++i) {
    double t = std::cos(kRefPi * (i + 0.75) / (n + 0.5));
    double dp = 1.0;
    for (int it = 0; it < 100; ++it) {
      double p0 = 1.0, p1 = t;
      for (int k = 2; k <= n; ++k) {
        const double p2 = ((2.0 * k - 1.0) * t * p1 - (k - 1.0) * p0) / k;
        p0 = p1;
        p1 = p2;
      }
      dp = n * (t * p1 - p0) / (t * t - 1.0);
      const double dt = p1 / dp;
      t -= dt;
      if (std::abs(dt) < 1e-16) break;
    }
    x[i] = t;
    w[i] = 2.0 / ((1.0 - t * t) * dp * dp);
  }
}

inline Vec3 cuboid_H_quadrature(const Vec3& size, const Vec3& M, const Vec3& r, int panels = 16,
                                int order = 10) {
  std::vector<double> gx, gw;
  gauss_legendre(order, gx, gw);
  Vec3 H;
  for (int axis = 0; axis < 3; ++axis) {
    const int u = (axis + 1) % 3, v = (axis + 2) % 3;
    const double lu = size[u], lv = size[v];
    for (int side = -1; side <= 1; side += 2) {
      const double sigma = side * M[axis];  // M . n, n = side * e_axis
      if (sigma == 0.0) continue;
      Vec3 sum;
      for (int pu = 0; pu < panels; ++pu)
        for (int pv = 0; pv < panels; ++pv)
          for (int iu = 0; iu < order; ++iu)
            for (int iv = 0; iv < order; ++iv) {
              Vec3 q;
              q[axis] = 0.5 * side * size[axis];
              q[u] = -0.5 * lu + lu * (pu + 0.5 * (gx[iu] + 1.0)) / panels;
              q[v] = -0.5 * lv + lv * (pv + 0.5 * (gx[iv] + 1.0)) / panels;
              const Vec3 d = r - q;
              const double dn = norm(d);
              const double wt = gw[iu] * gw[iv] * 0.25 * (lu / panels) * (lv / panels);
              sum += (wt / (dn * dn * dn)) * d;
            }
      H += (sigma / (4.0 * kRefPi)) * sum;
    }
  }
  return H;
}

}  // namespace odemag::reference
