// Placeholder until the scene loader lands (issue 2, item 3).
#include "engine/scene.h"

namespace odemag {

SceneError::SceneError(std::string file, std::string key, std::string message)
    : std::runtime_error(file + ": " + key + ": " + message),
      file_(std::move(file)), key_(std::move(key)), message_(std::move(message)) {}

int SceneDescription::find_body(const std::string& name) const {
  for (size_t b = 0; b < bodies.size(); ++b)
    if (bodies[b].name == name) return static_cast<int>(b);
  return -1;
}

SceneDescription parse_scene(const std::string&, const std::string& file) {
  throw SceneError(file, "", "scene loading is not implemented yet");
}

SceneDescription load_scene(const std::string& path) { return parse_scene("", path); }

}  // namespace odemag
