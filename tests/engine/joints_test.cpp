// Joints in scene files (docs/scene-format.md "joints"): a compass needle on
// a hinge oscillates about the field with the small-angle period and settles
// along it; a ball-joint pendulum swings with the physical pendulum's period;
// a slider stops at its limit; a fixed joint holds a body against gravity.
// References are closed forms written here.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "odemag/simulation.h"
#include "odemag/constants.h"
#include "tests/support/scene_builders.h"
#include "engine/simulation/rigid_world.h"

namespace odemag {
namespace {

using test_support::body;

// Times at which f(t) crosses zero from + to -, linearly interpolated.
template <class F>
std::vector<double> downward_crossings(Simulation& sim, double until, F f) {
  std::vector<double> crossings;
  double previous = f();
  while (sim.time() < until) {
    sim.step();
    const double a = f();
    if (previous > 0 && a <= 0) crossings.push_back(sim.time() - sim.scene().simulation.time_step * a / (a - previous));
    previous = a;
  }
  return crossings;
}

double mean_period(const std::vector<double>& crossings) {
  return (crossings.back() - crossings.front()) / static_cast<double>(crossings.size() - 1);
}

JointDescription joint(JointDescription::Type type, std::vector<std::string> bodies, const Vec3& anchor = {},
                       const Vec3& axis = {0, 0, 1}) {
  JointDescription j;
  j.type = type;
  j.bodies = std::move(bodies);
  j.anchor = anchor;
  j.axis = axis;
  return j;
}

// A bar magnet (one cell, M along its length) on a vertical hinge through its
// centre, in a uniform field along x and in gravity: the hinge holds it up and
// it swings about the field with T = 2 pi sqrt(I_zz / (mu0 m H)),
// I_zz = mass (lx^2 + ly^2) / 12.
TEST(Joints, HingedCompassNeedleHasTheSmallAnglePeriod) {
  const double M = 8e5, H = 2e3, density = 7500, lx = 0.04, ly = 0.004, lz = 0.002, theta0 = 0.05;
  SceneDescription s;
  s.file = "hinged_needle";
  s.simulation.ground = false;
  s.simulation.time_step = 0.0005;
  s.external_field = {H, 0, 0};
  s.materials["needle"] = PermanentMaterial{{M, 0, 0}, 0.0};
  BodyDescription needle = body("needle", Box{{lx, ly, lz}}, "needle", {0.01, 0.02, 0.05}, false, density);
  needle.orientation = {std::cos(theta0 / 2), 0, 0, std::sin(theta0 / 2)};
  s.bodies.push_back(needle);
  s.joints.push_back(joint(JointDescription::Type::hinge, {"needle"}, {0.01, 0.02, 0.05}));
  Simulation sim(s);
  const double volume = lx * ly * lz, mass = density * volume;
  const double period = 2 * kPi * std::sqrt(mass * (lx * lx + ly * ly) / 12.0 / (kMu0 * M * volume * H));
  const std::vector<double> crossings = downward_crossings(sim, 4.5 * period, [&] {
    const Vec3 m = sim.magnetics().moment(0);
    return std::atan2(m.y, m.x);
  });
  ASSERT_GE(crossings.size(), 3u);
  EXPECT_NEAR(mean_period(crossings), period, 0.02 * period);
  // Held at the pivot against gravity (it fell 0.5 g t^2 = 0.8 m in 0.4 s without the hinge).
  EXPECT_LT(norm(sim.world().pose(0).position - Vec3{0.01, 0.02, 0.05}), 1e-5);
}

// examples/compass_needle.json: started 60 degrees off, the damped needle
// settles along H_E = (2000, 0, 0) A/m within its 4 s.
TEST(Joints, CompassNeedleExampleSettlesAlongTheField) {
  Simulation sim(load_scene(ODEMAG_SOURCE_DIR "/examples/compass_needle.json"));
  const int needle = sim.scene().find_body("needle");
  const Vec3 m0 = sim.magnetics().moment(needle);
  ASSERT_GT(norm(m0), 0.0);
  sim.advance_to(sim.scene().simulation.duration);
  const Vec3 m = sim.magnetics().moment(needle);
  EXPECT_LT(std::abs(std::atan2(m.y, m.x)), 1.0 * kPi / 180.0);
  EXPECT_LT(norm(sim.world().pose(needle).position - Vec3{0, 0, 0.042}), 1e-5);
}

// A ball of radius r hanging on a ball joint at distance L above its centre:
// a physical pendulum, T = 2 pi sqrt((I_cm + m L^2) / (m g L)), I_cm = 2/5 m r^2.
TEST(Joints, BallJointPendulumHasThePhysicalPendulumPeriod) {
  const double r = 0.01, L = 0.2, g = 9.81, theta0 = 0.05;
  SceneDescription s;
  s.file = "pendulum";
  s.simulation.ground = false;
  s.simulation.time_step = 0.001;
  s.materials["wood"] = InertMaterial{};
  s.bodies.push_back(body("bob", Sphere{r}, "wood", {L * std::sin(theta0), 0, 1.0 - L * std::cos(theta0)}));
  s.joints.push_back(joint(JointDescription::Type::ball, {"bob"}, {0, 0, 1.0}));
  Simulation sim(s);
  const double period = 2 * kPi * std::sqrt((0.4 * r * r + L * L) / (g * L));
  const std::vector<double> crossings =
      downward_crossings(sim, 4.5 * period, [&] { return sim.world().pose(0).position.x; });
  ASSERT_GE(crossings.size(), 3u);
  EXPECT_NEAR(mean_period(crossings), period, 0.01 * period);
  EXPECT_NEAR(norm(sim.world().pose(0).position - Vec3{0, 0, 1.0}), L, 1e-4);
}

// A ball on a vertical slider falls until the low stop, 5 cm down, and stays.
TEST(Joints, SliderStopsAtItsLimit) {
  SceneDescription s;
  s.file = "slider";
  s.simulation.ground = false;
  s.simulation.time_step = 0.001;
  s.materials["wood"] = InertMaterial{};
  s.bodies.push_back(body("bead", Sphere{0.005}, "wood", {0, 0, 0.5}));
  JointDescription slider = joint(JointDescription::Type::slider, {"bead"}, {}, {0, 0, 1});
  slider.limits = std::array<double, 2>{-0.05, 0.0};
  s.joints.push_back(slider);
  Simulation sim(s);
  sim.advance_to(0.05);
  EXPECT_LT(sim.world().pose(0).position.z, 0.5 - 0.005);  // falling
  sim.advance_to(1.0);
  EXPECT_NEAR(sim.world().pose(0).position.z, 0.45, 2e-3);
  EXPECT_NEAR(sim.world().pose(0).position.x, 0.0, 1e-9);
  EXPECT_LT(norm(sim.world().velocity(0)), 1e-2);
}

// A fixed joint welds a body where it was placed: it neither falls nor turns,
// and a body welded to it (overlapping it) does not collide with it.
TEST(Joints, FixedJointHoldsBodiesAsPlaced) {
  SceneDescription s;
  s.file = "fixed";
  s.simulation.time_step = 0.001;
  s.materials["wood"] = InertMaterial{};
  s.bodies.push_back(body("shelf", Box{{0.1, 0.02, 0.01}}, "wood", {0, 0, 0.3}));
  s.bodies.push_back(body("bracket", Box{{0.01, 0.02, 0.05}}, "wood", {0.045, 0, 0.28}));
  s.joints.push_back(joint(JointDescription::Type::fixed, {"shelf"}));
  s.joints.push_back(joint(JointDescription::Type::fixed, {"bracket", "shelf"}));
  Simulation sim(s);
  sim.advance_to(1.0);
  EXPECT_LT(norm(sim.world().pose(0).position - Vec3{0, 0, 0.3}), 1e-4);
  EXPECT_LT(norm(sim.world().pose(1).position - Vec3{0.045, 0, 0.28}), 1e-4);
  EXPECT_LT(norm(sim.world().velocity(1)), 1e-3);
}

}  // namespace
}  // namespace odemag
