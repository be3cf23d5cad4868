// Self-checks of the contact-force references (tests/support/contact_references.h)
// against limits, symmetries and independent second methods:
//   (a) sphere next to a dipole: the known axial series, -grad U, the
//       dipole-induced-dipole limit, Kelvin images for mu = inf;
//   (b) two spheres in a uniform field: the mutually induced two-dipole model
//       far apart, chi -> 0, symmetry, Newton's third law, -dW/dd and the
//       angular energy derivative, rotation invariance, the addition theorem,
//       and the bispherical-coordinate solution (mu = inf) at small gaps;
//   (c) coaxial cylinders: Bessel vs elliptic route, direct disc-disc
//       Coulomb quadrature, the dipole-dipole far field;
//   (d) cube: chi -> 0 gives 1/3, the literature value at chi = 1000 and the
//       conducting-cube polarizability for chi -> inf, monotonicity.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <vector>

#include "tests/support/contact_references.h"
#include "tests/support/reference_fields.h"

namespace odemag {
namespace {

namespace ref = reference;

constexpr double kInf = std::numeric_limits<double>::infinity();

double rel(const Vec3& a, const Vec3& b) { return norm(a - b) / std::max(norm(a), norm(b)); }

// Field of a point dipole m at the origin (independent of the header).
Vec3 dipole_H(const Vec3& m, const Vec3& r) {
  const double d = norm(r);
  const Vec3 u = r / d;
  return (1.0 / (4.0 * kPi * d * d * d)) * (3.0 * dot(u, m) * u - m);
}

// ===========================================================================
// (a) Linear sphere next to a point dipole
// ===========================================================================

TEST(SphereNearDipole, AxialForceMatchesKnownSeries) {
  // F = mu0 m^2 / (4 pi D^4) sum gamma_l (l+1)^2 (l+2) (R/D)^(2l+1), attractive.
  const double R = 0.01, m = 1.3;
  for (double chi : {-1.0, -0.5, 0.5, 10.0, 1000.0, kInf})
    for (double D : {1.05 * R, 2.05 * R, 3.0 * R, 10.0 * R}) {
      double sum = 0.0;
      for (int l = 1; l < 20000; ++l) {
        const double mu = 1.0 + chi;
        const double g = std::isinf(chi) ? 1.0 : l * (mu - 1.0) / (l * mu + l + 1.0);
        sum += g * (l + 1.0) * (l + 1.0) * (l + 2.0) * std::pow(R / D, 2 * l + 1);
      }
      const double expected = kMu0 * m * m / (4.0 * kPi * std::pow(D, 4)) * sum;
      const Vec3 F = ref::linear_sphere_force_from_dipole(R, chi, {0, 0, 0}, {0, 0, D}, {0, 0, m});
      EXPECT_NEAR(F.z / expected, 1.0, 1e-12) << chi << " " << D / R;
      EXPECT_EQ(F.z > 0.0, chi > 0.0) << "attracted (paramagnets) or repelled (diamagnets)";
      EXPECT_NEAR(F.x, 0.0, 1e-14 * std::abs(F.z));
      EXPECT_NEAR(F.y, 0.0, 1e-14 * std::abs(F.z));
      // The reversed dipole gives the same force (quadratic in m).
      const Vec3 Fr = ref::linear_sphere_force_from_dipole(R, chi, {0, 0, 0}, {0, 0, D}, {0, 0, -m});
      EXPECT_NEAR(rel(F, Fr), 0.0, 1e-15);
    }
}

TEST(SphereNearDipole, ForceIsMinusEnergyGradient) {
  const double R = 0.02, chi = 300.0;
  const Vec3 centre{0.001, -0.002, 0.003};
  const Vec3 m = 0.7 * normalized(Vec3{0.3, -0.5, 0.8});
  for (const Vec3& offset : {Vec3{0.3 * R, -0.2 * R, 2.05 * R}, Vec3{1.2 * R, 0.4 * R, -0.5 * R},
                             Vec3{0, 0, 1.1 * R}}) {
    const Vec3 p = centre + offset;
    const Vec3 F = ref::linear_sphere_force_from_dipole(R, chi, centre, p, m);
    // Fourth-order central differences of U with respect to the sphere centre.
    const double h = 1e-4 * R;
    Vec3 g;
    for (int i = 0; i < 3; ++i) {
      Vec3 e;
      e[i] = h;
      auto U = [&](double s) { return ref::linear_sphere_reaction_energy(R, chi, centre + s * e, p, m); };
      g[i] = (-U(2) + 8 * U(1) - 8 * U(-1) + U(-2)) / (12 * h);
    }
    EXPECT_LT(rel(F, -1.0 * g), 1e-8) << offset.x << " " << offset.y << " " << offset.z;
    // Attractive on average: the force points towards the dipole side.
    EXPECT_GT(dot(F, offset), 0.0);
  }
}

TEST(SphereNearDipole, FarAwayReducesToInducedDipole) {
  // l = 1 only: U1 = -(mu0/2) 4 pi R^3 gamma_1 |H_m(centre)|^2, any orientation;
  // the full series differs by O((R/D)^2).
  const double R = 0.01, chi = 50.0;
  const double g1 = (chi) / (chi + 3.0);
  const Vec3 m = normalized(Vec3{0.2, 0.9, -0.4});
  for (double D : {30.0 * R, 100.0 * R}) {
    const Vec3 p = D * normalized(Vec3{0.3, -0.1, 1.0});
    auto U1 = [&](const Vec3& c) {
      const Vec3 H = dipole_H(m, c - p);
      return -0.5 * kMu0 * 4.0 * kPi * R * R * R * g1 * dot(H, H);
    };
    const double h = 1e-3 * R;
    Vec3 F1;
    for (int i = 0; i < 3; ++i) {
      Vec3 e;
      e[i] = h;
      F1[i] = -(-U1(2.0 * e) + 8 * U1(e) - 8 * U1(-1.0 * e) + U1(-2.0 * e)) / (12 * h);
    }
    const Vec3 F = ref::linear_sphere_force_from_dipole(R, chi, {0, 0, 0}, p, m);
    EXPECT_LT(rel(F, F1), 6.0 * (R / D) * (R / D)) << D / R;
    // l = 2 / l = 1 energy: (gamma_2/gamma_1) (6 (m.u)^2 + 3 m^2) / (3 (m.u)^2 + m^2) (R/D)^2 <= 3 (R/D)^2.
    EXPECT_NEAR(ref::linear_sphere_reaction_energy(R, chi, {0, 0, 0}, p, m) / U1({0, 0, 0}), 1.0,
                3.0 * (R / D) * (R / D));
  }
}

TEST(SphereNearDipole, InfiniteChiMatchesKelvinImages) {
  // mu = inf: the sphere is an equipotential with no net charge, i.e. an
  // isolated neutral conductor. The dipole as charges +-q (q delta = |m|),
  // each with its Kelvin image -q R/r at R^2/r^2 r plus +q R/r at the centre;
  // force on the sphere = -force on the source charges. Finite delta:
  // Richardson over delta, delta/2, delta/4 removes the delta^2, delta^4 terms.
  const double R = 0.01;
  auto image_force = [&](const Vec3& p, const Vec3& m, double delta) {
    const Vec3 mh = normalized(m);
    const double q = norm(m) / delta;
    const Vec3 pos[2] = {p + 0.5 * delta * mh, p - 0.5 * delta * mh};
    const double qs[2] = {q, -q};
    Vec3 F;
    for (int i = 0; i < 2; ++i)
      for (int j = 0; j < 2; ++j) {
        const double r = norm(pos[j]);
        const Vec3 img[2] = {(R * R / (r * r)) * pos[j], Vec3{0, 0, 0}};
        const double qi[2] = {-qs[j] * R / r, qs[j] * R / r};
        for (int k = 0; k < 2; ++k) {
          const Vec3 d = pos[i] - img[k];
          const double dn = norm(d);
          F += (kMu0 * qs[i] * qi[k] / (4.0 * kPi * dn * dn * dn)) * d;
        }
      }
    return -1.0 * F;
  };
  for (double D : {2.05 * R, 3.0 * R, 1.5 * R})
    for (const Vec3& dir : {Vec3{0, 0, 1}, normalized(Vec3{0.3, -0.5, 0.8}), Vec3{1, 0, 0}}) {
      const Vec3 p = D * normalized(Vec3{0.2, -0.1, 1.0});
      const Vec3 m = 0.9 * dir;
      const double delta = 0.02 * R;
      const Vec3 f1 = image_force(p, m, delta), f2 = image_force(p, m, delta / 2),
                 f4 = image_force(p, m, delta / 4);
      const Vec3 r12 = (4.0 * f2 - f1) / 3.0, r24 = (4.0 * f4 - f2) / 3.0;
      const Vec3 Fimg = (16.0 * r24 - r12) / 15.0;
      const Vec3 F = ref::linear_sphere_force_from_dipole(R, kInf, {0, 0, 0}, p, m);
      EXPECT_LT(rel(F, Fimg), 1e-9) << D / R << " " << dir.x << " " << dir.z;
    }
}

TEST(SphereNearDipole, ZeroSusceptibilityGivesNoForce) {
  const Vec3 F = ref::linear_sphere_force_from_dipole(0.01, 0.0, {0, 0, 0}, {0, 0.005, 0.02}, {1, 0, 0});
  EXPECT_EQ(norm(F), 0.0);
  // Small chi: linear in chi (gamma_l = l chi / (2l+1) + O(chi^2)).
  const Vec3 a = ref::linear_sphere_force_from_dipole(0.01, 1e-6, {0, 0, 0}, {0, 0.005, 0.02}, {1, 0, 0});
  const Vec3 b = ref::linear_sphere_force_from_dipole(0.01, 2e-6, {0, 0, 0}, {0, 0.005, 0.02}, {1, 0, 0});
  EXPECT_NEAR(norm(b) / norm(a), 2.0, 1e-5);
}

// ===========================================================================
// (b) Two linear spheres in a uniform field
// ===========================================================================

// Non-Condon-Shortley associated Legendre P_l^m(x), m = 0, 1.
double assoc_legendre(int l, int m, double x) {
  double pmm = m == 0 ? 1.0 : std::sqrt(1.0 - x * x);
  if (l == m) return pmm;
  double p1 = x * (2 * m + 1) * pmm, p0 = pmm;
  for (int k = m + 1; k < l; ++k) {
    const double p2 = ((2.0 * k + 1.0) * x * p1 - (k + m) * p0) / (k - m + 1.0);
    p0 = p1;
    p1 = p2;
  }
  return p1;
}

// Solid harmonics with cos(m phi).
double exterior_harmonic(int n, int m, const Vec3& r) {
  const double d = norm(r), rho = std::hypot(r.x, r.y);
  const double c = m == 0 ? 1.0 : (rho > 0 ? r.x / rho : 1.0);
  return std::pow(d, -(n + 1)) * assoc_legendre(n, m, r.z / d) * c;
}
double interior_harmonic(int l, int m, const Vec3& r) {
  const double d = norm(r), rho = std::hypot(r.x, r.y);
  const double c = m == 0 ? 1.0 : (rho > 0 ? r.x / rho : 1.0);
  return std::pow(d, l) * assoc_legendre(l, m, r.z / d) * c;
}

TEST(TwoSpheres, CoaxialAdditionTheorem) {
  // E_n^m(r -+ d z^) = sum_l s C(l,n) I_l^m(r) / d^(l+n+1), s = (-1)^(n+m) for
  // r - d z^ and (-1)^(l+m) for r + d z^, C = (l+n)! / ((l+m)! (n-m)!).
  const double d = 1.0;
  for (int m = 0; m <= 1; ++m)
    for (int n = std::max(1, m); n <= 6; ++n)
      for (const Vec3& r : {Vec3{0.2, 0.1, 0.3}, Vec3{-0.25, 0.05, -0.2}, Vec3{0.1, -0.3, 0.05}})
        for (int sgn = -1; sgn <= 1; sgn += 2) {
          const double direct = exterior_harmonic(n, m, r - (sgn * d) * Vec3{0, 0, 1});
          double series = 0.0;
          for (int l = m; l < 200; ++l) {
            const double C = std::exp(std::lgamma(l + n + 1.0) - std::lgamma(l + m + 1.0) -
                                      std::lgamma(n - m + 1.0));
            const int p = sgn > 0 ? n + m : l + m;
            series += (p % 2 ? -1.0 : 1.0) * C * interior_harmonic(l, m, r) / std::pow(d, l + n + 1);
          }
          EXPECT_NEAR(series, direct, 1e-12 * std::abs(direct) + 1e-13) << m << " " << n << " " << sgn;
        }
}

TEST(TwoSpheres, FarApartMatchesMutuallyInducedDipoles) {
  // The exact force differs from the two-dipole model by the induced
  // quadrupoles: relative O((R/d)^5) (measured: about 12 (R/d)^5 at chi = 1000).
  const double R1 = 0.01, R2 = 0.007;
  for (double chi : {3.0, 1000.0})
    for (double d : {10.0 * R1, 20.0 * R1, 40.0 * R1})
      for (const Vec3& H : {Vec3{0, 0, 1000}, Vec3{1000, 0, 0}, Vec3{300, -400, 800}}) {
        const Vec3 c1{0, 0, 0}, c2{0, 0, d};
        const ref::TwoSphereResult ex = ref::two_linear_spheres_in_uniform_field(R1, chi, R2, chi, c1, c2, H);
        const ref::TwoSphereResult dp = ref::two_sphere_dipole_model(R1, chi, R2, chi, c1, c2, H);
        const double eps = std::pow(R1 / d, 5);
        EXPECT_LT(rel(ex.force_on_2, dp.force_on_2), 20.0 * eps) << chi << " " << d / R1;
        EXPECT_LT(rel(ex.moment_1, dp.moment_1), 2.0 * eps * R1 / d) << chi << " " << d / R1;
        EXPECT_LT(rel(ex.moment_2, dp.moment_2), 2.0 * eps * R1 / d) << chi << " " << d / R1;
      }
}

TEST(TwoSpheres, SingleSphereMomentIsClausiusMossotti) {
  // At large distance each moment tends to 4 pi R^3 (mu-1)/(mu+2) H0.
  const double R = 0.01, chi = 7.0;
  const Vec3 H{100, 200, -300};
  const ref::TwoSphereResult r =
      ref::two_linear_spheres_in_uniform_field(R, chi, R, chi, {0, 0, 0}, {1.0, 0, 0}, H);
  const Vec3 cm = (4.0 * kPi * R * R * R * chi / (chi + 3.0)) * H;
  EXPECT_LT(rel(r.moment_1, cm), 1e-5);
  EXPECT_LT(rel(r.moment_2, cm), 1e-5);
}

TEST(TwoSpheres, ZeroSusceptibilityGivesNoForce) {
  const ref::TwoSphereResult r = ref::two_linear_spheres_in_uniform_field(
      0.01, 0.0, 0.02, 0.0, {0, 0, 0}, {0.031, 0, 0.001}, {300, 200, 100});
  EXPECT_EQ(norm(r.force_on_2), 0.0);
  EXPECT_EQ(norm(r.moment_1), 0.0);
  EXPECT_EQ(norm(r.moment_2), 0.0);
  // Small chi: force ~ chi^2 (one induced moment in the field of the other).
  const Vec3 a = ref::two_linear_spheres_in_uniform_field(0.01, 1e-5, 0.02, 1e-5, {0, 0, 0},
                                                          {0.031, 0, 0.001}, {300, 200, 100}).force_on_2;
  const Vec3 b = ref::two_linear_spheres_in_uniform_field(0.01, 2e-5, 0.02, 2e-5, {0, 0, 0},
                                                          {0.031, 0, 0.001}, {300, 200, 100}).force_on_2;
  EXPECT_NEAR(norm(b) / norm(a), 4.0, 1e-3);
}

TEST(TwoSpheres, SymmetryAndNewtonsThirdLaw) {
  const double R = 0.01;
  for (double chi : {10.0, 1e4, kInf})
    for (double gap : {0.1, 0.5}) {
      const double d = 2.0 * R + gap * R;
      const Vec3 c1{0.001, 0.002, -0.003};
      const Vec3 e = normalized(Vec3{0.2, 0.5, -0.7});
      const Vec3 c2 = c1 + d * e;
      // Axial field: equal moments along the axis, axial attractive force.
      const ref::TwoSphereResult a = ref::two_linear_spheres_in_uniform_field(R, chi, R, chi, c1, c2, 1e3 * e);
      EXPECT_LT(rel(a.moment_1, a.moment_2), 1e-12);
      EXPECT_LT(norm(cross(a.force_on_2, e)), 1e-12 * norm(a.force_on_2));
      EXPECT_LT(dot(a.force_on_2, e), 0.0);
      // Transverse field: equal moments, repulsive axial force.
      const Vec3 t = 1e3 * normalized(cross(e, Vec3{1, 0, 0}));
      const ref::TwoSphereResult b = ref::two_linear_spheres_in_uniform_field(R, chi, R, chi, c1, c2, t);
      EXPECT_LT(rel(b.moment_1, b.moment_2), 1e-12);
      EXPECT_LT(norm(cross(b.force_on_2, e)), 1e-12 * norm(b.force_on_2));
      EXPECT_GT(dot(b.force_on_2, e), 0.0);
      // Unequal spheres, oblique field: swapping the roles gives -F.
      const Vec3 H{300, -500, 700};
      const double d2 = 1.4 * R + 0.4 * gap * R;
      const ref::TwoSphereResult u = ref::two_linear_spheres_in_uniform_field(R, chi, 0.4 * R, 0.3 * chi, c1, c1 + d2 * e, H);
      const ref::TwoSphereResult v = ref::two_linear_spheres_in_uniform_field(0.4 * R, 0.3 * chi, R, chi, c1 + d2 * e, c1, H);
      EXPECT_LT(rel(u.force_on_2, -1.0 * v.force_on_2), 1e-12);
      EXPECT_LT(rel(u.moment_1, v.moment_2), 1e-12);
      EXPECT_LT(rel(u.moment_2, v.moment_1), 1e-12);
    }
}

TEST(TwoSpheres, ForceIsMinusEnergyDerivative) {
  // W = -(mu0/2) H0 . (m1 + m2) (linear bodies, sources fixed at infinity):
  // F_axial = -dW/dd, F_perp = -(1/d) dW/dtheta (rotating the line of centres
  // about centre 1 towards the transverse field direction).
  const double R1 = 0.01, R2 = 0.006, chi1 = 500.0, chi2 = 20.0;
  for (double gap : {0.3, 1.0})
    for (const Vec3& H : {Vec3{0, 0, 1000}, Vec3{800, 0, 0}, Vec3{600, 0, 800}}) {
      const double d = R1 + R2 + gap * R2;
      auto W = [&](double dd, double theta) {
        const Vec3 c2{dd * std::sin(theta), 0, dd * std::cos(theta)};
        const ref::TwoSphereResult r = ref::two_linear_spheres_in_uniform_field(R1, chi1, R2, chi2, {0, 0, 0}, c2, H);
        return -0.5 * kMu0 * dot(H, r.moment_1 + r.moment_2);
      };
      const ref::TwoSphereResult r = ref::two_linear_spheres_in_uniform_field(R1, chi1, R2, chi2, {0, 0, 0}, {0, 0, d}, H);
      const double h = 1e-3 * R2, ht = h / d;
      const double dWdd = (-W(d + 2 * h, 0) + 8 * W(d + h, 0) - 8 * W(d - h, 0) + W(d - 2 * h, 0)) / (12 * h);
      const double dWdt = (-W(d, 2 * ht) + 8 * W(d, ht) - 8 * W(d, -ht) + W(d, -2 * ht)) / (12 * ht);
      const double scale = norm(r.force_on_2);
      EXPECT_NEAR(r.force_on_2.z, -dWdd, 1e-7 * scale) << gap << " " << H.x;
      EXPECT_NEAR(r.force_on_2.x, -dWdt / d, 1e-7 * scale) << gap << " " << H.x;
      EXPECT_NEAR(r.force_on_2.y, 0.0, 1e-14 * scale);
    }
}

TEST(TwoSpheres, RotationInvariance) {
  const double R1 = 0.01, R2 = 0.013, chi = 200.0;
  const Vec3 H{200, -300, 500};
  const Mat3 Q = rotation_from_quaternion(0.9, 0.2, -0.3, 0.25);
  const Vec3 c1{0.01, 0.02, 0.0}, c2 = c1 + Vec3{0.003, -0.022, 0.013};  // gap 0.25 R1
  const ref::TwoSphereResult a = ref::two_linear_spheres_in_uniform_field(R1, chi, R2, chi, c1, c2, H);
  const ref::TwoSphereResult b =
      ref::two_linear_spheres_in_uniform_field(R1, chi, R2, chi, Q * c1, Q * c2, Q * H);
  EXPECT_LT(rel(Q * a.force_on_2, b.force_on_2), 1e-12);
  EXPECT_LT(rel(Q * a.moment_1, b.moment_1), 1e-12);
  EXPECT_LT(rel(Q * a.moment_2, b.moment_2), 1e-12);
}

TEST(TwoSpheres, MatchesBisphericalSolutionForInfiniteChi) {
  // Independent method (bispherical coordinates, closed-form series / 1D
  // quadrature), equal spheres, mu = inf, down to gaps of 0.05 R and below.
  const double R = 0.01, H = 1000.0;
  for (double gap : {0.02, 0.05, 0.1, 0.5, 2.0, 4.0}) {
    const double d = 2.0 * R + gap * R;
    const ref::TwoSphereResult a = ref::two_linear_spheres_in_uniform_field(R, kInf, R, kInf, {0, 0, 0}, {0, 0, d}, {0, 0, H});
    const ref::TwoSphereResult t = ref::two_linear_spheres_in_uniform_field(R, kInf, R, kInf, {0, 0, 0}, {0, 0, d}, {H, 0, 0});
    ASSERT_GT(a.orders, 0);
    ASSERT_GT(t.orders, 0);
    EXPECT_NEAR(a.force_on_2.z / ref::equal_infinite_mu_spheres_axial_force(R, d, H), 1.0, 1e-10) << gap;
    EXPECT_NEAR(t.force_on_2.z / ref::equal_infinite_mu_spheres_transverse_force(R, d, H), 1.0, 1e-10) << gap;
  }
}

TEST(TwoSpheres, ConvergesAtSmallGapsForHighChi) {
  // Gap 0.05 min(R), chi up to 1e4, radius ratios 1 and 1/3 (L = 160, 320; a
  // ratio of 1/10 still converges, at L = 640, 1.4 s): a converged answer
  // (not NaN), and chi = 1e4 close to chi = inf (the gap field saturates).
  const double R = 0.01;
  for (double ratio : {1.0, 1.0 / 3.0})
    for (double chi : {1e4}) {
      const double R2 = ratio * R, d = R + R2 + 0.05 * R2;
      const Vec3 H{500, 0, 800};
      const ref::TwoSphereResult r = ref::two_linear_spheres_in_uniform_field(R, chi, R2, chi, {0, 0, 0}, {0, 0, d}, H);
      ASSERT_GT(r.orders, 0) << ratio << " " << chi;
      EXPECT_TRUE(is_finite(r.force_on_2));
      const ref::TwoSphereResult q = ref::two_linear_spheres_in_uniform_field(R, kInf, R2, kInf, {0, 0, 0}, {0, 0, d}, H);
      EXPECT_LT(rel(r.force_on_2, q.force_on_2), 20.0 / chi) << ratio << " " << chi;
    }
}

// ===========================================================================
// (c) Coaxial cylinders
// ===========================================================================

TEST(CoaxialCylinders, BesselAndEllipticRoutesAgree) {
  const double a = 0.005;
  for (double g : {0.0, 1e-5, 1e-4, 1e-3, 2e-3, 0.005, 0.02, 0.2})
    for (const auto& LL : {std::pair{0.01, 0.01}, std::pair{0.002, 0.03}}) {
      const double fb = ref::coaxial_cylinder_force(a, LL.first, LL.second, 1e6, 8e5, g);
      const double fe = ref::coaxial_cylinder_force_elliptic(a, LL.first, LL.second, 1e6, 8e5, g);
      EXPECT_LT(fb, 0.0);
      EXPECT_NEAR(fb / fe, 1.0, 1e-10) << g << " " << LL.first;
    }
}

TEST(CoaxialCylinders, MatchesDirectDiscQuadrature) {
  // Sum of the four end-face pairs, each by direct Coulomb quadrature.
  const double a = 0.005, L1 = 0.01, L2 = 0.007, M1 = 1e6, M2 = 9e5, g = 0.001;
  // faces: +M1 at 0, -M1 at -L1; -M2 at g, +M2 at g + L2
  const double F = ref::coaxial_disc_force_direct(a, M1, -M2, g) +
                   ref::coaxial_disc_force_direct(a, M1, M2, g + L2) +
                   ref::coaxial_disc_force_direct(a, -M1, -M2, g + L1) +
                   ref::coaxial_disc_force_direct(a, -M1, M2, g + L1 + L2);
  EXPECT_NEAR(ref::coaxial_cylinder_force(a, L1, L2, M1, M2, g) / F, 1.0, 1e-10);
}

TEST(CoaxialCylinders, FarFieldIsDipoleDipole) {
  // F -> -3 mu0 m1 m2 / (2 pi D^4), D the centre distance; the first
  // correction (octupole, a symmetric body has no quadrupole) is O((size/D)^2).
  const double a = 0.005, L1 = 0.01, L2 = 0.006, M1 = 1e6, M2 = 7e5;
  const double m1 = M1 * kPi * a * a * L1, m2 = M2 * kPi * a * a * L2;
  double prev = 0.0;
  for (double D : {0.2, 0.4, 0.8}) {
    const double g = D - 0.5 * (L1 + L2);
    const double F = ref::coaxial_cylinder_force(a, L1, L2, M1, M2, g);
    const double Fd = -3.0 * kMu0 * m1 * m2 / (2.0 * kPi * std::pow(D, 4));
    const double dev = F / Fd - 1.0;
    EXPECT_LT(std::abs(dev), 0.5 * (a * a + L1 * L1) / (D * D)) << D;
    if (prev != 0.0) {
      EXPECT_NEAR(prev / dev, 4.0, 0.1) << D;  // ~ D^-2
    }
    prev = dev;
  }
}

TEST(CoaxialCylinders, SignsAndSymmetry) {
  const double a = 0.005;
  const double f = ref::coaxial_cylinder_force(a, 0.01, 0.004, 1e6, 5e5, 0.001);
  EXPECT_LT(f, 0.0);  // parallel: attraction
  EXPECT_NEAR(ref::coaxial_cylinder_force(a, 0.01, 0.004, 1e6, -5e5, 0.001), -f, 1e-14 * -f);
  EXPECT_NEAR(ref::coaxial_cylinder_force(a, 0.004, 0.01, 5e5, 1e6, 0.001), f, 1e-12 * -f);
}

// ===========================================================================
// (d) Cube magnetometric demagnetizing factor
// ===========================================================================

TEST(CubeDemag, RectangleFieldMatchesQuadrature) {
  // The closed-form panel fields against Gauss-Legendre quadrature of the
  // Coulomb integral (points well away from the panel).
  const double u1 = -0.2, u2 = 0.3, v1 = 0.1, v2 = 0.25;
  std::vector<double> gx, gw;
  const int n = 40;
  reference::gauss_legendre(n, gx, gw);
  for (const Vec3& r : {Vec3{0.05, 0.2, 0.3}, Vec3{-0.6, 0.4, -0.25}, Vec3{0.9, -0.3, 0.1}}) {
    Vec3 H;  // (u, v, w) components
    for (int i = 0; i < n; ++i)
      for (int j = 0; j < n; ++j) {
        const double u = 0.5 * (u1 + u2) + 0.5 * (u2 - u1) * gx[i];
        const double v = 0.5 * (v1 + v2) + 0.5 * (v2 - v1) * gx[j];
        const Vec3 d{r.x - u, r.y - v, r.z};
        const double dn = norm(d);
        H += (gw[i] * gw[j] * 0.25 * (u2 - u1) * (v2 - v1) / (4.0 * kPi * dn * dn * dn)) * d;
      }
    EXPECT_NEAR(ref::detail::rect_field_normal(u1, u2, v1, v2, r.z, r.x, r.y), H.z, 1e-12);
    EXPECT_NEAR(ref::detail::rect_field_tangential(u1, u2, v1, v2, r.z, r.x, r.y), H.x, 1e-12);
    EXPECT_NEAR(ref::detail::rect_field_tangential(v1, v2, u1, u2, r.z, r.y, r.x), H.y, 1e-12);
  }
}

TEST(CubeDemag, Limits) {
  const std::vector<ref::CubeDemagEstimate> e =
      ref::cube_magnetometric_demag_factor_estimates({0.0, 1000.0, kInf});
  // chi -> 0: the volume average of the demagnetizing tensor, 1/3.
  EXPECT_NEAR(e[0].value, 1.0 / 3.0, 3e-5);
  EXPECT_LT(std::abs(e[0].value - 1.0 / 3.0), e[0].error);
  // chi = 1000: Chen, Pardo & Sanchez's table gives 0.2746 (4 digits).
  EXPECT_NEAR(e[1].value, 0.2746, 1e-4);
  // chi -> inf: mu = inf cube = conducting cube, polarizability
  // alpha = 3.6442 V (e.g. Hubbard & Douglas), N_m = 1 / 3.6442 = 0.274409.
  EXPECT_NEAR(e[2].value, 1.0 / 3.6442, 3e-5);
  EXPECT_LT(std::abs(e[2].value - 1.0 / 3.6442), e[2].error);
  for (const ref::CubeDemagEstimate& x : e) EXPECT_LT(x.error, 1e-4);
  // Monotone in chi (single level, n = 16).
  const double a = ref::cube_magnetometric_demag_factor(0.0, 16),
               b = ref::cube_magnetometric_demag_factor(10.0, 16),
               c = ref::cube_magnetometric_demag_factor(1000.0, 16),
               d = ref::cube_magnetometric_demag_factor(kInf, 16);
  EXPECT_GT(a, b);
  EXPECT_GT(b, c);
  EXPECT_GT(c, d);
  EXPECT_GT(d, 0.27);
}

}  // namespace
}  // namespace odemag
