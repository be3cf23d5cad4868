// The scene loader: examples/bar_and_ball.json (docs/scene-format.md), every
// other key, and each class of rejection with the key path it must name.
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <string>

#include "odemag/scene.h"

namespace odemag {
namespace {

const char* kInterfaceExample = R"({
  "gravity": [0, 0, -9.81],
  "external_field": [0, 0, 0],
  "cell_size": 0.004,
  "materials": {
    "magnet": {"type": "permanent", "magnetization": [0, 0, 1.0e6]},
    "iron":   {"type": "soft", "saturation": 1.7e6, "susceptibility": 5000},
    "wood":   {"type": "inert"}
  },
  "bodies": [
    {"name": "bar", "shape": {"box": [0.10, 0.02, 0.02]}, "material": "magnet",
     "position": [0, 0, 0.10], "orientation": [1, 0, 0, 0], "fixed": true},
    {"name": "ball", "shape": {"sphere": 0.006}, "material": "iron",
     "position": [0, 0, 0.05], "density": 7870}
  ]
})";

// A valid scene with `extra` spliced in as further top-level keys.
std::string scene_with(const std::string& extra) {
  return R"({"materials": {"magnet": {"type": "permanent", "magnetization": [0, 0, 1e6]},
                           "iron": {"type": "soft", "saturation": 1.7e6}},
             "bodies": [{"name": "a", "shape": {"sphere": 0.01}, "material": "magnet"},
                        {"name": "b", "shape": {"sphere": 0.01}, "material": "iron",
                         "position": [0, 0, 0.05]}])" +
         std::string(extra.empty() ? "" : ", ") + extra + "}";
}

// The body list `bodies` with one permanent material "m".
std::string bodies_scene(const std::string& bodies) {
  return R"({"materials": {"m": {"type": "permanent", "magnetization": [0, 0, 1e6]}}, "bodies": )" +
         bodies + "}";
}

// Parses text that must be rejected; returns the error.
SceneError rejection(const std::string& text) {
  try {
    parse_scene(text, "bad.json");
  } catch (const SceneError& e) {
    return e;
  }
  ADD_FAILURE() << "accepted: " << text;
  return SceneError("", "", "");
}

void expect_key(const std::string& text, const std::string& key) {
  const SceneError e = rejection(text);
  EXPECT_EQ(e.file(), "bad.json");
  EXPECT_EQ(e.key(), key) << e.what();
  EXPECT_FALSE(e.message().empty());
  EXPECT_EQ(std::string(e.what()), key.empty() ? "bad.json: " + e.message()
                                               : "bad.json: " + key + ": " + e.message());
}

TEST(SceneParser, InterfaceExample) {
  const SceneDescription s = parse_scene(kInterfaceExample, "example.json");
  EXPECT_EQ(s.file, "example.json");
  EXPECT_EQ(s.gravity.z, -9.81);
  EXPECT_EQ(s.cell_size, 0.004);
  ASSERT_EQ(s.materials.size(), 3u);
  const auto& magnet = std::get<PermanentMaterial>(s.materials.at("magnet"));
  EXPECT_EQ(magnet.magnetization.z, 1.0e6);
  EXPECT_EQ(magnet.recoil_susceptibility, 0.0);
  const auto& iron = std::get<SoftMaterial>(s.materials.at("iron"));
  EXPECT_EQ(iron.saturation, 1.7e6);
  EXPECT_EQ(iron.susceptibility, 5000.0);
  EXPECT_EQ(iron.moments_per_cell, 2);
  EXPECT_TRUE(std::holds_alternative<InertMaterial>(s.materials.at("wood")));

  ASSERT_EQ(s.bodies.size(), 2u);
  const BodyDescription& bar = s.bodies[0];
  EXPECT_EQ(bar.name, "bar");
  const Box& box = std::get<Box>(bar.shape);
  EXPECT_EQ(box.size.x, 0.10);
  EXPECT_EQ(box.size.y, 0.02);
  EXPECT_EQ(bar.material, "magnet");
  EXPECT_EQ(bar.position.z, 0.10);
  EXPECT_EQ(bar.orientation.w, 1.0);
  EXPECT_TRUE(bar.fixed);
  EXPECT_FALSE(bar.cell_size.has_value());  // inherits the scene's 0.004
  EXPECT_EQ(bar.density, 1000.0);
  const BodyDescription& ball = s.bodies[1];
  EXPECT_EQ(std::get<Sphere>(ball.shape).radius, 0.006);
  EXPECT_EQ(ball.density, 7870.0);
  EXPECT_FALSE(ball.fixed);
  EXPECT_TRUE(ball.present);
  // docs/scene-format.md "Bodies": a sphere without a cell_size of its own is
  // one cell; the bar inherits the scene's spacing.
  EXPECT_FALSE(ball.cell_size.has_value());
  EXPECT_EQ(s.body_cell_size(1), 0.0);
  EXPECT_EQ(s.body_cell_size(0), 0.004);
  EXPECT_EQ(s.find_body("ball"), 1);
  EXPECT_EQ(s.find_body("nothing"), -1);
  // Defaults of what the example leaves out.
  EXPECT_EQ(s.seed, 1u);
  EXPECT_EQ(s.solver.backend, BackendKind::automatic);
  EXPECT_EQ(s.solver.relax.scheme, RelaxScheme::two_level);
  EXPECT_TRUE(s.timeline.empty());
}

TEST(SceneParser, ExampleFileMatchesInterface) {
  const SceneDescription s = load_scene(ODEMAG_SOURCE_DIR "/examples/bar_and_ball.json");
  const SceneDescription t = parse_scene(kInterfaceExample, "x");
  ASSERT_EQ(s.bodies.size(), t.bodies.size());
  for (size_t b = 0; b < s.bodies.size(); ++b) {
    EXPECT_EQ(s.bodies[b].name, t.bodies[b].name);
    EXPECT_EQ(s.bodies[b].position.z, t.bodies[b].position.z);
  }
}

TEST(SceneParser, EveryExampleLoads) {
  for (const char* name : {"bar_and_ball", "two_magnets", "iron_between_magnets", "drop_on_magnet", "solenoid_plunger",
                           "superconductor_levitation", "relay_armature"})
    EXPECT_NO_THROW(load_scene(std::string(ODEMAG_SOURCE_DIR "/examples/") + name + ".json")) << name;
}

TEST(SceneParser, AllSettings) {
  const SceneDescription s = parse_scene(scene_with(R"(
    "title": "all", "seed": 42, "external_field": [1, 2, 3],
    "solver": {"scheme": "paper", "tolerance": 1e-5, "max_iterations": 50, "anderson_depth": 0,
               "mixing": 0.5, "mutual_induction": false, "time_step_factor": 0.3, "noise": 0,
               "far_field_theta": 0.5, "skip_unchanged": true, "near_field": false, "backend": "cpu",
               "threads": 3},
    "simulation": {"time_step": 0.001, "duration": 1.5, "frame_rate": 60, "solver_iterations": 20,
                   "ground": false, "ground_height": -0.1,
                   "contact": {"friction": 0.3, "restitution": 0.5, "softness": 0, "erp": 0.8,
                               "rolling_friction": 2e-5, "spinning_friction": 0},
                   "linear_damping": 0.01, "angular_damping": 0.02, "max_substeps": 8,
                   "stiffness_limit": 0.5},
    "camera": {"position": [1, 0, 0], "target": [0, 0, 0], "up": [0, 0, 2], "fov": 60,
               "width": 320, "height": 200},
    "render": {"field_lines": true, "field_line_count": 10, "force_colors": true},
    "outcomes": [{"name": "up", "count_above": {"prefix": "b", "height": 0.02}},
                 {"name": "early", "count_above": {"prefix": "", "height": 0}, "time": 0.5}])"),
                                         "all.json");
  EXPECT_EQ(s.title, "all");
  EXPECT_EQ(s.seed, 42u);
  EXPECT_EQ(s.external_field.y, 2.0);
  EXPECT_EQ(s.solver.relax.scheme, RelaxScheme::paper);
  EXPECT_EQ(s.solver.relax.tolerance, 1e-5);
  EXPECT_EQ(s.solver.relax.max_iterations, 50);
  EXPECT_EQ(s.solver.relax.anderson_depth, 0);
  EXPECT_EQ(s.solver.relax.mixing, 0.5);
  EXPECT_FALSE(s.solver.relax.mutual_induction);
  EXPECT_EQ(s.solver.relax.local.time_step_factor, 0.3);
  EXPECT_EQ(s.solver.relax.local.noise_ratio, 0.0);
  EXPECT_EQ(s.solver.relax.far_field_theta, 0.5);
  EXPECT_TRUE(s.solver.relax.skip_unchanged);
  EXPECT_FALSE(s.solver.relax.near_field);
  EXPECT_EQ(s.solver.backend, BackendKind::cpu);
  EXPECT_EQ(s.solver.threads, 3);
  EXPECT_EQ(s.simulation.time_step, 0.001);
  EXPECT_EQ(s.simulation.duration, 1.5);
  EXPECT_EQ(s.simulation.frame_rate, 60.0);
  EXPECT_EQ(s.simulation.solver_iterations, 20);
  EXPECT_FALSE(s.simulation.ground);
  EXPECT_EQ(s.simulation.ground_height, -0.1);
  EXPECT_EQ(s.simulation.contact.friction, 0.3);
  EXPECT_EQ(s.simulation.contact.restitution, 0.5);
  EXPECT_EQ(s.simulation.contact.softness, 0.0);
  EXPECT_EQ(s.simulation.contact.erp, 0.8);
  EXPECT_EQ(s.simulation.linear_damping, 0.01);
  EXPECT_EQ(s.simulation.angular_damping, 0.02);
  EXPECT_EQ(s.simulation.contact.rolling_friction, 2e-5);
  EXPECT_EQ(s.simulation.contact.spinning(), 0.0);
  EXPECT_EQ(s.simulation.max_substeps, 8);
  EXPECT_EQ(s.simulation.stiffness_limit, 0.5);
  EXPECT_EQ(s.camera.position.x, 1.0);
  EXPECT_EQ(s.camera.up.z, 2.0);
  EXPECT_EQ(s.camera.fov_degrees, 60.0);
  EXPECT_EQ(s.camera.width, 320);
  EXPECT_EQ(s.camera.height, 200);
  EXPECT_TRUE(s.render.field_lines);
  EXPECT_EQ(s.render.field_line_count, 10);
  EXPECT_TRUE(s.render.force_colors);
  ASSERT_EQ(s.outcomes.size(), 2u);
  EXPECT_EQ(s.outcomes[0].prefix, "b");
  EXPECT_EQ(s.outcomes[0].height, 0.02);
  EXPECT_EQ(s.outcomes[0].time, -1.0);
  EXPECT_EQ(s.outcomes[1].time, 0.5);
}

TEST(SceneParser, MaterialAndBodyDetails) {
  const SceneDescription s = parse_scene(R"({
    "materials": {
      "nd": {"type": "permanent", "magnetization": [1e6, 0, 0], "recoil_susceptibility": 0.05,
             "color": [1, 0, 0.5]},
      "fe": {"type": "soft", "saturation": 1e6, "susceptibility": "infinite", "anisotropy_field": 100,
             "easy_axis": [0, 2, 0], "damping": 0.5, "moments_per_cell": 4}},
    "bodies": [
      {"name": "c", "shape": {"cylinder": {"radius": 0.01, "length": 0.03}}, "material": "nd",
       "orientation": [2, 0, 0, 0], "velocity": [1, 2, 3], "angular_velocity": [0, 0, 1],
       "cell_size": 0.005, "present": false, "color": [0, 1, 0]},
      {"name": "s", "shape": {"sphere": 0.01}, "material": "fe", "cell_size": 0.004}]})",
                                         "d.json");
  const auto& nd = std::get<PermanentMaterial>(s.materials.at("nd"));
  EXPECT_EQ(nd.recoil_susceptibility, 0.05);
  EXPECT_EQ(s.material_colors.at("nd")[2], 0.5);
  EXPECT_EQ(s.material_colors.count("fe"), 0u);
  const auto& fe = std::get<SoftMaterial>(s.materials.at("fe"));
  EXPECT_TRUE(std::isinf(fe.susceptibility));
  EXPECT_EQ(fe.anisotropy_field, 100.0);
  EXPECT_EQ(fe.easy_axis.y, 2.0);
  EXPECT_EQ(fe.damping, 0.5);
  EXPECT_EQ(fe.moments_per_cell, 4);
  const BodyDescription& c = s.bodies[0];
  EXPECT_EQ(std::get<Cylinder>(c.shape).length, 0.03);
  EXPECT_EQ(c.orientation.w, 1.0);  // normalised
  EXPECT_EQ(c.velocity.y, 2.0);
  EXPECT_EQ(c.angular_velocity.z, 1.0);
  EXPECT_EQ(*c.cell_size, 0.005);
  EXPECT_FALSE(c.present);
  EXPECT_EQ((*c.color)[1], 1.0);
  EXPECT_EQ(*s.bodies[1].cell_size, 0.004);  // a sphere's own cell_size is kept
}

TEST(SceneParser, Timeline) {
  const SceneDescription s = parse_scene(scene_with(R"("timeline": [
      {"time": 0.5, "action": "add", "body": "b"},
      {"time": 1, "action": "remove", "body": "b"},
      {"time": 1, "action": "scale_magnetization", "body": "a", "to": 0.25, "end_time": 2},
      {"time": 3, "action": "scale_magnetization", "body": "a", "to": -1},
      {"time": 2, "action": "mutual_induction", "enabled": false},
      {"time": 0, "action": "external_field", "field": [0, 0, 1000], "end_time": 1},
      {"action": "keyframes", "body": "a", "keys": [
         {"time": 0.2, "position": [0, 0, 1]},
         {"time": 0.4, "position": [0, 0, 2], "orientation": [0, 0, 0, 3]}]}])"),
                                         "t.json");
  using Kind = TimelineEvent::Kind;
  ASSERT_EQ(s.timeline.size(), 7u);
  EXPECT_EQ(s.timeline[0].kind, Kind::add_body);
  EXPECT_EQ(s.timeline[0].body, "b");
  EXPECT_EQ(s.timeline[0].time, 0.5);
  EXPECT_EQ(s.timeline[0].end_time, 0.5);
  EXPECT_EQ(s.timeline[1].kind, Kind::remove_body);
  EXPECT_EQ(s.timeline[2].kind, Kind::scale_magnetization);
  EXPECT_EQ(s.timeline[2].value, 0.25);
  EXPECT_EQ(s.timeline[2].end_time, 2.0);
  EXPECT_EQ(s.timeline[3].end_time, 3.0);
  EXPECT_EQ(s.timeline[3].value, -1.0);
  EXPECT_EQ(s.timeline[4].kind, Kind::mutual_induction);
  EXPECT_FALSE(s.timeline[4].enabled);
  EXPECT_EQ(s.timeline[5].kind, Kind::external_field);
  EXPECT_EQ(s.timeline[5].field.z, 1000.0);
  EXPECT_EQ(s.timeline[5].end_time, 1.0);
  const TimelineEvent& k = s.timeline[6];
  EXPECT_EQ(k.kind, Kind::keyframes);
  EXPECT_EQ(k.time, 0.2);  // omitted: the first key's time
  EXPECT_EQ(k.end_time, 0.4);
  ASSERT_EQ(k.keys.size(), 2u);
  EXPECT_EQ(k.keys[0].position.z, 1.0);
  EXPECT_EQ(k.keys[0].orientation.w, 1.0);  // default: the body's orientation
  EXPECT_EQ(k.keys[1].orientation.z, 1.0);  // normalised
}

// ---- rejections ---------------------------------------------------------------------

TEST(SceneParser, RejectsBadJson) {
  const SceneError e = rejection("{\"materials\": {},\n \"bodies\": [1, 2,]}");
  EXPECT_EQ(e.key(), "bodies[2]");  // the value being read where the text breaks
  EXPECT_EQ(e.message().rfind("invalid JSON: ", 0), 0u) << e.what();
  EXPECT_NE(e.message().find("line 2"), std::string::npos) << e.what();
  EXPECT_NE(e.message().find("column"), std::string::npos) << e.what();
}

TEST(SceneParser, RejectsNanLiteralAsSyntaxError) {
  const SceneError e = rejection(R"({"gravity": [0, 0, NaN]})");
  EXPECT_EQ(e.key(), "gravity[2]");
  EXPECT_NE(e.message().find("line 1, column"), std::string::npos) << e.what();
}

TEST(SceneParser, RejectsOverflowingNumberWithItsKey) {
  expect_key(scene_with(R"("gravity": [0, 1e999, 0])"), "gravity[1]");
  expect_key(bodies_scene(R"([{"name": "a", "shape": {"sphere": -1e400}, "material": "m"}])"),
             "bodies[0].shape.sphere");
}

TEST(SceneParser, RejectsNonObjectAndEmptyText) {
  expect_key("[1, 2, 3]", "");
  expect_key("", "");
}

TEST(SceneParser, RejectsUnknownTopLevelKey) { expect_key(scene_with(R"("gravty": [0, 0, 1])"), "gravty"); }

TEST(SceneParser, RejectsUnknownNestedKeys) {
  expect_key(scene_with(R"("solver": {"tolerence": 1e-6})"), "solver.tolerence");
  expect_key(scene_with(R"("simulation": {"contact": {"bounce": 1}})"), "simulation.contact.bounce");
  expect_key(bodies_scene(R"([{"name": "a", "shape": {"sphere": 1}, "material": "m", "mass": 2}])"),
             "bodies[0].mass");
  expect_key(R"({"materials": {"m": {"type": "inert", "saturation": 1}}, "bodies": []})",
             "materials.m.saturation");
  expect_key(bodies_scene(R"([{"name": "a", "shape": {"cube": 1}, "material": "m"}])"),
             "bodies[0].shape.cube");
}

TEST(SceneParser, RejectsUnknownMaterialReference) {
  expect_key(bodies_scene(R"([{"name": "a", "shape": {"sphere": 1}, "material": "steel"}])"),
             "bodies[0].material");
}

TEST(SceneParser, RejectsBadShapes) {
  expect_key(bodies_scene(R"([{"name": "a", "shape": {"sphere": -0.01}, "material": "m"}])"),
             "bodies[0].shape.sphere");
  expect_key(bodies_scene(R"([{"name": "a", "shape": {"sphere": 1}, "material": "m"},
                              {"name": "b", "shape": {"box": [1, 0, 1]}, "material": "m"}])"),
             "bodies[1].shape.box[1]");
  expect_key(bodies_scene(R"([{"name": "a", "shape": {"box": [1, 1]}, "material": "m"}])"),
             "bodies[0].shape.box");
  expect_key(bodies_scene(R"([{"name": "a", "shape": {"cylinder": {"radius": 1}}, "material": "m"}])"),
             "bodies[0].shape.cylinder.length");
  expect_key(bodies_scene(R"([{"name": "a", "shape": {"sphere": 1, "box": [1, 1, 1]}, "material": "m"}])"),
             "bodies[0].shape");
}

TEST(SceneParser, RejectsWrongTypes) {
  expect_key(bodies_scene(R"([{"name": "a", "shape": {"sphere": "1"}, "material": "m"}])"),
             "bodies[0].shape.sphere");
  expect_key(bodies_scene(R"([{"name": "a", "shape": {"sphere": 1}, "material": "m", "fixed": 1}])"),
             "bodies[0].fixed");
  expect_key(bodies_scene(R"([{"name": 7, "shape": {"sphere": 1}, "material": "m"}])"), "bodies[0].name");
  expect_key(scene_with(R"("solver": {"max_iterations": 2.5})"), "solver.max_iterations");
  expect_key(scene_with(R"("seed": -1)"), "seed");
  expect_key(R"({"materials": [], "bodies": []})", "materials");
  expect_key(scene_with(R"("timeline": {"time": 1})"), "timeline");
}

TEST(SceneParser, RejectsMissingRequiredKeys) {
  expect_key(R"({"materials": {}})", "bodies");
  expect_key(R"({"bodies": [1]})", "materials");
  expect_key(bodies_scene(R"([{"shape": {"sphere": 1}, "material": "m"}])"), "bodies[0].name");
  expect_key(bodies_scene(R"([{"name": "a", "material": "m"}])"), "bodies[0].shape");
  expect_key(R"({"materials": {"iron": {"type": "soft"}}, "bodies": []})", "materials.iron.saturation");
  expect_key(R"({"materials": {"x": {"magnetization": [0, 0, 1]}}, "bodies": []})", "materials.x.type");
  expect_key(scene_with(R"("timeline": [{"action": "remove", "body": "a"}])"), "timeline[0].time");
}

TEST(SceneParser, RejectsEmptyBodyList) { expect_key(bodies_scene("[]"), "bodies"); }

TEST(SceneParser, RejectsDuplicateBodyName) {
  expect_key(bodies_scene(R"([{"name": "a", "shape": {"sphere": 1}, "material": "m"},
                              {"name": "a", "shape": {"sphere": 2}, "material": "m"}])"),
             "bodies[1].name");
}

TEST(SceneParser, RejectsDuplicateJsonKey) {
  expect_key(bodies_scene(R"([{"name": "a", "shape": {"sphere": 1}, "material": "m", "name": "b"}])"),
             "bodies[0].name");
}

TEST(SceneParser, RejectsBadTimelineBody) {
  expect_key(scene_with(R"("timeline": [{"time": 1, "action": "remove", "body": "zz"}])"),
             "timeline[0].body");
  // Only a permanent magnet's magnetization can be scaled; "b" is soft iron.
  expect_key(scene_with(R"("timeline": [{"time": 0, "action": "add", "body": "a"},
                                        {"time": 1, "action": "scale_magnetization", "body": "b", "to": 0}])"),
             "timeline[1].body");
}

TEST(SceneParser, RejectsBadTimelineEvents) {
  expect_key(scene_with(R"("timeline": [{"time": 1, "action": "explode"}])"), "timeline[0].action");
  expect_key(scene_with(R"("timeline": [{"time": -1, "action": "remove", "body": "a"}])"), "timeline[0].time");
  expect_key(scene_with(R"("timeline": [{"time": 2, "action": "external_field", "field": [0, 0, 1],
                                         "end_time": 1}])"),
             "timeline[0].end_time");
  expect_key(scene_with(R"("timeline": [{"action": "keyframes", "body": "a", "keys": []}])"),
             "timeline[0].keys");
  expect_key(scene_with(R"("timeline": [{"action": "keyframes", "body": "a",
                                         "keys": [{"time": 1}, {"time": 1}]}])"),
             "timeline[0].keys[1].time");
  expect_key(scene_with(R"("timeline": [{"time": 0, "action": "mutual_induction"}])"),
             "timeline[0].enabled");
}

TEST(SceneParser, RejectsBadMomentsPerCell) {
  for (const char* n : {"3", "0", "10", "2.5", "\"2\""})
    expect_key(std::string(R"({"materials": {"fe": {"type": "soft", "saturation": 1e6, "moments_per_cell": )") +
                   n + "}}, \"bodies\": []}",
               "materials.fe.moments_per_cell");
}

TEST(SceneParser, RejectsBadMaterialValues) {
  expect_key(R"({"materials": {"fe": {"type": "soft", "saturation": 0}}, "bodies": []})",
             "materials.fe.saturation");
  expect_key(R"({"materials": {"fe": {"type": "soft", "saturation": 1, "susceptibility": "huge"}}, "bodies": []})",
             "materials.fe.susceptibility");
  expect_key(R"({"materials": {"fe": {"type": "soft", "saturation": 1, "easy_axis": [0, 0, 0]}}, "bodies": []})",
             "materials.fe.easy_axis");
  expect_key(R"({"materials": {"nd": {"type": "permanent", "magnetization": [0, 0, 1],
                                      "recoil_susceptibility": -0.1}}, "bodies": []})",
             "materials.nd.recoil_susceptibility");
  expect_key(R"({"materials": {"nd": {"type": "inert", "color": [0, 1.5, 0]}}, "bodies": []})",
             "materials.nd.color[1]");
}

TEST(SceneParser, RejectsOutOfRangeSettings) {
  expect_key(scene_with(R"("cell_size": -0.001)"), "cell_size");
  expect_key(scene_with(R"("solver": {"tolerance": 0})"), "solver.tolerance");
  expect_key(scene_with(R"("solver": {"backend": "gpu"})"), "solver.backend");
  expect_key(scene_with(R"("solver": {"far_field_theta": 1})"), "solver.far_field_theta");
  expect_key(scene_with(R"("solver": {"far_field_theta": -0.5})"), "solver.far_field_theta");
  expect_key(scene_with(R"("solver": {"skip_unchanged": 1})"), "solver.skip_unchanged");
  expect_key(scene_with(R"("simulation": {"contact": {"restitution": 1.5}})"), "simulation.contact.restitution");
  expect_key(scene_with(R"("simulation": {"max_substeps": 0})"), "simulation.max_substeps");
  expect_key(scene_with(R"("simulation": {"stiffness_limit": 0})"), "simulation.stiffness_limit");
  expect_key(scene_with(R"("camera": {"fov": 180})"), "camera.fov");
  expect_key(scene_with(R"("camera": {"width": 8})"), "camera.width");
  expect_key(scene_with(R"("camera": {"position": [0, 0, 1], "target": [0, 0, 0], "up": [0, 0, 1]})"),
             "camera.up");
  expect_key(bodies_scene(R"([{"name": "a", "shape": {"sphere": 1}, "material": "m",
                               "orientation": [0, 0, 0, 0]}])"),
             "bodies[0].orientation");
  expect_key(bodies_scene(R"([{"name": "a", "shape": {"sphere": 1}, "material": "m", "density": 0}])"),
             "bodies[0].density");
  expect_key(scene_with(R"("outcomes": [{"name": "x", "count_above": {"prefix": "a"}}])"),
             "outcomes[0].count_above.height");
  // A statistic's start time: >= 0, and only with a statistic; a statistic has no `time`.
  expect_key(scene_with(R"("outcomes": [{"name": "x", "height": {"body": "a"}, "statistic": "mean", "from": -1}])"),
             "outcomes[0].from");
  expect_key(scene_with(R"("outcomes": [{"name": "x", "height": {"body": "a"}, "from": 0.5}])"), "outcomes[0].from");
  expect_key(scene_with(R"("outcomes": [{"name": "x", "height": {"body": "a"}, "statistic": "mean", "time": 1}])"),
             "outcomes[0].time");
  expect_key(scene_with(R"("outcomes": [{"name": "x", "height": {"body": "a"}, "statistic": "median"}])"),
             "outcomes[0].statistic");
}

TEST(SceneParser, RejectsHugeLattice) {
  expect_key(bodies_scene(R"([{"name": "a", "shape": {"box": [1, 1, 1]}, "material": "m",
                               "cell_size": 1e-4}])"),
             "bodies[0].cell_size");
}

TEST(SceneParser, MissingFileNamesTheFile) {
  try {
    load_scene("/nonexistent/scene.json");
    FAIL() << "loaded a missing file";
  } catch (const SceneError& e) {
    EXPECT_EQ(e.file(), "/nonexistent/scene.json");
    EXPECT_EQ(e.key(), "");
    EXPECT_NE(e.message().find("cannot open"), std::string::npos);
  }
}

// Joints: each type takes its own keys; bodies must exist, differ and not all be fixed.
// Coils carried by bodies (docs/scene-format.md "Coils"): each type's keys
// read into its source, defaults where left out; bad types, keys, geometry and
// ampere-turns rejected with their key; a scale event on a body with coils.
std::string coil_scene(const std::string& coils, const std::string& extra = "") {
  return R"({"materials": {"wood": {"type": "inert"}, "iron": {"type": "soft", "saturation": 1.7e6}},
             "bodies": [{"name": "frame", "shape": {"box": [0.01, 0.01, 0.01]}, "material": "wood", "fixed": true,
                         "coils": )" +
         coils + R"(},
                        {"name": "b", "shape": {"sphere": 0.01}, "material": "iron", "position": [0, 0, 0.05]}])" +
         (extra.empty() ? "" : ", " + extra) + "}";
}

TEST(SceneParser, CoilsAreReadPerType) {
  const SceneDescription s = parse_scene(coil_scene(R"([
      {"type": "loop", "radius": 0.02, "current": 3, "turns": 10, "axis": [1, 0, 0]},
      {"type": "solenoid", "radius": 0.01, "length": 0.05, "current": 1, "centre": [0, 0, 0.01]},
      {"type": "circular_coil", "inner_radius": 0.01, "outer_radius": 0.02, "length": 0.03, "current": 2,
       "quadrature_order": 12},
      {"type": "rounded_rectangle", "core_half_width": 0.0125, "core_half_depth": 0.0125,
       "inner_corner_radius": 0.005, "outer_corner_radius": 0.025, "height": 0.1, "current": 1000},
      {"type": "segment", "a": [0, 0, 0], "b": [0.1, 0, 0], "current": 5},
      {"type": "arc", "radius": 0.03, "angle": 1.5, "current": -2}])",
                                                    R"("timeline": [{"time": 0.1, "action": "scale_magnetization",
                                                                     "body": "frame", "to": 0.5}])"),
                                         "coils.json");
  const std::vector<CoilSource>& c = s.bodies[0].coils;
  ASSERT_EQ(c.size(), 6u);
  const CircularLoop& loop = std::get<CircularLoop>(c[0]);
  EXPECT_EQ(loop.radius, 0.02);
  EXPECT_EQ(loop.turns, 10.0);
  EXPECT_EQ(loop.axis.x, 1.0);
  EXPECT_EQ(std::get<Solenoid>(c[1]).centre.z, 0.01);
  EXPECT_EQ(std::get<Solenoid>(c[1]).turns, 1.0);  // default
  EXPECT_EQ(std::get<CircularCoil>(c[2]).quadrature_order, 12);
  EXPECT_EQ(std::get<RoundedRectangleCoil>(c[3]).quadrature_order, 8);  // default
  EXPECT_EQ(std::get<RoundedRectangleCoil>(c[3]).width_direction.x, 1.0);
  EXPECT_EQ(std::get<StraightSegment>(c[4]).b.x, 0.1);
  EXPECT_EQ(std::get<Arc>(c[5]).angle, 1.5);
  EXPECT_EQ(std::get<Arc>(c[5]).current, -2.0);
  EXPECT_TRUE(s.bodies[1].coils.empty());
  ASSERT_EQ(s.timeline.size(), 1u);
}

// A linear material (diamagnet): a recoil cell with M_r = 0 and chi < 0;
// chi outside -1..1e6 rejected with its key.
TEST(SceneParser, LinearMaterials) {
  const SceneDescription s = parse_scene(R"({"materials": {"m": {"type": "linear", "susceptibility": -0.5}},
                                            "bodies": [{"name": "g", "shape": {"sphere": 0.01}, "material": "m"}]})",
                                         "linear.json");
  const PermanentMaterial& m = std::get<PermanentMaterial>(s.materials.at("m"));
  EXPECT_EQ(m.recoil_susceptibility, -0.5);
  EXPECT_EQ(norm(m.magnetization), 0.0);
  for (const char* chi : {"-1.5", "2e6", "\"big\""})
    expect_key(std::string(R"({"materials": {"m": {"type": "linear", "susceptibility": )") + chi +
                   R"(}}, "bodies": [{"name": "g", "shape": {"sphere": 0.01}, "material": "m"}]})",
               "materials.m.susceptibility");
  expect_key(R"({"materials": {"m": {"type": "linear", "susceptibility": -0.5, "magnetization": [0, 0, 1]}},
                 "bodies": [{"name": "g", "shape": {"sphere": 0.01}, "material": "m"}]})",
             "materials.m.magnetization");
}

// A soft material with a B-H curve: the points read as given; saturation and
// susceptibility then rejected, saturation required without a curve, bad
// curves rejected with the key.
TEST(SceneParser, BhCurves) {
  auto scene = [](const std::string& material) {
    return R"({"materials": {"s": )" + material +
           R"(}, "bodies": [{"name": "g", "shape": {"sphere": 0.01}, "material": "s"}]})";
  };
  const SceneDescription s =
      parse_scene(scene(R"({"type": "soft", "bh_curve": [[0, 0], [100, 0.5], [1000, 1.5], [1e5, 2.1]]})"), "bh.json");
  const SoftMaterial& m = std::get<SoftMaterial>(s.materials.at("s"));
  ASSERT_EQ(m.bh_curve.size(), 4u);
  EXPECT_EQ(m.bh_curve[2][0], 1000.0);
  EXPECT_EQ(m.bh_curve[3][1], 2.1);
  expect_key(scene(R"({"type": "soft", "bh_curve": [[0, 0], [100, 0.5]], "saturation": 1e6})"),
             "materials.s.saturation");
  expect_key(scene(R"({"type": "soft", "bh_curve": [[0, 0], [100, 0.5]], "susceptibility": 10})"),
             "materials.s.susceptibility");
  expect_key(scene(R"({"type": "soft"})"), "materials.s.saturation");
  expect_key(scene(R"({"type": "soft", "bh_curve": [[0, 0]]})"), "materials.s.bh_curve");
  expect_key(scene(R"({"type": "soft", "bh_curve": [[0, 0], [100, 0.5], [50, 0.7]]})"), "materials.s.bh_curve");
  expect_key(scene(R"({"type": "soft", "bh_curve": [[0, 0], [100, -0.5]]})"), "materials.s.bh_curve[1][1]");
  expect_key(scene(R"({"type": "soft", "bh_curve": [[0, 0], [100]]})"), "materials.s.bh_curve[1]");
}

TEST(SceneParser, RejectsBadCoils) {
  expect_key(coil_scene(R"({"type": "loop"})"), "bodies[0].coils");
  expect_key(coil_scene(R"([{"type": "helix", "radius": 0.01, "current": 1}])"), "bodies[0].coils[0].type");
  expect_key(coil_scene(R"([{"radius": 0.01, "current": 1}])"), "bodies[0].coils[0].type");
  expect_key(coil_scene(R"([{"type": "loop", "current": 1}])"), "bodies[0].coils[0].radius");
  expect_key(coil_scene(R"([{"type": "loop", "radius": 0.01}])"), "bodies[0].coils[0].current");
  expect_key(coil_scene(R"([{"type": "loop", "radius": 0.01, "current": 1, "length": 2}])"),
             "bodies[0].coils[0].length");  // a key of another type
  expect_key(coil_scene(R"([{"type": "loop", "radius": -0.01, "current": 1}])"), "bodies[0].coils[0].radius");
  expect_key(coil_scene(R"([{"type": "loop", "radius": 0.01, "current": 1, "axis": [0, 0, 0]}])"),
             "bodies[0].coils[0].axis");
  expect_key(coil_scene(R"([{"type": "loop", "radius": 0.01, "current": 1, "turns": 0}])"),
             "bodies[0].coils[0].turns");
  expect_key(coil_scene(R"([{"type": "loop", "radius": 0.01, "current": 1e8, "turns": 100}])"),
             "bodies[0].coils[0].current");  // 1e10 ampere-turns
  expect_key(coil_scene(R"([{"type": "circular_coil", "inner_radius": 0.03, "outer_radius": 0.02,
                              "length": 0.01, "current": 1}])"),
             "bodies[0].coils[0]");  // inner above outer
  expect_key(coil_scene(R"([{"type": "circular_coil", "inner_radius": 0.01, "outer_radius": 0.02,
                              "length": 0.01, "current": 1, "quadrature_order": 65}])"),
             "bodies[0].coils[0].quadrature_order");
  expect_key(coil_scene(R"([{"type": "loop", "radius": 0.01, "current": 1e6}])",
                        R"("timeline": [{"time": 0.1, "action": "scale_magnetization", "body": "frame", "to": 2e3}])"),
             "timeline[0].to");  // scaled beyond 1e9 A
  // A scale event on a body with neither magnet nor coils is still refused.
  expect_key(coil_scene(R"([{"type": "loop", "radius": 0.01, "current": 1}])",
                        R"("timeline": [{"time": 0.1, "action": "scale_magnetization", "body": "b", "to": 2}])"),
             "timeline[0].body");
}

TEST(SceneParser, JointsAreReadAndCheckedPerType) {
  const std::string two = R"([{"name": "a", "shape": {"sphere": 0.01}, "material": "m", "fixed": true},
                              {"name": "b", "shape": {"sphere": 0.01}, "material": "m"}])";
  auto with_joints = [&](const std::string& joints) {
    std::string text = bodies_scene(two);
    return text.substr(0, text.size() - 1) + R"(, "joints": )" + joints + "}";
  };
  const SceneDescription s = parse_scene(
      with_joints(R"([{"type": "hinge", "bodies": ["b", "a"], "anchor": [0, 0, 0.01], "axis": [1, 0, 0],
                       "limits": [-0.5, 1]}, {"type": "slider", "bodies": ["b"]}])"),
      "ok.json");
  ASSERT_EQ(s.joints.size(), 2u);
  EXPECT_EQ(s.joints[0].type, JointDescription::Type::hinge);
  EXPECT_EQ(s.joints[0].bodies, (std::vector<std::string>{"b", "a"}));
  EXPECT_EQ(s.joints[0].anchor.z, 0.01);
  EXPECT_EQ(s.joints[0].axis.x, 1.0);
  ASSERT_TRUE(s.joints[0].limits.has_value());
  EXPECT_EQ((*s.joints[0].limits)[1], 1.0);
  EXPECT_EQ(s.joints[1].axis.z, 1.0);  // the default axis
  EXPECT_FALSE(s.joints[1].limits.has_value());

  expect_key(with_joints(R"([{"type": "hinge", "bodies": ["c"], "anchor": [0, 0, 0]}])"), "joints[0].bodies[0]");
  expect_key(with_joints(R"([{"type": "ball", "bodies": ["b", "b"], "anchor": [0, 0, 0]}])"), "joints[0].bodies[1]");
  expect_key(with_joints(R"([{"type": "ball", "bodies": ["a"], "anchor": [0, 0, 0]}])"), "joints[0].bodies");
  expect_key(with_joints(R"([{"type": "fixed", "bodies": ["a", "b", "b"]}])"), "joints[0].bodies");
  expect_key(with_joints(R"([{"type": "hinge", "bodies": ["b"]}])"), "joints[0].anchor");
  expect_key(with_joints(R"([{"type": "slider", "bodies": ["b"], "anchor": [0, 0, 0]}])"), "joints[0].anchor");
  expect_key(with_joints(R"([{"type": "ball", "bodies": ["b"], "anchor": [0, 0, 0], "axis": [0, 0, 1]}])"),
             "joints[0].axis");
  expect_key(with_joints(R"([{"type": "ball", "bodies": ["b"], "anchor": [0, 0, 0], "limits": [0, 1]}])"),
             "joints[0].limits");
  expect_key(with_joints(R"([{"type": "hinge", "bodies": ["b"], "anchor": [0, 0, 0], "limits": [1, 0]}])"),
             "joints[0].limits");
  expect_key(with_joints(R"([{"type": "hinge", "bodies": ["b"], "anchor": [0, 0, 0], "limits": [-4, 0]}])"),
             "joints[0].limits[0]");
  expect_key(with_joints(R"([{"type": "hinge", "bodies": ["b"], "anchor": [0, 0, 0], "axis": [0, 0, 0]}])"),
             "joints[0].axis");
  expect_key(with_joints(R"([{"type": "weld", "bodies": ["b"]}])"), "joints[0].type");
  expect_key(with_joints(R"([{"type": "fixed", "bodies": ["b"], "strength": 1}])"), "joints[0].strength");
}

}  // namespace
}  // namespace odemag
