// Scene builders of the tests and the benchmarks (tests/support/): bodies and
// materials for SceneDescriptions. Needs odemag_engine (engine/scene).
#pragma once

#include <string>

#include "odemag/scene.h"

namespace odemag::test_support {

// Soft steel: M_s = 1.6e6 A/m, chi = 1000.
inline SoftMaterial steel() {
  SoftMaterial m;
  m.saturation = 1.6e6;
  m.susceptibility = 1000.0;
  return m;
}

// A body of `material` (a key of SceneDescription::materials) with its centre
// of mass at `position`, at rest, unrotated.
inline BodyDescription body(const std::string& name, const Shape& shape, const std::string& material,
                            const Vec3& position, bool fixed = false, double density = 7800.0) {
  BodyDescription b;
  b.name = name;
  b.shape = shape;
  b.material = material;
  b.position = position;
  b.fixed = fixed;
  b.density = density;
  return b;
}

// A scene named `file` with no gravity and no ground.
inline SceneDescription weightless_scene(const std::string& file) {
  SceneDescription s;
  s.file = file;
  s.gravity = {0, 0, 0};
  s.simulation.ground = false;
  return s;
}

}  // namespace odemag::test_support
