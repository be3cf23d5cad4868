// The CUDA backend (gpu/): the same MagneticBackend interface on an NVIDIA GPU.
#pragma once

#include <memory>
#include <string>

#include "magnetics/backend.h"

namespace odemag {

// True when this build contains the CUDA backend.
bool cuda_backend_compiled();

// The CUDA backend, or nullptr with the reason in *why (not compiled in, no
// device, driver too old, ...).
std::unique_ptr<MagneticBackend> make_cuda_backend(std::string* why);

}  // namespace odemag
