// Cell moments mu = V M from the magnetizations the host holds (and their
// body-frame copies for the intra-body sums), as the CPU backend's
// CellArrays::load_moments and body_moment_ do.
#include "gpu/cuda_check.cuh"
#include "gpu/device_data.cuh"

namespace odemag::gpu {

namespace {

__global__ void __launch_bounds__(kThreadsPerBlock) cell_moments_kernel(CellMomentsArgs a) {
  const int i = blockIdx.x * kThreadsPerBlock + threadIdx.x;
  if (i >= a.cells) return;
  const DeviceBody& body = a.bodies[a.body[i]];
  const Vec3 mu = a.volume[i] * a.magnetization[i];
  a.mu[i] = mu;
  if (a.mu_body) a.mu_body[i] = body.rotation.transpose_times(mu);
}

}  // namespace

void launch_cell_moments(const CellMomentsArgs& a, cudaStream_t stream) {
  if (a.cells <= 0) return;
  cell_moments_kernel<<<block_count(a.cells), kThreadsPerBlock, 0, stream>>>(a);
  ODEMAG_CUDA_CHECK_LAUNCH("cell_moments_kernel");
}

cudaError_t check_kernel_image() {
  cudaFuncAttributes attributes{};
  return cudaFuncGetAttributes(&attributes, cell_moments_kernel);
}

}  // namespace odemag::gpu
