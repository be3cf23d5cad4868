// The field of a run of source cells at one target through the dipole kernel
// (magnetics/kernels/kernels.h): the inner loop of every O(N^2) field sum of the CPU
// backend and of the near part of the far-field tree (magnetics/relax/far_field.h).
#pragma once

#include "magnetics/kernels/kernels.h"
#include "magnetics/kernels/simd.h"
#include "odemag/vec3.h"

namespace odemag {

// Source cells as structure of arrays: position, contact radius, moment
// mu = M V, and (optional) the body of each cell as a double.
struct SourceArrays {
  const double* x;
  const double* y;
  const double* z;
  const double* radius;
  const double* mx;
  const double* my;
  const double* mz;
  const double* body = nullptr;
};

// The pair loop, written once: field (A/m) at target t of sources [j0, j1),
// each pair through the kernel with contact distance target_radius + source
// radius, and, when WithForce, the force (N) on the target's moment mt,
// F = mu0 [B ((r.mu_a) mu_b + (r.mu_b) mu_a + (mu_a.mu_b) r) + C (r.mu_a)(r.mu_b) r]
// (magnetics/kernels/kernels.h), mu_a the source, mu_b the target. SkipSameBody:
// sources whose body equals target_body add nothing (their pairs are the
// intra-body sum's).
struct FieldAndForce {
  Vec3 field, force;
};

template <bool WithForce, bool SkipSameBody>
inline FieldAndForce sum_pairs(const SourceArrays& s, int j0, int j1, const Vec3& t, const Vec3& mt,
                               double target_radius, double target_body) {
  const double* __restrict x = s.x;
  const double* __restrict y = s.y;
  const double* __restrict z = s.z;
  const double* __restrict r = s.radius;
  const double* __restrict mx = s.mx;
  const double* __restrict my = s.my;
  const double* __restrict mz = s.mz;
#if ODEMAG_HAVE_SIMD
  SimdD hx, hy, hz, fx, fy, fz;
  const SimdD bx(mt.x), by(mt.y), bz(mt.z);
  for (int j = j0; j < j1; j += kSimdWidth) {
    const int count = j1 - j < kSimdWidth ? j1 - j : kSimdWidth;
    const SimdD dx = SimdD(t.x) - SimdD::load(x + j, count), dy = SimdD(t.y) - SimdD::load(y + j, count),
                dz = SimdD(t.z) - SimdD::load(z + j, count);
    const SimdD contact = SimdD(target_radius) + SimdD::load(r + j, count);
    const SimdD r2 = dx * dx + dy * dy + dz * dz;
    DipoleCoefficientsT<SimdD> c = dipole_coefficients_from(r2, inverse_sqrt(max(r2, contact * contact)));
    if constexpr (SkipSameBody) {
      const SimdD b = SimdD::load(s.body + j, count), tb(target_body);
      c.A = zero_where_equal(c.A, b, tb);
      c.B = zero_where_equal(c.B, b, tb);
    }
    // Lanes past the end hold zero moments, so they add nothing.
    const SimdD ax = SimdD::load(mx + j, count), ay = SimdD::load(my + j, count), az = SimdD::load(mz + j, count);
    const SimdD ra = dx * ax + dy * ay + dz * az;
    const SimdD rm = c.B * ra;
    hx += c.A * ax + rm * dx;
    hy += c.A * ay + rm * dy;
    hz += c.A * az + rm * dz;
    if constexpr (WithForce) {
      const SimdD rb = dx * bx + dy * by + dz * bz;
      const SimdD radial = c.B * (ax * bx + ay * by + az * bz) + c.C * ra * rb;
      fx += c.B * (ra * bx + rb * ax) + radial * dx;
      fy += c.B * (ra * by + rb * ay) + radial * dy;
      fz += c.B * (ra * bz + rb * az) + radial * dz;
    }
  }
  FieldAndForce out{{hx.sum(), hy.sum(), hz.sum()}, {}};
  if constexpr (WithForce) out.force = kMu0 * Vec3{fx.sum(), fy.sum(), fz.sum()};
  return out;
#else
  double hx = 0, hy = 0, hz = 0, fx = 0, fy = 0, fz = 0;
#pragma omp simd reduction(+ : hx, hy, hz, fx, fy, fz)
  for (int j = j0; j < j1; ++j) {
    const double dx = t.x - x[j], dy = t.y - y[j], dz = t.z - z[j];
    const double contact = target_radius + r[j];
    DipoleCoefficients c = dipole_coefficients(dx * dx + dy * dy + dz * dz, contact * contact);
    if constexpr (SkipSameBody) {
      const double keep = s.body[j] != target_body ? 1.0 : 0.0;
      c.A *= keep;
      c.B *= keep;
    }
    const double ra = dx * mx[j] + dy * my[j] + dz * mz[j];
    const double rm = c.B * ra;
    hx += c.A * mx[j] + rm * dx;
    hy += c.A * my[j] + rm * dy;
    hz += c.A * mz[j] + rm * dz;
    if constexpr (WithForce) {
      const double rb = dx * mt.x + dy * mt.y + dz * mt.z;
      const double radial = c.B * (mx[j] * mt.x + my[j] * mt.y + mz[j] * mt.z) + c.C * ra * rb;
      fx += c.B * (ra * mt.x + rb * mx[j]) + radial * dx;
      fy += c.B * (ra * mt.y + rb * my[j]) + radial * dy;
      fz += c.B * (ra * mt.z + rb * mz[j]) + radial * dz;
    }
  }
  FieldAndForce out{{hx, hy, hz}, {}};
  if constexpr (WithForce) out.force = kMu0 * Vec3{fx, fy, fz};
  return out;
#endif
}

// Field (A/m) at (tx, ty, tz) of sources [j0, j1) (sum_pairs).
template <bool SkipSameBody = false>
inline Vec3 sum_field(const SourceArrays& s, int j0, int j1, double tx, double ty, double tz,
                      double target_radius, double target_body = -1.0) {
  return sum_pairs<false, SkipSameBody>(s, j0, j1, {tx, ty, tz}, {}, target_radius, target_body).field;
}

// Field at, and force on, a target cell (position t, moment mt, contact
// radius rt) from sources [j0, j1) (sum_pairs).
inline FieldAndForce sum_field_and_force(const SourceArrays& s, int j0, int j1, const Vec3& t, const Vec3& mt,
                                         double rt) {
  return sum_pairs<true, false>(s, j0, j1, t, mt, rt, -1.0);
}

}  // namespace odemag
