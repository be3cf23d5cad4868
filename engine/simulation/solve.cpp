#include "odemag/solve.h"

#include "engine/simulation/magnetic_system.h"
#include "gpu/backend_choice.h"
#include "magnetics/relax/relax.h"

#include "magnetics/model/state.h"

namespace odemag {

namespace {

// The system at t = 0 and its relaxation options, with the progress callback.
RelaxOptions start(const SceneDescription& scene, MagneticSystem& system, const SolveProgressCallback& progress) {
  RelaxOptions o = scene.solver.relax;
  apply_events_at_start(scene, system, o);
  o.progress = progress;
  return o;
}

}  // namespace

SceneSolution solve_scene(const SceneDescription& scene, MagneticBackend& backend,
                          const SolveProgressCallback& progress) {
  MagneticSystem ms = build_magnetic_system(scene);
  const RelaxOptions options = start(scene, ms, progress);
  SceneSolution s;
  s.report = magnetic_step(ms.model, ms.state, options, backend);
  s.bodies.resize(scene.bodies.size());
  for (size_t b = 0; b < scene.bodies.size(); ++b) {
    const int i = static_cast<int>(b);
    SolvedBody& body = s.bodies[b];
    body.present = ms.state.active[b] != 0;
    body.cells = ms.model.body(i).cell_count();
    if (!body.present) continue;
    body.moment = body_moment(ms.model, ms.state, i);
    body.force = ms.state.force[b];
    body.torque = ms.state.torque[b];
  }
  return s;
}

SceneField scene_field(const SceneDescription& scene, MagneticBackend& backend, const std::vector<Vec3>& points,
                       const SolveProgressCallback& progress) {
  MagneticSystem ms = build_magnetic_system(scene);
  const RelaxOptions options = start(scene, ms, progress);
  SceneField f;
  f.report = relax(ms.model, ms.state, options, backend);
  field_at_points(ms.model, ms.state, backend, points, f.B, f.H);
  return f;
}

namespace {

std::unique_ptr<MagneticBackend> scene_backend(const SceneDescription& scene) {
  return make_backend(scene.solver.backend, scene.solver.threads, nullptr, cpu_only_feature(scene));
}

}  // namespace

SceneSolution solve_scene(const SceneDescription& scene, const SolveProgressCallback& progress) {
  return solve_scene(scene, *scene_backend(scene), progress);
}

SceneField scene_field(const SceneDescription& scene, const std::vector<Vec3>& points,
                       const SolveProgressCallback& progress) {
  return scene_field(scene, *scene_backend(scene), points, progress);
}

}  // namespace odemag
