// Eight doubles in an AVX-512 register, with the operations the dipole kernel
// needs (magnetics/kernels.h is written once for double and for this type).
// Host only; used by the CPU backend when compiled for AVX-512.
#pragma once

#if defined(__AVX512F__) && !defined(__CUDACC__)
#define ODEMAG_HAVE_SIMD8 1
#include <immintrin.h>

namespace odemag {

struct Simd8 {
  __m512d v;
  Simd8() : v(_mm512_setzero_pd()) {}
  Simd8(__m512d x) : v(x) {}  // NOLINT: implicit on purpose
  Simd8(double x) : v(_mm512_set1_pd(x)) {}  // NOLINT: broadcast
  static Simd8 load(const double* p) { return _mm512_loadu_pd(p); }
  // The first `count` lanes from p, zero elsewhere.
  static Simd8 load(const double* p, int count) {
    return _mm512_maskz_loadu_pd(static_cast<__mmask8>((1u << count) - 1u), p);
  }
  double sum() const { return _mm512_reduce_add_pd(v); }
};

inline Simd8 operator+(const Simd8& a, const Simd8& b) { return _mm512_add_pd(a.v, b.v); }
inline Simd8 operator-(const Simd8& a, const Simd8& b) { return _mm512_sub_pd(a.v, b.v); }
inline Simd8 operator*(const Simd8& a, const Simd8& b) { return _mm512_mul_pd(a.v, b.v); }
inline Simd8 operator*(double a, const Simd8& b) { return _mm512_mul_pd(_mm512_set1_pd(a), b.v); }
inline Simd8& operator+=(Simd8& a, const Simd8& b) { return a = a + b; }
inline Simd8 max(const Simd8& a, const Simd8& b) { return _mm512_max_pd(a.v, b.v); }

// 1/sqrt(x) to double precision: the 14-bit estimate and two Newton steps
// y <- y (3 - x y^2) / 2 (relative error ~1e-16; a division and a square root
// cost ten times as much).
inline Simd8 inverse_sqrt(const Simd8& x) {
  __m512d y = _mm512_rsqrt14_pd(x.v);
  const __m512d half = _mm512_set1_pd(0.5), three = _mm512_set1_pd(3.0);
  for (int i = 0; i < 2; ++i) {
    const __m512d xyy = _mm512_mul_pd(_mm512_mul_pd(x.v, y), y);
    y = _mm512_mul_pd(_mm512_mul_pd(half, y), _mm512_sub_pd(three, xyy));
  }
  return y;
}

}  // namespace odemag

#endif
