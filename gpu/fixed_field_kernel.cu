// fixed_field: H_E plus the field of every fixed permanent cell at each
// responsive cell. One thread per target; the sources pass through shared
// memory in tiles of kThreadsPerBlock (the classic N-body scheme), each target
// summing them in source order, so the result does not depend on scheduling.
#include "gpu/cuda_check.cuh"
#include "gpu/device_data.cuh"
#include "magnetics/kernels/kernels.h"

namespace odemag::gpu {

namespace {

struct FixedSource {
  double x, y, z, radius, mx, my, mz;
};

__global__ void __launch_bounds__(kThreadsPerBlock) fixed_field_kernel(FixedFieldArgs a) {
  __shared__ FixedSource tile[kThreadsPerBlock];
  const int i = blockIdx.x * kThreadsPerBlock + threadIdx.x;
  const bool target = i < a.targets;  // threads past the end still load tiles
  CellPoint p{0.0, 0.0, 0.0, 0.0};
  if (target) p = a.target[i];
  Vec3 h;
  for (int base = 0; base < a.sources; base += kThreadsPerBlock) {
    const int j = base + threadIdx.x;
    if (j < a.sources) {
      const CellPoint q = a.source[j];
      const Vec3 mu = a.source_mu[j];
      tile[threadIdx.x] = {q.x, q.y, q.z, q.radius, mu.x, mu.y, mu.z};
    }
    __syncthreads();
    const int count = a.sources - base < kThreadsPerBlock ? a.sources - base : kThreadsPerBlock;
    if (target) {
      for (int t = 0; t < count; ++t) {
        const FixedSource& s = tile[t];
        // Contact distance: target radius + source radius (kernels.h "Overlap").
        const double contact = p.radius + s.radius;
        h += dipole_field({p.x - s.x, p.y - s.y, p.z - s.z}, {s.mx, s.my, s.mz}, contact * contact);
      }
    }
    __syncthreads();  // the tile is overwritten next
  }
  if (target) a.H[i] = a.external + h;
}

}  // namespace

void launch_fixed_field(const FixedFieldArgs& a, cudaStream_t stream) {
  if (a.targets <= 0) return;
  fixed_field_kernel<<<block_count(a.targets), kThreadsPerBlock, 0, stream>>>(a);
  ODEMAG_CUDA_CHECK_LAUNCH("fixed_field_kernel");
}

}  // namespace odemag::gpu
