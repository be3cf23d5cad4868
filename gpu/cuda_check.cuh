// Error checking for the CUDA runtime: every runtime call of the backend goes
// through ODEMAG_CUDA_CHECK, which throws std::runtime_error naming the call,
// the place and the runtime's message (cudaGetErrorString).
#pragma once

#include <cuda_runtime.h>

#include <stdexcept>
#include <string>

namespace odemag::gpu {

inline void check_cuda(cudaError_t status, const char* what, const char* file, int line) {
  if (status == cudaSuccess) return;
  throw std::runtime_error(std::string("CUDA error in ") + what + " (" + file + ":" +
                           std::to_string(line) + "): " + cudaGetErrorName(status) + ": " +
                           cudaGetErrorString(status));
}

}  // namespace odemag::gpu

#define ODEMAG_CUDA_CHECK(call) ::odemag::gpu::check_cuda((call), #call, __FILE__, __LINE__)
// After a kernel launch: reports launch-configuration errors now; errors while
// the kernel runs surface at the next synchronisation (cudaStreamSynchronize).
#define ODEMAG_CUDA_CHECK_LAUNCH(kernel_name) \
  ::odemag::gpu::check_cuda(cudaGetLastError(), "launch of " kernel_name, __FILE__, __LINE__)
