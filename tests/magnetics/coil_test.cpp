// Current sources (magnetics/sources/coil.h) against references written here,
// independently of the library: closed forms (loop and solenoid on the axis,
// infinite wire, point dipole, mutual inductance of coaxial loops), brute-force
// Biot-Savart quadrature of dl x r / r^3 (this file's own Gauss-Legendre and
// trapezoidal rules), Maxwell's equations by finite differences, and Newton's
// third law. docs/model.md "Current sources (coils)" quotes the measured errors
// these tests print ("measured:" lines).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <functional>
#include <vector>

#include "magnetics/sources/coil.h"
#include "odemag/constants.h"
#include "odemag/vec3.h"

namespace odemag {
namespace {

double rel(const Vec3& a, const Vec3& b) { return norm(a - b) / norm(b); }

Mat3 tilted() { return rotation_from_quaternion(0.9, 0.2, -0.3, 0.25); }

// ---------------------------------------------------------------------------
// This file's quadrature: Gauss-Legendre nodes by bisection-free Newton from
// Tricomi's initial guesses, and composite rules.
struct Rule {
  std::vector<double> x, w;
};

Rule legendre(int n) {
  Rule r;
  for (int i = 1; i <= n; ++i) {
    double x = (1.0 - 1.0 / (8.0 * n * n) + 1.0 / (8.0 * n * n * n)) * std::cos(kPi * (4.0 * i - 1.0) / (4.0 * n + 2.0));
    double dp = 1.0;
    for (int it = 0; it < 50; ++it) {
      double p0 = 1.0, p1 = x;
      for (int k = 2; k <= n; ++k) {
        const double p2 = ((2.0 * k - 1.0) * x * p1 - (k - 1.0) * p0) / k;
        p0 = p1;
        p1 = p2;
      }
      dp = n * (p0 - x * p1) / (1.0 - x * x);
      const double dx = p1 / dp;
      x -= dx;
      if (std::abs(dx) < 1e-16) break;
    }
    r.x.push_back(x);
    r.w.push_back(2.0 / ((1.0 - x * x) * dp * dp));
  }
  return r;
}

// Composite Gauss-Legendre of f over [lo, hi]: `panels` equal panels of n points.
template <class F>
auto integrate(F f, double lo, double hi, int panels, int n) {
  static thread_local std::vector<Rule> cache(65);
  if (cache[n].x.empty()) cache[n] = legendre(n);
  const Rule& r = cache[n];
  const double h = (hi - lo) / panels;
  decltype(f(lo)) sum{};
  for (int p = 0; p < panels; ++p)
    for (int i = 0; i < n; ++i) sum += (0.5 * h * r.w[i]) * f(lo + h * (p + 0.5 + 0.5 * r.x[i]));
  return sum;
}

// Biot-Savart integrand NI dl x (x - x') / (4 pi |x - x'|^3) per unit parameter.
Vec3 biot_savart(const Vec3& source, const Vec3& dl, const Vec3& x) {
  const Vec3 r = x - source;
  const double d = norm(r);
  return cross(dl, r) / (4.0 * kPi * d * d * d);
}

// A circle by the trapezoidal rule (exponentially convergent: periodic integrand).
Vec3 brute_circle(const Vec3& c, const Vec3& e1, const Vec3& e2, double R, double ni, const Vec3& x, int n) {
  Vec3 h;
  for (int k = 0; k < n; ++k) {
    const double phi = 2.0 * kPi * (k + 0.5) / n;
    const Vec3 dl = (ni * R * 2.0 * kPi / n) * (std::cos(phi) * e2 - std::sin(phi) * e1);
    h += biot_savart(c + R * (std::cos(phi) * e1 + std::sin(phi) * e2), dl, x);
  }
  return h;
}

Vec3 brute_line(const Vec3& a, const Vec3& b, double ni, const Vec3& x, int panels = 64, int n = 20) {
  return integrate([&](double t) { return biot_savart(a + t * (b - a), ni * (b - a), x); }, 0.0, 1.0, panels, n);
}

Vec3 brute_arc(const Vec3& c, const Vec3& e1, const Vec3& e2, double R, double angle, double ni, const Vec3& x,
               int panels = 64, int n = 20) {
  return integrate(
      [&](double phi) {
        const Vec3 dl = (ni * R) * (std::cos(phi) * e2 - std::sin(phi) * e1);
        return biot_savart(c + R * (std::cos(phi) * e1 + std::sin(phi) * e2), dl, x);
      },
      0.0, angle, panels, n);
}

// Point dipole H = (3 (m.r) r / r^2 - m) / (4 pi r^3).
Vec3 dipole_H(const Vec3& m, const Vec3& r) {
  const double d = norm(r);
  return (3.0 * dot(m, r) / (d * d) * r - m) / (4.0 * kPi * d * d * d);
}

// Fourth-order central differences of H: div H and curl H.
struct Derivatives {
  double div;
  Vec3 curl;
};
Derivatives derivatives(const std::function<Vec3(const Vec3&)>& H, const Vec3& x, double h) {
  Vec3 d[3];  // d[i] = dH/dx_i
  for (int i = 0; i < 3; ++i) {
    Vec3 e;
    e[i] = h;
    d[i] = (8.0 * (H(x + e) - H(x - e)) - (H(x + 2.0 * e) - H(x - 2.0 * e))) / (12.0 * h);
  }
  return {d[0].x + d[1].y + d[2].z, {d[1].z - d[2].y, d[2].x - d[0].z, d[0].y - d[1].x}};
}

// The TEAM 20 coil (Compumag TEAM problem 20, Takahashi et al. 1994; mm here, m in the code): outer 75 x 75
// with corner radius 23, inner 39 x 39 with corner radius 5 (so the corner
// centres sit at +-14.5 for both), z from 26.7 to 123.3.
RoundedRectangleCoil team20_coil(double ampere_turns) {
  RoundedRectangleCoil c;
  c.centre = {0.0, 0.0, 0.075};
  c.core_half_width = c.core_half_depth = 0.0145;
  c.inner_corner_radius = 0.005;
  c.outer_corner_radius = 0.023;
  c.height = 0.0966;
  c.current = ampere_turns;
  return c;
}

// Brute force for a rounded-rectangle coil: the cross-section (offset r,
// height w) by composite Gauss-Legendre, each filament (4 lines, 4 quarter
// arcs) by Biot-Savart quadrature.
Vec3 brute_rounded(const RoundedRectangleCoil& c, const Vec3& x, int cross_panels, int n, int along_panels) {
  const double a = c.core_half_width, b = c.core_half_depth;
  const double j = c.current * c.turns / ((c.outer_corner_radius - c.inner_corner_radius) * c.height);
  const Vec3 ex{1, 0, 0}, ey{0, 1, 0};
  auto filament = [&](double r, double w) {
    const Vec3 o = c.centre + Vec3{0, 0, w};
    Vec3 h;
    h += brute_line(o + Vec3{a + r, -b, 0}, o + Vec3{a + r, b, 0}, 1.0, x, along_panels, n);
    h += brute_line(o + Vec3{a, b + r, 0}, o + Vec3{-a, b + r, 0}, 1.0, x, along_panels, n);
    h += brute_line(o + Vec3{-a - r, b, 0}, o + Vec3{-a - r, -b, 0}, 1.0, x, along_panels, n);
    h += brute_line(o + Vec3{-a, -b - r, 0}, o + Vec3{a, -b - r, 0}, 1.0, x, along_panels, n);
    const Vec3 centres[4] = {{a, b, 0}, {-a, b, 0}, {-a, -b, 0}, {a, -b, 0}};
    for (int k = 0; k < 4; ++k) {
      const double phi0 = 0.5 * kPi * k;
      const Vec3 e1 = std::cos(phi0) * ex + std::sin(phi0) * ey, e2 = -std::sin(phi0) * ex + std::cos(phi0) * ey;
      h += brute_arc(o + centres[k], e1, e2, r, 0.5 * kPi, 1.0, x, along_panels, n);
    }
    return h;
  };
  return j * integrate(
                 [&](double r) {
                   return integrate([&](double w) { return filament(r, w); }, -0.5 * c.height, 0.5 * c.height,
                                    cross_panels, n);
                 },
                 c.inner_corner_radius, c.outer_corner_radius, cross_panels, n);
}

// ---------------------------------------------------------------------------
// 1. Special functions.

TEST(CoilSpecialFunctions, EllipticIntegralsAgainstStdAndAsymptotics) {
  double worst = 0.0;
  for (double k : {0.0, 0.1, 0.3, 0.5, 0.7, 0.9}) {
    worst = std::max(worst, std::abs(elliptic_K(k) / std::comp_ellint_1(k) - 1.0));
    worst = std::max(worst, std::abs(elliptic_E(k) / std::comp_ellint_2(k) - 1.0));
  }
  EXPECT_LT(worst, 1e-14);
  // Closer to 1, libstdc++'s comp_ellint_2 loses digits (4e-13 at k = 0.99):
  // reference values from mpmath 1.3 (ellipk, ellipe at 25 digits).
  struct Value {
    double k, K, E;
  };
  for (const Value& v : {Value{0.99, 3.35660052336119238, 1.028475809028804},
                         Value{0.9999, 5.64514821682969279, 1.00051450008378118}}) {
    EXPECT_NEAR(elliptic_K(v.k) / v.K, 1.0, 1e-13) << v.k;
    EXPECT_NEAR(elliptic_E(v.k) / v.E, 1.0, 2e-15) << v.k;
    std::printf("measured: k = %g AGM K, E rel error %.1e %.1e; std::comp_ellint_1, _2 %.1e %.1e\n", v.k,
                std::abs(elliptic_K(v.k) / v.K - 1.0), std::abs(elliptic_E(v.k) / v.E - 1.0),
                std::abs(std::comp_ellint_1(v.k) / v.K - 1.0), std::abs(std::comp_ellint_2(v.k) / v.E - 1.0));
  }
  // k -> 1: K = L + kc^2/4 (L - 1) + O(kc^4 L), E = 1 + kc^2/2 (L - 1/2) + O(kc^4 L),
  // L = ln(4 / kc) (Abramowitz & Stegun 17.3.26, 17.3.36). k is set from kc
  // exactly: k = sqrt(1 - kc^2) rounds, so compare at the k actually used.
  for (double kc : {1e-4, 1e-6, 1e-8}) {
    const double k = std::sqrt(1.0 - kc * kc);
    const double kc_used = std::sqrt((1.0 - k) * (1.0 + k));
    const double L = std::log(4.0 / kc_used);
    EXPECT_NEAR(elliptic_K(k), L + 0.25 * kc_used * kc_used * (L - 1.0), 1e-13 * L) << kc;
    EXPECT_NEAR(elliptic_E(k), 1.0 + 0.5 * kc_used * kc_used * (L - 0.5), 1e-14) << kc;
  }
  // Legendre's relation E K' + E' K - K K' = pi / 2, K' = K(kc).
  for (double k : {0.2, 0.6, 0.95, 0.999999}) {
    const double kc = std::sqrt((1.0 - k) * (1.0 + k));
    const double K = elliptic_K(k), E = elliptic_E(k), Kp = elliptic_K(kc), Ep = elliptic_E(kc);
    EXPECT_NEAR(E * Kp + Ep * K - K * Kp, 0.5 * kPi, 1e-13) << k;
  }
}

TEST(CoilSpecialFunctions, CarlsonAndBulirschAgainstKnownValues) {
  // Carlson, Numer. Algorithms 10 (1995), Sec. 3 test values.
  EXPECT_NEAR(carlson_RF(1, 2, 0), 1.3110287771461, 1e-13);
  EXPECT_NEAR(carlson_RF(2, 3, 4), 0.58408284167715, 1e-13);
  EXPECT_NEAR(carlson_RD(0, 2, 1), 1.7972103521034, 1e-13);
  EXPECT_NEAR(carlson_RD(2, 3, 4), 0.16510527294261, 1e-13);
  EXPECT_NEAR(carlson_RF(0.7, 0.7, 0.7), 1.0 / std::sqrt(0.7), 1e-15);
  EXPECT_NEAR(carlson_RD(0.7, 0.7, 0.7), std::pow(0.7, -1.5), 1e-14);
  for (double k : {0.1, 0.5, 0.9, 0.9999}) {
    const double kc2 = (1.0 - k) * (1.0 + k), kc = std::sqrt(kc2);
    // std:: where it is accurate, mpmath's value (above) at 0.9999.
    const double K = k < 0.95 ? std::comp_ellint_1(k) : 5.64514821682969279;
    const double E = k < 0.95 ? std::comp_ellint_2(k) : 1.00051450008378118;
    // K = R_F(0, kc^2, 1), E = K - k^2/3 R_D(0, kc^2, 1) (DLMF 19.25.1).
    EXPECT_NEAR(carlson_RF(0, kc2, 1) / K, 1.0, 1e-13) << k;
    EXPECT_NEAR((carlson_RF(0, kc2, 1) - k * k / 3.0 * carlson_RD(0, kc2, 1)) / E, 1.0, 1e-13) << k;
    // cel(kc, 1, 1, 1) = K, cel(kc, 1, 1, kc^2) = E.
    EXPECT_NEAR(bulirsch_cel(kc, 1, 1, 1) / K, 1.0, 1e-13) << k;
    EXPECT_NEAR(bulirsch_cel(kc, 1, 1, kc2) / E, 1.0, 1e-13) << k;
    // General p, a, b against this file's quadrature of the defining integral.
    for (double p : {0.04, 0.5, 2.0}) {
      const double reference = integrate(
          [&](double t) {
            const double c2 = std::cos(t) * std::cos(t), s2 = 1.0 - c2;
            return (1.3 * c2 - 0.4 * s2) / ((c2 + p * s2) * std::sqrt(c2 + kc2 * s2));
          },
          0.0, 0.5 * kPi, 64, 20);
      EXPECT_NEAR(bulirsch_cel(kc, p, 1.3, -0.4), reference, 1e-12 * std::abs(reference)) << k << " " << p;
    }
  }
}

// ---------------------------------------------------------------------------
// 2. Circular loop.

TEST(CircularLoop, OnAxisClosedForm) {
  // B = mu0 I R^2 / (2 (R^2 + z^2)^(3/2)) along the axis, any orientation.
  const double R = 0.03, I = 2.5, N = 7;
  for (const Mat3& rot : {Mat3{}, tilted()}) {
    CircularLoop loop{{0.01, -0.02, 0.005}, rot * Vec3{0, 0, 1}, R, I, N};
    const Vec3 e3 = normalized(loop.axis);
    double worst = 0.0;
    for (double z : {0.0, 1e-6, 0.01, -0.02, 0.1, -1.0, 10.0}) {
      const double b = kMu0 * N * I * R * R / (2.0 * std::pow(R * R + z * z, 1.5));
      worst = std::max(worst, rel(coil_field_B(loop, loop.centre + z * e3), b * e3));
    }
    EXPECT_LT(worst, 1e-12);
    std::printf("measured: loop on-axis max rel error %.2e\n", worst);
  }
}

TEST(CircularLoop, FarFieldIsDipoleWithSecondOrderError) {
  const double R = 0.02, I = 3.0;
  CircularLoop loop{{0.1, 0.2, -0.1}, tilted() * Vec3{0, 0, 1}, R, I, 1};
  const Vec3 m = (I * kPi * R * R) * normalized(loop.axis);
  EXPECT_LT(rel(dipole_moment(loop), m), 1e-14);
  const Vec3 dir = normalized(Vec3{0.3, -0.5, 0.8});
  double previous = 0.0;
  for (double r : {10.0, 20.0, 40.0, 80.0, 160.0}) {
    const double e = rel(coil_field_H(loop, loop.centre + r * R * dir), dipole_H(m, r * R * dir));
    EXPECT_LT(e, 3.0 / (r * r));  // the octupole term: O((R/r)^2)
    if (previous > 0.0) {
      EXPECT_GT(previous / e, 3.8);
      EXPECT_LT(previous / e, 4.2);
    }
    std::printf("measured: loop far field r/R = %g rel deviation from dipole %.3e\n", r, e);
    previous = e;
  }
}

TEST(CircularLoop, OffAxisAgainstBruteForceBiotSavart) {
  const double R = 0.05, I = 1.7;
  const Mat3 rot = tilted();
  CircularLoop loop{{0.01, 0.02, 0.03}, rot * Vec3{0, 0, 1}, R, I, 3};
  const Vec3 e1 = rot * Vec3{1, 0, 0}, e2 = rot * Vec3{0, 1, 0}, e3 = rot * Vec3{0, 0, 1};
  double worst = 0.0;
  for (const Vec3& local : {Vec3{0.5 * R, 0, 0.3 * R}, Vec3{1.5 * R, 0.2 * R, -0.4 * R}, Vec3{0.99 * R, 0, 0.01 * R},
                            Vec3{0, 1.01 * R, -0.005 * R}, Vec3{3 * R, R, 2 * R}, Vec3{0.1 * R, 0.05 * R, 0},
                            Vec3{1e-7 * R, 0, 0.2 * R}, Vec3{20 * R, -5 * R, 3 * R}}) {
    const Vec3 x = loop.centre + local.x * e1 + local.y * e2 + local.z * e3;
    const Vec3 reference = brute_circle(loop.centre, e1, e2, R, 3 * I, x, 400000);
    const double e = rel(coil_field_H(loop, x), reference);
    EXPECT_LT(e, 1e-8) << local.x << " " << local.y << " " << local.z;
    worst = std::max(worst, e);
  }
  std::printf("measured: loop off-axis vs brute force (4e5 points) max rel error %.2e\n", worst);
}

TEST(CircularLoop, OnAThinWiresCentreLineIsZeroAndNearItTheWireField) {
  const double R = 0.1, I = 2.0;
  CircularLoop loop{{}, {0, 0, 1}, R, I, 1, 1e-9 * R};  // a wire far thinner than the distances below
  const Vec3 on = coil_field_H(loop, {R, 0, 0});
  EXPECT_EQ(norm(on), 0.0);
  EXPECT_TRUE(is_finite(coil_field_H(loop, {R * (1 + 1e-11), 0, 0})));
  // At distance d << R: I / (2 pi d) plus O(I/R log(R/d)) (the curvature term).
  for (double d : {1e-4, 1e-6}) {
    const double h = norm(coil_field_H(loop, {R, 0, d * R}));
    EXPECT_NEAR(h * 2.0 * kPi * d * R / I, 1.0, 5.0 * d * std::log(8.0 / d));
  }
}

// ---------------------------------------------------------------------------
// Filaments with a wire radius (include/odemag/coil.h "Filaments have a wire").

// H (rho, z components) per unit current of a filament ring of radius r at
// height zr, at (rho, z): the standard elliptic-integral form (Smythe 7.10),
// with the standard library's K and E, independent of the library's cel.
void ring_H(double r, double zr, double rho, double z, double& h_rho, double& h_z) {
  const double zeta = z - zr, q2 = (r + rho) * (r + rho) + zeta * zeta, d2 = (r - rho) * (r - rho) + zeta * zeta;
  const double k = std::min(std::sqrt(4.0 * r * rho / q2), 1.0 - 1e-16);  // rounding must not take it to 1
  const double K = std::comp_ellint_1(k), E = std::comp_ellint_2(k);
  const double q = std::sqrt(q2);
  h_z = (K + (r * r - rho * rho - zeta * zeta) / d2 * E) / (2.0 * kPi * q);
  h_rho = rho > 0.0 ? zeta / (2.0 * kPi * rho * q) * (-K + (r * r + rho * rho + zeta * zeta) / d2 * E) : 0.0;
}

// The field of a thick ring: current NI spread uniformly over the disc of
// radius a about (R, 0) in the (rho, z) half-plane, integrated in polar
// coordinates (s, theta) about the point, where the ring's 1 / s is cancelled
// by the area element s ds: trapezoidal in theta, Gauss-Legendre in s on
// panels halving towards s = 0 (the s ln s of the curvature term).
void thick_ring_H(double R, double a, double NI, double rho, double z, double& h_rho, double& h_z) {
  const Rule rule = legendre(8);
  const int n_theta = 128;
  h_rho = h_z = 0.0;
  const double qx = rho - R, qz = z, J = NI / (kPi * a * a);
  if (qx * qx + qz * qz > 2.0 * a * a) {  // outside, off the section by >= 0.41 a: polar about its centre
    const Rule radial = legendre(32);
    const int n_phi = 256;
    for (int t = 0; t < n_phi; ++t) {
      const double phi = 2.0 * kPi * (t + 0.5) / n_phi;
      for (size_t i = 0; i < radial.x.size(); ++i) {
        const double r = 0.5 * a * (1.0 + radial.x[i]);
        double hr, hz;
        ring_H(R + r * std::cos(phi), r * std::sin(phi), rho, z, hr, hz);
        const double w = J * 0.5 * a * radial.w[i] * r * (2.0 * kPi / n_phi);
        h_rho += w * hr;
        h_z += w * hz;
      }
    }
    return;
  }
  for (int t = 0; t < n_theta; ++t) {
    const double theta = 2.0 * kPi * (t + 0.5) / n_theta, ux = std::cos(theta), uz = std::sin(theta);
    // The ray P + s u meets the disc for s in [s1, s2].
    const double b = qx * ux + qz * uz, disc = b * b - (qx * qx + qz * qz - a * a);
    if (disc <= 0.0) continue;
    const double s1 = std::max(0.0, -b - std::sqrt(disc)), s2 = -b + std::sqrt(disc);
    if (s2 <= s1) continue;
    std::vector<double> edges = {s2};
    if (s1 == 0.0)
      for (int k = 0; k < 30; ++k) edges.push_back(edges.back() * 0.5);
    edges.push_back(s1);
    for (size_t p = 0; p + 1 < edges.size(); ++p) {
      const double hi = edges[p], lo = edges[p + 1], mid = 0.5 * (hi + lo), half = 0.5 * (hi - lo);
      for (size_t i = 0; i < rule.x.size(); ++i) {
        const double sv = mid + half * rule.x[i];
        double hr, hz;
        ring_H(rho + sv * ux, z + sv * uz, rho, z, hr, hz);
        const double w = J * rule.w[i] * half * sv * (2.0 * kPi / n_theta);
        h_rho += w * hr;
        h_z += w * hz;
      }
    }
  }
}

// Inside a straight wire the field is the round conductor's, N I d / (2 pi a^2);
// at and beyond the surface the filament's; the default radius is 1% of the length.
TEST(FilamentWire, InsideAStraightWireIsTheRoundConductorsField) {
  const double I = 4.0, a = 1e-3, L = 10.0;
  const StraightSegment wire{{0, 0, -0.5 * L}, {0, 0, 0.5 * L}, I, 2, a};
  for (double d : {0.0, 1e-9 * a, 0.1 * a, 0.5 * a, 0.9 * a, a, 1.5 * a, 4 * a}) {
    // The infinite wire's, times (cos theta1 - cos theta2) / 2 of the finite length.
    const double z = 0.01, t1 = z + 0.5 * L, t2 = z - 0.5 * L;
    const double length_factor = 0.5 * (t1 / std::hypot(d, t1) - t2 / std::hypot(d, t2));
    const double inside =
        length_factor * (d < a ? 2.0 * I * d / (2.0 * kPi * a * a) : 2.0 * I / (2.0 * kPi * d));
    const Vec3 h = coil_field_H(wire, {d * std::cos(0.3), d * std::sin(0.3), z});
    EXPECT_NEAR(norm(h), inside, 1e-12 * inside + 1e-15) << "d / a = " << d / a;
    EXPECT_NEAR(dot(h, Vec3{-std::sin(0.3), std::cos(0.3), 0.0}), norm(h), 1e-12 * (norm(h) + 1.0));
  }
  EXPECT_DOUBLE_EQ(filament_wire_radius(StraightSegment{{0, 0, 0}, {0, 0, 0.2}, 1.0, 1}), 0.002);
  EXPECT_DOUBLE_EQ(filament_wire_radius(CircularLoop{{}, {0, 0, 1}, 0.05, 1.0, 1}), 5e-4);
  EXPECT_DOUBLE_EQ(filament_wire_radius(Arc{{}, {0, 0, 1}, 0.05, {1, 0, 0}, 1.0, 1.0, 1, 3e-4}), 3e-4);
  EXPECT_NE(coil_source_error(CircularLoop{{}, {0, 0, 1}, 0.05, 1.0, 1, -1e-3}), "");
}

// A loop's wire against the thick ring of the same circular section: the
// error relative to the surface field N I / (2 pi a), inside and outside the
// wire, for a = 1% of R (the default); docs/model.md quotes the numbers.
TEST(FilamentWire, LoopInsideItsWireAgainstAThickRing) {
  const double R = 0.05, a = 0.01 * R, NI = 1000.0, surface = NI / (2.0 * kPi * a);
  const CircularLoop loop{{}, {0, 0, 1}, R, 100.0, 10.0};  // the default wire radius
  double worst_inside = 0.0, worst_outside = 0.0;
  for (double d_over_a : {0.0, 0.25, 0.5, 0.75, 0.95, 1.5, 3.0})
    for (double angle : {0.0, 0.5 * kPi, kPi, 1.5 * kPi, 0.7}) {
      const double rho = R + d_over_a * a * std::cos(angle), z = d_over_a * a * std::sin(angle);
      double hr, hz;
      thick_ring_H(R, a, NI, rho, z, hr, hz);
      const Vec3 h = coil_field_H(loop, {rho, 0.0, z});
      const double e = std::hypot(h.x - hr, h.z - hz) / surface;
      ASSERT_TRUE(std::isfinite(e));
      (d_over_a < 1.0 ? worst_inside : worst_outside) = std::max(d_over_a < 1.0 ? worst_inside : worst_outside, e);
      if (d_over_a == 0.0) break;
    }
  EXPECT_LT(worst_inside, 0.035);
  EXPECT_LT(worst_outside, 1e-3);
  std::printf("measured: loop wire (a = R / 100) vs thick ring, |H - H_ring| / (NI / (2 pi a)) max %.2e inside, "
              "%.2e outside\n",
              worst_inside, worst_outside);
}

// Across every filament's wire the field and its gradient stay bounded
// (|H| <= N I / (2 pi a), |grad H| <= 3 N I / (2 pi a^2), with 10% for the
// curvature), and the field is continuous at the surface.
TEST(FilamentWire, FieldAndGradientAreBoundedAcrossTheWire) {
  const double R = 0.05, NI = 1000.0;
  const std::vector<CoilSource> filaments = {CircularLoop{{}, {0, 0, 1}, R, 100.0, 10.0},
                                             Arc{{}, {0, 0, 1}, R, {1, 0, 0}, 2.0, 100.0, 10.0},
                                             StraightSegment{{R, 0, -R}, {R, 0, R}, 100.0, 10.0, 5e-4}};
  for (const CoilSource& f : filaments) {
    const double a = filament_wire_radius(f);
    double largest_H = 0.0, largest_gradient = 0.0, jump = 0.0;
    for (int i = -60; i <= 60; ++i)
      for (int j = -60; j <= 60; ++j) {
        // A plane across the wire at (R, 0, 0) and, for the arc, across its start.
        const Vec3 x{R + 2.5 * a * i / 60.0, 1e-3 * a, 2.5 * a * j / 60.0};
        largest_H = std::max(largest_H, norm(coil_field_H(f, x)));
        const double step = 1e-4 * a;
        for (const Vec3& e : {Vec3{step, 0, 0}, Vec3{0, step, 0}, Vec3{0, 0, step}})
          largest_gradient = std::max(largest_gradient, norm(coil_field_H(f, x + e) - coil_field_H(f, x - e)) / (2 * step));
      }
    for (double angle : {0.0, 1.0, 2.0, 3.0}) {
      const Vec3 dir{std::cos(angle), 0.0, std::sin(angle)};
      const Vec3 p{R, 1e-3 * a, 0.0};
      jump = std::max(jump, norm(coil_field_H(f, p + (a * (1 - 1e-9)) * dir) - coil_field_H(f, p + (a * (1 + 1e-9)) * dir)));
    }
    EXPECT_LT(largest_H, 1.1 * NI / (2.0 * kPi * a)) << f.index();
    EXPECT_LT(largest_gradient, 3.3 * NI / (2.0 * kPi * a * a)) << f.index();
    EXPECT_LT(jump, 1e-6 * NI / (2.0 * kPi * a)) << f.index();
  }
}

TEST(CircularLoop, DivergenceAndCurlVanishAwayFromTheWire) {
  const double R = 0.04;
  CircularLoop loop{{0.01, 0, 0}, tilted() * Vec3{0, 0, 1}, R, 5.0, 1};
  auto H = [&](const Vec3& x) { return coil_field_H(loop, x); };
  double worst = 0.0;
  for (const Vec3& x : {Vec3{0.02, 0.01, 0.015}, Vec3{-0.03, 0.05, 0.0}, Vec3{0.05, -0.02, 0.03}, Vec3{0.011, 0, 0}}) {
    const Derivatives d = derivatives(H, x, 1e-4 * R);
    const double scale = norm(H(x)) / R;
    worst = std::max({worst, std::abs(d.div) / scale, norm(d.curl) / scale});
  }
  EXPECT_LT(worst, 1e-8);
  std::printf("measured: loop |div H|, |curl H| * R / |H| max %.2e\n", worst);
}

// ---------------------------------------------------------------------------
// 3. Straight segments and arcs.

TEST(StraightSegment, InfiniteWireLimitAndBruteForce) {
  const double I = 4.0, d = 0.01;
  StraightSegment wire{{0, 0, -1e4 * d}, {0, 0, 1e4 * d}, I, 1, 1e-3 * d};  // a thin wire, not 1% of its length
  // B = mu0 I / (2 pi d) e_phi; the finite length changes it by d^2 / (2 L^2) = 5e-9.
  const Vec3 b = coil_field_B(wire, {d, 0, 0});
  EXPECT_NEAR(b.y / (kMu0 * I / (2.0 * kPi * d)), 1.0, 6e-9);
  EXPECT_NEAR(b.x, 0.0, 1e-20);
  EXPECT_NEAR(b.z, 0.0, 1e-20);
  const double exact = kMu0 * I / (2.0 * kPi * d) * 1e4 / std::sqrt(1e8 + 1.0);
  EXPECT_NEAR(b.y / exact, 1.0, 1e-14);
  // Off the middle, beside and beyond the ends, against quadrature.
  StraightSegment s{{0.01, -0.02, 0.03}, {-0.04, 0.05, 0.01}, 1.5, 2, 1e-6};
  double worst = 0.0;
  for (const Vec3& x : {Vec3{0, 0, 0}, Vec3{0.1, 0.1, 0.1}, Vec3{-0.06, 0.08, 0.0}, Vec3{0.02, -0.03, 0.035},
                        Vec3{-0.015, 0.015, 0.0205}}) {
    const double e = rel(coil_field_H(s, x), brute_line(s.a, s.b, 3.0, x, 256, 20));
    EXPECT_LT(e, 1e-12);
    worst = std::max(worst, e);
  }
  std::printf("measured: segment vs brute force max rel error %.2e\n", worst);
  // On the line: zero on the segment and on its extension.
  EXPECT_EQ(norm(coil_field_H(s, 0.5 * (s.a + s.b))), 0.0);
  EXPECT_LT(norm(coil_field_H(s, s.b + 0.3 * (s.b - s.a))), 1e-12 * norm(coil_field_H(s, {})));
  EXPECT_EQ(norm(coil_field_H(s, s.a)), 0.0);
}

TEST(StraightSegment, ClosedSquareAgainstBruteForceAndDipole) {
  const double a = 0.02, I = 2.0;
  const Vec3 c[4] = {{a, a, 0}, {-a, a, 0}, {-a, -a, 0}, {a, -a, 0}};
  std::vector<CoilSource> square;
  for (int k = 0; k < 4; ++k) square.push_back(StraightSegment{c[k], c[(k + 1) % 4], I, 1});
  double worst = 0.0;
  for (const Vec3& x : {Vec3{0, 0, 0}, Vec3{0.01, 0.005, 0.01}, Vec3{0.03, -0.01, 0.005}, Vec3{0.021, 0.0, 0.0}}) {
    Vec3 reference;
    for (int k = 0; k < 4; ++k) reference += brute_line(c[k], c[(k + 1) % 4], I, x, 256, 20);
    const double e = rel(coil_field_H(square, x), reference);
    EXPECT_LT(e, 1e-12);
    worst = std::max(worst, e);
  }
  // Centre of a square loop of side 2a: H = 2 sqrt(2) I / (pi 2a).
  EXPECT_NEAR(coil_field_H(square, {}).z / (2.0 * std::sqrt(2.0) * I / (kPi * 2 * a)), 1.0, 1e-14);
  const Vec3 m{0, 0, I * 4 * a * a};
  Vec3 m_sum;
  for (const CoilSource& s : square) m_sum += dipole_moment(s);
  EXPECT_LT(rel(m_sum, m), 1e-14);
  const Vec3 far = 50 * a * normalized(Vec3{1, 2, 2});
  EXPECT_LT(rel(coil_field_H(square, far), dipole_H(m, far)), 1e-3);
  std::printf("measured: square of segments vs brute force max rel error %.2e\n", worst);
  // Maxwell away from the wire.
  auto H = [&](const Vec3& x) { return coil_field_H(square, x); };
  const Derivatives d = derivatives(H, {0.01, 0.015, 0.004}, 1e-5);
  const double scale = norm(H({0.01, 0.015, 0.004})) / a;
  EXPECT_LT(std::abs(d.div) / scale, 1e-8);
  EXPECT_LT(norm(d.curl) / scale, 1e-8);
}

TEST(Arc, FullTurnEqualsTheLoopAndArcsMatchBruteForce) {
  const double R = 0.03, I = 1.2;
  const Mat3 rot = tilted();
  const Vec3 centre{0.01, -0.01, 0.02}, axis = rot * Vec3{0, 0, 1};
  // Thin wires: the points below come within 1e-3 R of the wire.
  const double wire = 1e-6 * R;
  CircularLoop loop{centre, axis, R, I, 2, wire};
  double worst_loop = 0.0;
  for (const Vec3& local : {Vec3{0.3 * R, 0.2 * R, 0.1 * R}, Vec3{2 * R, -R, 0.5 * R}, Vec3{0, 0, 0.4 * R},
                            Vec3{-0.98 * R, 0.05 * R, 0.01 * R}, Vec3{0, -R, 0.001 * R}}) {
    const Vec3 x = centre + rot * local;
    const Vec3 h_loop = coil_field_H(loop, x);
    for (const Vec3& start : {rot * Vec3{1, 0, 0}, rot * Vec3{-0.3, 0.8, 0.1}}) {
      const double e = rel(coil_field_H(Arc{centre, axis, R, start, 2.0 * kPi, I, 2, wire}, x), h_loop);
      worst_loop = std::max(worst_loop, e);
      // The same turn the other way round about the reversed axis, and two half turns.
      worst_loop =
          std::max(worst_loop, rel(coil_field_H(Arc{centre, -axis, R, start, -2.0 * kPi, I, 2, wire}, x), h_loop));
      const Vec3 halves = coil_field_H(Arc{centre, axis, R, start, kPi, I, 2, wire}, x) +
                          coil_field_H(Arc{centre, axis, R, -start, kPi, I, 2, wire}, x);
      worst_loop = std::max(worst_loop, rel(halves, h_loop));
    }
  }
  EXPECT_LT(worst_loop, 1e-12);
  std::printf("measured: arc of 2 pi vs loop max rel error %.2e\n", worst_loop);
  const Vec3 e1 = rot * Vec3{1, 0, 0}, e2 = rot * Vec3{0, 1, 0};
  double worst = 0.0;
  for (double angle : {0.3, 0.5 * kPi, 2.5, 4.0, 7.0}) {
    Arc arc{centre, axis, R, e1, angle, I, 1};
    for (const Vec3& local : {Vec3{0.3 * R, 0.2 * R, 0.1 * R}, Vec3{2 * R, -R, 0.5 * R}, Vec3{R, -0.02 * R, 0.01 * R},
                              Vec3{0.5 * R, -0.9 * R, 0.02 * R}, Vec3{0, 0, -R},
                              // On the circle, off the arc (for angle < 2 pi - 0.1).
                              Vec3{R * std::cos(0.1), -R * std::sin(0.1), 0.0}}) {
      if (angle > 2 * kPi && local.z == 0.0) continue;  // on the wire of a second turn
      const Vec3 x = centre + rot * local;
      const double e = rel(coil_field_H(arc, x), brute_arc(centre, e1, e2, R, angle, I, x, 4096, 20));
      EXPECT_LT(e, 1e-11) << angle << " " << local.x << " " << local.y;
      worst = std::max(worst, e);
    }
  }
  std::printf("measured: arcs vs brute force max rel error %.2e\n", worst);
  // A closed D (half turn and its diameter) satisfies div H = curl H = 0.
  std::vector<CoilSource> d_shape = {Arc{centre, axis, R, e1, kPi, I, 1},
                                     StraightSegment{centre - R * e1, centre + R * e1, I, 1}};
  auto H = [&](const Vec3& x) { return coil_field_H(d_shape, x); };
  const Vec3 x = centre + rot * Vec3{0.2 * R, 0.3 * R, 0.2 * R};
  const Derivatives d = derivatives(H, x, 1e-4 * R);
  EXPECT_LT(std::abs(d.div) * R / norm(H(x)), 1e-8);
  EXPECT_LT(norm(d.curl) * R / norm(H(x)), 1e-8);
}

// ---------------------------------------------------------------------------
// 4. Solenoid sheet.

TEST(Solenoid, OnAxisClosedFormLongLimitAndDipole) {
  const double R = 0.01, L = 0.05, I = 0.5, N = 200;
  const double n = N / L;
  Solenoid sol{{0.0, 0.01, 0.0}, tilted() * Vec3{0, 0, 1}, R, L, I, N};
  const Vec3 e3 = normalized(sol.axis);
  double worst = 0.0;
  for (double z : {0.0, 0.01, -0.02, 0.025, 0.03, -0.1, 0.2, 1.0, 30.0}) {
    // B = mu0 n I / 2 (cos a1 - cos a2) in terms of the distances to the ends.
    // (written without the cancellation of the two terms far away).
    const double zp = z + 0.5 * L, zm = z - 0.5 * L, A = std::hypot(zp, R), B = std::hypot(zm, R);
    const double cosines = zp * zm > 0.0 ? R * R * (zp * zp - zm * zm) / (A * B * (zp * B + zm * A)) : zp / A - zm / B;
    const double b = 0.5 * kMu0 * n * I * cosines;
    worst = std::max(worst, rel(coil_field_B(sol, sol.centre + z * e3), b * e3));
  }
  EXPECT_LT(worst, 1e-13);
  std::printf("measured: solenoid on-axis max rel error %.2e\n", worst);
  // Long solenoid: centre field -> mu0 n I, the deficit 1 - L / sqrt(L^2 + 4 R^2) ~ 2 (R/L)^2.
  for (double ratio : {100.0, 1000.0}) {
    Solenoid lng{{}, {0, 0, 1}, R, ratio * R, I, N};
    const double b0 = kMu0 * N / (ratio * R) * I;
    const double deficit = 1.0 - coil_field_B(lng, {}).z / b0;
    EXPECT_NEAR(deficit / (1.0 - ratio / std::sqrt(ratio * ratio + 4.0)), 1.0, 1e-9);
    EXPECT_LT(deficit, 2.0 / (ratio * ratio));
    // Uniform inside, away from the ends (end corrections ~ (R / distance)^2 / 2 each).
    EXPECT_NEAR(coil_field_B(lng, {0.7 * R, 0.0, 0.1 * ratio * R}).z / b0, 1.0, 1.0 / (0.16 * ratio * ratio));
  }
  // Far outside: a dipole of moment N I pi R^2.
  const Vec3 m = (N * I * kPi * R * R) * e3;
  EXPECT_LT(rel(dipole_moment(sol), m), 1e-14);
  const Vec3 dir = normalized(Vec3{0.2, 0.9, -0.4});
  double previous = 0.0;
  for (double r : {40.0, 80.0, 160.0}) {
    const double e = rel(coil_field_H(sol, sol.centre + r * R * dir), dipole_H(m, r * R * dir));
    if (previous > 0) {
      EXPECT_NEAR(previous / e, 4.0, 0.3);
    }
    previous = e;
  }
  EXPECT_LT(previous, 1e-3);
}

TEST(Solenoid, OffAxisEqualsLoopsIntegratedOverTheLength) {
  const double R = 0.02, L = 0.03, NI = 100.0;
  Solenoid sol{{}, {0, 0, 1}, R, L, 1.0, NI};
  double worst = 0.0;
  for (const Vec3& x : {Vec3{0.01, 0.0, 0.005}, Vec3{0.03, 0.01, -0.01}, Vec3{0.005, 0.005, 0.03},
                        Vec3{0.0199, 0.0, 0.0}, Vec3{0.04, 0.0, 0.0151}, Vec3{0.1, 0.05, 0.2}}) {
    // The loops by this file's composite Gauss-Legendre (the loop's own accuracy is tested above).
    const Vec3 reference = integrate(
        [&](double z) { return coil_field_H(CircularLoop{{0, 0, z}, {0, 0, 1}, R, NI / L, 1, 1e-9 * R}, x); }, -0.5 * L,
        0.5 * L, 400, 20);
    const double e = rel(coil_field_H(sol, x), reference);
    EXPECT_LT(e, 1e-10) << x.x << " " << x.z;
    worst = std::max(worst, e);
  }
  std::printf("measured: solenoid off-axis vs integrated loops max rel error %.2e\n", worst);
  // On the sheet: the mean of both sides (H_z jumps by K = NI / L).
  const Vec3 inside = coil_field_H(sol, {R * (1 - 1e-9), 0, 0.004}), outside = coil_field_H(sol, {R * (1 + 1e-9), 0, 0.004});
  EXPECT_NEAR(inside.z - outside.z, NI / L, 1e-5 * NI / L);
  EXPECT_LT(rel(coil_field_H(sol, {R, 0, 0.004}), 0.5 * (inside + outside)), 1e-6);
  // Edge rings: zero on them, finite near.
  EXPECT_EQ(norm(coil_field_H(sol, {R, 0, 0.5 * L})), 0.0);
  EXPECT_TRUE(is_finite(coil_field_H(sol, {R * (1 + 1e-8), 0, 0.5 * L})));
  // Maxwell off the sheet.
  auto H = [&](const Vec3& x) { return coil_field_H(sol, x); };
  double worst_maxwell = 0.0;
  for (const Vec3& x : {Vec3{0.01, 0.004, 0.005}, Vec3{0.025, -0.01, 0.014}, Vec3{0.005, 0.0, 0.02}}) {
    const Derivatives d = derivatives(H, x, 1e-5);
    const double scale = norm(H(x)) / R;
    worst_maxwell = std::max({worst_maxwell, std::abs(d.div) / scale, norm(d.curl) / scale});
  }
  EXPECT_LT(worst_maxwell, 1e-8);
}

// ---------------------------------------------------------------------------
// 5. Finite cross-sections.

// The axial field of a thick coil: integrate the loop's on-axis field over the
// section, B = mu0 J / 2 [F(z + L/2) - F(z - L/2)],
// F(zeta) = zeta ln((r2 + sqrt(r2^2 + zeta^2)) / (r1 + sqrt(r1^2 + zeta^2))).
TEST(CircularCoil, OnAxisClosedFormAndConvergence) {
  const double r1 = 0.01, r2 = 0.025, L = 0.04, NI = 1000.0;
  CircularCoil coil{{0, 0, 0.01}, {0, 0, 1}, r1, r2, L, 1.0, NI};
  const double J = NI / ((r2 - r1) * L);
  auto F = [&](double zeta) {
    return zeta * std::log((r2 + std::hypot(r2, zeta)) / (r1 + std::hypot(r1, zeta)));
  };
  double worst = 0.0;
  for (double z : {0.0, 0.01, 0.02, -0.03, 0.1}) {
    const double h = 0.5 * J * (F(z + 0.5 * L) - F(z - 0.5 * L));
    worst = std::max(worst, rel(coil_field_H(coil, coil.centre + Vec3{0, 0, z}), Vec3{0, 0, h}));
  }
  EXPECT_LT(worst, 1e-12);
  std::printf("measured: circular coil on-axis max rel error %.2e\n", worst);
  // Convergence in the quadrature order against order 32, and against this
  // file's brute force (loops over the section) for the points off the copper.
  struct Probe {
    Vec3 x;
    const char* where;
  };
  const Probe probes[] = {{{0.005, 0.0, 0.015}, "in the bore"},
                          {{0.0262, 0.0, 0.02}, "1.2 mm outside"},
                          {{0.018, 0.004, 0.011}, "inside the copper"},
                          {{0.02, 0.0, 0.0305}, "on the end face"}};
  for (const Probe& p : probes) {
    CircularCoil fine = coil;
    fine.quadrature_order = 32;
    const Vec3 reference = coil_field_H(fine, p.x);
    std::printf("measured: circular coil %s, rel error by order:", p.where);
    double e_prev = 1.0;
    for (int order : {2, 3, 4, 6, 8, 12}) {
      CircularCoil c = coil;
      c.quadrature_order = order;
      const double e = rel(coil_field_H(c, p.x), reference);
      std::printf(" n=%d %.1e", order, e);
      if (order == 8) {
        EXPECT_LT(e, 1e-9) << p.where;
      }
      if (order <= 6 && e > 1e-13) {
        EXPECT_LT(e, e_prev) << p.where;
      }
      e_prev = e;
    }
    std::printf("\n");
  }
  for (int k = 0; k < 2; ++k) {
    const Vec3 x = probes[k].x;
    const Vec3 brute = integrate(
        [&](double r) {
          return integrate(
              [&](double z) { return coil_field_H(CircularLoop{{0, 0, 0.01 + z}, {0, 0, 1}, r, J, 1}, x); },
              -0.5 * L, 0.5 * L, 64, 20);
        },
        r1, r2, 16, 20);
    const double e = rel(coil_field_H(coil, x), brute);
    EXPECT_LT(e, 1e-9) << probes[k].where;
    std::printf("measured: circular coil %s vs brute force %.2e\n", probes[k].where, e);
  }
  // Far field: m = J L pi (r2^3 - r1^3) / 3.
  const Vec3 m{0, 0, J * L * kPi * (r2 * r2 * r2 - r1 * r1 * r1) / 3.0};
  EXPECT_LT(rel(dipole_moment(coil), m), 1e-12);
  const Vec3 far = coil.centre + 2.0 * normalized(Vec3{1, 0.5, 2});
  EXPECT_LT(rel(coil_field_H(coil, far), dipole_H(m, far - coil.centre)), 1e-3);
}

TEST(CircularCoil, MaxwellOutsideAndAmpereInsideTheCopper) {
  const double r1 = 0.01, r2 = 0.02, L = 0.03, NI = 500.0;
  CircularCoil coil{{}, normalized(Vec3{0.1, 0.2, 1.0}), r1, r2, L, 1.0, NI};
  const double J = NI / ((r2 - r1) * L);
  auto H = [&](const Vec3& x) { return coil_field_H(coil, x); };
  const Vec3 e3 = normalized(coil.axis);
  const Vec3 e1 = normalized(cross(Vec3{0, 1, 0}, e3)), e2 = cross(e3, e1);
  double worst_out = 0.0;
  for (const Vec3& local : {Vec3{0.005, 0.0, 0.0}, Vec3{0.03, 0.01, 0.01}, Vec3{0.015, 0.0, 0.02}}) {
    const Vec3 x = local.x * e1 + local.y * e2 + local.z * e3;
    const Derivatives d = derivatives(H, x, 2e-5);
    const double scale = norm(H(x)) / r1;
    worst_out = std::max({worst_out, std::abs(d.div) / scale, norm(d.curl) / scale});
  }
  EXPECT_LT(worst_out, 1e-7);
  // Inside: curl H = J e_phi.
  double worst_in = 0.0;
  for (const Vec3& local : {Vec3{0.015, 0.0, 0.0}, Vec3{0.012, 0.005, -0.01}}) {
    const Vec3 x = local.x * e1 + local.y * e2 + local.z * e3;
    const Derivatives d = derivatives(H, x, 2e-5);
    const Vec3 phi = normalized(cross(e3, x));
    worst_in = std::max({worst_in, norm(d.curl - J * phi) / J, std::abs(d.div) * r1 / norm(H(x))});
  }
  EXPECT_LT(worst_in, 1e-6);
  std::printf("measured: circular coil Maxwell outside %.1e, curl H = J inside %.1e\n", worst_out, worst_in);
}

TEST(RoundedRectangleCoil, Team20CoilAgainstBruteForceAndConvergence) {
  const RoundedRectangleCoil coil = team20_coil(1000.0);
  struct Probe {
    Vec3 x;
    const char* where;
  };
  // P1, P2 of the TEAM 20 gap; a point in the pole's corner region, beside
  // the coil, above it, over a corner.
  const Probe probes[] = {{{0.0, 0.0, 0.02575}, "P1"},
                          {{0.0125, 0.005, 0.02575}, "P2"},
                          {{0.0125, 0.005, 0.07}, "pole corner, mid-height"},
                          {{0.045, 0.01, 0.06}, "beside the coil"},
                          {{0.03, 0.03, 0.13}, "above a corner"}};
  double worst = 0.0;
  for (const Probe& p : probes) {
    const Vec3 brute = brute_rounded(coil, p.x, 6, 16, 8);
    const Vec3 h = coil_field_H(coil, p.x);
    const double e = rel(h, brute);
    EXPECT_LT(e, 1e-9) << p.where;
    worst = std::max(worst, e);
    std::printf("measured: TEAM 20 coil %s: B = (%.6e, %.6e, %.6e) T at 1000 AT, vs brute force %.1e; by order:",
                p.where, kMu0 * h.x, kMu0 * h.y, kMu0 * h.z, e);
    for (int order : {2, 3, 4, 6, 8}) {
      RoundedRectangleCoil c = coil;
      c.quadrature_order = order;
      std::printf(" n=%d %.1e", order, rel(coil_field_H(c, p.x), brute));
    }
    std::printf("\n");
  }
  std::printf("measured: TEAM 20 coil vs brute force max rel error %.2e\n", worst);
  // Far field: m = J h int_r1^r2 (4 (a + r)(b + r) - (4 - pi) r^2) dr along the axis.
  const double a = coil.core_half_width, b = coil.core_half_depth;
  const double j = 1000.0 / ((coil.outer_corner_radius - coil.inner_corner_radius) * coil.height);
  const double area = integrate([&](double r) { return 4 * (a + r) * (b + r) - (4 - kPi) * r * r; },
                                coil.inner_corner_radius, coil.outer_corner_radius, 1, 4);
  const Vec3 m{0, 0, j * coil.height * area};
  EXPECT_LT(rel(dipole_moment(coil), m), 1e-12);
  const Vec3 far = 3.0 * normalized(Vec3{0.4, -0.3, 1.0});
  EXPECT_LT(rel(coil_field_H(coil, coil.centre + far), dipole_H(m, far)), 2e-3);
}

TEST(RoundedRectangleCoil, WithoutStraightSidesEqualsTheCircularCoil) {
  // Zero core: the four corners make an annulus, r in [r1, r2].
  for (const Mat3& rot : {Mat3{}, tilted()}) {
    RoundedRectangleCoil rr;
    rr.centre = {0.01, 0.0, -0.02};
    rr.axis = rot * Vec3{0, 0, 1};
    rr.width_direction = rot * Vec3{1, 0, 0};
    rr.inner_corner_radius = 0.01;
    rr.outer_corner_radius = 0.02;
    rr.height = 0.03;
    rr.current = 300.0;
    CircularCoil cc{rr.centre, rr.axis, 0.01, 0.02, 0.03, 300.0, 1};
    RoundedRectangleCoil rr12 = rr;
    rr12.quadrature_order = 12;
    double worst = 0.0, worst12 = 0.0;
    // Off the copper (near and far), in it, on its faces.
    for (const Vec3& local : {Vec3{0.005, 0.001, 0.0}, Vec3{0.025, 0.0, 0.01}, Vec3{0.0, 0.0, 0.05},
                              Vec3{0.04, -0.03, -0.02}, Vec3{0.0099, 0.001, 0.0}, Vec3{0.02001, 0.003, 0.01},
                              Vec3{0.03, 0.0, 0.03}, Vec3{0.015, 0.002, 0.003}, Vec3{0.0141, 0.0141, 0.0},
                              Vec3{0.0100001, 0.0, 0.0}, Vec3{0.015, 0.0, 0.0150001}}) {
      const Vec3 x = rr.centre + rot * local;
      const Vec3 reference = coil_field_H(cc, x);
      const double e = rel(coil_field_H(rr, x), reference), e12 = rel(coil_field_H(rr12, x), reference);
      EXPECT_LT(e, 5e-9) << local.x;
      EXPECT_LT(e12, 1e-13) << local.x;
      worst = std::max(worst, e);
      worst12 = std::max(worst12, e12);
    }
    std::printf("measured: rounded coil without sides vs circular coil, order 12: max rel error %.2e\n", worst12);
    std::printf("measured: rounded coil without sides vs circular coil, order 8: max rel error %.2e\n", worst);
  }
}

TEST(RoundedRectangleCoil, MaxwellOutsideAndAmpereInsideTheCopper) {
  const RoundedRectangleCoil coil = team20_coil(3000.0);
  const double j = 3000.0 / ((coil.outer_corner_radius - coil.inner_corner_radius) * coil.height);
  auto H = [&](const Vec3& x) { return coil_field_H(coil, x); };
  double worst_out = 0.0;
  for (const Vec3& x : {Vec3{0.0, 0.0, 0.02575}, Vec3{0.0125, 0.005, 0.07}, Vec3{0.03, 0.03, 0.13}}) {
    const Derivatives d = derivatives(H, x, 2e-5);
    const double scale = norm(H(x)) / 0.01;
    worst_out = std::max({worst_out, std::abs(d.div) / scale, norm(d.curl) / scale});
  }
  EXPECT_LT(worst_out, 1e-7);
  // In a straight side (current +y at x > 0) and in a corner (e_phi about (a, b)).
  double worst_in = 0.0;
  {
    const Derivatives d = derivatives(H, {0.025, 0.003, 0.08}, 2e-5);
    worst_in = std::max(worst_in, norm(d.curl - Vec3{0, j, 0}) / j);
  }
  {
    const Vec3 x{0.0145 + 0.012 * std::cos(0.7), 0.0145 + 0.012 * std::sin(0.7), 0.06};
    const Derivatives d = derivatives(H, x, 2e-5);
    worst_in = std::max(worst_in, norm(d.curl - j * Vec3{-std::sin(0.7), std::cos(0.7), 0}) / j);
  }
  EXPECT_LT(worst_in, 1e-5);
  std::printf("measured: TEAM 20 coil Maxwell outside %.1e, curl H = J inside %.1e\n", worst_out, worst_in);
}

// ---------------------------------------------------------------------------
// 6. Forces and torques.

// Mutual inductance of coaxial loops (Maxwell's formula; Smythe, Grover):
// M = mu0 sqrt(a b) ((2/k - k) K(k) - (2/k) E(k)), k^2 = 4 a b / ((a + b)^2 + d^2),
// and its derivative dM/dd = -mu0 d k / (4 sqrt(a b)) ((2 - k^2) / (1 - k^2) E - 2 K);
// F_z on loop 2 = I1 I2 dM/dd. K, E from std::comp_ellint_1/2 (k <= 0.96 here).
double mutual_inductance(double a, double b, double d) {
  const double k = std::sqrt(4.0 * a * b / ((a + b) * (a + b) + d * d));
  return kMu0 * std::sqrt(a * b) * ((2.0 / k - k) * std::comp_ellint_1(k) - 2.0 / k * std::comp_ellint_2(k));
}
double mutual_inductance_derivative(double a, double b, double d) {
  const double k2 = 4.0 * a * b / ((a + b) * (a + b) + d * d), k = std::sqrt(k2);
  return -kMu0 * d * k / (4.0 * std::sqrt(a * b)) *
         ((2.0 - k2) / (1.0 - k2) * std::comp_ellint_2(k) - 2.0 * std::comp_ellint_1(k));
}

TEST(CoilForce, CoaxialLoopsAgainstMutualInductance) {
  const double a = 0.05, b = 0.03, I1 = 3.0, I2 = -2.0;
  double worst = 0.0;
  for (double d : {0.01, 0.04, 0.2}) {
    CircularLoop one{{0, 0, 0}, {0, 0, 1}, a, I1, 1};
    CircularLoop two{{0, 0, d}, {0, 0, 1}, b, I2, 1};
    const double dM = mutual_inductance_derivative(a, b, d);
    // The derivative against a difference quotient of M (checks the formula, to the quotient's 1e-8).
    const double h = 1e-3 * d;
    EXPECT_NEAR((mutual_inductance(a, b, d + h) - mutual_inductance(a, b, d - h)) / (2.0 * h) / dM, 1.0, 1e-5);
    const Wrench w = coil_wrench(two, [&](const Vec3& x) { return coil_field_B(one, x); }, two.centre);
    const double e = std::abs(w.force.z / (I1 * I2 * dM) - 1.0);
    EXPECT_LT(e, 1e-12) << d;
    EXPECT_LT(std::hypot(w.force.x, w.force.y), 1e-12 * std::abs(w.force.z));
    EXPECT_LT(norm(w.torque), 1e-12 * std::abs(w.force.z) * b);
    worst = std::max(worst, e);
  }
  std::printf("measured: coaxial loop force vs I1 I2 dM/dz max rel error %.2e\n", worst);
}

TEST(CoilForce, NewtonsThirdLawAndAngularMomentum) {
  // Pairs of closed sources in general position: F12 = -F21 and the torques
  // about a common point cancel (closed steady currents).
  const Mat3 rot = tilted();
  std::vector<CoilSource> square;
  const double s = 0.02;
  const Vec3 c[4] = {{0.03 + s, s, 0.01}, {0.03 - s, s, 0.01}, {0.03 - s, -s, 0.01}, {0.03 + s, -s, 0.01}};
  for (int k = 0; k < 4; ++k) square.push_back(StraightSegment{c[k], c[(k + 1) % 4], 2.0, 1});
  const std::vector<CoilSource> loop = {CircularLoop{{0.0, 0.01, 0.0}, rot * Vec3{0, 0, 1}, 0.025, 1.5, 1}};
  const std::vector<CoilSource> tilted_loop = {
      CircularLoop{{0.02, -0.03, 0.04}, rot * Vec3{1, 0.3, 0.2}, 0.015, -4.0, 3}};
  struct Pair {
    const std::vector<CoilSource>* one;
    const std::vector<CoilSource>* two;
    const char* name;
  };
  const Vec3 about{0.01, 0.02, -0.03};
  ElementOptions options;
  options.per_turn = 256;
  options.along = 48;
  for (const Pair& p : {Pair{&loop, &tilted_loop, "loop-loop"}, Pair{&square, &loop, "square-loop"},
                        Pair{&square, &tilted_loop, "square-loop2"}}) {
    Wrench on_two, on_one;
    for (const CoilSource& src : *p.two) {
      const Wrench w = coil_wrench(src, [&](const Vec3& x) { return kMu0 * coil_field_H(*p.one, x); }, about, options);
      on_two.force += w.force;
      on_two.torque += w.torque;
    }
    for (const CoilSource& src : *p.one) {
      const Wrench w = coil_wrench(src, [&](const Vec3& x) { return kMu0 * coil_field_H(*p.two, x); }, about, options);
      on_one.force += w.force;
      on_one.torque += w.torque;
    }
    const double ef = norm(on_one.force + on_two.force) / norm(on_two.force);
    const double et = norm(on_one.torque + on_two.torque) / (norm(on_two.force) * 0.05 + norm(on_two.torque));
    EXPECT_LT(ef, 1e-10) << p.name;
    EXPECT_LT(et, 1e-10) << p.name;
    std::printf("measured: %s |F12 + F21| / |F| %.1e, torque balance %.1e\n", p.name, ef, et);
  }
}

TEST(CoilForce, FiniteSectionCoilsBalanceAndFeelNoUniformForce) {
  // TEAM 20 coil and a circular coil beside it: third law at the
  // quadrature's accuracy (elements across 6, along 24).
  const RoundedRectangleCoil rr = team20_coil(1000.0);
  const CircularCoil cc{{0.02, 0.01, 0.17}, normalized(Vec3{0.2, 0.1, 1.0}), 0.01, 0.02, 0.02, 1.0, 500.0};
  const Vec3 about = rr.centre;
  double previous = 1.0;
  ElementOptions options;
  for (int across : {2, 4, 6, 8}) {
    options.across = across;
    options.along = 4 * across;
    options.per_turn = 16 * across;
    const Wrench on_cc = coil_wrench(cc, [&](const Vec3& x) { return coil_field_B(rr, x); }, about, options);
    const Wrench on_rr = coil_wrench(rr, [&](const Vec3& x) { return coil_field_B(cc, x); }, about, options);
    const double ef = norm(on_cc.force + on_rr.force) / norm(on_cc.force);
    const double et = norm(on_cc.torque + on_rr.torque) / norm(on_cc.torque);
    std::printf("measured: TEAM 20 coil - circular coil, elements across %d along %d per turn %d: "
                "|F12 + F21| / |F| %.1e, torque %.1e (F = %.6e N)\n",
                across, options.along, options.per_turn, ef, et, norm(on_cc.force));
    EXPECT_LT(std::max(ef, et), previous);
    previous = std::max(ef, et);
  }
  EXPECT_LT(previous, 1e-7);
  // A uniform field: no force, torque m x B.
  const Vec3 B{0.1, -0.2, 0.3};
  for (const CoilSource& src : {CoilSource{rr}, CoilSource{cc}, CoilSource{Solenoid{{}, {0, 1, 1}, 0.01, 0.02, 2.0, 10}}}) {
    const Wrench w = coil_wrench(src, [&](const Vec3&) { return B; }, {}, options);
    const Vec3 m = dipole_moment(src, options);
    EXPECT_LT(norm(w.force), 1e-12 * norm(m) * norm(B) / 0.01);
    EXPECT_LT(rel(w.torque, cross(m, B)), 1e-12);
  }
}

// ---------------------------------------------------------------------------
// 7. Poses and validation.

TEST(CoilSources, PosedEvaluationEqualsTheTransformedSource) {
  const Mat3 rot = tilted();
  const Vec3 position{0.1, -0.2, 0.05};
  const std::vector<CoilSource> sources = {CircularLoop{{0.01, 0, 0}, {0, 0, 1}, 0.02, 1.0, 1},
                                           StraightSegment{{0, 0, 0}, {0.03, 0.01, 0}, 2.0, 1},
                                           Arc{{}, {0, 1, 0}, 0.02, {1, 0, 0}, 2.0, 1.0, 1},
                                           Solenoid{{}, {1, 0, 0}, 0.01, 0.03, 1.0, 50},
                                           CircularCoil{{}, {0, 0, 1}, 0.01, 0.02, 0.01, 1.0, 20},
                                           team20_coil(100.0)};
  const Vec3 body_point{0.013, -0.007, 0.021};
  const Vec3 world_point = rot * body_point + position;
  for (const CoilSource& s : sources) {
    EXPECT_EQ(coil_source_error(s), "");
    const Vec3 posed = coil_field_H(s, rot, position, world_point);
    EXPECT_LT(rel(posed, coil_field_H(transformed(s, rot, position), world_point)), 1e-12);
    EXPECT_LT(rel(posed, rot * coil_field_H(s, body_point)), 1e-15);
  }
}

TEST(CoilSources, FiniteEverywhere) {
  // Special points (centres, axes, wires, sheet edges, cuboid edges and
  // corners, corner centres of the rounded coil) and a lattice through all
  // of them: every field is finite.
  const RoundedRectangleCoil rr = team20_coil(1000.0);
  const std::vector<CoilSource> sources = {
      CircularLoop{{}, {0, 0, 1}, 0.02, 1.0, 1},         StraightSegment{{-0.02, 0, 0}, {0.02, 0, 0}, 1.0, 1},
      Arc{{}, {0, 0, 1}, 0.02, {1, 0, 0}, 1.0, 1.0, 1}, Solenoid{{}, {0, 0, 1}, 0.02, 0.04, 1.0, 10},
      CircularCoil{{}, {0, 0, 1}, 0.01, 0.02, 0.04, 1.0, 10}, CircularCoil{{}, {0, 0, 1}, 0.0, 0.02, 0.0, 1.0, 10},
      rr};
  std::vector<Vec3> points = {{0, 0, 0},          {0, 0, 0.02},       {0.02, 0, 0},       {0.02, 0, 0.02},
                              {0.01, 0, 0.02},    {-0.02, 0, 0},      {0.02 * std::cos(1.0), 0.02 * std::sin(1.0), 0},
                              {0.0145, 0.0145, 0.075}, {0.0195, 0.0145, 0.0267}, {0.0375, -0.0145, 0.1233},
                              {0.0195, 0.0, 0.075}, {0.0, 0.0375, 0.075}, {0.0145, 0.0375, 0.1233}};
  for (int i = -4; i <= 4; ++i)
    for (int j = -4; j <= 4; ++j)
      for (int k = -4; k <= 4; ++k) points.push_back({0.005 * i, 0.005 * j, 0.005 * k});
  for (int i = 0; i <= 8; ++i)
    for (int k = 0; k <= 8; ++k) points.push_back({0.0145 + 0.00225 * i + 0.005, 0.0145 * (i % 3 - 1), 0.0267 + 0.012075 * k});
  for (const CoilSource& source : sources)
    for (const Vec3& x : points) {
      const Vec3 h = coil_field_H(source, x);
      EXPECT_TRUE(is_finite(h)) << source.index() << " at " << x.x << " " << x.y << " " << x.z;
    }
}

TEST(CoilSources, InvalidGeometryIsReported) {
  EXPECT_NE(coil_source_error(CircularLoop{{}, {0, 0, 0}, 0.01, 1.0, 1}), "");
  EXPECT_NE(coil_source_error(CircularLoop{{}, {0, 0, 1}, -0.01, 1.0, 1}), "");
  EXPECT_NE(coil_source_error(StraightSegment{{1, 1, 1}, {1, 1, 1}, 1.0, 1}), "");
  EXPECT_NE(coil_source_error(Arc{{}, {0, 0, 1}, 0.01, {0, 0, 2}, 1.0, 1.0, 1}), "");
  EXPECT_NE(coil_source_error(CircularCoil{{}, {0, 0, 1}, 0.02, 0.01, 0.01, 1.0, 1}), "");
  RoundedRectangleCoil bad = team20_coil(1.0);
  bad.width_direction = {0, 0, 1};
  EXPECT_NE(coil_source_error(bad), "");
  bad = team20_coil(1.0);
  bad.quadrature_order = 0;
  EXPECT_NE(coil_source_error(bad), "");
  EXPECT_EQ(ampere_turns(team20_coil(381.0)), 381.0);
}

}  // namespace
}  // namespace odemag
