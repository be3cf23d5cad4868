// Sleeping bodies (docs/simulation.md "Sleeping bodies", scene key
// simulation.sleep): resting bodies fall asleep and stay where they were; a
// magnet brought near wakes a sleeping ball, and so does a ball rolling into
// it; each ends where the same scene without sleeping ends.
#include <gtest/gtest.h>

#include <cmath>

#include "engine/simulation/simulation.h"
#include "tests/support/scene_builders.h"

namespace odemag {
namespace {

using test_support::body;
using test_support::steel;

constexpr double kRadius = 0.005;  // m, the steel balls

// Steel balls on the ground (gravity, no field), asleep after 20 ms at rest.
SceneDescription resting_scene(const std::string& file) {
  SceneDescription s;
  s.file = file;
  s.gravity = {0, 0, -9.81};
  s.simulation.time_step = 0.001;
  s.simulation.sleep.time = 0.02;
  s.materials["steel"] = steel();
  return s;
}

TEST(Sleep, RestingBallsFallAsleepAndStayPut) {
  SceneDescription s = resting_scene("resting");
  // A row of three touching balls on the ground.
  for (int i = 0; i < 3; ++i)
    s.bodies.push_back(body("ball" + std::to_string(i), Sphere{kRadius}, "steel", {2.0 * kRadius * i, 0, kRadius}));
  Simulation sim(s);
  sim.advance_to(0.1);
  ASSERT_EQ(sim.world().sleeping_count(), 3);
  Vec3 at[3];
  for (int i = 0; i < 3; ++i) at[i] = sim.world().pose(i).position;
  sim.advance_to(0.3);
  EXPECT_EQ(sim.world().sleeping_count(), 3);
  for (int i = 0; i < 3; ++i) {
    EXPECT_EQ(sim.world().pose(i).position.x, at[i].x) << i;  // not stepped at all
    EXPECT_EQ(sim.world().pose(i).position.z, at[i].z) << i;
    EXPECT_EQ(norm(sim.world().velocity(i)), 0.0) << i;
  }
  EXPECT_EQ(sim.records().back().sleeping, 3);
  // Where they rest: on the ground (within the 0.1 mm collision skin).
  for (int i = 0; i < 3; ++i) EXPECT_NEAR(at[i].z, kRadius, 2e-4) << i;
}

// A magnet (R = 8 mm, 9e5 A/m) keyframed from 6 cm to 2.5 cm of a steel ball
// asleep on the ground between t = 0.1 and 0.3 s: its pull wakes the ball,
// which rolls to it and ends touching it, as without sleeping.
SceneDescription magnet_approaches(double sleep_time) {
  SceneDescription s = resting_scene("magnet_approaches");
  s.simulation.sleep.time = sleep_time;
  s.materials["magnet"] = PermanentMaterial{{0.9e6, 0, 0}, 0.0};
  s.bodies.push_back(body("ball", Sphere{kRadius}, "steel", {0, 0, kRadius}));
  s.bodies.push_back(body("magnet", Sphere{0.008}, "magnet", {0.06, 0, 0.008}, true));
  TimelineEvent keys;
  keys.kind = TimelineEvent::Kind::keyframes;
  keys.body = "magnet";
  keys.keys = {{0.1, {0.06, 0, 0.008}, {}}, {0.3, {0.025, 0, 0.008}, {}}};
  keys.time = 0.1;
  keys.end_time = 0.3;
  s.timeline = {keys};
  return s;
}

TEST(Sleep, AMagnetBroughtNearWakesASleepingBall) {
  Simulation asleep(magnet_approaches(0.02));
  asleep.advance_to(0.1);
  ASSERT_TRUE(asleep.world().sleeping(0));
  asleep.advance_to(0.8);
  Simulation awake(magnet_approaches(0.0));
  awake.advance_to(0.8);
  for (Simulation* sim : {&asleep, &awake}) {
    const double gap = norm(sim->world().pose(0).position - sim->world().pose(1).position) - (kRadius + 0.008);
    EXPECT_NEAR(gap, 0.0, 2e-4) << "touching the magnet";
  }
  EXPECT_NEAR(asleep.world().pose(0).position.x, awake.world().pose(0).position.x, 1e-3);
}

// Ball "resting" asleep at x = 0; ball "rolling" sent at 0.3 m/s along x
// from 4 cm away along the ground: it hits the sleeping ball, which wakes
// and is pushed on, as without sleeping (a sleeping body left a fixed
// support would stop the rolling ball and stay at x = 0).
SceneDescription rolling_into(double sleep_time) {
  SceneDescription s = resting_scene("rolling_into");
  s.simulation.sleep.time = sleep_time;
  s.materials["wood"] = InertMaterial{};
  s.bodies.push_back(body("resting", Sphere{kRadius}, "wood", {0, 0, kRadius}));
  BodyDescription rolling = body("rolling", Sphere{kRadius}, "wood", {-0.04, 0, kRadius});
  rolling.velocity = {0.3, 0, 0};
  rolling.angular_velocity = {0, 0.3 / kRadius, 0};  // rolling without slipping
  s.bodies.push_back(rolling);
  return s;
}

TEST(Sleep, ABallRollingIntoASleepingBallWakesIt) {
  Simulation asleep(rolling_into(0.02));
  asleep.advance_to(0.05);
  ASSERT_TRUE(asleep.world().sleeping(0));
  ASSERT_LT(asleep.world().pose(1).position.x, -0.02);  // not there yet
  asleep.advance_to(0.5);
  Simulation awake(rolling_into(0.0));
  awake.advance_to(0.5);
  const double pushed = awake.world().pose(0).position.x;
  ASSERT_GT(pushed, 0.01);  // the reference: the struck ball rolls on
  EXPECT_NEAR(asleep.world().pose(0).position.x, pushed, 0.1 * pushed);
}

// A wooden box (2 x 2 x 1 cm) asleep on the ground, a steel ball asleep on
// it; the box is taken away at t = 0.1 s: the ball, which lost its support,
// falls to the ground.
TEST(Sleep, ABodyThatLosesItsSupportWakes) {
  SceneDescription s = resting_scene("support_removed");
  s.materials["wood"] = InertMaterial{};
  s.bodies.push_back(body("box", Box{{0.02, 0.02, 0.01}}, "wood", {0, 0, 0.005}, false, 700.0));
  s.bodies.push_back(body("ball", Sphere{kRadius}, "steel", {0, 0, 0.01 + kRadius}));
  TimelineEvent remove;
  remove.kind = TimelineEvent::Kind::remove_body;
  remove.body = "box";
  remove.time = remove.end_time = 0.1;
  s.timeline = {remove};
  Simulation sim(s);
  sim.advance_to(0.09);
  ASSERT_TRUE(sim.world().sleeping(1));
  sim.advance_to(0.4);
  EXPECT_NEAR(sim.world().pose(1).position.z, kRadius, 2e-4);  // on the ground
}

}  // namespace
}  // namespace odemag
