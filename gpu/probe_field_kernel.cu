// probe_field: one thread per point, summing H_E and probe_cell_field of
// every probe cell (magnetics/relax/field_probe.h builds the list on the host) in
// list order, as the CPU backend does. Every thread of a warp reads the same
// cell at the same time, so the loads are broadcasts served by the cache.
#include "gpu/cuda_check.cuh"
#include "gpu/device_data.cuh"

namespace odemag::gpu {

namespace {

__global__ void __launch_bounds__(kThreadsPerBlock) probe_field_kernel(ProbeFieldArgs a) {
  const int p = blockIdx.x * kThreadsPerBlock + threadIdx.x;
  if (p >= a.points) return;  // no shared memory, no barrier: threads may leave
  const Vec3 x = a.point[p];
  Vec3 h = a.external;
  for (int c = 0; c < a.cells; ++c) h += probe_cell_field(a.cell[c], x);
  a.H[p] = h;
}

}  // namespace

void launch_probe_field(const ProbeFieldArgs& a, cudaStream_t stream) {
  if (a.points <= 0) return;
  probe_field_kernel<<<block_count(a.points), kThreadsPerBlock, 0, stream>>>(a);
  ODEMAG_CUDA_CHECK_LAUNCH("probe_field_kernel");
}

}  // namespace odemag::gpu
