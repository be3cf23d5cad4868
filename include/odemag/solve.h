// A scene relaxed with its bodies held in place at t = 0: what `odemag solve`
// and `odemag field` report, and what the Python bindings' Scene.solve and
// Scene.field return (one computation, so the two agree bit for bit).
#pragma once

#include <functional>
#include <vector>

#include "odemag/scene.h"
#include "odemag/settings.h"
#include "odemag/vec3.h"

namespace odemag {

class MagneticBackend;  // magnetics/model/backend.h: opaque here

// Called after every outer iteration of the relaxation (RelaxOptions::progress).
using SolveProgressCallback = std::function<void(const RelaxReport&)>;

// One body of a solved scene, in the world frame; zeros for a body that is
// not present at t = 0.
struct SolvedBody {
  bool present = false;
  int cells = 0;
  Vec3 moment;  // A m^2
  Vec3 force;   // N
  Vec3 torque;  // N m, about the centre of mass
};

struct SceneSolution {
  std::vector<SolvedBody> bodies;  // scene order
  RelaxReport report;
};

// `odemag solve`: the scene's magnetic system with the time line's t = 0
// events (apply_events_at_start), relaxed and with forces and torques
// (magnetic_step).
SceneSolution solve_scene(const SceneDescription& scene, MagneticBackend& backend,
                          const SolveProgressCallback& progress = {});
// The same on the backend the scene's solver.backend and solver.threads ask
// for (std::invalid_argument as Simulation's constructor).
SceneSolution solve_scene(const SceneDescription& scene, const SolveProgressCallback& progress = {});

struct SceneField {
  std::vector<Vec3> B;  // T
  std::vector<Vec3> H;  // A/m
  RelaxReport report;
};

// `odemag field`: B and H at world points (m) of the scene relaxed as in
// solve_scene (relax only: the field needs no forces).
SceneField scene_field(const SceneDescription& scene, MagneticBackend& backend, const std::vector<Vec3>& points,
                       const SolveProgressCallback& progress = {});
SceneField scene_field(const SceneDescription& scene, const std::vector<Vec3>& points,
                       const SolveProgressCallback& progress = {});

}  // namespace odemag
