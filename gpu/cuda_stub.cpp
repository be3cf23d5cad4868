// Built when the CUDA backend is not compiled in (ODEMAG_CUDA=OFF, or AUTO
// without nvcc).
#include "gpu/cuda_backend.h"

namespace odemag {

bool cuda_backend_compiled() { return false; }

std::unique_ptr<MagneticBackend> make_cuda_backend(std::string* why) {
  if (why) *why = "this build has no CUDA backend (configured with ODEMAG_CUDA=OFF or without nvcc)";
  return nullptr;
}

CudaBackendStats cuda_backend_stats(const MagneticBackend&) { return {}; }

void reset_cuda_backend_stats(MagneticBackend&) {}

}  // namespace odemag
