// Builds the magnetic model and state of a scene. Model body b is scene body b
// (inert bodies are bodies without cells), so indices agree everywhere.
#pragma once

#include <memory>
#include <string>

#include "engine/scene/scene.h"
#include "magnetics/backend.h"
#include "magnetics/model.h"
#include "magnetics/state.h"

namespace odemag {

// The magnetic system of a scene: its model and its state. ("Scene" names one
// type, the scene file's SceneDescription; the renderer draws RenderFrames.)
struct MagneticSystem {
  MagneticModel model;
  MagneticState state;  // poses from the scene, bodies with present=false inactive
};

// Throws SceneError naming the body when a shape or material is rejected.
MagneticSystem build_magnetic_system(const SceneDescription& scene);

// The body's pose in the scene description.
BodyPose scene_pose(const BodyDescription& body);

// Backend by name: "cpu", "cuda" or "auto". "auto" falls back to the CPU
// backend when no CUDA device is usable and writes one notice to `notice`;
// "cuda" without a device throws std::invalid_argument (usage error, exit 2).
std::unique_ptr<MagneticBackend> make_backend(const std::string& name, int threads,
                                              std::string* notice);

}  // namespace odemag
