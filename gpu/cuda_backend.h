// The CUDA backend (gpu/): the same MagneticBackend interface on an NVIDIA GPU,
// in double precision (docs/gpu.md).
#pragma once

#include <memory>
#include <string>

#include "magnetics/model/backend.h"

namespace odemag {

// True when this build contains the CUDA backend.
bool cuda_backend_compiled();

// The CUDA backend, or nullptr with the reason in *why (not compiled in, no
// device, driver too old, ...).
std::unique_ptr<MagneticBackend> make_cuda_backend(std::string* why);

// Where the CUDA backend's time goes, per interface call, accumulated since it
// was made (or reset). Times from CUDA events on the backend's stream; wall_ms
// includes the host's gathering and scattering of cell data.
struct CudaCallStats {
  long calls = 0;
  double upload_ms = 0.0;    // host -> device copies
  double kernel_ms = 0.0;
  double download_ms = 0.0;  // device -> host copies
  double wall_ms = 0.0;      // the whole call as the host sees it
  double upload_bytes = 0.0;
  double download_bytes = 0.0;
};

struct CudaBackendStats {
  CudaCallStats begin_step, fixed_field, responsive_field, relax_cells, forces, probe_field;
};

// The statistics of a backend made by make_cuda_backend; zeros for any other.
CudaBackendStats cuda_backend_stats(const MagneticBackend& backend);
void reset_cuda_backend_stats(MagneticBackend& backend);

}  // namespace odemag
