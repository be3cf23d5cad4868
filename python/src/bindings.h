// The pieces of odemag._core (python/odemag/__init__.py is the public API;
// docs/python.md documents it).
#pragma once

#include <pybind11/pybind11.h>

#include <memory>
#include <optional>
#include <string>

#include "odemag/scene.h"
#include "magnetics/model/backend.h"

namespace odemag::python {

namespace py = pybind11;

// The backend a call asks for (backend, threads) or, without them, the
// scene's solver.backend and solver.threads, as `odemag` picks it. A bad
// argument is a ValueError; a bad scene setting a SceneError naming
// solver.backend. `name` receives the backend's name.
std::unique_ptr<MagneticBackend> backend_for(const SceneDescription& scene, const std::optional<std::string>& backend,
                                             const std::optional<int>& threads);

void bind_scene(py::module_& m);       // load, Scene, Solution, Field, SceneError (scene.cpp)
void bind_simulation(py::module_& m);  // Simulation, Magnetics (simulation.cpp)

}  // namespace odemag::python
