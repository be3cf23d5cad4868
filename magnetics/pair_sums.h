// The field of a run of source cells at one target through the dipole kernel
// (magnetics/kernels.h): the inner loop of every O(N^2) field sum of the CPU
// backend and of the near part of the far-field tree (magnetics/far_field.h).
#pragma once

#include "magnetics/kernels.h"
#include "magnetics/simd.h"
#include "magnetics/vec3.h"

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

// Field (A/m) at (tx, ty, tz) of sources [j0, j1), each pair through the
// kernel with contact distance target_radius + source radius. SkipSameBody:
// sources whose body equals target_body add nothing (their pairs are the
// intra-body sum's).
template <bool SkipSameBody = false>
inline Vec3 sum_field(const SourceArrays& s, int j0, int j1, double tx, double ty, double tz,
                      double target_radius, double target_body = -1.0) {
  const double* __restrict x = s.x;
  const double* __restrict y = s.y;
  const double* __restrict z = s.z;
  const double* __restrict r = s.radius;
  const double* __restrict mx = s.mx;
  const double* __restrict my = s.my;
  const double* __restrict mz = s.mz;
#if ODEMAG_HAVE_SIMD
  SimdD hx, hy, hz;
  for (int j = j0; j < j1; j += kSimdWidth) {
    const int count = j1 - j < kSimdWidth ? j1 - j : kSimdWidth;
    const SimdD dx = SimdD(tx) - SimdD::load(x + j, count), dy = SimdD(ty) - SimdD::load(y + j, count),
                dz = SimdD(tz) - SimdD::load(z + j, count);
    const SimdD contact = SimdD(target_radius) + SimdD::load(r + j, count);
    const SimdD r2 = dx * dx + dy * dy + dz * dz;
    DipoleCoefficientsT<SimdD> c = dipole_coefficients_from(r2, inverse_sqrt(max(r2, contact * contact)));
    if constexpr (SkipSameBody) {
      const SimdD b = SimdD::load(s.body + j, count), tb(target_body);
      c.A = zero_where_equal(c.A, b, tb);
      c.B = zero_where_equal(c.B, b, tb);
    }
    const SimdD ax = SimdD::load(mx + j, count), ay = SimdD::load(my + j, count), az = SimdD::load(mz + j, count);
    const SimdD rm = c.B * (dx * ax + dy * ay + dz * az);
    // Lanes past the end hold zero moments, so they add nothing.
    hx += c.A * ax + rm * dx;
    hy += c.A * ay + rm * dy;
    hz += c.A * az + rm * dz;
  }
  return {hx.sum(), hy.sum(), hz.sum()};
#else
  double hx = 0, hy = 0, hz = 0;
#pragma omp simd reduction(+ : hx, hy, hz)
  for (int j = j0; j < j1; ++j) {
    const double dx = tx - x[j], dy = ty - y[j], dz = tz - z[j];
    const double contact = target_radius + r[j];
    DipoleCoefficients c = dipole_coefficients(dx * dx + dy * dy + dz * dz, contact * contact);
    if constexpr (SkipSameBody) {
      const double keep = s.body[j] != target_body ? 1.0 : 0.0;
      c.A *= keep;
      c.B *= keep;
    }
    const double rm = c.B * (dx * mx[j] + dy * my[j] + dz * mz[j]);
    hx += c.A * mx[j] + rm * dx;
    hy += c.A * my[j] + rm * dy;
    hz += c.A * mz[j] + rm * dz;
  }
  return {hx, hy, hz};
#endif
}

}  // namespace odemag
