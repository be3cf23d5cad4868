// Pictures of simulations (demos/view/scene_view.h): what is drawn for a
// scene's state, field lines, and the frames `odemag run` writes.
#include "demos/view/scene_view.h"

#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>

#include "magnetics/relax.h"
#include "tests/support/scene_builders.h"

namespace odemag {
namespace {

// A bar magnet (M along +x), a steel ball, a wood block.
SceneDescription small_scene() {
  SceneDescription s;
  s.file = "view";
  s.title = "View test: a magnet, a ball and a block";
  s.materials["magnet"] = PermanentMaterial{{8e5, 0, 0}, 0.0};
  SoftMaterial steel;
  steel.saturation = 1.6e6;
  s.materials["steel"] = steel;
  s.materials["wood"] = InertMaterial{};
  auto add = [&](const std::string& name, const Shape& shape, const std::string& material, const Vec3& p) {
    s.bodies.push_back(test_support::body(name, shape, material, p, true, BodyDescription{}.density));
  };
  add("magnet", Box{{0.04, 0.01, 0.01}}, "magnet", {0, 0, 0.02});
  add("ball", Sphere{0.005}, "steel", {0.04, 0, 0.02});
  add("block", Box{{0.02, 0.02, 0.02}}, "wood", {-0.05, 0, 0.01});
  s.cell_size = 0.005;
  s.camera.position = {0.0, -0.2, 0.08};
  s.camera.target = {0, 0, 0.02};
  s.camera.width = 96;
  s.camera.height = 72;
  return s;
}

TEST(SceneView, MagnetsSplitAlongTheirMagnetizationOthersInTheirColours) {
  SceneDescription scene = small_scene();
  scene.material_colors["wood"] = {0.6, 0.4, 0.2};
  Simulation sim(scene, make_cpu_backend(1));
  sim.step();
  const RenderFrame view = render_scene_of(sim, ViewOptions{}, nullptr);
  ASSERT_EQ(view.primitives.size(), 3u);
  EXPECT_GT(view.primitives[0].pole_axis.x, 0.99);          // north along +M
  EXPECT_EQ(norm(view.primitives[1].pole_axis), 0.0);       // soft ball: one colour
  EXPECT_NEAR(view.primitives[2].color[0], 0.6f, 1e-6);     // the material's colour
  ASSERT_EQ(view.text.size(), 2u);
  EXPECT_EQ(view.text[1], "View test");                     // the title up to its colon
}

TEST(SceneView, ForceColoursRankBodiesByForce) {
  SceneDescription scene = small_scene();
  scene.render.force_colors = true;
  Simulation sim(scene, make_cpu_backend(1));
  sim.step();
  const RenderFrame view = render_scene_of(sim, view_options(scene), nullptr);
  // The ball feels the largest force: red (t = 1); the magnet keeps its poles.
  EXPECT_LT(hue_degrees(view.primitives[1].color), 10.0);
}

TEST(SceneView, FieldLinesLeaveTheNorthFaceAndReturnToTheMagnet) {
  SceneDescription scene = small_scene();
  Simulation sim(scene, make_cpu_backend(1));
  sim.step();
  auto backend = make_cpu_backend(1);
  const MagneticForces& m = sim.magnetics();
  const auto lines = trace_field_lines(m.model(), m.state(), *backend, 8, 0.2);
  ASSERT_EQ(lines.size(), 8u);
  int returned = 0;
  for (const RenderLine& line : lines) {
    ASSERT_GE(line.points.size(), 2u);
    EXPECT_GT(line.points.front().x, 0.0199);  // start beyond the +x (north) face
    for (const Vec3& p : line.points) ASSERT_TRUE(is_finite(p));
    // A closed line ends back at the magnet, on its south side.
    const Vec3 end = line.points.back();
    if (std::abs(end.x) < 0.021 && std::abs(end.y) < 0.006 && std::abs(end.z - 0.02) < 0.006) {
      ++returned;
      EXPECT_LT(end.x, 0.0);
    }
  }
  EXPECT_GE(returned, 4);
}

TEST(SceneView, RunWritesOnePngPerFrame) {
  const std::filesystem::path dir = std::filesystem::temp_directory_path() / "odemag_view_frames";
  std::filesystem::remove_all(dir);
  const std::string scene = std::string(ODEMAG_SOURCE_DIR) + "/demos/scenes/ball_chain.json";
  const std::string command = std::string(ODEMAG_BINARY_DIR) + "/bin/odemag run '" + scene + "' --out '" +
                              dir.string() + "' --duration 0.2 --frame-rate 10 --width 64 --height 48 --quiet yes"
                              " --backend cpu 2>/dev/null";
  ASSERT_EQ(std::system(command.c_str()), 0);
  for (int k = 0; k <= 2; ++k) {
    char name[32];
    std::snprintf(name, sizeof name, "frame_%05d.png", k);
    EXPECT_TRUE(std::filesystem::exists(dir / name)) << name;
    EXPECT_GT(std::filesystem::file_size(dir / name), 100u);
  }
  EXPECT_FALSE(std::filesystem::exists(dir / "frame_00003.png"));
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace odemag
