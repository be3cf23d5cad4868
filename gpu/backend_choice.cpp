#include "gpu/backend_choice.h"

#include <stdexcept>

#include "gpu/cuda_backend.h"
#include "odemag/magnetic_forces.h"

namespace odemag {

BackendKind backend_kind(const std::string& name) {
  if (name == "cpu") return BackendKind::cpu;
  if (name == "cuda") return BackendKind::cuda;
  if (name == "auto") return BackendKind::automatic;
  throw std::invalid_argument("unknown backend \"" + name + "\" (cpu, cuda or auto)");
}

std::unique_ptr<MagneticBackend> make_backend(BackendKind kind, int threads, std::string* notice,
                                              const std::string& cpu_only) {
  if (kind == BackendKind::cpu) return make_cpu_backend(threads);
  if (!cpu_only.empty() && kind == BackendKind::cuda)
    throw std::invalid_argument("backend \"cuda\" does not support " + cpu_only);
  if (!cpu_only.empty()) return make_cpu_backend(threads);
  std::string why;
  if (auto gpu = make_cuda_backend(&why)) return gpu;
  if (kind == BackendKind::cuda) throw std::invalid_argument("backend \"cuda\" is not available: " + why);
  if (notice) *notice = "odemag: no CUDA device (" + why + "); using the CPU backend";
  return make_cpu_backend(threads);
}


// The MagneticForces constructor that picks a backend by kind lives here,
// beside the CUDA backend, so that the embedding library alone links no GPU
// code (include/odemag/magnetic_forces.h).
MagneticForces::MagneticForces(const RelaxOptions& options, BackendKind backend, int threads, uint64_t seed,
                               IntraBodyTensor intra_tensor)
    : MagneticForces(options, make_backend(backend, threads, nullptr), seed, intra_tensor) {}

}  // namespace odemag
