// Scene outcomes (docs/scene-format.md "outcomes"): each quantity at a time,
// at the end, and as the largest or smallest value over the run, for a steel
// ball that falls onto a magnet and stays there.
#include <gtest/gtest.h>

#include <cmath>

#include "odemag/simulation.h"
#include "odemag/constants.h"
#include "tests/support/scene_builders.h"
#include "engine/simulation/rigid_world.h"

namespace odemag {
namespace {

using test_support::body;
using test_support::steel;

OutcomeDescription outcome(const std::string& name, OutcomeDescription::Quantity q, std::vector<std::string> bodies,
                           double time = -1.0,
                           OutcomeDescription::Statistic statistic = OutcomeDescription::Statistic::none) {
  OutcomeDescription o;
  o.name = name;
  o.quantity = q;
  o.bodies = std::move(bodies);
  o.time = time;
  o.statistic = statistic;
  return o;
}

// A steel ball (radius kBallRadius) released at kStartHeight above a fixed
// magnet ball (kMagnetRadius) on the ground falls onto it and stays.
constexpr double kMagnetRadius = 0.008, kBallRadius = 0.005, kStartHeight = 0.045;

SceneDescription ball_onto_magnet(const std::string& file) {
  SceneDescription s;
  s.file = file;
  s.simulation.time_step = 0.002;
  s.materials["magnet"] = PermanentMaterial{{0, 0, 9e5}, 0.0};
  s.materials["steel"] = steel();
  s.bodies.push_back(body("magnet", Sphere{kMagnetRadius}, "magnet", {0, 0, kMagnetRadius}, true));
  s.bodies.push_back(body("ball", Sphere{kBallRadius}, "steel", {0, 0, kStartHeight}));
  return s;
}

TEST(Outcomes, EachQuantityAtATimeAtTheEndAndOverTheRun) {
  using Q = OutcomeDescription::Quantity;
  const double R = kMagnetRadius, r = kBallRadius, z0 = kStartHeight;
  SceneDescription s = ball_onto_magnet("outcomes");
  s.outcomes = {outcome("start_height", Q::height, {"ball"}, 0.0),
                outcome("closest", Q::distance, {"ball", "magnet"}, -1.0, OutcomeDescription::Statistic::min),
                outcome("farthest", Q::distance, {"ball", "magnet"}, -1.0, OutcomeDescription::Statistic::max),
                outcome("fastest", Q::speed, {"ball"}, -1.0, OutcomeDescription::Statistic::max),
                outcome("contacts", Q::contact_count, {"ball"}),
                outcome("pull_z", Q::force, {"ball"}),
                outcome("moment", Q::moment, {"ball"}),
                outcome("never", Q::height, {"ball"}, 99.0)};
  s.outcomes[5].component = 2;
  OutcomeDescription held;
  held.name = "held";
  held.prefix = "ba";
  held.height = 2 * R;
  s.outcomes.push_back(held);
  Simulation sim(s);
  sim.advance_to(1.0);
  sim.finish();
  const auto& v = sim.outcomes();
  EXPECT_EQ(v.at("start_height"), z0);
  // Touching: centres R + r apart, within the collision skin (2% of r per body).
  EXPECT_NEAR(v.at("closest"), R + r, 0.05 * r);
  EXPECT_NEAR(v.at("farthest"), z0 - R, 1e-12);  // where it started
  // It fell at least z0 - (2 R + r) under gravity alone, faster with the pull.
  EXPECT_GT(v.at("fastest"), std::sqrt(2 * 9.81 * (z0 - 2 * R - r)));
  EXPECT_GE(v.at("contacts"), 1.0);
  EXPECT_EQ(v.at("pull_z"), sim.magnetics().force(1).z);
  EXPECT_LT(v.at("pull_z"), 0.0);  // towards the magnet below
  EXPECT_EQ(v.at("moment"), norm(sim.magnetics().moment(1)));
  EXPECT_EQ(v.at("held"), 1.0);
  EXPECT_EQ(v.count("never"), 0u);  // a time the run did not reach
}

// "mean" over the steps from `from` on: the ball rests on the magnet from
// well before 0.5 s, so the mean of its height equals its height at the end
// (to the contact's settling), and a statistic's start time the run does
// not reach leaves the outcome out. A falling ball's mean speed over the
// whole run lies between its smallest and largest.
TEST(Outcomes, MeanFromAStartTime) {
  using Q = OutcomeDescription::Quantity;
  SceneDescription s = ball_onto_magnet("outcomes_mean");
  s.outcomes = {outcome("height_end", Q::height, {"ball"}), outcome("height_mean", Q::height, {"ball"}, -1.0, OutcomeDescription::Statistic::mean),
                outcome("speed_mean", Q::speed, {"ball"}, -1.0, OutcomeDescription::Statistic::mean),
                outcome("speed_max", Q::speed, {"ball"}, -1.0, OutcomeDescription::Statistic::max),
                outcome("speed_min", Q::speed, {"ball"}, -1.0, OutcomeDescription::Statistic::min),
                outcome("late", Q::height, {"ball"}, -1.0, OutcomeDescription::Statistic::mean)};
  s.outcomes[1].from = 0.5;
  s.outcomes[5].from = 99.0;
  Simulation sim(s);
  double sum = 0.0;
  int samples = 0;
  while (sim.time() < 1.0 - 1e-9) {
    sim.step();
    if (sim.time() + 0.5 * 0.002 >= 0.5) sum += sim.world().pose(1).position.z, ++samples;
  }
  sim.finish();
  const auto& v = sim.outcomes();
  EXPECT_NEAR(v.at("height_mean"), sum / samples, 1e-15);
  EXPECT_NEAR(v.at("height_mean"), v.at("height_end"), 1e-4);
  EXPECT_GT(v.at("speed_mean"), v.at("speed_min"));
  EXPECT_LT(v.at("speed_mean"), v.at("speed_max"));
  EXPECT_EQ(v.count("late"), 0u);
}

}  // namespace
}  // namespace odemag
