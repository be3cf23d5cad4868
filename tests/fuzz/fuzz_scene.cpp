// libFuzzer target: arbitrary bytes as the text of a scene file. The loader
// must return a scene or throw SceneError; any other exception, a crash, UB
// (ASan/UBSan), a hang or a huge allocation is a bug (docs/testing.md).
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <string>

#include "odemag/scene.h"

namespace {

// What an accepted scene promises (docs/scene-format.md): checked here so that
// a value the loader lets through and the simulation would choke on is a
// finding too. __builtin_trap: libFuzzer reports it with the input.
void check(bool ok) {
  if (!ok) __builtin_trap();
}

bool finite(const odemag::Vec3& v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }
bool usable_direction(const odemag::Vec3& v) {
  const double n = odemag::norm(v);
  return n > 0.0 && std::isfinite(n);
}

void check_scene(const odemag::SceneDescription& scene) {
  using namespace odemag;
  check(!scene.bodies.empty());
  check(std::isfinite(scene.cell_size) && scene.cell_size >= 0.0);
  check(finite(scene.gravity) && finite(scene.external_field));
  for (int b = 0; b < static_cast<int>(scene.bodies.size()); ++b) {
    const BodyDescription& body = scene.bodies[static_cast<size_t>(b)];
    check(validate_shape(body.shape).empty());
    check(scene.materials.count(body.material) == 1);
    check(finite(body.position) && finite(body.velocity) && finite(body.angular_velocity));
    const Quaternion& q = body.orientation;
    check(std::abs(q.w * q.w + q.x * q.x + q.y * q.y + q.z * q.z - 1.0) < 1e-9);
    check(body.density > 0.0 && std::isfinite(body.density));
    const double h = scene.body_cell_size(b);
    check(h >= 0.0 && std::isfinite(h));
    // The lattice stays within the loader's bound (2^22 points).
    if (h > 0.0 && !is_inert(scene.materials.at(body.material))) {
      const Vec3 half = shape_half_extents(body.shape);
      double points = 1.0;
      for (int a = 0; a < 3; ++a) points *= std::max(1.0, std::round(2.0 * half[a] / h));
      check(points <= 4194304.0);
    }
  }
  for (const auto& [name, material] : scene.materials) {
    check(validate_material(material).empty());
    if (const auto* soft = std::get_if<SoftMaterial>(&material)) check(usable_direction(soft->easy_axis));
  }
  for (const TimelineEvent& e : scene.timeline) {
    check(std::isfinite(e.time) && e.time >= 0.0 && e.end_time >= e.time && std::isfinite(e.end_time));
    if (!e.body.empty()) check(scene.find_body(e.body) >= 0);
    for (size_t k = 1; k < e.keys.size(); ++k) check(e.keys[k].time > e.keys[k - 1].time);
  }
  const CameraSettings& c = scene.camera;
  check(usable_direction(c.target - c.position) && usable_direction(c.up));
  check(odemag::norm(odemag::cross(odemag::normalized(c.target - c.position), odemag::normalized(c.up))) >= 1e-9);
  const SimulationSettings& sim = scene.simulation;
  check(sim.time_step > 0.0 && sim.frame_rate > 0.0 && sim.duration >= 0.0 && std::isfinite(sim.duration));
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  try {
    check_scene(odemag::parse_scene(text, "fuzz.json"));
  } catch (const odemag::SceneError& e) {
    // Rejected with a message naming the file: fine.
    check(std::string(e.what()).rfind("fuzz.json: ", 0) == 0);
  }
  // Any other exception escapes and libFuzzer reports it as a crash.
  return 0;
}
