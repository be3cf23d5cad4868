// relax_cells: one thread per responsive cell. Soft cells relax their moments
// under the frozen applied field with relax_soft_cell (LLG steps, then the
// Newton polish; magnetics/kernels/llg.h), recoil magnets take
// recoil_magnetization. The moments, Hc history and noise counters stay in
// device memory; the backend copies them to the host state after the call.
#include "gpu/cuda_check.cuh"
#include "gpu/device_data.cuh"
#include "magnetics/model/model.h"
#include "magnetics/kernels/rng.h"

namespace odemag::gpu {

namespace {

// Bits of a quiet NaN. Above the bits of every non-negative double (+inf is
// 0x7ff0...), so the integer maximum below keeps it: a cell whose residual or
// magnetization is not finite makes the call's largest residual NaN, as on
// the CPU (cpu_backend.cpp), and the relaxation then fails (relax.cpp).
constexpr unsigned long long kNaNBits = 0x7ff8000000000000ULL;

__device__ unsigned long long larger(unsigned long long a, unsigned long long b) { return a > b ? a : b; }

__global__ void __launch_bounds__(kThreadsPerBlock) relax_cells_kernel(RelaxCellsArgs a) {
  const int i = blockIdx.x * kThreadsPerBlock + threadIdx.x;
  unsigned long long llg = 0, newton = 0, worst = 0;
  if (i < a.cells) {
    const DeviceBody& b = a.bodies[a.body[i]];
    if (b.kind == static_cast<int>(CellKind::recoil_permanent)) {
      a.magnetization[i] = recoil_magnetization(b.remanent, b.recoil, a.applied[i]);
      if (!is_finite(a.magnetization[i])) worst = kNaNBits;
    } else {
      const int off = a.moment[i];
      bool history = a.history[i] != 0;
      uint64_t counter = a.counter[i];
      const LocalRelaxResult r = relax_soft_cell(
          b.soft, b.rotation.transpose_times(a.applied[i]), a.moments + off, a.hc_prev + off, history,
          counter, noise_stream(a.seed, static_cast<uint64_t>(a.cell[i])), a.options);
      a.history[i] = history ? 1 : 0;
      a.counter[i] = counter;
      const Vec3 M = b.rotation * (b.soft.Ms * mean_moment(a.moments + off, b.soft.n));
      a.magnetization[i] = M;
      llg = static_cast<unsigned long long>(r.llg_steps);
      newton = static_cast<unsigned long long>(r.newton_steps);
      if (!isfinite(r.residual) || !is_finite(M))
        worst = kNaNBits;
      else if (r.residual > 0.0)
        worst = static_cast<unsigned long long>(__double_as_longlong(r.residual));
    }
  }
  // Warp sums, then one atomic per warp. Every lane takes part (no early
  // return above), as __shfl_down_sync with the full mask requires.
  for (int offset = 16; offset > 0; offset /= 2) {
    llg += __shfl_down_sync(0xffffffffu, llg, offset);
    newton += __shfl_down_sync(0xffffffffu, newton, offset);
    worst = larger(worst, __shfl_down_sync(0xffffffffu, worst, offset));
  }
  if ((threadIdx.x & 31) == 0) {
    if (llg) atomicAdd(&a.totals->llg_steps, llg);
    if (newton) atomicAdd(&a.totals->newton_steps, newton);
    if (worst) atomicMax(&a.totals->max_residual_bits, worst);
  }
}

}  // namespace

void launch_relax_cells(const RelaxCellsArgs& a, cudaStream_t stream) {
  if (a.cells <= 0) return;
  relax_cells_kernel<<<block_count(a.cells), kThreadsPerBlock, 0, stream>>>(a);
  ODEMAG_CUDA_CHECK_LAUNCH("relax_cells_kernel");
}

}  // namespace odemag::gpu
