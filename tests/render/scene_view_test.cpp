// Pictures of simulations (render/scene_view.h): what is drawn for a
// scene's state, field lines, and the frames `odemag run` writes.
#include "render/scene_view.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>

#include "magnetics/relax/relax.h"
#include "tests/support/mesh_builders.h"
#include "tests/support/scene_builders.h"
#include "engine/simulation/rigid_world.h"

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

// A mesh magnet and a compound are drawn as surfaces (three vertices per
// triangle, unit normals), the magnet split by its magnetization.
TEST(SceneView, MeshesAndCompoundsAreSurfaces) {
  SceneDescription scene = small_scene();
  scene.bodies[0].shape = test::box_surface_mesh({0.04, 0.01, 0.01}, 2);
  std::vector<CompoundPart> parts(2);
  parts[0].shape = Box{{0.01, 0.02, 0.02}};
  parts[0].position = {-0.005, 0, 0};
  parts[1].shape = Sphere{0.008};
  parts[1].position = {0.008, 0, 0};
  scene.bodies[2].shape = Compound(parts);
  Simulation sim(scene, make_cpu_backend(1));
  sim.step();
  const RenderFrame view = render_scene_of(sim, ViewOptions{}, nullptr);
  ASSERT_EQ(view.primitives.size(), 3u);
  for (int k : {0, 2}) {
    const RenderPrimitive& p = view.primitives[k];
    ASSERT_EQ(p.kind, RenderPrimitive::Kind::surface);
    ASSERT_TRUE(p.surface);
    ASSERT_EQ(p.surface->positions.size() % 9, 0u);
    ASSERT_EQ(p.surface->normals.size(), p.surface->positions.size());
    for (size_t i = 0; i < p.surface->normals.size(); i += 3)
      EXPECT_NEAR(std::hypot(p.surface->normals[i], p.surface->normals[i + 1], p.surface->normals[i + 2]), 1.0, 1e-5);
  }
  EXPECT_EQ(view.primitives[0].surface->positions.size(), 9u * 48u);  // 8 triangles per face
  EXPECT_GT(view.primitives[0].pole_axis.x, 0.99);
  EXPECT_NEAR(view.primitives[0].surface->radius, std::sqrt(0.02 * 0.02 + 2 * 0.005 * 0.005), 1e-9);
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
  EXPECT_EQ(view.text[1], scene.title);                     // the whole title (wrapped by the renderer)
  // The legend names the pole colours the magnet is drawn in, and a scale.
  EXPECT_TRUE(view.legend.poles);
  EXPECT_EQ(view.legend.north, view.primitives[0].north_color);
  EXPECT_EQ(view.legend.south, view.primitives[0].south_color);
  EXPECT_TRUE(view.legend.scale_bar);
  EXPECT_TRUE(view.legend.colorbar.empty());  // force colours off
  ViewOptions bare;
  bare.legend = false;
  EXPECT_FALSE(render_scene_of(sim, bare, nullptr).legend.any());
}

// A coil carried by the (turned, shifted) wood block is drawn as copper
// polylines at the block's pose: a circular coil's four rings, every point at
// its inner or outer radius from the turned axis, on its end planes.
TEST(SceneView, CoilsAreDrawnAtTheirBodysPose) {
  SceneDescription scene = small_scene();
  CircularCoil coil;
  coil.inner_radius = 0.01;
  coil.outer_radius = 0.015;
  coil.length = 0.02;
  coil.current = 100.0;
  coil.centre = {0.0, 0.0, 0.005};  // body frame
  scene.bodies[2].coils.push_back(coil);
  scene.bodies[2].orientation = {std::cos(0.25 * M_PI), std::sin(0.25 * M_PI), 0.0, 0.0};  // 90 degrees about x
  Simulation sim(scene, make_cpu_backend(1));
  const RenderFrame view = render_scene_of(sim, ViewOptions{}, nullptr);
  const BodyPose pose = sim.world().pose(2);
  const Vec3 axis = pose.rotation * Vec3{0.0, 0.0, 1.0}, centre = pose.position + pose.rotation * coil.centre;
  int copper = 0;
  for (const RenderLine& line : view.lines) {
    if (line.color != palette::copper) continue;
    ++copper;
    for (const Vec3& x : line.points) {
      const Vec3 d = x - centre;
      const double along = dot(d, axis), radial = norm(d - along * axis);
      EXPECT_NEAR(std::fabs(along), 0.01, 1e-9);
      EXPECT_TRUE(std::fabs(radial - 0.01) < 1e-9 || std::fabs(radial - 0.015) < 1e-9) << radial;
    }
  }
  EXPECT_EQ(copper, 4);
}

TEST(SceneView, ForceColoursRankBodiesByForce) {
  SceneDescription scene = small_scene();
  scene.render.force_colors = true;
  Simulation sim(scene, make_cpu_backend(1));
  sim.step();
  const RenderFrame view = render_scene_of(sim, view_options(scene), nullptr);
  // The ball feels the largest force: the top of the force map (yellow, not
  // the north pole's red); the magnet keeps its poles.
  EXPECT_EQ(view.primitives[1].color, force_color(1.0));
  EXPECT_GT(hue_degrees(view.primitives[1].color), 40.0);
  EXPECT_GT(norm(view.primitives[0].pole_axis), 0.0);
  // The legend's colour bar: the same map, from 0 to the strongest force (N).
  ASSERT_GE(view.legend.colorbar.size(), 2u);
  EXPECT_EQ(view.legend.colorbar.front(), force_color(0.0));
  EXPECT_EQ(view.legend.colorbar.back(), force_color(1.0));
  EXPECT_EQ(view.legend.colorbar_low, 0.0);
  EXPECT_NEAR(view.legend.colorbar_high, norm(sim.magnetics().force(1)), 1e-12);
  EXPECT_EQ(view.legend.colorbar_unit, "N");
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

// No permanent magnet: an electromagnet's core (a soft box driven by its coil
// along +z) and a small steel ball far off.
SceneDescription electromagnet_scene(const Vec3& coil_field) {
  SceneDescription s;
  s.file = "electromagnet";
  s.gravity = {0, 0, 0};
  s.simulation.ground = false;
  SoftMaterial core;
  core.saturation = 1.6e6;
  core.susceptibility = 1000;
  core.coil_field = coil_field;
  s.materials["core"] = core;
  SoftMaterial steel;
  steel.saturation = 1.6e6;
  steel.susceptibility = 1000;
  s.materials["steel"] = steel;
  s.bodies.push_back(test_support::body("core", Box{{0.02, 0.02, 0.04}}, "core", {0, 0, 0.05}, true));
  s.bodies.push_back(test_support::body("ball", Sphere{0.003}, "steel", {0.08, 0, 0.05}, true));
  s.cell_size = 0.005;
  s.camera.position = {0.0, -0.3, 0.08};
  s.camera.target = {0, 0, 0.05};
  return s;
}

TEST(SceneView, FieldLinesStartAtAnElectromagnet) {
  Simulation sim(electromagnet_scene({0, 0, 5e4}), make_cpu_backend(1));
  sim.step();
  const MagneticForces& m = sim.magnetics();
  const auto sources = field_sources(m.model(), m.state());
  ASSERT_GE(sources.size(), 1u);
  EXPECT_EQ(sources[0].body, 0);
  EXPECT_EQ(sources[0].kind, FieldSource::Kind::electromagnet);
  EXPECT_GT(sources[0].axis.z, 0.99);  // magnetized along its coil
  // The ball's induced moment is far below the core's: no lines of its own.
  for (const FieldSource& s : sources) EXPECT_NE(s.body, 1);
  auto backend = make_cpu_backend(1);
  const auto lines = trace_field_lines(m.model(), m.state(), *backend, 8, 0.3);
  ASSERT_EQ(lines.size(), 8u);
  int returned = 0;
  for (const RenderLine& line : lines) {
    ASSERT_GE(line.points.size(), 2u);
    const Vec3 start = line.points.front();
    EXPECT_GT(start.z, 0.05 + 0.02) << "starts beyond the core's north (+z) face";
    EXPECT_LT(start.z, 0.05 + 0.025);
    EXPECT_LT(std::hypot(start.x, start.y), 0.01);
    const Vec3 end = line.points.back();
    if (std::abs(end.x) < 0.011 && std::abs(end.y) < 0.011 && std::abs(end.z - 0.05) < 0.021) {
      ++returned;
      EXPECT_LT(end.z, 0.05);  // back in through the south half
    }
  }
  EXPECT_GE(returned, 4);
  // Coil off and never magnetized: nothing to draw.
  Simulation off(electromagnet_scene({0, 0, 0}), make_cpu_backend(1));
  off.step();
  EXPECT_TRUE(trace_field_lines(off.magnetics().model(), off.magnetics().state(), *backend, 8, 0.3).empty());
}

TEST(SceneView, FieldLinesStartAtAnInducedBody) {
  // A steel ball in a uniform applied field, nothing else magnetic.
  SceneDescription scene = electromagnet_scene({0, 0, 0});
  scene.bodies.resize(2);
  scene.bodies[0].material = "steel";  // a plain soft core: induced only
  scene.external_field = {1e4, 0, 0};
  Simulation sim(scene, make_cpu_backend(1));
  sim.step();
  const MagneticForces& m = sim.magnetics();
  const auto sources = field_sources(m.model(), m.state());
  ASSERT_GE(sources.size(), 1u);
  EXPECT_EQ(sources[0].kind, FieldSource::Kind::induced);
  EXPECT_GT(sources[0].axis.x, 0.9);  // along the applied field
  auto backend = make_cpu_backend(1);
  const auto lines = trace_field_lines(m.model(), m.state(), *backend, 8, 0.3);
  ASSERT_FALSE(lines.empty());
  for (const RenderLine& line : lines) {
    const Vec3 start = line.points.front();
    // On the +x face of the core or just outside the ball's +x side.
    const bool at_core = start.x > 0.01 && start.x < 0.0125 && std::abs(start.z - 0.05) < 0.02;
    const bool at_ball = start.x > 0.08 && norm(start - Vec3{0.08, 0, 0.05}) < 1.3 * 0.003;
    EXPECT_TRUE(at_core || at_ball) << start.x << " " << start.y << " " << start.z;
  }
}

TEST(SceneView, GlassTubeShowsTheBallInside) {
  // A red ball in a square glass tube, seen through the tube's front wall.
  SceneDescription s;
  s.file = "tube";
  s.title = "tube";
  s.gravity = {0, 0, 0};
  s.simulation.ground = false;
  SoftMaterial steel;
  steel.saturation = 1.6e6;
  s.materials["steel"] = steel;
  s.materials["glass"] = InertMaterial{};
  s.material_colors["steel"] = {0.9, 0.1, 0.1};
  s.material_colors["glass"] = {0.75, 0.85, 0.9};
  auto add = [&](const std::string& name, const Shape& shape, const std::string& material, const Vec3& p) {
    s.bodies.push_back(test_support::body(name, shape, material, p, true));
  };
  add("ball", Sphere{0.005}, "steel", {0, 0, 0.04});
  add("tube_1", Box{{0.002, 0.03, 0.08}}, "glass", {0.0066, 0, 0.04});
  add("tube_2", Box{{0.002, 0.03, 0.08}}, "glass", {-0.0066, 0, 0.04});
  add("tube_3", Box{{0.03, 0.002, 0.08}}, "glass", {0, 0.0066, 0.04});
  add("tube_4", Box{{0.03, 0.002, 0.08}}, "glass", {0, -0.0066, 0.04});
  s.camera.position = {0.0, -0.15, 0.04};
  s.camera.target = {0, 0, 0.04};
  s.camera.width = 96;
  s.camera.height = 72;
  Simulation sim(s, make_cpu_backend(1));
  sim.step();
  ViewOptions options;
  options.caption = false;
  options.legend = false;
  const RenderFrame view = render_scene_of(sim, options, nullptr);
  ASSERT_EQ(view.primitives.size(), 5u);
  EXPECT_EQ(view.primitives[0].opacity, 1.0f);
  for (std::size_t i = 1; i < 5; ++i) EXPECT_LT(view.primitives[i].opacity, 0.5f);
  OffscreenRenderer renderer(96, 72);
  const auto rgb = renderer.render(view);
  // The ball's red shows in the middle of the tube (the front wall covers it).
  int red = 0;
  for (int y = 30; y < 42; ++y)
    for (int x = 42; x < 54; ++x) {
      const std::size_t i = (static_cast<std::size_t>(y) * 96 + static_cast<std::size_t>(x)) * 3;
      if (rgb[i] > rgb[i + 1] + 50 && rgb[i] > rgb[i + 2] + 50) ++red;
    }
  EXPECT_GT(red, 20);
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
