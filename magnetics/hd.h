// Functions marked ODEMAG_HD are compiled for the host and, under nvcc, for the
// device as well, so the CPU and CUDA backends share one copy of each formula.
#pragma once

#if defined(__CUDACC__)
#define ODEMAG_HD __host__ __device__ inline
#else
#define ODEMAG_HD inline
#endif
