// odemag._core: the C++ side of the Python package (python/odemag).
#include "python/src/bindings.h"

PYBIND11_MODULE(_core, m) {
  m.doc() = "odemag's C++ core; use the odemag package (docs/python.md).";
  odemag::python::bind_scene(m);
  odemag::python::bind_simulation(m);
}
