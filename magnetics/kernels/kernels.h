// The dipole interaction kernel: one place for the field, force and torque
// between two cells (docs/model.md "Effective field", "Forces and torques";
// docs/hard-cases.md "Overlapping cells: the bounded core"; docs/model.md
// "Inter-body kernel and overlapping cells" derives the overlap form).
//
// The field of a moment mu at offset r is H = T(r) mu with T the Hessian of
// g(r) = 1 / (4 pi |r|):  T = A(r) I + B(r) r r^T,
//   A = -1/(4 pi r^3),  B = 3/(4 pi r^5)          (exact point dipole, = -D(r)).
// The force on moment b from moment a (r = x_b - x_a) is
//   F_b = mu0 [ B ((r.mu_a) mu_b + (r.mu_b) mu_a + (mu_a.mu_b) r) + C (r.mu_a)(r.mu_b) r ],
// with C = B'(r)/r = -15/(4 pi r^7); A'(r)/r = B for every radial g.
//
// Overlap: below the contact distance s (sum of the two cells' contact radii,
// magnetics/cells/cells.h) g is
// replaced by the even polynomial c0 + c1 r^2 + c2 r^4 + c3 r^6 that matches
// g, g', g'', g''' at s. Then A, B and C are polynomials: fields and forces
// are bounded, continuous at s, exactly dipolar for r >= s, and still the
// derivatives of one pair energy (so F = -grad U holds everywhere).
#pragma once

#include "odemag/constants.h"
#include "magnetics/kernels/hd.h"
#include "odemag/vec3.h"

namespace odemag {

template <class T>
struct DipoleCoefficientsT {
  T A;  // isotropic part of T
  T B;  // r r^T part of T
  T C;  // B'(r) / r, for the force
};
using DipoleCoefficients = DipoleCoefficientsT<double>;

// The coefficients from r^2 and inv_r = 1 / r_e, r_e^2 = max(r^2, s^2): with
// q = r^2 / r_e^2 the core polynomials become the dipole coefficients at q = 1,
// i.e. wherever r >= s: A = -1/(4 pi r^3), B = 3/(4 pi r^5), and C is the same
// expression in both regions. Branch-free, for scalars and SIMD vectors alike
// (magnetics/kernels/simd.h).
template <class T>
ODEMAG_HD DipoleCoefficientsT<T> dipole_coefficients_from(const T& r2, const T& inv_r) {
  const double k = 1.0 / (4.0 * kPi);
  const T inv_r2 = inv_r * inv_r;
  const T inv_r3 = inv_r2 * inv_r;
  const T inv_r5 = inv_r3 * inv_r2;
  const T q = r2 * inv_r2;
  return {(k * inv_r3) * (T(-35.0 / 8.0) + q * (T(21.0 / 4.0) - q * T(15.0 / 8.0))),
          (k * inv_r5) * (T(21.0 / 2.0) - q * T(15.0 / 2.0)), (-15.0 * k) * (inv_r5 * inv_r2)};
}

// s2 = s^2, the squared contact distance; s2 = 0 gives the exact point dipole.
ODEMAG_HD DipoleCoefficients dipole_coefficients(double r2, double s2) {
  return dipole_coefficients_from(r2, 1.0 / sqrt(r2 > s2 ? r2 : s2));
}

// Field H (A/m) at offset r from a moment mu (A m^2): T(r) mu, with the
// pair's coefficients c at r.
ODEMAG_HD Vec3 dipole_field(const DipoleCoefficients& c, const Vec3& r, const Vec3& mu) {
  return c.A * mu + (c.B * dot(r, mu)) * r;
}
ODEMAG_HD Vec3 dipole_field(const Vec3& r, const Vec3& mu, double s2) {
  return dipole_field(dipole_coefficients(dot(r, r), s2), r, mu);
}

// Force (N) on moment mu_b from moment mu_a, r = x_b - x_a.
ODEMAG_HD Vec3 dipole_force(const DipoleCoefficients& c, const Vec3& r, const Vec3& mu_a, const Vec3& mu_b) {
  const double ra = dot(r, mu_a), rb = dot(r, mu_b);
  return kMu0 * (c.B * (ra * mu_b + rb * mu_a + dot(mu_a, mu_b) * r) + (c.C * ra * rb) * r);
}
ODEMAG_HD Vec3 dipole_force(const Vec3& r, const Vec3& mu_a, const Vec3& mu_b, double s2) {
  return dipole_force(dipole_coefficients(dot(r, r), s2), r, mu_a, mu_b);
}

// Torque (N m) about a body's centre of mass of one of its cells at offset
// r_from_centre, with force F on it, moment mu and field H there from the
// other bodies and H_E: tau = r x F + mu0 mu x H (docs/model.md "Forces and torques").
ODEMAG_HD Vec3 cell_torque(const Vec3& r_from_centre, const Vec3& F, const Vec3& mu, const Vec3& H) {
  return cross(r_from_centre, F) + kMu0 * cross(mu, H);
}

// Interaction energy (J) of the pair: U = -mu0 mu_b . T(r) mu_a.
ODEMAG_HD double dipole_energy(const Vec3& r, const Vec3& mu_a, const Vec3& mu_b, double s2) {
  return -kMu0 * dot(mu_b, dipole_field(r, mu_a, s2));
}

// The six independent components (xx, xy, xz, yy, yz, zz) of T(r).
ODEMAG_HD void dipole_tensor(const Vec3& r, double s2, double* t) {
  const DipoleCoefficients c = dipole_coefficients(dot(r, r), s2);
  t[0] = c.A + c.B * r.x * r.x;
  t[1] = c.B * r.x * r.y;
  t[2] = c.B * r.x * r.z;
  t[3] = c.A + c.B * r.y * r.y;
  t[4] = c.B * r.y * r.z;
  t[5] = c.A + c.B * r.z * r.z;
}

ODEMAG_HD Vec3 symmetric_times(const double* t, const Vec3& v) {
  return {t[0] * v.x + t[1] * v.y + t[2] * v.z, t[1] * v.x + t[3] * v.y + t[4] * v.z,
          t[2] * v.x + t[4] * v.y + t[5] * v.z};
}

}  // namespace odemag
