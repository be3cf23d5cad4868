// Simulations in Python: odemag.Simulation (the scene stepped as `odemag run`
// steps it) and odemag.Magnetics (a scene's magnetics at poses the caller
// sets: the embedding API for Python programs with their own rigid bodies).
#include <pybind11/stl.h>

#include <cmath>
#include <map>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "engine/simulation/magnetic_system.h"
#include "odemag/simulation.h"
#include "python/src/arrays.h"
#include "python/src/bindings.h"
#include "engine/simulation/rigid_world.h"

namespace odemag::python {

namespace {

// A body named or numbered in a call; IndexError / KeyError when there is none.
int body_index(const std::vector<BodyDescription>& bodies, const py::object& body) {
  if (py::isinstance<py::str>(body)) {
    const std::string name = body.cast<std::string>();
    for (size_t b = 0; b < bodies.size(); ++b)
      if (bodies[b].name == name) return static_cast<int>(b);
    throw py::key_error("no body named '" + name + "'");
  }
  const long i = body.cast<long>();
  if (i < 0 || i >= static_cast<long>(bodies.size()))
    throw py::index_error("body " + std::to_string(i) + ": expected 0 .. " + std::to_string(bodies.size() - 1));
  return static_cast<int>(i);
}

std::vector<std::string> names(const SceneDescription& scene) {
  std::vector<std::string> n;
  for (const BodyDescription& b : scene.bodies) n.push_back(b.name);
  return n;
}

Vec3 vec3_from(const py::object& object, const char* what) {
  auto a = py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(object);
  if (!a || a.ndim() != 1 || a.shape(0) != 3) {
    PyErr_Clear();
    throw py::value_error(std::string(what) + ": expected three numbers");
  }
  return {a.at(0), a.at(1), a.at(2)};
}

// A control of MagneticForces (its checks: docs/embedding.md "Checks"), its
// std::invalid_argument raised as ValueError naming the Python call:
// "set_magnetization_scale: the scale 1e+300 of body 0 "magnet" ...".
template <class F>
void checked(const char* call, F control) {
  try {
    control();
  } catch (const std::invalid_argument& e) {
    std::string message = e.what();
    if (message.rfind("MagneticForces::", 0) == 0)
      if (const size_t colon = message.find(": "); colon != std::string::npos) message.erase(0, colon + 2);
    throw py::value_error(std::string(call) + ": " + message);
  }
}

py::dict report_dict(const RelaxReport& r) {
  py::dict d;
  d["iterations"] = r.iterations;
  d["field_evaluations"] = r.field_evaluations;
  d["residual"] = r.residual;
  d["converged"] = r.converged;
  d["skipped"] = r.skipped;
  return d;
}

// Per-body world-frame vectors of the magnetics (moments, forces, torques).
template <class F>
py::array_t<double> per_body(int count, F value) {
  std::vector<Vec3> v(static_cast<size_t>(count));
  for (int b = 0; b < count; ++b) v[static_cast<size_t>(b)] = value(b);
  return vec3_array(std::move(v));
}

class PySimulation {
 public:
  PySimulation(const SceneDescription& scene, const std::optional<std::string>& backend,
               const std::optional<int>& threads)
      : sim_(scene, backend_for(scene, backend, threads)) {
    // Frame 0 of `odemag run`: the magnetization relaxed at t = 0, from
    // which the first step's relaxation starts.
    py::gil_scoped_release release;
    sim_.magnetics().compute();
  }

  void step() {
    {
      py::gil_scoped_release release;
      sim_.step();
    }
    check_finite();
  }

  // Steps until time() >= t (within half a step), as `odemag run` does up to
  // its duration; Ctrl-C stops between steps (KeyboardInterrupt).
  void advance_to(double t) {
    if (!std::isfinite(t)) throw py::value_error("time: expected a finite number (s)");
    const double dt = sim_.scene().simulation.time_step;
    py::gil_scoped_release release;
    for (long n = 1; sim_.time() + 0.5 * dt < t; ++n) {
      sim_.step();
      if (!sim_.non_finite_message().empty() || n % 64 == 0) {
        py::gil_scoped_acquire acquire;
        check_finite();
        if (PyErr_CheckSignals() != 0) throw py::error_already_set();
      }
    }
  }

  // duration None: to the scene's simulation.duration (`odemag run`).
  void run(const std::optional<double>& duration) {
    if (duration && !(*duration >= 0.0)) throw py::value_error("duration: expected a number >= 0 (s)");
    advance_to(duration ? sim_.time() + *duration : sim_.scene().simulation.duration);
  }

  py::dict finish() {
    sim_.finish();
    return outcomes();
  }

  py::dict outcomes() const {
    py::dict d;
    for (const auto& [name, value] : sim_.outcomes()) d[py::str(name)] = value;
    return d;
  }

  int count() const { return sim_.world().body_count(); }
  py::array_t<double> positions() const {
    return per_body(count(), [&](int b) { return sim_.world().pose(b).position; });
  }
  py::array_t<double> quaternions() const {
    std::vector<double> q;
    for (int b = 0; b < count(); ++b) {
      const dReal* r = dBodyGetQuaternion(sim_.world().body(b));
      q.insert(q.end(), {r[0], r[1], r[2], r[3]});
    }
    return double_array(std::move(q), 4);
  }
  py::array_t<double> velocities() const {
    return per_body(count(), [&](int b) { return sim_.world().velocity(b); });
  }
  py::array_t<double> angular_velocities() const {
    return per_body(count(), [&](int b) { return sim_.world().angular_velocity(b); });
  }
  py::array_t<double> moments() const {
    return per_body(count(), [&](int b) { return sim_.magnetics().moment(b); });
  }
  py::array_t<double> forces() const {
    return per_body(count(), [&](int b) { return sim_.magnetics().force(b); });
  }
  py::array_t<double> torques() const {
    return per_body(count(), [&](int b) { return sim_.magnetics().torque(b); });
  }
  py::array_t<bool> present() const {
    std::vector<char> p;
    for (int b = 0; b < count(); ++b) p.push_back(sim_.world().enabled(b) ? 1 : 0);
    return copied_array<bool>(p);
  }

  // One array per StepReport field, one entry per rigid step.
  py::dict records() const {
    const std::vector<StepReport>& r = sim_.records();
    auto column = [&](auto field) {
      using T = std::decay_t<decltype(r.front().*field)>;
      std::vector<T> v;
      for (const StepReport& s : r) v.push_back(s.*field);
      return v;
    };
    py::dict d;
    d["time"] = double_array(column(&StepReport::time));
    d["magnetic_ms"] = double_array(column(&StepReport::magnetic_ms));
    d["rigid_ms"] = double_array(column(&StepReport::rigid_ms));
    d["wall_ms"] = double_array(column(&StepReport::wall_ms));
    d["substeps"] = copied_array<int>(column(&StepReport::substeps));
    d["substeps_wanted"] = copied_array<int>(column(&StepReport::substeps_wanted));
    d["iterations"] = copied_array<int>(column(&StepReport::iterations));
    d["llg_steps"] = copied_array<long>(column(&StepReport::llg_steps));
    d["newton_steps"] = copied_array<long>(column(&StepReport::newton_steps));
    d["relaxations"] = copied_array<int>(column(&StepReport::relaxations));
    d["skipped"] = copied_array<int>(column(&StepReport::skipped));
    d["converged"] = copied_array<bool>(column(&StepReport::converged));
    d["residual"] = double_array(column(&StepReport::residual));
    d["held"] = copied_array<int>(column(&StepReport::held));
    d["rezoned"] = copied_array<int>(column(&StepReport::rezoned));
    return d;
  }

  void set_magnetization_scale(const py::object& body, double scale) {
    const int b = index(body);
    checked("set_magnetization_scale", [&] { sim_.magnetics().set_magnetization_scale(b, scale); });
  }
  double magnetization_scale(const py::object& body) const { return sim_.magnetics().magnetization_scale(index(body)); }
  py::array_t<double> external_field() const {
    const Vec3 H = sim_.magnetics().external_field();
    return double_array({H.x, H.y, H.z});
  }
  void set_external_field(const py::object& H) {
    const Vec3 field = vec3_from(H, "external_field");
    checked("external_field", [&] { sim_.magnetics().set_external_field(field); });
  }

  const Simulation& simulation() const { return sim_; }
  std::string backend_name() { return sim_.magnetics().backend().name(); }

 private:
  int index(const py::object& body) const { return body_index(sim_.scene().bodies, body); }
  void check_finite() const {
    if (std::string message = sim_.non_finite_message(); !message.empty()) throw std::runtime_error(message);
  }

  Simulation sim_;
};

// A scene's magnetics with no rigid world: the caller sets every body's pose
// and reads forces and torques (a Python program with its own physics).
class PyMagnetics {
 public:
  PyMagnetics(const SceneDescription& scene, const std::optional<std::string>& backend,
              const std::optional<int>& threads)
      : scene_(scene) {
    MagneticSystem ms = build_magnetic_system(scene);
    RelaxOptions options = scene.solver.relax;
    apply_events_at_start(scene, ms, options);
    forces_ = std::make_unique<MagneticForces>(std::move(ms.model), std::move(ms.state), options,
                                               backend_for(scene, backend, threads));
  }

  // positions (B, 3), m; rotations (B, 4) unit quaternions w, x, y, z or (B, 3, 3)
  // body-to-world matrices (row-major, as ODE's dBodyGetRotation / PyODE's getRotation).
  void set_poses(const py::object& positions_object, const py::object& rotations_object) {
    using Array = py::array_t<double, py::array::c_style | py::array::forcecast>;
    const py::ssize_t n = static_cast<py::ssize_t>(scene_.bodies.size());
    Array p = Array::ensure(positions_object), r = Array::ensure(rotations_object);
    if (!p || !r) PyErr_Clear();
    if (!p || p.ndim() != 2 || p.shape(0) != n || p.shape(1) != 3)
      throw py::value_error("positions: expected an array of shape (" + std::to_string(n) + ", 3) (m)");
    const bool quaternions = r && r.ndim() == 2 && r.shape(0) == n && r.shape(1) == 4;
    const bool matrices = r && r.ndim() == 3 && r.shape(0) == n && r.shape(1) == 3 && r.shape(2) == 3;
    if (!quaternions && !matrices)
      throw py::value_error("rotations: expected quaternions w, x, y, z of shape (" + std::to_string(n) +
                            ", 4) or matrices of shape (" + std::to_string(n) + ", 3, 3)");
    const double* pd = p.data();
    const double* rd = r.data();
    std::vector<BodyPose> poses;
    for (py::ssize_t b = 0; b < n; ++b) {
      BodyPose pose;
      pose.position = {pd[3 * b], pd[3 * b + 1], pd[3 * b + 2]};
      if (quaternions) {
        const double* q = rd + 4 * b;
        pose.rotation = rotation_from_quaternion(q[0], q[1], q[2], q[3]);
      } else {
        for (int i = 0; i < 3; ++i)
          for (int j = 0; j < 3; ++j) pose.rotation.m[i][j] = rd[9 * b + 3 * i + j];
      }
      poses.push_back(pose);
    }
    // A refused pose (not finite, beyond the length bound, a rotation not
    // orthonormal to 1e-9: docs/embedding.md "Checks") changes nothing.
    const std::vector<BodyPose> before = forces_->state().pose;
    try {
      checked("set_poses", [&] {
        for (py::ssize_t b = 0; b < n; ++b) forces_->set_pose(static_cast<int>(b), poses[static_cast<size_t>(b)]);
      });
    } catch (const py::value_error&) {
      forces_->state().pose = before;
      throw;
    }
  }

  py::dict compute() {
    py::gil_scoped_release release;
    const RelaxReport report = forces_->compute();
    py::gil_scoped_acquire acquire;
    return report_dict(report);
  }
  void recompute_forces() {
    py::gil_scoped_release release;
    forces_->recompute_forces();
  }

  int count() const { return forces_->body_count(); }
  py::array_t<double> moments() const { return per_body(count(), [&](int b) { return forces_->moment(b); }); }
  py::array_t<double> forces() const { return per_body(count(), [&](int b) { return forces_->force(b); }); }
  py::array_t<double> torques() const { return per_body(count(), [&](int b) { return forces_->torque(b); }); }

  void set_active(const py::object& body, bool active) { forces_->set_active(index(body), active); }
  bool active(const py::object& body) const { return forces_->active(index(body)); }
  void set_magnetization_scale(const py::object& body, double scale) {
    const int b = index(body);
    checked("set_magnetization_scale", [&] { forces_->set_magnetization_scale(b, scale); });
  }
  double magnetization_scale(const py::object& body) const { return forces_->magnetization_scale(index(body)); }
  py::array_t<double> external_field() const {
    const Vec3 H = forces_->external_field();
    return double_array({H.x, H.y, H.z});
  }
  void set_external_field(const py::object& H) {
    const Vec3 field = vec3_from(H, "external_field");
    checked("external_field", [&] { forces_->set_external_field(field); });
  }
  const SceneDescription& scene() const { return scene_; }
  std::string backend_name() { return forces_->backend().name(); }

 private:
  int index(const py::object& body) const { return body_index(scene_.bodies, body); }

  SceneDescription scene_;
  std::unique_ptr<MagneticForces> forces_;
};

}  // namespace

void bind_simulation(py::module_& m) {
  const auto none = py::none();
  py::class_<PySimulation>(m, "Simulation", "A scene in motion (docs/python.md \"Simulation\").")
      .def(py::init<const SceneDescription&, const std::optional<std::string>&, const std::optional<int>&>(),
           py::arg("scene"), py::arg("backend") = none, py::arg("threads") = none)
      .def("step", &PySimulation::step, "One rigid step of time_step s (time-line events, magnetics, ODE).")
      .def("advance_to", &PySimulation::advance_to, py::arg("time"), "Steps until time >= t (s, within half a step).")
      .def("run", &PySimulation::run, py::arg("duration") = none,
           "Steps for duration s from now; None: up to the scene's simulation.duration (`odemag run`).")
      .def("finish", &PySimulation::finish, "Takes the end-of-run outcomes; returns outcomes (summary.json's).")
      .def_property_readonly("outcomes", &PySimulation::outcomes)
      .def_property_readonly("time", [](const PySimulation& s) { return s.simulation().time(); })
      .def_property_readonly("steps", [](const PySimulation& s) { return s.simulation().steps(); })
      .def_property_readonly(
          "notices", [](const PySimulation& s) { return s.simulation().notices(); },
          "Notices as odemag run prints them (a contact outside its refined contact zones), oldest first.")
      .def_property_readonly("time_step", [](const PySimulation& s) { return s.simulation().scene().simulation.time_step; })
      .def_property_readonly("duration", [](const PySimulation& s) { return s.simulation().scene().simulation.duration; })
      .def_property_readonly("body_names", [](const PySimulation& s) { return names(s.simulation().scene()); })
      .def_property_readonly("backend", &PySimulation::backend_name)
      .def_property_readonly("positions", &PySimulation::positions, "(B, 3) centres of mass, m")
      .def_property_readonly("quaternions", &PySimulation::quaternions, "(B, 4) orientations, ODE's order w, x, y, z (body to world)")
      .def_property_readonly("velocities", &PySimulation::velocities, "(B, 3) m/s")
      .def_property_readonly("angular_velocities", &PySimulation::angular_velocities, "(B, 3) rad/s")
      .def_property_readonly("moments", &PySimulation::moments, "(B, 3) magnetic moments, A m^2")
      .def_property_readonly("forces", &PySimulation::forces, "(B, 3) magnetic forces, N (last substep)")
      .def_property_readonly("torques", &PySimulation::torques, "(B, 3) magnetic torques about the centres of mass, N m")
      .def_property_readonly("present", &PySimulation::present)
      .def_property_readonly("records", &PySimulation::records,
                             "Per rigid step, a dict of arrays (time s; magnetic_ms, rigid_ms, wall_ms ms; substeps, "
                             "iterations, ...; docs/python.md)")
      .def("set_magnetization_scale", &PySimulation::set_magnetization_scale, py::arg("body"), py::arg("scale"))
      .def("magnetization_scale", &PySimulation::magnetization_scale, py::arg("body"))
      .def_property("external_field", &PySimulation::external_field, &PySimulation::set_external_field);

  py::class_<PyMagnetics>(m, "Magnetics", "A scene's magnetics at poses you set (docs/python.md \"Magnetics\").")
      .def(py::init<const SceneDescription&, const std::optional<std::string>&, const std::optional<int>&>(),
           py::arg("scene"), py::arg("backend") = none, py::arg("threads") = none)
      .def("set_poses", &PyMagnetics::set_poses, py::arg("positions"), py::arg("rotations"),
           "positions (B, 3) m; rotations (B, 4) quaternions w, x, y, z or (B, 3, 3) body-to-world matrices.")
      .def("compute", &PyMagnetics::compute,
           "Relaxes from the last moments and computes forces and torques at the poses; the report as a dict.")
      .def("recompute_forces", &PyMagnetics::recompute_forces,
           "Forces and torques at the current poses with the magnetization of the last compute() held.")
      .def_property_readonly("body_names", [](const PyMagnetics& s) { return names(s.scene()); })
      .def_property_readonly("backend", &PyMagnetics::backend_name)
      .def_property_readonly("moments", &PyMagnetics::moments, "(B, 3) A m^2")
      .def_property_readonly("forces", &PyMagnetics::forces, "(B, 3) N")
      .def_property_readonly("torques", &PyMagnetics::torques, "(B, 3) N m about the centres of mass")
      .def("set_active", &PyMagnetics::set_active, py::arg("body"), py::arg("active"))
      .def("active", &PyMagnetics::active, py::arg("body"))
      .def("set_magnetization_scale", &PyMagnetics::set_magnetization_scale, py::arg("body"), py::arg("scale"))
      .def("magnetization_scale", &PyMagnetics::magnetization_scale, py::arg("body"))
      .def_property("external_field", &PyMagnetics::external_field, &PyMagnetics::set_external_field);
}

}  // namespace odemag::python
