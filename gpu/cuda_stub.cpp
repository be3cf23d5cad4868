// Built when the CUDA backend is not compiled in.
#include "gpu/cuda_backend.h"

namespace odemag {

bool cuda_backend_compiled() { return false; }

std::unique_ptr<MagneticBackend> make_cuda_backend(std::string* why) {
  if (why) *why = "this build has no CUDA backend";
  return nullptr;
}

}  // namespace odemag
