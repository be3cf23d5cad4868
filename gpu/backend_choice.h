// The magnetic backend a scene or an embedder asks for (BackendKind:
// solver.backend, --backend, MagneticForces' constructor): the CPU backend,
// the CUDA backend, or automatic, the CUDA backend where a device is usable.
#pragma once

#include <memory>
#include <string>

#include "magnetics/model/backend.h"
#include "odemag/settings.h"

namespace odemag {

// The backend of a kind: cpu, cuda or automatic. automatic falls back to the CPU
// backend when no CUDA device is usable and writes one notice to `notice`;
// cuda without a device throws std::invalid_argument (usage error, exit 2).
// cpu_only: a feature of the scene that only the CPU backend supports
// (cpu_only_feature), so automatic picks it and cuda throws naming it.
std::unique_ptr<MagneticBackend> make_backend(BackendKind kind, int threads, std::string* notice,
                                              const std::string& cpu_only = "");
// The backend a name gives ("cpu", "cuda" or "auto", as solver.backend and
// --backend spell it); std::invalid_argument on any other.
BackendKind backend_kind(const std::string& name);

}  // namespace odemag
