// TEAM workshop problem 20 as users run it: benchmarks/team20.json through
// solve_scene and scene_field (what `odemag solve`, `odemag field` and
// Python's Scene.solve / Scene.field compute), against the problem's geometry
// and the measured force and gap flux density written in
// tests/support/team20.h (docs/validation.md "TEAM 20 as a scene").
#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <variant>

#include "odemag/scene.h"
#include "odemag/solve.h"
#include "tests/support/team20.h"

namespace odemag {
namespace {

SceneDescription team20_scene(double ampere_turns) {
  SceneDescription scene = load_scene(ODEMAG_SOURCE_DIR "/benchmarks/team20.json");
  for (BodyDescription& body : scene.bodies)
    for (CoilSource& coil : body.coils) std::get<RoundedRectangleCoil>(coil).current = ampere_turns;
  return scene;
}

const team20::Measured& measured(double ampere_turns) {
  for (const team20::Measured& m : team20::kMeasured)
    if (m.ampere_turns == ampere_turns) return m;
  throw std::invalid_argument("no measurement at this current");
}

// The scene's steel bodies are the problem's pole and five yoke bars, its
// coil the problem's coil: boxes compared corner by corner (1 um), the coil
// field for field at points inside and outside the winding.
TEST(Team20Scene, GeometryIsTheProblemStatements) {
  const SceneDescription scene = team20_scene(1000.0);
  std::vector<team20::Box> steel = team20::pole_boxes();
  for (const team20::Box& b : team20::yoke_boxes()) steel.push_back(b);
  std::vector<bool> matched(steel.size(), false);
  const RoundedRectangleCoil* coil = nullptr;
  Vec3 coil_body;
  int steel_bodies = 0;
  for (const BodyDescription& body : scene.bodies) {
    EXPECT_TRUE(body.fixed) << body.name;
    EXPECT_EQ(body.orientation.w, 1.0) << body.name;
    for (const CoilSource& c : body.coils) coil = &std::get<RoundedRectangleCoil>(c), coil_body = body.position;
    if (body.material != "steel") continue;
    ++steel_bodies;
    const Vec3 half = 0.5 * std::get<Box>(body.shape).size;
    const Vec3 lo = body.position - half, hi = body.position + half;
    for (size_t i = 0; i < steel.size(); ++i)
      if (norm(lo - steel[i].lo) < 1e-6 && norm(hi - steel[i].hi) < 1e-6) matched[i] = true;
  }
  EXPECT_EQ(steel_bodies, 6);
  for (size_t i = 0; i < steel.size(); ++i) EXPECT_TRUE(matched[i]) << "steel box " << i << " not in the scene";
  ASSERT_NE(coil, nullptr);
  RoundedRectangleCoil placed = *coil;
  placed.centre = coil_body + placed.centre;
  const RoundedRectangleCoil reference = team20::coil(1000.0);
  for (const Vec3& p : {Vec3{0, 0, 0.075}, Vec3{0.02, 0.01, 0.05}, Vec3{0.03, -0.03, 0.12}, Vec3{0.1, 0.02, 0.0}}) {
    const Vec3 a = coil_field_H(placed, p), b = coil_field_H(reference, p);
    EXPECT_LT(norm(a - b), 1e-9 * norm(b)) << p.x << " " << p.y << " " << p.z;
  }
  // The B-H curve is the problem's Table 1.
  const auto& steel_material = std::get<SoftMaterial>(scene.materials.at("steel"));
  ASSERT_EQ(steel_material.bh_curve.size(), team20::bh_table().size());
  for (size_t i = 0; i < steel_material.bh_curve.size(); ++i) {
    EXPECT_EQ(steel_material.bh_curve[i][0], team20::bh_table()[i][0]);
    EXPECT_EQ(steel_material.bh_curve[i][1], team20::bh_table()[i][1]);
  }
  EXPECT_EQ(scene.cell_size, 0.005);
}

// The force on the pole at the ends of the measured range, default settings,
// 5 mm cells. Tolerance 8% of the measured force: what the scene reaches at
// 5 mm (-7.2% at 1000 AT, +5.2% at 5000 AT; docs/validation.md "TEAM 20 as a
// scene"), short of the 5% the static solver's quarter model reaches at 3.33
// mm. Whole cells without the gap's refinement give -73% and -54%.
class Team20SceneForce : public ::testing::TestWithParam<double> {};

TEST_P(Team20SceneForce, PoleForceWithin8PercentOfTheMeasuredForce) {
  const double ampere_turns = GetParam();
  const SceneSolution solution = solve_scene(team20_scene(ampere_turns));
  ASSERT_TRUE(solution.report.converged);
  const Vec3 force = solution.bodies[0].force;  // the pole, toward the bar: -z
  const double expected = measured(ampere_turns).force;
  EXPECT_NEAR(-force.z, expected, 0.08 * expected) << ampere_turns << " AT";
  EXPECT_LT(std::hypot(force.x, force.y), 1e-6 * std::abs(force.z));
}

INSTANTIATE_TEST_SUITE_P(Team20, Team20SceneForce, ::testing::Values(1000.0, 5000.0));

// Bz at P1, the middle of the gap, at 5000 AT: within 5% of the measured
// 1.03 T (the scene gives 1.001 T, -2.9%).
TEST(Team20Scene, GapFluxDensityAt5000AmpereTurns) {
  const SceneField field = scene_field(team20_scene(5000.0), {team20::kP1});
  ASSERT_TRUE(field.report.converged);
  EXPECT_NEAR(field.B[0].z, measured(5000.0).Bz_P1, 0.05 * measured(5000.0).Bz_P1);
}

}  // namespace
}  // namespace odemag
