// Functions marked ODEMAG_HD are compiled for the host and, under nvcc, for the
// device as well, so the CPU and CUDA backends share one copy of each formula.
#pragma once

#if defined(__CUDACC__)
#define ODEMAG_HD __host__ __device__ inline
#else
#define ODEMAG_HD inline
#endif

// fmax(a, b), inlined (on the host the library's fmax is a call, about 1% of
// the crane's time): the larger of the two, the other one where one is NaN.
ODEMAG_HD double larger(double a, double b) { return (b > a || a != a) ? b : a; }
