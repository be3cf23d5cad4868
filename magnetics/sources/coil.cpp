// Current sources: closed-form fields of filaments and sheets, quadrature over
// finite cross-sections, current elements for forces (magnetics/sources/coil.h;
// docs/model.md "Current sources (coils)").
#include "magnetics/sources/coil.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>
#include <type_traits>
#include <utility>

#include "odemag/constants.h"

namespace odemag {

CoilFrame frame_from_axis(const Vec3& axis) {
  CoilFrame f;
  f.e3 = normalized(axis);
  const Vec3 helper = std::abs(f.e3.x) < 0.9 ? Vec3{1.0, 0.0, 0.0} : Vec3{0.0, 1.0, 0.0};
  f.e1 = normalized(cross(helper, f.e3));
  f.e2 = cross(f.e3, f.e1);
  return f;
}

CoilFrame frame_from_axis_and(const Vec3& axis, const Vec3& first) {
  CoilFrame f;
  f.e3 = normalized(axis);
  f.e1 = normalized(first - dot(first, f.e3) * f.e3);
  f.e2 = cross(f.e3, f.e1);
  return f;
}

namespace {

constexpr int kMaxOrder = 64;

// ---------------------------------------------------------------------------
// Gauss-Legendre rules on [-1, 1], n = 1..kMaxOrder: the roots of P_n by
// Newton's iteration on the three-term recurrence, weights 2 / ((1 - x^2) P_n'(x)^2).
struct GaussRule {
  std::vector<double> x, w;
};

GaussRule make_gauss_rule(int n) {
  GaussRule rule;
  rule.x.assign(n, 0.0);
  rule.w.assign(n, 0.0);
  for (int i = 0; i < (n + 1) / 2; ++i) {
    double x = std::cos(kPi * (i + 0.75) / (n + 0.5));
    double derivative = 1.0;
    for (int iteration = 0; iteration < 100; ++iteration) {
      double p = 1.0, p_previous = 0.0;
      for (int j = 1; j <= n; ++j) {
        const double p_before = p_previous;
        p_previous = p;
        p = ((2.0 * j - 1.0) * x * p_previous - (j - 1.0) * p_before) / j;
      }
      derivative = n * (x * p - p_previous) / (x * x - 1.0);
      const double step = p / derivative;
      x -= step;
      if (std::abs(step) < 1e-16) break;
    }
    const double w = 2.0 / ((1.0 - x * x) * derivative * derivative);
    rule.x[i] = -x;
    rule.x[n - 1 - i] = x;
    rule.w[i] = w;
    rule.w[n - 1 - i] = w;
  }
  if (n % 2 == 1) rule.x[n / 2] = 0.0;
  return rule;
}

const GaussRule& gauss_rule(int n) {
  static const std::vector<GaussRule> rules = [] {
    std::vector<GaussRule> r(kMaxOrder + 1);
    for (int order = 1; order <= kMaxOrder; ++order) r[order] = make_gauss_rule(order);
    return r;
  }();
  return rules[std::clamp(n, 1, kMaxOrder)];
}

// Panels covering [lo, hi], graded towards s in [lo, hi]: boundaries at
// s +- h0 {0, 1, 2, 4, 8, ...}. A panel of length L is at least L from s (the
// first ones: h0 long, the singularity >= h0 off the real line), so the
// singularity lies outside each panel's Bernstein ellipse of parameter ~4.6:
// Gauss-Legendre's error ~4.6^(-2n) per panel, whatever the distance.
void graded_panels(double lo, double hi, double s, double h0, std::vector<std::pair<double, double>>& panels) {
  panels.clear();
  if (!(hi > lo)) return;
  s = std::clamp(s, lo, hi);
  h0 = std::max(h0, 1e-300);
  for (double a = s, h = h0; a < hi; h *= 2.0) {
    const double b = std::min(hi, s + h);
    panels.emplace_back(a, b);
    a = b;
  }
  for (double b = s, h = h0; b > lo; h *= 2.0) {
    const double a = std::max(lo, s - h);
    panels.emplace_back(a, b);
    b = a;
  }
}

// Rectangles covering [lo0, hi0] x [lo1, hi1], graded towards s: four
// squares of side h0 meeting at s, then square rings between half-sizes h and
// 2 h (h = h0 2^k), each cut on the grid s + {-2h, -h, 0, h, 2h} into twelve
// squares of side h, all clipped to the domain. A square of side L is at least
// L from s, as in one dimension, with O(log(size / h0)) squares instead of the
// tensor product's O(log^2).
struct Rect {
  double lo0, hi0, lo1, hi1;
};

void graded_rects(const Rect& domain, double s0, double s1, double h0, std::vector<Rect>& rects) {
  rects.clear();
  s0 = std::clamp(s0, domain.lo0, domain.hi0);
  s1 = std::clamp(s1, domain.lo1, domain.hi1);
  const double reach = std::max({s0 - domain.lo0, domain.hi0 - s0, s1 - domain.lo1, domain.hi1 - s1});
  h0 = std::max(h0, 1e-300);
  auto add = [&](double a0, double b0, double a1, double b1) {
    a0 = std::max(a0, domain.lo0);
    b0 = std::min(b0, domain.hi0);
    a1 = std::max(a1, domain.lo1);
    b1 = std::min(b1, domain.hi1);
    if (b0 > a0 && b1 > a1) rects.push_back({a0, b0, a1, b1});
  };
  // Centre: four squares of side h0 meeting at s.
  for (int i = 0; i < 2; ++i)
    for (int j = 0; j < 2; ++j)
      add(s0 + (i - 1) * h0, s0 + i * h0, s1 + (j - 1) * h0, s1 + j * h0);
  for (double h = h0; h < reach; h *= 2.0) {
    const double g[5] = {-2.0 * h, -h, 0.0, h, 2.0 * h};
    for (int i = 0; i < 4; ++i)
      for (int j = 0; j < 4; ++j) {
        if ((i == 1 || i == 2) && (j == 1 || j == 2)) continue;  // inside the previous ring
        add(s0 + g[i], s0 + g[i + 1], s1 + g[j], s1 + g[j + 1]);
      }
  }
}

// Two of Bulirsch's cel with the same kc and p > 0 (the iteration on kc and p
// does not depend on a, b): the loop's two components in one pass.
void cel_pair(double kc, double p, double a1, double b1, double a2, double b2, double& cel1, double& cel2) {
  constexpr double kTolerance = 1.5e-8;
  kc = std::abs(kc);
  double e = kc, mean = 1.0;
  p = std::sqrt(p);
  b1 /= p;
  b2 /= p;
  for (int iteration = 0; iteration < 64; ++iteration) {
    const double f1 = a1, f2 = a2;
    a1 += b1 / p;
    a2 += b2 / p;
    double g = e / p;
    b1 = 2.0 * (b1 + f1 * g);
    b2 = 2.0 * (b2 + f2 * g);
    p += g;
    g = mean;
    mean += kc;
    if (std::abs(g - kc) <= g * kTolerance) break;
    kc = 2.0 * std::sqrt(e);
    e = kc * mean;
  }
  const double scale = 0.5 * kPi / (mean * (mean + p));
  cel1 = scale * (b1 + a1 * mean);
  cel2 = scale * (b2 + a2 * mean);
}

// ---------------------------------------------------------------------------
// Axisymmetric kernels in cylindrical coordinates (rho, z) about the source's
// axis; they return H_rho and H_z.

// Circular loop of radius a, ampere-turns NI, at z = 0. Biot-Savart
// (Jackson Sec. 5.5, Eq. 5.37; Smythe) with phi = pi - 2t becomes
//   B_z   = mu0 NI a / (pi q^3) cel(kc, kc^2, a + rho, a - rho),
//   B_rho = mu0 NI a z / (pi q^3) cel(kc, kc^2, -1, 1),
// q^2 = (a + rho)^2 + z^2, kc^2 = ((a - rho)^2 + z^2) / q^2 (the complementary
// modulus): Delta^-3 = Delta^-1 / (cos^2 + kc^2 sin^2) is cel's p = kc^2. No
// 1/rho, so the axis needs no special case (cel(1, 1, a, b) = pi (a + b) / 4).
void loop_kernel(double a, double ni, double rho, double z, double& h_rho, double& h_z) {
  const double alpha2 = (a - rho) * (a - rho) + z * z;
  if (alpha2 <= (kOnConductor * a) * (kOnConductor * a)) {
    h_rho = h_z = 0.0;
    return;
  }
  const double q2 = (a + rho) * (a + rho) + z * z;
  const double q = std::sqrt(q2);
  const double kc2 = alpha2 / q2;
  const double kc = std::sqrt(kc2);
  const double scale = ni * a / (kPi * q2 * q);
  double cel_z, cel_rho;
  cel_pair(kc, kc2, a + rho, a - rho, -1.0, 1.0, cel_z, cel_rho);
  h_z = scale * cel_z;
  h_rho = scale * z * cel_rho;
}

// Solenoid sheet of radius a, ends at z = -+ L/2, surface current density K
// (A/m). Derby & Olbert, Am. J. Phys. 78, 229 (2010), written in
// H: with z+- = z +- L/2, q+-^2 = z+-^2 + (a + rho)^2, kc+- = sqrt(z+-^2 + (a - rho)^2) / q+-,
// gamma = (a - rho) / (a + rho),
//   H_rho = K/pi  sum +- (a / q+-) cel(kc+-, 1, 1, -1),
//   H_z   = K/pi  a / (a + rho) sum +- (z+- / q+-) cel(kc+-, gamma^2, 1, gamma).
// On the sheet (gamma = 0) cel's principal value is the mean of both sides.
void sheet_kernel(double a, double length, double k_surface, double rho, double z, double& h_rho, double& h_z) {
  h_rho = h_z = 0.0;
  const double half = 0.5 * length;
  // Far from the sheet the two ends' terms cancel (relative rounding error
  // ~eps (r / a)^2 (r / L)): there the loops are summed instead, by 12-point
  // Gauss-Legendre over the length (nearest singularity >= 2 L from the
  // interval: Bernstein parameter >= 8, error < 1e-20).
  if (std::hypot(std::max(0.0, std::abs(z) - half), rho - a) >= 2.0 * length) {
    const GaussRule& rule = gauss_rule(12);
    for (int i = 0; i < 12; ++i) {
      double loop_rho, loop_z;
      loop_kernel(a, k_surface * half * rule.w[i], rho, z - half * rule.x[i], loop_rho, loop_z);
      h_rho += loop_rho;
      h_z += loop_z;
    }
    return;
  }
  const double edge = kOnConductor * a;
  for (const double zz : {z + half, z - half})
    if ((a - rho) * (a - rho) + zz * zz <= edge * edge) return;
  const double gamma = (a - rho) / (a + rho);
  double sum_rho = 0.0, sum_z = 0.0;
  for (int end = 0; end < 2; ++end) {
    const double zz = end == 0 ? z + half : z - half;
    const double sign = end == 0 ? 1.0 : -1.0;
    const double q2 = zz * zz + (a + rho) * (a + rho);
    const double q = std::sqrt(q2);
    const double kc = std::sqrt((zz * zz + (a - rho) * (a - rho)) / q2);
    sum_rho += sign * (a / q) * bulirsch_cel(kc, 1.0, 1.0, -1.0);
    sum_z += sign * (zz / q) * bulirsch_cel(kc, gamma * gamma, 1.0, gamma);
  }
  h_rho = k_surface / kPi * sum_rho;
  h_z = k_surface / kPi * a / (a + rho) * sum_z;
}

// Cylindrical coordinates of a point about (centre, unit axis e3).
struct Cylindrical {
  double rho, z;
  Vec3 radial;  // unit, or zero on the axis
};

Cylindrical cylindrical(const Vec3& centre, const Vec3& e3, const Vec3& point) {
  const Vec3 d = point - centre;
  Cylindrical c;
  c.z = dot(d, e3);
  const Vec3 perpendicular = d - c.z * e3;
  c.rho = norm(perpendicular);
  c.radial = c.rho > 0.0 ? perpendicular / c.rho : Vec3{};
  return c;
}

// ---------------------------------------------------------------------------
// Arcs. Integrals over t of Delta^-3 and sin^2 Delta^-3, Delta^2 = 1 - m sin^2 t
// = cos^2 t + kc2 sin^2 t, from 0 to t (DLMF 19.25.1 and 19.25.10 in
// Carlson's form): j2 = s^3/3 R_D(c^2, 1, Delta^2), j0 = s R_F(c^2, Delta^2, 1) + m j2.
struct ArcIntegrals {
  double j0 = 0.0, j2 = 0.0;
};

ArcIntegrals arc_integrals_reduced(double t, double m, double kc2) {
  const double s = std::sin(t), c = std::cos(t);
  const double delta2 = c * c + kc2 * s * s;
  ArcIntegrals r;
  r.j2 = s * s * s / 3.0 * carlson_RD(c * c, 1.0, delta2);
  r.j0 = s * carlson_RF(c * c, delta2, 1.0) + m * r.j2;
  return r;
}

// The integrals from t_low to t_high (t_low <= t_high): each integrand has
// period pi, so t = n pi + t0 with |t0| <= pi/2 and the whole periods are
// 2 (n_high - n_low) times the complete integrals (computed only if needed:
// they diverge on the circle, where the arc may still not pass the point).
ArcIntegrals arc_integrals(double t_low, double t_high, double m, double kc2) {
  const double n_low = std::nearbyint(t_low / kPi), n_high = std::nearbyint(t_high / kPi);
  const ArcIntegrals low = arc_integrals_reduced(t_low - n_low * kPi, m, kc2);
  const ArcIntegrals high = arc_integrals_reduced(t_high - n_high * kPi, m, kc2);
  ArcIntegrals r{high.j0 - low.j0, high.j2 - low.j2};
  if (n_high != n_low) {
    const double complete_j2 = carlson_RD(0.0, 1.0, kc2) / 3.0;
    const double complete_j0 = carlson_RF(0.0, kc2, 1.0) + m * complete_j2;
    r.j0 += 2.0 * (n_high - n_low) * complete_j0;
    r.j2 += 2.0 * (n_high - n_low) * complete_j2;
  }
  return r;
}

// ---------------------------------------------------------------------------
// A cuboid conductor lo <= x <= hi (local frame) with uniform current density:
// H = J x G / (4 pi), G(x) = int (x - x') / |x - x'|^3 dV' = -grad int dV' / |x - x'|,
// the field of a uniform rectangular prism (as for gravity: MacMillan 1930,
// Nagy 1966): G_x = -sum_ijk (-1)^(i+j+k) F(X_i, Y_j, Z_k), X_i = x - {lo, hi}_x, with
// F(X, Y, Z) = Y ln(Z + r) + Z ln(Y + r) - X atan(Y Z / (X r)) (d^2F/dYdZ = 1/r),
// and cyclically for G_y, G_z.
double log_sum(double a, double r, double others2) {
  // ln(a + r), r = sqrt(a^2 + others2), without cancellation for a < 0.
  if (a >= 0.0) return std::log(a + r);
  return std::log(others2 / (r - a));
}

Vec3 cuboid_G(const Vec3& lo, const Vec3& hi, const Vec3& x) {
  Vec3 g;
  for (int i = 0; i < 2; ++i)
    for (int j = 0; j < 2; ++j)
      for (int k = 0; k < 2; ++k) {
        const double X = x.x - (i == 0 ? lo.x : hi.x);
        const double Y = x.y - (j == 0 ? lo.y : hi.y);
        const double Z = x.z - (k == 0 ? lo.z : hi.z);
        const double X2 = X * X, Y2 = Y * Y, Z2 = Z * Z;
        const double r = std::sqrt(X2 + Y2 + Z2);
        if (r == 0.0) continue;  // a corner: every term vanishes
        const double sign = ((i + j + k) % 2 == 0) ? -1.0 : 1.0;
        const double lx = (Y != 0.0 || Z != 0.0) ? log_sum(X, r, Y2 + Z2) : 0.0;
        const double ly = (X != 0.0 || Z != 0.0) ? log_sum(Y, r, X2 + Z2) : 0.0;
        const double lz = (X != 0.0 || Y != 0.0) ? log_sum(Z, r, X2 + Y2) : 0.0;
        const double ax = X != 0.0 ? X * std::atan(Y * Z / (X * r)) : 0.0;
        const double ay = Y != 0.0 ? Y * std::atan(Z * X / (Y * r)) : 0.0;
        const double az = Z != 0.0 ? Z * std::atan(X * Y / (Z * r)) : 0.0;
        g.x += sign * ((Y != 0.0 ? Y * lz : 0.0) + (Z != 0.0 ? Z * ly : 0.0) - ax);
        g.y += sign * ((Z != 0.0 ? Z * lx : 0.0) + (X != 0.0 ? X * lz : 0.0) - ay);
        g.z += sign * ((X != 0.0 ? X * ly : 0.0) + (Y != 0.0 ? Y * lx : 0.0) - az);
      }
  return g;
}

// The parts of a rounded-rectangle coil in its local frame (u, v, w): four
// straight cuboids and four corner sectors.
struct CoilSide {
  Vec3 lo, hi;
  Vec3 direction;  // of the current
};
struct CoilCorner {
  double u, v;        // corner centre
  double phi_start;  // the sector phi_start .. phi_start + pi/2
};

struct CoilParts {
  CoilSide sides[4];
  int side_count = 0;
  CoilCorner corners[4];
};

CoilParts rounded_rectangle_parts(const RoundedRectangleCoil& c) {
  CoilParts parts;
  const double a = c.core_half_width, b = c.core_half_depth;
  const double r1 = c.inner_corner_radius, r2 = c.outer_corner_radius, hw = 0.5 * c.height;
  if (b > 0.0) {
    parts.sides[parts.side_count++] = {{a + r1, -b, -hw}, {a + r2, b, hw}, {0.0, 1.0, 0.0}};
    parts.sides[parts.side_count++] = {{-a - r2, -b, -hw}, {-a - r1, b, hw}, {0.0, -1.0, 0.0}};
  }
  if (a > 0.0) {
    parts.sides[parts.side_count++] = {{-a, b + r1, -hw}, {a, b + r2, hw}, {-1.0, 0.0, 0.0}};
    parts.sides[parts.side_count++] = {{-a, -b - r2, -hw}, {a, -b - r1, hw}, {1.0, 0.0, 0.0}};
  }
  parts.corners[0] = {a, b, 0.0};
  parts.corners[1] = {-a, b, 0.5 * kPi};
  parts.corners[2] = {-a, -b, kPi};
  parts.corners[3] = {a, -b, 1.5 * kPi};
  return parts;
}

// Field of one corner sector (current density J, per 4 pi) at the local point
// p: the axial integral in closed form,
//   int Z / (s^2 + Z^2)^(3/2) dZ = G1,  int (s^2 + Z^2)^(-3/2) dZ = G0,
// over Z = w - w' in [w - h/2, w + h/2], then (r, phi) by graded Gauss-Legendre.
Vec3 corner_field(const RoundedRectangleCoil& c, const CoilCorner& corner, const Vec3& p, int order,
                  std::vector<Rect>& rects) {
  const double r1 = c.inner_corner_radius, r2 = c.outer_corner_radius, hw = 0.5 * c.height;
  const double za = p.z - hw, zb = p.z + hw;
  const double du = p.x - corner.u, dv = p.y - corner.v;
  const double rho = std::hypot(du, dv);
  // Nearest source point in (r, phi) and the distance to the sector.
  double psi = std::atan2(dv, du) - corner.phi_start;
  psi -= 2.0 * kPi * std::floor(psi / (2.0 * kPi));  // 0 .. 2 pi
  double phi_near, r_near;
  if (psi <= 0.5 * kPi) {
    phi_near = psi;
    r_near = std::clamp(rho, r1, r2);
  } else {
    phi_near = psi < 1.25 * kPi ? 0.5 * kPi : 0.0;
    r_near = std::clamp(rho * std::cos(psi - phi_near), r1, r2);
  }
  const double nu = corner.u + r_near * std::cos(corner.phi_start + phi_near) - p.x;
  const double nv = corner.v + r_near * std::sin(corner.phi_start + phi_near) - p.y;
  const double plan = std::hypot(nu, nv);
  const double outside_w = std::max(0.0, std::abs(p.z) - hw);
  const double delta = std::hypot(plan, outside_w);
  // Grading in (r, r_ref phi): roughly isotropic squares.
  const double r_ref = std::max(0.5 * (r1 + r2), 1e-300);
  const double size = std::max(r2 - r1, 0.5 * kPi * r_ref);
  graded_rects({r1, r2, 0.0, 0.5 * kPi * r_ref}, r_near, phi_near * r_ref, std::max(delta, 1e-6 * size), rects);
  const GaussRule& rule = gauss_rule(order);
  Vec3 h;
  for (const Rect& rect : rects) {
    const double rm = 0.5 * (rect.lo0 + rect.hi0), rh = 0.5 * (rect.hi0 - rect.lo0);
    const double pm = 0.5 * (rect.lo1 + rect.hi1) / r_ref, ph = 0.5 * (rect.hi1 - rect.lo1) / r_ref;
    for (int j = 0; j < order; ++j) {
      const double phi = corner.phi_start + pm + ph * rule.x[j];
      const double cs = std::cos(phi), sn = std::sin(phi);
      for (int i = 0; i < order; ++i) {
        const double r = rm + rh * rule.x[i];
        const double rx = du - r * cs, ry = dv - r * sn;
        const double s2 = rx * rx + ry * ry;
        const double a2 = s2 + za * za, b2 = s2 + zb * zb;
        const double sa = std::sqrt(a2), sb = std::sqrt(b2);
        if (sa == 0.0 || sb == 0.0) continue;
        const double diff = (zb - za) * (zb + za);  // zb^2 - za^2
        const double g1 = diff / (sa * sb * (sa + sb));
        double g0;
        if (za * zb > 0.0)
          g0 = diff / (sa * sb * (zb * sa + za * sb));
        else if (s2 > 0.0)
          g0 = (zb / sb - za / sa) / s2;
        else
          continue;
        const double weight = rule.w[i] * rule.w[j] * rh * ph * r;
        h.x += weight * cs * g1;
        h.y += weight * sn * g1;
        h.z -= weight * (sn * ry + cs * rx) * g0;
      }
    }
  }
  return h;
}

// Local coordinates of a point in a frame at origin.
Vec3 to_local(const CoilFrame& f, const Vec3& origin, const Vec3& point) {
  const Vec3 d = point - origin;
  return {dot(d, f.e1), dot(d, f.e2), dot(d, f.e3)};
}
Vec3 to_global(const CoilFrame& f, const Vec3& v) { return v.x * f.e1 + v.y * f.e2 + v.z * f.e3; }

// Inside a filament's round wire of radius a (include/odemag/coil.h): the
// filament's field times (d / a)^2, the part of the uniform current closer to
// the centre line than the point (Ampere's law about a straight wire gives
// H = N I d / (2 pi a^2)); 1 at and beyond the surface. distance2 = d^2.
double inside_wire_factor(double distance2, double a) {
  const double a2 = a * a;
  return distance2 < a2 ? distance2 / a2 : 1.0;
}

// Closer to the centre line than kOnConductor a the field is 0: at most
// ~kOnConductor N I / (2 pi a) there, and the filament's own formulas lose
// their precision (they diverge on the line).
bool on_centre_line(double distance2, double a) { return distance2 <= (kOnConductor * a) * (kOnConductor * a); }

double wire_radius_of(const CircularLoop& s) { return s.wire_radius > 0.0 ? s.wire_radius : kDefaultWireRadius * s.radius; }
double wire_radius_of(const Arc& s) { return s.wire_radius > 0.0 ? s.wire_radius : kDefaultWireRadius * s.radius; }
double wire_radius_of(const StraightSegment& s) {
  return s.wire_radius > 0.0 ? s.wire_radius : kDefaultWireRadius * norm(s.b - s.a);
}

bool finite(double v) { return std::isfinite(v); }
bool finite(const Vec3& v) { return is_finite(v); }

}  // namespace

// ---------------------------------------------------------------------------
// Special functions.

// Arithmetic-geometric mean a_n, b_n from (1, kc), c_n = (a_{n-1} - b_{n-1}) / 2,
// c_0 = k: K = pi / (2 a_inf), E = K (1 - sum 2^(n-1) c_n^2) (Abramowitz & Stegun 17.6).
double elliptic_K(double k) {
  double a = 1.0, b = std::sqrt((1.0 - k) * (1.0 + k));
  for (int n = 0; n < 64 && std::abs(a - b) > 1e-16 * a; ++n) {
    const double mean = 0.5 * (a + b);
    b = std::sqrt(a * b);
    a = mean;
  }
  return 0.5 * kPi / a;
}

double elliptic_E(double k) {
  double a = 1.0, b = std::sqrt((1.0 - k) * (1.0 + k)), c = k;
  double sum = 0.5 * k * k, power = 0.5;
  for (int n = 0; n < 64 && std::abs(a - b) > 1e-16 * a; ++n) {
    const double mean = 0.5 * (a + b);
    c = c * c / (4.0 * mean);  // (a - b) / 2 without the cancellation: a^2 - b^2 = c^2
    b = std::sqrt(a * b);
    a = mean;
    power *= 2.0;
    sum += power * c * c;
  }
  return 0.5 * kPi / a * (1.0 - sum);
}

// Bulirsch, Numer. Math. 13, 305 (1969): a Gauss (AGM-like) transformation
// of the integrand, quadratically convergent; p <= 0 is first mapped to p > 0
// (the principal value). Stops when kc has converged to the AGM limit within
// sqrt(eps) (the error is then below eps).
double bulirsch_cel(double kc, double p, double a, double b) {
  if (kc == 0.0) return std::numeric_limits<double>::infinity();
  constexpr double kTolerance = 1.5e-8;
  kc = std::abs(kc);
  double e = kc, mean = 1.0;
  if (p > 0.0) {
    p = std::sqrt(p);
    b /= p;
  } else {
    double f = kc * kc;
    double q = 1.0 - f;
    const double g = 1.0 - p;
    f -= p;
    q *= b - a * p;
    p = std::sqrt(f / g);
    a = (a - b) / g;
    b = -q / (g * g * p) + a * p;
  }
  for (int iteration = 0; iteration < 64; ++iteration) {
    const double f = a;
    a += b / p;
    double g = e / p;
    b += f * g;
    b += b;
    p += g;
    g = mean;
    mean += kc;
    if (std::abs(g - kc) <= g * kTolerance) break;
    kc = 2.0 * std::sqrt(e);
    e = kc * mean;
  }
  return 0.5 * kPi * (b + a * mean) / (mean * (mean + p));
}

// Carlson, Numer. Algorithms 10, 13 (1995): duplication x <- (x + lambda) / 4
// until the arguments agree to 2e-3 of their mean, then the Taylor series to
// fifth order (relative error below 1e-16; DLMF 19.36.1-2).
double carlson_RF(double x, double y, double z) {
  const double mean0 = (x + y + z) / 3.0;
  const double dx0 = mean0 - x, dy0 = mean0 - y;
  double mean = mean0, scale = 1.0;
  const double spread = std::max({std::abs(mean0 - x), std::abs(mean0 - y), std::abs(mean0 - z)});
  for (int n = 0; n < 100 && spread * scale > 2e-3 * std::abs(mean); ++n) {
    const double sx = std::sqrt(x), sy = std::sqrt(y), sz = std::sqrt(z);
    const double lambda = sx * sy + sy * sz + sz * sx;
    x = 0.25 * (x + lambda);
    y = 0.25 * (y + lambda);
    z = 0.25 * (z + lambda);
    mean = 0.25 * (mean + lambda);
    scale *= 0.25;
  }
  const double X = dx0 * scale / mean, Y = dy0 * scale / mean, Z = -(X + Y);
  const double e2 = X * Y - Z * Z, e3 = X * Y * Z;
  return (1.0 - e2 / 10.0 + e3 / 14.0 + e2 * e2 / 24.0 - 3.0 * e2 * e3 / 44.0) / std::sqrt(mean);
}

double carlson_RD(double x, double y, double z) {
  const double mean0 = (x + y + 3.0 * z) / 5.0;
  const double dx0 = mean0 - x, dy0 = mean0 - y;
  double mean = mean0, scale = 1.0, sum = 0.0;
  const double spread = std::max({std::abs(mean0 - x), std::abs(mean0 - y), std::abs(mean0 - z)});
  for (int n = 0; n < 100 && spread * scale > 1e-3 * std::abs(mean); ++n) {
    const double sx = std::sqrt(x), sy = std::sqrt(y), sz = std::sqrt(z);
    const double lambda = sx * sy + sy * sz + sz * sx;
    sum += scale / (sz * (z + lambda));
    x = 0.25 * (x + lambda);
    y = 0.25 * (y + lambda);
    z = 0.25 * (z + lambda);
    mean = 0.25 * (mean + lambda);
    scale *= 0.25;
  }
  const double X = dx0 * scale / mean, Y = dy0 * scale / mean, Z = -(X + Y) / 3.0;
  const double xy = X * Y, z2 = Z * Z;
  const double e2 = xy - 6.0 * z2, e3 = (3.0 * xy - 8.0 * z2) * Z, e4 = 3.0 * (xy - z2) * z2, e5 = xy * z2 * Z;
  const double series = 1.0 - 3.0 * e2 / 14.0 + e3 / 6.0 + 9.0 * e2 * e2 / 88.0 - 3.0 * e4 / 22.0 -
                        9.0 * e2 * e3 / 52.0 + 3.0 * e5 / 26.0;
  return scale * series / (mean * std::sqrt(mean)) + 3.0 * sum;
}

// ---------------------------------------------------------------------------
// Fields.

Vec3 coil_field_H(const CircularLoop& loop, const Vec3& point) {
  if (!(loop.radius > 0.0)) return {};
  const Vec3 e3 = normalized(loop.axis);
  const Cylindrical c = cylindrical(loop.centre, e3, point);
  double h_rho, h_z;
  loop_kernel(loop.radius, loop.current * loop.turns, c.rho, c.z, h_rho, h_z);
  const double distance2 = (c.rho - loop.radius) * (c.rho - loop.radius) + c.z * c.z;
  const double wire = wire_radius_of(loop);
  if (on_centre_line(distance2, wire)) return {};
  const double inside = inside_wire_factor(distance2, wire);
  return (inside * h_rho) * c.radial + (inside * h_z) * e3;
}

// Biot-Savart for a straight filament (Jackson problem 5.1; Purcell 6.3):
// H = NI / (4 pi d) (cos theta1 - cos theta2) e_phi, written as
// NI / (4 pi) (u x r1) f with f = (t1 / R1 - t2 / R2) / d^2 where the foot of
// the perpendicular lies on the segment (the two cosines add), and the
// equivalent f = 2 L (R1 + R2) / (R1 R2 ((R1 + R2)^2 - L^2)) beyond its ends
// (Hanson & Hirshman, Phys. Plasmas 9, 4410 (2002)), free of cancellation.
Vec3 coil_field_H(const StraightSegment& segment, const Vec3& point) {
  const Vec3 d = segment.b - segment.a;
  const double length = norm(d);
  if (!(length > 0.0)) return {};
  const Vec3 u = d / length;
  const Vec3 r1 = point - segment.a, r2 = point - segment.b;
  const double R1 = norm(r1), R2 = norm(r2);
  const double t1 = dot(r1, u), t2 = dot(r2, u);
  const Vec3 azimuth = cross(u, r1);  // |azimuth| = distance from the line
  const double d2 = squared_norm(azimuth);
  // The distance from the segment (its nearest point: an end or the foot).
  const double distance2 = t1 <= 0.0 ? R1 * R1 : (t2 >= 0.0 ? R2 * R2 : d2);
  const double wire = wire_radius_of(segment);
  if (on_centre_line(distance2, wire)) return {};
  double f;
  if (t1 > 0.0 && t2 < 0.0) {  // inside the wire d^2 / a^2 replaces 1 / d^2
    f = (t1 / R1 - t2 / R2) / std::max(d2, wire * wire);
  } else {
    const double sum = R1 + R2;
    f = inside_wire_factor(distance2, wire) * 2.0 * length * sum / (R1 * R2 * (sum - length) * (sum + length));
  }
  return (segment.current * segment.turns / (4.0 * kPi) * f) * azimuth;
}

// Arc of radius a from azimuth 0 to Phi (local frame e1 = start, e3 = axis),
// point at azimuth psi, distance rho from the axis and height z; source
// azimuth relative to the point phi in [-psi, Phi - psi],
// D = rho^2 + a^2 + z^2 - 2 a rho cos phi:
//   H_rho = NI a z / (4 pi) int cos phi D^-3/2,  H_phi = NI a z / (4 pi) int sin phi D^-3/2,
//   H_z = NI a / (4 pi) int (a - rho cos phi) D^-3/2.
// With phi = pi - 2t, D = q^2 Delta^2 (q^2 = (a + rho)^2 + z^2, m = 4 a rho / q^2):
// int D^-3/2 dphi = 2 q^-3 j0, int cos phi D^-3/2 dphi = 2 q^-3 (2 j2 - j0) over
// t from pi/2 - phi2/2 to pi/2 - phi1/2, exact via Carlson's R_F, R_D, and
// int sin phi D^-3/2 dphi = (D1^-1/2 - D2^-1/2) / (a rho) in closed form.
Vec3 coil_field_H(const Arc& arc, const Vec3& point) {
  const double a = arc.radius;
  if (!(a > 0.0) || arc.angle == 0.0) return {};
  const double angle = std::abs(arc.angle);
  const CoilFrame f = frame_from_axis_and(arc.angle > 0.0 ? arc.axis : -arc.axis, arc.start);
  const Vec3 local = to_local(f, arc.centre, point);
  const double rho = std::hypot(local.x, local.y), z = local.z;
  const double psi = rho > 0.0 ? std::atan2(local.y, local.x) : 0.0;
  // The distance from the arc (its nearest point: on the arc at the point's
  // azimuth, or an end).
  double distance2;
  {
    const double psi_positive = psi < 0.0 ? psi + 2.0 * kPi : psi;
    if (angle >= 2.0 * kPi || psi_positive <= angle) {
      distance2 = (rho - a) * (rho - a) + z * z;
    } else {
      const Vec3 start{a, 0.0, 0.0}, end{a * std::cos(angle), a * std::sin(angle), 0.0};
      distance2 = std::min(squared_norm(local - start), squared_norm(local - end));
    }
    if (on_centre_line(distance2, wire_radius_of(arc))) return {};
  }
  const double phi1 = -psi, phi2 = angle - psi;
  const double q2 = (a + rho) * (a + rho) + z * z;
  const double q = std::sqrt(q2);
  const double alpha2 = (a - rho) * (a - rho) + z * z;
  const double m = 4.0 * a * rho / q2, kc2 = alpha2 / q2;
  const ArcIntegrals j = arc_integrals(0.5 * kPi - 0.5 * phi2, 0.5 * kPi - 0.5 * phi1, m, kc2);
  const double q3 = q2 * q;
  const double i0 = 2.0 / q3 * j.j0;
  const double ic = 2.0 / q3 * (2.0 * j.j2 - j.j0);
  // D_i = alpha^2 + 4 a rho sin^2(phi_i / 2); cos phi1 - cos phi2 = 2 sin((phi1 + phi2)/2) sin((phi2 - phi1)/2).
  const double s1 = std::sin(0.5 * phi1), s2 = std::sin(0.5 * phi2);
  const double d1 = std::sqrt(alpha2 + 4.0 * a * rho * s1 * s1), d2 = std::sqrt(alpha2 + 4.0 * a * rho * s2 * s2);
  const double cos_difference = 2.0 * std::sin(0.5 * (phi1 + phi2)) * std::sin(0.5 * (phi2 - phi1));
  const double is = 2.0 * cos_difference / (d1 * d2 * (d1 + d2));
  const double scale =
      inside_wire_factor(distance2, wire_radius_of(arc)) * arc.current * arc.turns * a / (4.0 * kPi);
  const double h_rho = scale * z * ic, h_phi = scale * z * is, h_z = scale * (a * i0 - rho * ic);
  const double cp = std::cos(psi), sp = std::sin(psi);
  const Vec3 h_local{h_rho * cp - h_phi * sp, h_rho * sp + h_phi * cp, h_z};
  return to_global(f, h_local);
}

Vec3 coil_field_H(const Solenoid& solenoid, const Vec3& point) {
  if (!(solenoid.radius > 0.0)) return {};
  if (!(solenoid.length > 0.0))
    return coil_field_H(CircularLoop{solenoid.centre, solenoid.axis, solenoid.radius, solenoid.current,
                                     solenoid.turns},
                        point);
  const Vec3 e3 = normalized(solenoid.axis);
  const Cylindrical c = cylindrical(solenoid.centre, e3, point);
  double h_rho, h_z;
  sheet_kernel(solenoid.radius, solenoid.length, solenoid.current * solenoid.turns / solenoid.length, c.rho, c.z,
               h_rho, h_z);
  return h_rho * c.radial + h_z * e3;
}

// Sum of solenoid sheets r in [r1, r2], each carrying K = J dr (loops if the
// length is 0), by Gauss-Legendre on panels graded towards the nearest
// singularity of the integrand in r: the sheet through the point (a jump at
// r = rho, only a panel boundary when rho is inside the winding) and the end
// rings, at r = rho +- i (|z| - L/2).
Vec3 coil_field_H(const CircularCoil& coil, const Vec3& point) {
  const double r1 = coil.inner_radius, r2 = coil.outer_radius, length = coil.length;
  if (!(r2 > r1))
    return coil_field_H(Solenoid{coil.centre, coil.axis, r2, length, coil.current, coil.turns}, point);
  const Vec3 e3 = normalized(coil.axis);
  const Cylindrical c = cylindrical(coil.centre, e3, point);
  const double ni = coil.current * coil.turns;
  const double s = std::clamp(c.rho, r1, r2);
  const double ends = std::hypot(c.rho - s, std::abs(c.z) - 0.5 * length);
  const bool through = length > 0.0 && std::abs(c.z) < 0.5 * length && (c.rho <= r1 || c.rho >= r2);
  const double delta = through ? std::min(ends, std::abs(c.rho - s)) : ends;
  thread_local std::vector<std::pair<double, double>> panels;  // scratch
  graded_panels(r1, r2, s, std::max(delta, 1e-7 * (r2 - r1)), panels);
  const int order = std::clamp(coil.quadrature_order, 1, kMaxOrder);
  const GaussRule& rule = gauss_rule(order);
  double sum_rho = 0.0, sum_z = 0.0;
  for (const auto& [lo, hi] : panels) {
    const double mid = 0.5 * (lo + hi), half = 0.5 * (hi - lo);
    for (int i = 0; i < order; ++i) {
      const double r = mid + half * rule.x[i];
      const double weight = rule.w[i] * half * ni / (r2 - r1);  // ampere-turns of the sheet
      double h_rho, h_z;
      if (length > 0.0)
        sheet_kernel(r, length, weight / length, c.rho, c.z, h_rho, h_z);
      else
        loop_kernel(r, weight, c.rho, c.z, h_rho, h_z);
      sum_rho += h_rho;
      sum_z += h_z;
    }
  }
  return sum_rho * c.radial + sum_z * e3;
}

Vec3 coil_field_H(const RoundedRectangleCoil& coil, const Vec3& point) {
  const double width = coil.outer_corner_radius - coil.inner_corner_radius;
  if (!(width > 0.0) || !(coil.height > 0.0)) return {};
  const CoilFrame f = frame_from_axis_and(coil.axis, coil.width_direction);
  const Vec3 p = to_local(f, coil.centre, point);
  const double j = coil.current * coil.turns / (width * coil.height);
  const CoilParts parts = rounded_rectangle_parts(coil);
  Vec3 h;
  for (int k = 0; k < parts.side_count; ++k)
    h += cross(parts.sides[k].direction, cuboid_G(parts.sides[k].lo, parts.sides[k].hi, p));
  thread_local std::vector<Rect> rects;  // scratch
  const int order = std::clamp(coil.quadrature_order, 1, kMaxOrder);
  for (const CoilCorner& corner : parts.corners) h += corner_field(coil, corner, p, order, rects);
  return to_global(f, (j / (4.0 * kPi)) * h);
}

Vec3 coil_field_H(const CoilSource& source, const Vec3& point) {
  return std::visit([&](const auto& s) { return coil_field_H(s, point); }, source);
}

Vec3 coil_field_H(const std::vector<CoilSource>& sources, const Vec3& point) {
  Vec3 h;
  for (const CoilSource& s : sources) h += coil_field_H(s, point);
  return h;
}

Vec3 coil_field_B(const CoilSource& source, const Vec3& point) { return kMu0 * coil_field_H(source, point); }

Vec3 coil_field_H(const CoilSource& source, const Mat3& rotation, const Vec3& position, const Vec3& world_point) {
  return rotation * coil_field_H(source, rotation.transpose_times(world_point - position));
}

CoilSource transformed(const CoilSource& source, const Mat3& rotation, const Vec3& position) {
  auto place = [&](const Vec3& x) { return rotation * x + position; };
  return std::visit(
      [&](auto s) -> CoilSource {
        using T = std::decay_t<decltype(s)>;
        if constexpr (std::is_same_v<T, StraightSegment>) {
          s.a = place(s.a);
          s.b = place(s.b);
        } else {
          s.centre = place(s.centre);
          s.axis = rotation * s.axis;
          if constexpr (std::is_same_v<T, Arc>) s.start = rotation * s.start;
          if constexpr (std::is_same_v<T, RoundedRectangleCoil>) s.width_direction = rotation * s.width_direction;
        }
        return s;
      },
      source);
}

// ---------------------------------------------------------------------------
// Validation.

std::string coil_source_error(const CoilSource& source) {
  std::ostringstream why;
  auto check_axis = [&](const Vec3& axis) {
    if (!finite(axis) || squared_norm(axis) == 0.0) why << "axis must be a finite non-zero vector; ";
  };
  auto check_common = [&](double current, double turns) {
    if (!finite(current)) why << "current must be finite; ";
    if (!finite(turns)) why << "turns must be finite; ";
  };
  auto check_order = [&](int order) {
    if (order < 1 || order > kMaxOrder) why << "quadrature_order must be 1.." << kMaxOrder << "; ";
  };
  std::visit(
      [&](const auto& s) {
        using T = std::decay_t<decltype(s)>;
        check_common(s.current, s.turns);
        if constexpr (std::is_same_v<T, StraightSegment>) {
          if (!finite(s.a) || !finite(s.b)) why << "end points must be finite; ";
          else if (squared_norm(s.b - s.a) == 0.0) why << "end points must differ; ";
        } else {
          if (!finite(s.centre)) why << "centre must be finite; ";
          check_axis(s.axis);
        }
        if constexpr (std::is_same_v<T, CircularLoop> || std::is_same_v<T, Arc> || std::is_same_v<T, Solenoid>) {
          if (!(s.radius > 0.0) || !finite(s.radius)) why << "radius must be positive; ";
        }
        if constexpr (std::is_same_v<T, CircularLoop> || std::is_same_v<T, Arc> ||
                      std::is_same_v<T, StraightSegment>) {
          if (!(s.wire_radius >= 0.0) || !finite(s.wire_radius)) why << "wire_radius must be >= 0 (0: the default); ";
        }
        if constexpr (std::is_same_v<T, Arc>) {
          if (!finite(s.angle)) why << "angle must be finite; ";
          const Vec3 e3 = normalized(s.axis);
          if (!finite(s.start) || squared_norm(s.start - dot(s.start, e3) * e3) <= 1e-24 * squared_norm(s.start))
            why << "start must have a component normal to the axis; ";
        }
        if constexpr (std::is_same_v<T, Solenoid>) {
          if (!(s.length >= 0.0) || !finite(s.length)) why << "length must be >= 0; ";
        }
        if constexpr (std::is_same_v<T, CircularCoil>) {
          if (!(s.inner_radius >= 0.0) || !(s.outer_radius > 0.0) || !(s.inner_radius <= s.outer_radius) ||
              !finite(s.outer_radius))
            why << "radii must satisfy 0 <= inner_radius <= outer_radius, outer_radius > 0; ";
          if (!(s.length >= 0.0) || !finite(s.length)) why << "length must be >= 0; ";
          check_order(s.quadrature_order);
        }
        if constexpr (std::is_same_v<T, RoundedRectangleCoil>) {
          if (!(s.inner_corner_radius >= 0.0) || !(s.outer_corner_radius > s.inner_corner_radius) ||
              !finite(s.outer_corner_radius))
            why << "corner radii must satisfy 0 <= inner_corner_radius < outer_corner_radius; ";
          if (!(s.core_half_width >= 0.0) || !(s.core_half_depth >= 0.0) || !finite(s.core_half_width) ||
              !finite(s.core_half_depth))
            why << "core_half_width and core_half_depth must be >= 0; ";
          if (!(s.height > 0.0) || !finite(s.height)) why << "height must be positive; ";
          const Vec3 e3 = normalized(s.axis);
          const Vec3 u = s.width_direction;
          if (!finite(u) || squared_norm(u - dot(u, e3) * e3) <= 1e-24 * squared_norm(u))
            why << "width_direction must have a component normal to the axis; ";
          check_order(s.quadrature_order);
        }
      },
      source);
  std::string text = why.str();
  if (text.size() >= 2) text.resize(text.size() - 2);
  return text;
}

double ampere_turns(const CoilSource& source) {
  return std::visit([](const auto& s) { return s.current * s.turns; }, source);
}

double filament_wire_radius(const CoilSource& source) {
  return std::visit(
      [](const auto& s) -> double {
        using T = std::decay_t<decltype(s)>;
        if constexpr (std::is_same_v<T, CircularLoop> || std::is_same_v<T, Arc> || std::is_same_v<T, StraightSegment>)
          return wire_radius_of(s);
        else
          return 0.0;
      },
      source);
}

// ---------------------------------------------------------------------------
// Current elements.

namespace {

void add_circle(std::vector<CurrentElement>& out, const CoilFrame& f, const Vec3& centre,
                double radius, double ni, int per_turn) {
  const double step = 2.0 * kPi / per_turn;
  for (int k = 0; k < per_turn; ++k) {
    const double phi = step * k;
    const double c = std::cos(phi), s = std::sin(phi);
    out.push_back({centre + radius * (c * f.e1 + s * f.e2), (ni * radius * step) * (c * f.e2 - s * f.e1)});
  }
}

}  // namespace

std::vector<CurrentElement> current_elements(const CoilSource& source, const ElementOptions& options) {
  const int per_turn = std::max(options.per_turn, 3);
  const int along = std::clamp(options.along, 1, kMaxOrder);
  const int across = std::clamp(options.across, 1, kMaxOrder);
  const GaussRule& rule_along = gauss_rule(along);
  const GaussRule& rule_across = gauss_rule(across);
  std::vector<CurrentElement> out;
  const double ni = ampere_turns(source);
  std::visit(
      [&](const auto& s) {
        using T = std::decay_t<decltype(s)>;
        if constexpr (std::is_same_v<T, CircularLoop>) {
          add_circle(out, frame_from_axis(s.axis), s.centre, s.radius, ni, per_turn);
        } else if constexpr (std::is_same_v<T, StraightSegment>) {
          const Vec3 mid = 0.5 * (s.a + s.b), half = 0.5 * (s.b - s.a);
          for (int i = 0; i < along; ++i) out.push_back({mid + rule_along.x[i] * half, (ni * rule_along.w[i]) * half});
        } else if constexpr (std::is_same_v<T, Arc>) {
          const CoilFrame f = frame_from_axis_and(s.axis, s.start);
          const double half = 0.5 * s.angle;
          for (int i = 0; i < along; ++i) {
            const double phi = half + half * rule_along.x[i];
            const double c = std::cos(phi), sn = std::sin(phi);
            out.push_back({s.centre + s.radius * (c * f.e1 + sn * f.e2),
                           (ni * s.radius * half * rule_along.w[i]) * (c * f.e2 - sn * f.e1)});
          }
        } else if constexpr (std::is_same_v<T, Solenoid>) {
          const CoilFrame f = frame_from_axis(s.axis);
          if (!(s.length > 0.0)) {
            add_circle(out, f, s.centre, s.radius, ni, per_turn);
            return;
          }
          for (int i = 0; i < across; ++i)
            add_circle(out, f, s.centre + (0.5 * s.length * rule_across.x[i]) * f.e3, s.radius,
                       0.5 * ni * rule_across.w[i], per_turn);
        } else if constexpr (std::is_same_v<T, CircularCoil>) {
          const CoilFrame f = frame_from_axis(s.axis);
          const double r_mid = 0.5 * (s.inner_radius + s.outer_radius), r_half = 0.5 * (s.outer_radius - s.inner_radius);
          const int nr = r_half > 0.0 ? across : 1;
          const int nz = s.length > 0.0 ? across : 1;
          const GaussRule& rr = gauss_rule(nr);
          const GaussRule& rz = gauss_rule(nz);
          for (int i = 0; i < nr; ++i)
            for (int k = 0; k < nz; ++k)
              add_circle(out, f, s.centre + (0.5 * s.length * rz.x[k]) * f.e3, r_mid + r_half * rr.x[i],
                         ni * 0.25 * rr.w[i] * rz.w[k], per_turn);
        } else if constexpr (std::is_same_v<T, RoundedRectangleCoil>) {
          const CoilFrame f = frame_from_axis_and(s.axis, s.width_direction);
          const double width = s.outer_corner_radius - s.inner_corner_radius;
          const double j = ni / (width * s.height);
          const CoilParts parts = rounded_rectangle_parts(s);
          for (int side_index = 0; side_index < parts.side_count; ++side_index) {
            const CoilSide& side = parts.sides[side_index];
            const Vec3 mid = 0.5 * (side.lo + side.hi), half = 0.5 * (side.hi - side.lo);
            // Along the current: `along` points; across: `across` in each other direction.
            const int axis_along = side.direction.x != 0.0 ? 0 : 1;
            for (int i = 0; i < across; ++i)
              for (int k = 0; k < across; ++k)
                for (int l = 0; l < along; ++l) {
                  Vec3 x = mid;
                  double w = half.x * half.y * half.z;
                  const double t_along = rule_along.x[l], t_across = rule_across.x[i], t_w = rule_across.x[k];
                  if (axis_along == 0) {
                    x.x += half.x * t_along;
                    x.y += half.y * t_across;
                  } else {
                    x.y += half.y * t_along;
                    x.x += half.x * t_across;
                  }
                  x.z += half.z * t_w;
                  w *= rule_along.w[l] * rule_across.w[i] * rule_across.w[k];
                  out.push_back({s.centre + to_global(f, x), (j * w) * to_global(f, side.direction)});
                }
          }
          const double r_mid = 0.5 * (s.inner_corner_radius + s.outer_corner_radius), r_half = 0.5 * width;
          const double hh = 0.5 * s.height, quarter = 0.25 * kPi;
          for (const CoilCorner& corner : parts.corners)
            for (int i = 0; i < across; ++i)
              for (int k = 0; k < across; ++k)
                for (int l = 0; l < along; ++l) {
                  const double r = r_mid + r_half * rule_across.x[i];
                  const double phi = corner.phi_start + quarter + quarter * rule_along.x[l];
                  const double c = std::cos(phi), sn = std::sin(phi);
                  const Vec3 x{corner.u + r * c, corner.v + r * sn, hh * rule_across.x[k]};
                  const double w = rule_across.w[i] * r_half * rule_across.w[k] * hh * rule_along.w[l] * quarter * r;
                  out.push_back({s.centre + to_global(f, x), (j * w) * to_global(f, Vec3{-sn, c, 0.0})});
                }
        }
      },
      source);
  return out;
}

Wrench coil_wrench(const std::vector<CurrentElement>& elements, const std::function<Vec3(const Vec3&)>& field_B,
                   const Vec3& about) {
  Wrench w;
  for (const CurrentElement& e : elements) {
    const Vec3 f = cross(e.moment, field_B(e.position));
    w.force += f;
    w.torque += cross(e.position - about, f);
  }
  return w;
}

Wrench coil_wrench(const CoilSource& source, const std::function<Vec3(const Vec3&)>& field_B, const Vec3& about,
                   const ElementOptions& options) {
  return coil_wrench(current_elements(source, options), field_B, about);
}

Vec3 dipole_moment(const CoilSource& source, const ElementOptions& options) {
  Vec3 m;
  for (const CurrentElement& e : current_elements(source, options)) m += 0.5 * cross(e.position, e.moment);
  return m;
}

}  // namespace odemag
