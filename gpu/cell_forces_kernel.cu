// forces, per cell: the force on each cell and the field at it from every cell
// of the other bodies (pairs inside a body cancel; docs/model.md "Forces
// and torques"). One thread per cell, sources in shared-memory tiles, summed in
// cell order. The per-body sums run on the host in the CPU backend's order.
#include "gpu/cuda_check.cuh"
#include "gpu/device_data.cuh"
#include "magnetics/kernels/kernels.h"

namespace odemag::gpu {

namespace {

struct ForceSource {
  double x, y, z, radius, mx, my, mz;
  int body;
};

__global__ void __launch_bounds__(kThreadsPerBlock) cell_forces_kernel(CellForcesArgs a) {
  __shared__ ForceSource tile[kThreadsPerBlock];
  const int n = a.cells;
  const int i = blockIdx.x * kThreadsPerBlock + threadIdx.x;
  const bool target = i < n;  // threads past the end still load tiles
  CellPoint p{0.0, 0.0, 0.0, 0.0};
  Vec3 mi;
  int body = -1;
  if (target) {
    p = a.point[i];
    mi = a.mu[i];
    body = a.body[i];
  }
  Vec3 f, h;
  for (int base = 0; base < n; base += kThreadsPerBlock) {
    const int j = base + threadIdx.x;
    if (j < n) {
      const CellPoint q = a.point[j];
      const Vec3 mu = a.mu[j];
      tile[threadIdx.x] = {q.x, q.y, q.z, q.radius, mu.x, mu.y, mu.z, a.body[j]};
    }
    __syncthreads();
    const int count = n - base < kThreadsPerBlock ? n - base : kThreadsPerBlock;
    if (target) {
      for (int t = 0; t < count; ++t) {
        const ForceSource& s = tile[t];
        if (s.body == body) continue;  // pairs inside a body cancel
        const Vec3 r{p.x - s.x, p.y - s.y, p.z - s.z};  // x_i - x_j
        const Vec3 mj{s.mx, s.my, s.mz};
        const double contact = p.radius + s.radius;
        f += dipole_force(r, mj, mi, contact * contact);
        h += dipole_field(r, mj, contact * contact);
      }
    }
    __syncthreads();  // the tile is overwritten next
  }
  if (target) {
    a.force[i] = f;
    a.field[i] = h;
  }
}

}  // namespace

void launch_cell_forces(const CellForcesArgs& a, cudaStream_t stream) {
  if (a.cells <= 0) return;
  cell_forces_kernel<<<block_count(a.cells), kThreadsPerBlock, 0, stream>>>(a);
  ODEMAG_CUDA_CHECK_LAUNCH("cell_forces_kernel");
}

}  // namespace odemag::gpu
