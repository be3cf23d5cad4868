// A vector of doubles with the operations the dipole kernel needs
// (magnetics/kernels/kernels.h is written once for double and for this type): eight
// lanes in an AVX-512 register (Simd8), or four in an AVX2 one (Simd4) where
// the compiler targets AVX2 and FMA but not AVX-512. SimdD names the one in
// use and kSimdWidth its lanes; ODEMAG_HAVE_SIMD is 0 when neither is
// available (the pair loops then fall back to `omp simd`). Host only.
#pragma once

#if defined(__AVX512F__) && !defined(__CUDACC__)
#define ODEMAG_HAVE_SIMD 1
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
// x where a != b, zero where a == b.
inline Simd8 zero_where_equal(const Simd8& x, const Simd8& a, const Simd8& b) {
  return _mm512_maskz_mov_pd(_mm512_cmp_pd_mask(a.v, b.v, _CMP_NEQ_OQ), x.v);
}

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

using SimdD = Simd8;
inline constexpr int kSimdWidth = 8;

}  // namespace odemag

#elif defined(__AVX2__) && defined(__FMA__) && !defined(__CUDACC__)
#define ODEMAG_HAVE_SIMD 1
#include <immintrin.h>

namespace odemag {

struct Simd4 {
  __m256d v;
  Simd4() : v(_mm256_setzero_pd()) {}
  Simd4(__m256d x) : v(x) {}  // NOLINT: implicit on purpose
  Simd4(double x) : v(_mm256_set1_pd(x)) {}  // NOLINT: broadcast
  static Simd4 load(const double* p) { return _mm256_loadu_pd(p); }
  // The first `count` lanes from p, zero elsewhere (masked lanes are not read).
  static Simd4 load(const double* p, int count) {
    if (count >= 4) return _mm256_loadu_pd(p);  // masked loads are slow on AMD
    const __m256i mask = _mm256_cmpgt_epi64(_mm256_set1_epi64x(count), _mm256_set_epi64x(3, 2, 1, 0));
    return _mm256_maskload_pd(p, mask);
  }
  double sum() const {
    const __m128d pair = _mm_add_pd(_mm256_castpd256_pd128(v), _mm256_extractf128_pd(v, 1));
    return _mm_cvtsd_f64(_mm_add_sd(pair, _mm_unpackhi_pd(pair, pair)));
  }
};

inline Simd4 operator+(const Simd4& a, const Simd4& b) { return _mm256_add_pd(a.v, b.v); }
inline Simd4 operator-(const Simd4& a, const Simd4& b) { return _mm256_sub_pd(a.v, b.v); }
inline Simd4 operator*(const Simd4& a, const Simd4& b) { return _mm256_mul_pd(a.v, b.v); }
inline Simd4 operator*(double a, const Simd4& b) { return _mm256_mul_pd(_mm256_set1_pd(a), b.v); }
inline Simd4& operator+=(Simd4& a, const Simd4& b) { return a = a + b; }
inline Simd4 max(const Simd4& a, const Simd4& b) { return _mm256_max_pd(a.v, b.v); }
// x where a != b, zero where a == b.
inline Simd4 zero_where_equal(const Simd4& x, const Simd4& a, const Simd4& b) {
  return _mm256_and_pd(x.v, _mm256_cmp_pd(a.v, b.v, _CMP_NEQ_OQ));
}
// 1/sqrt(x): square root and division. (The single-precision estimate with
// three Newton steps, as the AVX-512 path does with its double estimate, was
// 1.3x slower on the AMD EPYC of docs/benchmarks.md.)
inline Simd4 inverse_sqrt(const Simd4& x) { return _mm256_div_pd(_mm256_set1_pd(1.0), _mm256_sqrt_pd(x.v)); }

using SimdD = Simd4;
inline constexpr int kSimdWidth = 4;

}  // namespace odemag

#else
#define ODEMAG_HAVE_SIMD 0
#endif
