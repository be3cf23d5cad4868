// responsive_field: the field of the responsive cells (their current moments)
// at each responsive cell. One thread per target; sources in shared-memory
// tiles. A source of another body acts through the dipole kernel with the
// contact distance target radius + source radius; a source of the target's own
// body through the body's cached offset tensor (body frame), summed apart and
// rotated to the world once, exactly as the CPU backend does. Every target
// sums its sources in cell order (deterministic). The boundary correction of
// bodies with partial cells is added on the host (add_boundary_field).
#include "gpu/cuda_check.cuh"
#include "gpu/device_data.cuh"
#include "magnetics/kernels/kernels.h"

namespace odemag::gpu {

namespace {

struct ResponsiveSource {
  double x, y, z, radius;
  double mx, my, mz;  // world moment
  double bx, by, bz;  // body-frame moment
  int body, key;
};

__global__ void __launch_bounds__(kThreadsPerBlock) responsive_field_kernel(ResponsiveFieldArgs a) {
  __shared__ ResponsiveSource tile[kThreadsPerBlock];
  const int n = a.cells;
  const int i = blockIdx.x * kThreadsPerBlock + threadIdx.x;
  const bool target = i < n;  // threads past the end still load tiles
  CellPoint p{0.0, 0.0, 0.0, 0.0};
  int body = -1, key = 0, centre = 0;
  const double* table = nullptr;  // the target body's offset tensors; null: one-cell body
  if (target) {
    p = a.point[i];
    body = a.body[i];
    key = a.key[i];
    const DeviceBody& b = a.bodies[body];
    if (b.cell_count > 1 && b.table >= 0) {
      table = a.tables + b.table;
      centre = b.key_centre;
    }
  }
  Vec3 h, hb;  // inter-body part (world), intra-body part (body frame)
  for (int base = 0; base < n; base += kThreadsPerBlock) {
    const int j = base + threadIdx.x;
    if (j < n) {
      const CellPoint q = a.point[j];
      const Vec3 mu = a.mu[j], mb = a.mu_body[j];
      tile[threadIdx.x] = {q.x, q.y, q.z, q.radius, mu.x, mu.y, mu.z, mb.x, mb.y, mb.z, a.body[j], a.key[j]};
    }
    __syncthreads();
    const int count = n - base < kThreadsPerBlock ? n - base : kThreadsPerBlock;
    if (target) {
      for (int t = 0; t < count; ++t) {
        const ResponsiveSource& s = tile[t];
        if (s.body != body) {
          const double contact = p.radius + s.radius;
          h += dipole_field({p.x - s.x, p.y - s.y, p.z - s.z}, {s.mx, s.my, s.mz}, contact * contact);
        } else if (table && base + t != i) {
          const long long entry = static_cast<long long>(key - s.key + centre);
          hb += symmetric_times(table + 6 * entry, {s.bx, s.by, s.bz});
        }
      }
    }
    __syncthreads();  // the tile is overwritten next
  }
  if (target) a.H[i] = table ? h + a.bodies[body].rotation * hb : h;
}

}  // namespace

void launch_responsive_field(const ResponsiveFieldArgs& a, cudaStream_t stream) {
  if (a.cells <= 0) return;
  responsive_field_kernel<<<block_count(a.cells), kThreadsPerBlock, 0, stream>>>(a);
  ODEMAG_CUDA_CHECK_LAUNCH("responsive_field_kernel");
}

}  // namespace odemag::gpu
