// Scenes in Python: load, Scene.solve (`odemag solve`), Scene.field
// (`odemag field`), and SceneError.
#include <pybind11/stl.h>

#include <cmath>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "engine/simulation/magnetic_system.h"
#include "odemag/constants.h"
#include "odemag/solve.h"
#include "python/src/arrays.h"
#include "python/src/bindings.h"

namespace odemag::python {

namespace {


// odemag.SceneError (a ValueError), made once and kept for the process.
PyObject* scene_error_type = nullptr;

// A C++ SceneError as odemag.SceneError: str() is what() ("FILE: KEY:
// message", the line `odemag` prints after "odemag: "), with the parts as
// attributes file, key ("" when the error has none) and message.
void translate_scene_error(std::exception_ptr p) {
  try {
    if (p) std::rethrow_exception(p);
  } catch (const SceneError& e) {
    py::object error = py::reinterpret_borrow<py::object>(scene_error_type)(py::str(e.what()));
    error.attr("file") = py::str(e.file());
    error.attr("key") = py::str(e.key());
    error.attr("message") = py::str(e.message());
    PyErr_SetObject(scene_error_type, error.ptr());
  }
}

// The result of Scene.solve.
struct Solution {
  std::vector<std::string> body_names;
  py::array_t<bool> present;
  py::array_t<int> cells;
  py::array_t<double> moments, forces, torques;
  int iterations = 0, field_evaluations = 0;
  double residual = 0.0;
  bool converged = false;
  std::string backend;
};

// The result of Scene.field.
struct Field {
  py::array_t<double> points, B, H;
  int iterations = 0;
  double residual = 0.0;
  bool converged = false;
  std::string backend;
};

Solution solve(const SceneDescription& scene, const std::optional<std::string>& backend_name,
               const std::optional<int>& threads) {
  const std::unique_ptr<MagneticBackend> backend = backend_for(scene, backend_name, threads);
  SceneSolution s;
  {
    py::gil_scoped_release release;
    s = solve_scene(scene, *backend);
  }
  Solution out;
  std::vector<Vec3> moments, forces, torques;
  std::vector<char> present;
  std::vector<int> cells;
  for (size_t b = 0; b < s.bodies.size(); ++b) {
    const SolvedBody& body = s.bodies[b];
    out.body_names.push_back(scene.bodies[b].name);
    present.push_back(body.present ? 1 : 0);
    cells.push_back(body.cells);
    moments.push_back(body.moment);
    forces.push_back(body.force);
    torques.push_back(body.torque);
  }
  out.present = copied_array<bool>(present);
  out.cells = copied_array<int>(cells);
  out.moments = vec3_array(std::move(moments));
  out.forces = vec3_array(std::move(forces));
  out.torques = vec3_array(std::move(torques));
  out.iterations = s.report.iterations;
  out.field_evaluations = s.report.field_evaluations;
  out.residual = s.report.residual;
  out.converged = s.report.converged;
  out.backend = backend->name();
  return out;
}

// points as Vec3s: an (N, 3) array (or anything numpy makes one of) of
// finite numbers, metres. ValueError naming the shape or the row otherwise.
std::vector<Vec3> points_from(const py::object& object) {
  auto a = py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(object);
  if (!a) {
    PyErr_Clear();
    throw py::value_error("points: expected an (N, 3) array of numbers (m), got " +
                          std::string(py::str(py::type::of(object).attr("__name__"))));
  }
  if (a.ndim() != 2 || a.shape(1) != 3) {
    std::string shape = "(";
    for (py::ssize_t d = 0; d < a.ndim(); ++d) shape += (d ? ", " : "") + std::to_string(a.shape(d));
    if (a.ndim() == 1) shape += ",";
    throw py::value_error("points: expected an array of shape (N, 3) (m), got shape " + shape + ")");
  }
  const auto r = a.unchecked<2>();
  std::vector<Vec3> points(static_cast<size_t>(a.shape(0)));
  for (py::ssize_t i = 0; i < a.shape(0); ++i) {
    points[static_cast<size_t>(i)] = {r(i, 0), r(i, 1), r(i, 2)};
    if (!is_finite(points[static_cast<size_t>(i)]))
      throw py::value_error("points[" + std::to_string(i) + "]: expected three finite numbers x, y, z (m)");
    if (norm(points[static_cast<size_t>(i)]) > ranges::kLength.max)
      throw py::value_error("points[" + std::to_string(i) + "]: farther than the largest accepted length, " +
                            std::string(py::str(py::float_(ranges::kLength.max))) + " m, from the origin (docs/scene-format.md \"Ranges\")");
  }
  return points;
}

Field field(const SceneDescription& scene, const py::object& points_object, const std::optional<std::string>& backend_name,
            const std::optional<int>& threads) {
  std::vector<Vec3> points = points_from(points_object);
  const std::unique_ptr<MagneticBackend> backend = backend_for(scene, backend_name, threads);
  SceneField f;
  {
    py::gil_scoped_release release;
    f = scene_field(scene, *backend, points);
  }
  Field out;
  out.points = vec3_array(std::move(points));
  out.B = vec3_array(std::move(f.B));
  out.H = vec3_array(std::move(f.H));
  out.iterations = f.report.iterations;
  out.residual = f.report.residual;
  out.converged = f.report.converged;
  out.backend = backend->name();
  return out;
}

}  // namespace

std::unique_ptr<MagneticBackend> backend_for(const SceneDescription& scene, const std::optional<std::string>& backend,
                                             const std::optional<int>& threads) {
  if (threads && *threads < 0) throw py::value_error("threads: expected 0 (all cores) or more, got " + std::to_string(*threads));
  try {
    // The "no CUDA device, using the CPU" notice is dropped: the result's backend says which ran.
    return make_backend(backend ? backend_kind(*backend) : scene.solver.backend, threads.value_or(scene.solver.threads), nullptr,
                        cpu_only_feature(scene));
  } catch (const std::invalid_argument& e) {
    if (backend) throw py::value_error(std::string("backend: ") + e.what());
    throw SceneError(scene.file, "solver.backend", e.what());
  }
}

void bind_scene(py::module_& m) {
  scene_error_type = py::exception<SceneError>(m, "SceneError", PyExc_ValueError).release().ptr();
  py::register_exception_translator(translate_scene_error);

  py::class_<Solution>(m, "Solution", "Scene.solve's result (docs/python.md).")
      .def_readonly("body_names", &Solution::body_names)
      .def_readonly("present", &Solution::present, "(B,) bool: present at t = 0 (absent bodies report zeros)")
      .def_readonly("cells", &Solution::cells, "(B,) int32: cells per body")
      .def_readonly("moments", &Solution::moments, "(B, 3) float64: magnetic moments, A m^2, world frame")
      .def_readonly("forces", &Solution::forces, "(B, 3) float64: magnetic forces, N, world frame")
      .def_readonly("torques", &Solution::torques, "(B, 3) float64: torques about the centres of mass, N m")
      .def_readonly("iterations", &Solution::iterations)
      .def_readonly("field_evaluations", &Solution::field_evaluations)
      .def_readonly("residual", &Solution::residual)
      .def_readonly("converged", &Solution::converged)
      .def_readonly("backend", &Solution::backend);

  py::class_<Field>(m, "Field", "Scene.field's result (docs/python.md); unpacks as B, H.")
      .def_readonly("points", &Field::points, "(N, 3) float64: the points, m")
      .def_readonly("B", &Field::B, "(N, 3) float64: flux density, T")
      .def_readonly("H", &Field::H, "(N, 3) float64: field strength, A/m")
      .def_readonly("iterations", &Field::iterations)
      .def_readonly("residual", &Field::residual)
      .def_readonly("converged", &Field::converged)
      .def_readonly("backend", &Field::backend)
      .def("__iter__", [](const Field& f) { return py::iter(py::make_tuple(f.B, f.H)); });

  py::class_<SceneDescription, std::shared_ptr<SceneDescription>>(m, "Scene",
      "A validated scene (docs/scene-format.md); made by odemag.load.")
      .def_readonly("file", &SceneDescription::file, "where the scene came from, as named in messages")
      .def_readonly("title", &SceneDescription::title)
      .def_property_readonly("body_names", [](const SceneDescription& s) {
        std::vector<std::string> names;
        for (const BodyDescription& b : s.bodies) names.push_back(b.name);
        return names;
      }, "the bodies' names, in scene order (the row order of every per-body array)")
      .def_property_readonly("time_step", [](const SceneDescription& s) { return s.simulation.time_step; },
                             "simulation.time_step, s")
      .def_property_readonly("duration", [](const SceneDescription& s) { return s.simulation.duration; },
                             "simulation.duration, s")
      .def("solve", &solve, py::arg("backend") = py::none(), py::arg("threads") = py::none(),
           "`odemag solve`: the scene at t = 0 relaxed with its bodies held in place, with forces and\n"
           "torques. backend ('cpu', 'cuda', 'auto') and threads (0: all cores) override solver.backend\n"
           "and solver.threads. Returns a Solution (per-body (B, 3) arrays in A m^2, N, N m).")
      .def("field", &field, py::arg("points"), py::arg("backend") = py::none(), py::arg("threads") = py::none(),
           "`odemag field`: B (T) and H (A/m) at points, an (N, 3) array in m, of the scene relaxed as\n"
           "in solve. Returns a Field (B, H: (N, 3) float64); unpacks as B, H.");

  m.def("load_file", [](const std::string& path) { return std::make_shared<SceneDescription>(load_scene(path)); },
        py::arg("path"), py::call_guard<py::gil_scoped_release>());
  m.def("parse_scene", [](const std::string& text, const std::string& file) {
        return std::make_shared<SceneDescription>(parse_scene(text, file));
      }, py::arg("text"), py::arg("file"), py::call_guard<py::gil_scoped_release>());
}

}  // namespace odemag::python
