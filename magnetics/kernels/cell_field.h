// The field of one uniformly magnetized cell at an arbitrary point, for field
// probes (`odemag field`, field lines): cubes for lattice cells, the body's own
// box or sphere for single-cell bodies. The relaxation and the forces use the
// dipole kernel (magnetics/kernels/kernels.h); outside a cell both agree up to
// (size / distance)^4 for cubes and exactly for spheres.
#pragma once

#include "odemag/constants.h"
#include "magnetics/kernels/hd.h"
#include "magnetics/kernels/kernels.h"
#include "odemag/vec3.h"

namespace odemag {

// H (A/m) at offset r from the centre of a uniformly magnetized sphere of
// radius R and moment mu: the dipole field outside, -M/3 = -mu/(4 pi R^3) inside.
ODEMAG_HD Vec3 uniform_sphere_field(const Vec3& r, double R, const Vec3& mu) {
  if (squared_norm(r) >= R * R) return dipole_field(r, mu, 0.0);
  return (-1.0 / (4.0 * kPi * R * R * R)) * mu;
}

// log(Z2 + R2) - log(Z1 + R1) at the same (X, Y): the difference that the
// cuboid's off-diagonal terms need, written so that it stays finite on the
// line of an edge beyond its end (Z + R = (X^2 + Y^2) / (R - Z) for Z < 0).
// On the edge itself (rho = 0 between the ends) the field of one cuboid
// diverges; rho is floored at eps there, so that on an edge shared by
// neighbouring cubes of a lattice their equal and opposite terms cancel.
ODEMAG_HD double log_pair(double X, double Y, double Z1, double Z2, double eps) {
  const double rho2 = larger(X * X + Y * Y, eps * eps);
  const double R1 = sqrt(rho2 + Z1 * Z1), R2 = sqrt(rho2 + Z2 * Z2);
  if (Z1 >= 0.0 && Z2 >= 0.0) return log((Z2 + R2) / (Z1 + R1));
  if (Z1 < 0.0 && Z2 < 0.0) return log((R1 - Z1) / (R2 - Z2));
  return log((Z2 >= 0.0 ? Z2 + R2 : rho2 / (R2 - Z2)) / (Z1 >= 0.0 ? Z1 + R1 : rho2 / (R1 - Z1)));
}

// atan(Y Z / (X R)), taken as 0 in the plane X = 0 (the mean of the two
// sides: exact outside the face, the average of both sides on it).
ODEMAG_HD double corner_angle(double X, double Y, double Z) {
  if (X == 0.0) return 0.0;
  return atan(Y * Z / (X * sqrt(X * X + Y * Y + Z * Z)));
}

// (A / R_A - B / R_B) / rho^2 with R = sqrt(rho^2 + Z^2), rho^2 = X^2 + Y^2, for
// the two ends Z = A > B of a pair along one axis: the factor that the
// gradient of the cuboid's tensor needs. Where A and B have the same sign (the
// point beyond the ends of the edge's line) the difference is rewritten as
// (A^2 - B^2) / (R_A R_B (A R_B + B R_A)), finite as rho -> 0; beside the
// edge (B < 0 < A) it diverges like 1 / rho^2 on the edge itself (rho floored
// at eps, as in log_pair).
ODEMAG_HD double edge_ratio(double X, double Y, double A, double B, double eps) {
  const double rho2 = larger(X * X + Y * Y, eps * eps);
  const double RA = sqrt(rho2 + A * A), RB = sqrt(rho2 + B * B);
  if (A * B >= 0.0) {
    const double den = A * RB + B * RA;
    if (den != 0.0) return (A - B) * (A + B) / (RA * RB * den);
  }
  return (A / RA - B / RB) / rho2;
}

// The corner terms of an axis-aligned cuboid's demagnetising tensor at a point
// p: what cuboid_demag_tensor and cuboid_demag_gradient sum with the corners'
// signs. Index 0 is the lower face plane of an axis (x' = -a, s = -1), 1 the
// upper (x' = +a, s = +1); offset[k][i] = p_k - x'_k. Edges e run along one
// axis between two face planes of the other two: e = 0 along z (x, y planes),
// 1 along y (x, z planes), 2 along x (y, z planes). Lattices whose cells share
// face planes compute each term once for all cells (ball_lattice_near_field.cpp).
struct CuboidCornerTerms {
  double offset[3][2];                // p_k - x'_k, unsnapped
  double angle[2][2][2][3];           // corner_angle(X, Y, Z), (Y, X, Z), (Z, X, Y)
  double inverse_distance[2][2][2];   // 1 / R (the gradient only)
  double log_pair[3][2][2];           // log_pair along the edge
  double edge_ratio[3][2][2];         // edge_ratio along the edge (the gradient only)
};

// The snapping distance of a cuboid's terms: points within 1e-12 of its size
// of a face plane count as on it (cuboid_demag_tensor).
ODEMAG_HD double cuboid_snap_distance(const Vec3& half) { return 1e-12 * (half.x + half.y + half.z); }

// An offset from a face plane, 0 within the snapping distance eps.
ODEMAG_HD double snap_to_plane(double v, double eps) { return fabs(v) < eps ? 0.0 : v; }

// The three angles at corner offsets (X, Y, Z), unsnapped, of a cuboid with
// snapping distance eps; with_gradient: also 1 / R.
ODEMAG_HD void cuboid_corner(double X, double Y, double Z, double eps, bool with_gradient, double angle[3],
                             double& inverse_distance) {
  const double Xs = snap_to_plane(X, eps), Ys = snap_to_plane(Y, eps), Zs = snap_to_plane(Z, eps);
  angle[0] = corner_angle(Xs, Ys, Zs);
  angle[1] = corner_angle(Ys, Xs, Zs);
  angle[2] = corner_angle(Zs, Xs, Ys);
  if (with_gradient) inverse_distance = 1.0 / sqrt(larger(X * X + Y * Y + Z * Z, eps * eps));
}

// log_pair of the edge at offsets (U, W) from its two planes, running from
// offset A (the lower plane) to B (the upper), unsnapped; with_gradient: also
// edge_ratio.
ODEMAG_HD void cuboid_edge(double U, double W, double A, double B, double eps, bool with_gradient,
                           double& log_term, double& ratio) {
  log_term = log_pair(snap_to_plane(U, eps), snap_to_plane(W, eps), snap_to_plane(A, eps), snap_to_plane(B, eps), eps);
  if (with_gradient) ratio = edge_ratio(U, W, A, B, eps);
}

// The corner terms of the cuboid of half extents `half` centred at the
// origin, at p (with_gradient = false leaves inverse_distance and edge_ratio
// unset).
ODEMAG_HD void cuboid_corner_terms(const Vec3& p, const Vec3& half, bool with_gradient, CuboidCornerTerms& t) {
  const double eps = cuboid_snap_distance(half);
  const double P[3] = {p.x, p.y, p.z}, H[3] = {half.x, half.y, half.z};
  for (int k = 0; k < 3; ++k) {
    t.offset[k][0] = P[k] + H[k];
    t.offset[k][1] = P[k] - H[k];
  }
  for (int i = 0; i < 2; ++i)
    for (int j = 0; j < 2; ++j)
      for (int l = 0; l < 2; ++l)
        cuboid_corner(t.offset[0][i], t.offset[1][j], t.offset[2][l], eps, with_gradient, t.angle[i][j][l],
                      t.inverse_distance[i][j][l]);
  // Edge e runs along axis `along[e]` between planes of axes u[e], w[e].
  constexpr int u[3] = {0, 0, 1}, w[3] = {1, 2, 2}, along[3] = {2, 1, 0};
  for (int e = 0; e < 3; ++e)
    for (int i = 0; i < 2; ++i)
      for (int j = 0; j < 2; ++j)
        cuboid_edge(t.offset[u[e]][i], t.offset[w[e]][j], t.offset[along[e]][0], t.offset[along[e]][1], eps,
                    with_gradient, t.log_pair[e][i][j], t.edge_ratio[e][i][j]);
}

// Demagnetising tensor N(p) of an axis-aligned cuboid of half extents
// (a, b, c) centred at the origin: H(p) = -N(p) M. From the surface charges
// sigma = M.n summed over the eight corners (x' = +-a, ...), sign s = sx sy sz:
//   N_xx = -(1/4pi) sum s atan(Y Z / (X R)),  N_xy = (1/4pi) sum s log(Z + R),
// with X = x - x', etc., and the other components by permutation; the logs
// are summed in pairs along an edge (log_pair). Six components (xx, xy, xz,
// yy, yz, zz), from the corner terms.
ODEMAG_HD void cuboid_demag_tensor(const CuboidCornerTerms& t, double n[6]) {
  const double k = 1.0 / (4.0 * kPi);
  double xx = 0, yy = 0, zz = 0, xy = 0, xz = 0, yz = 0;
  for (int i = 0; i < 2; ++i)
    for (int j = 0; j < 2; ++j)
      for (int l = 0; l < 2; ++l) {
        const double s = (i ? 1.0 : -1.0) * (j ? 1.0 : -1.0) * (l ? 1.0 : -1.0);
        xx -= s * t.angle[i][j][l][0];
        yy -= s * t.angle[i][j][l][1];
        zz -= s * t.angle[i][j][l][2];
      }
  for (int i = 0; i < 2; ++i)
    for (int j = 0; j < 2; ++j) {
      const double s = (i ? 1.0 : -1.0) * (j ? 1.0 : -1.0);
      xy += s * t.log_pair[0][i][j];
      xz += s * t.log_pair[1][i][j];
      yz += s * t.log_pair[2][i][j];
    }
  n[0] = k * xx;
  n[1] = k * xy;
  n[2] = k * xz;
  n[3] = k * yy;
  n[4] = k * yz;
  n[5] = k * zz;
}

// N(p) of the cuboid of half extents `half` centred at the origin. N(0) = I/3
// for a cube. Points within 1e-12 of the size of a face plane count as on it
// (both sides then take the mean, so a point on a face shared by two lattice
// cubes gets a consistent value from each, whatever the round-off of its
// position).
ODEMAG_HD void cuboid_demag_tensor(const Vec3& p, const Vec3& half, double n[6]) {
  CuboidCornerTerms t;
  cuboid_corner_terms(p, half, false, t);
  cuboid_demag_tensor(t, n);
}

// The gradient of cuboid_demag_tensor: g[m][k] = dN_m / dp_k (m in the
// order xx, xy, xz, yy, yz, zz). N = -grad grad psi with psi the Newtonian
// potential of the cuboid, (1/4pi) int dV' / |p - p'|, so dN_ij / dp_k is
// fully symmetric in i, j, k (10 components) and, because tr N is constant
// off the surface (1 inside, 0 outside), dN_ii / dp_i = -sum_(j != i)
// dN_jj / dp_i. With the corners as in cuboid_demag_tensor (s = sx sy sz):
//   dN_xy / dz = (1/4pi) sum s / R,
//   dN_xy / dx = dN_xx / dy = (1/4pi) sum_(sx, sy) sx sy X E(X, Y; z + c, z - c),
//   dN_xy / dy = dN_yy / dx = (1/4pi) sum_(sx, sy) sx sy Y E(X, Y; z + c, z - c),
// E = edge_ratio (from d log(Z + R) / dX = X / rho^2 - X Z / (R rho^2), whose
// first term cancels between the two ends), and the other pairs by
// permutation. Valid off the cuboid's surface; singular on its edges (like
// N's off-diagonal logs) and, as the field's normal component jumps there,
// meaningless on its faces. From corner terms computed with the gradient.
ODEMAG_HD void cuboid_demag_gradient(const CuboidCornerTerms& t, double g[6][3]) {
  const double k = 1.0 / (4.0 * kPi);
  // d[o][r] = dN_rr / dp_o = dN_ro / dp_r for o != r (the symmetry above).
  double d[3][3] = {};
  for (int i = 0; i < 3; ++i)
    for (int j = i + 1; j < 3; ++j) {
      const int e = i + j - 1;  // the edge index of the pair (0: xy along z, 1: xz along y, 2: yz along x)
      double di = 0.0, dj = 0.0;
      for (int a = 0; a < 2; ++a)
        for (int b = 0; b < 2; ++b) {
          const double si = a ? 1.0 : -1.0, sj = b ? 1.0 : -1.0;
          const double r = t.edge_ratio[e][a][b];
          di += si * sj * t.offset[i][a] * r;
          dj += si * sj * t.offset[j][b] * r;
        }
      d[i][j] = k * dj;  // dN_ij / dp_j = dN_jj / dp_i
      d[j][i] = k * di;  // dN_ij / dp_i = dN_ii / dp_j
    }
  double xyz = 0.0;
  for (int a = 0; a < 2; ++a)
    for (int b = 0; b < 2; ++b)
      for (int c = 0; c < 2; ++c)
        xyz += (a ? 1.0 : -1.0) * (b ? 1.0 : -1.0) * (c ? 1.0 : -1.0) * t.inverse_distance[a][b][c];
  xyz *= k;
  // G(i, j, l) = dN_ij / dp_l, fully symmetric.
  auto G = [&](int i, int j, int l) {
    if (i != j && j != l && i != l) return xyz;
    if (i == j && j == l) {
      double s = 0.0;  // dN_ii / dp_i = -sum_(m != i) dN_mm / dp_i
      for (int m = 0; m < 3; ++m)
        if (m != i) s -= d[i][m];
      return s;
    }
    // two equal indices: the repeated one r, the other o; dN_rr / dp_o = d[o][r].
    const int r = i == j ? i : (i == l ? i : j), o = i + j + l - 2 * r;
    return d[o][r];
  };
  constexpr int row[6] = {0, 0, 0, 1, 1, 2}, col[6] = {0, 1, 2, 1, 2, 2};
  for (int m = 0; m < 6; ++m)
    for (int l = 0; l < 3; ++l) g[m][l] = G(row[m], col[m], l);
}

ODEMAG_HD void cuboid_demag_gradient(const Vec3& p, const Vec3& half, double g[6][3]) {
  CuboidCornerTerms t;
  cuboid_corner_terms(p, half, true, t);
  cuboid_demag_gradient(t, g);
}

// H (A/m) at p (cuboid frame) of an axis-aligned cuboid with magnetization M.
ODEMAG_HD Vec3 uniform_cuboid_field(const Vec3& p, const Vec3& half, const Vec3& M) {
  double n[6];
  cuboid_demag_tensor(p, half, n);
  return -symmetric_times(n, M);
}


// One cell as a field source for probes.
struct ProbeCell {
  enum Kind : int { sphere = 0, cuboid = 1 };
  Vec3 position;   // centre, world, m
  Vec3 moment;     // mu = M V, world, A m^2
  Mat3 rotation;   // cell frame -> world (the body's rotation)
  Vec3 half;       // cuboid half extents, m; sphere: (R, R, R)
  double volume;   // m^3 of the uniformly magnetized solid the cell stands for
  Vec3 body_centre;  // the cell's body, world
  double near2;      // within this squared distance of the body centre, exact fields
  int kind;
};

// Near a body (within this many times its bounding radius) its cuboid cells
// give their exact fields; farther, all of them are point dipoles, whose sum
// over a lattice body is accurate to O((h / distance)^4) with the errors of
// neighbouring cells cancelling. The choice is made per body: mixing exact and
// dipole cells within one body would lose that cancellation.
inline constexpr double kProbeNearBodies = 12.0;

// H (A/m) of one cell at a world point.
ODEMAG_HD Vec3 probe_cell_field(const ProbeCell& c, const Vec3& point) {
  const Vec3 r = point - c.position;
  if (c.kind == ProbeCell::sphere) return uniform_sphere_field(r, c.half.x, c.moment);
  if (squared_norm(point - c.body_centre) > c.near2) return dipole_field(r, c.moment, 0.0);
  const Vec3 M_local = c.rotation.transpose_times(c.moment) / c.volume;
  return c.rotation * uniform_cuboid_field(c.rotation.transpose_times(r), c.half, M_local);
}

}  // namespace odemag
