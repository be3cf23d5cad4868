#include "engine/sim/magnetic_system.h"

#include <stdexcept>

#include "gpu/cuda_backend.h"

namespace odemag {

BodyPose scene_pose(const BodyDescription& body) {
  BodyPose pose;
  pose.position = body.position;
  pose.rotation = rotation_from_quaternion(body.orientation.w, body.orientation.x,
                                           body.orientation.y, body.orientation.z);
  return pose;
}

MagneticSystem build_magnetic_system(const SceneDescription& scene) {
  MagneticSystem ms;
  for (size_t b = 0; b < scene.bodies.size(); ++b) {
    const BodyDescription& body = scene.bodies[b];
    const auto material = scene.materials.find(body.material);
    if (material == scene.materials.end())
      throw SceneError(scene.file, "bodies[" + std::to_string(b) + "].material",
                       "unknown material \"" + body.material + "\"");
    try {
      ms.model.add_body(body.name, body.shape, material->second, scene.body_cell_size(static_cast<int>(b)));
    } catch (const std::invalid_argument& e) {
      throw SceneError(scene.file, "bodies[" + std::to_string(b) + "]", e.what());
    }
  }
  ms.state = make_state(ms.model, scene.seed);
  ms.state.external_field = scene.external_field;
  for (size_t b = 0; b < scene.bodies.size(); ++b) {
    ms.state.pose[b] = scene_pose(scene.bodies[b]);
    ms.state.active[b] = scene.bodies[b].present ? 1 : 0;
  }
  place_cells(ms.model, ms.state);
  return ms;
}

std::unique_ptr<MagneticBackend> make_backend(const std::string& name, int threads,
                                              std::string* notice) {
  if (name == "cpu") return make_cpu_backend(threads);
  if (name == "cuda" || name == "auto") {
    std::string why;
    if (auto gpu = make_cuda_backend(&why)) return gpu;
    if (name == "cuda") throw std::invalid_argument("backend \"cuda\" is not available: " + why);
    if (notice) *notice = "odemag: no CUDA device (" + why + "); using the CPU backend";
    return make_cpu_backend(threads);
  }
  throw std::invalid_argument("unknown backend \"" + name + "\" (cpu, cuda or auto)");
}

}  // namespace odemag
