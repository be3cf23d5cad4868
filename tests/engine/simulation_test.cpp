// Rigid bodies with ODE: a ball comes to rest
// on a magnet at 1, 4 and 10 ms steps; a compass needle's period in a uniform
// field; momentum conservation of two attracting magnets; time-line events.
#include "odemag/simulation.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>

#include "engine/simulation/magnetic_system.h"
#include "engine/simulation/rigid_world.h"
#include "magnetics/model/backend.h"
#include "odemag/constants.h"
#include "magnetics/relax/relax.h"
#include "tests/support/scene_builders.h"

namespace odemag {
namespace {

using test_support::body;
using test_support::steel;
using test_support::weightless_scene;

// A steel ball (R = 5 mm) released 24 mm above (and slightly beside) the
// pole of a fixed spherical magnet (R = 8 mm) lying on the ground. The pole is
// where the field is strongest: the ball's stable resting place.
SceneDescription ball_onto_magnet(double dt) {
  SceneDescription s;
  s.file = "ball_onto_magnet";
  s.materials["magnet"] = PermanentMaterial{{0, 0, 9e5}, 0.0};
  s.materials["steel"] = steel();
  s.bodies.push_back(body("magnet", Sphere{0.008}, "magnet", {0, 0, 0.008}, true));
  s.bodies.push_back(body("ball", Sphere{0.005}, "steel", {0.002, 0.001, 0.045}));
  s.simulation.time_step = dt;
  return s;
}

// The end of ball_onto_magnet: the ball at rest touching the magnet near its
// pole; closest: the smallest centre distance seen during the run.
void expect_resting_on_the_pole(const Simulation& sim, double closest, double dt) {
  const BodyPose ball = sim.world().pose(1);
  const Vec3 centre{0, 0, 0.008};
  // Touching: centres one sum of radii (13 mm) apart, within the 0.1 mm
  // collision skin and a little slack.
  EXPECT_NEAR(norm(ball.position - centre), 0.013, 2e-4) << "dt=" << dt;
  // Near the pole, at rest, held by the magnet (force towards its centre).
  EXPECT_GT(ball.position.z, 0.018);
  EXPECT_LT(norm(sim.world().velocity(1)), 1e-2);
  EXPECT_LT(dot(sim.magnetics().force(1), normalized(ball.position - centre)), -1.0);
  // No tunnelling: the ball never sank into the magnet by more than the
  // transient interpenetration the substep rule allows a body that was in
  // contact (3/10 of its size, docs/simulation.md).
  EXPECT_GT(closest, 0.013 - 0.3 * 0.005) << "dt=" << dt;
}

class BallOntoMagnet : public ::testing::TestWithParam<double> {};

TEST_P(BallOntoMagnet, ComesToRestTouchingItWithoutTunnellingOrNaN) {
  const double dt = GetParam();
  Simulation sim(ball_onto_magnet(dt));
  double closest = 1.0;
  while (sim.time() < 1.5) {
    sim.step();
    for (int b = 0; b < 2; ++b) ASSERT_TRUE(sim.finite_state(b)) << "t=" << sim.time();
    closest = std::min(closest, norm(sim.world().pose(1).position - Vec3{0, 0, 0.008}));
  }
  expect_resting_on_the_pole(sim, closest, dt);
}

INSTANTIATE_TEST_SUITE_P(TimeSteps, BallOntoMagnet, ::testing::Values(0.001, 0.004, 0.010));

// simulation.magnetic_solve "moving": every substep relaxes, but a later
// substep holds the magnetization of the bodies that neither need the
// substeps nor touch one that does (docs/simulation.md "Substeps"). A second
// steel ball rests on the ground 10 cm away: it is held whenever the falling
// one takes substeps, and the falling one comes to rest as before.
class BallOntoMagnetMovingSolve : public ::testing::TestWithParam<double> {};

TEST_P(BallOntoMagnetMovingSolve, ComesToRestTouchingItWhileTheRestingBallIsHeld) {
  const double dt = GetParam();
  SceneDescription scene = ball_onto_magnet(dt);
  scene.bodies.push_back(body("resting", Sphere{0.005}, "steel", {0.1, 0.0, 0.005}));
  scene.simulation.magnetic_solve = MagneticSolve::moving;
  Simulation sim(scene);
  double closest = 1.0;
  int later_substeps = 0, held = 0;
  while (sim.time() < 1.5) {
    sim.step();
    for (int b = 0; b < 3; ++b) ASSERT_TRUE(sim.finite_state(b)) << "t=" << sim.time();
    closest = std::min(closest, norm(sim.world().pose(1).position - Vec3{0, 0, 0.008}));
    const StepReport& r = sim.records().back();
    ASSERT_EQ(r.relaxations, r.substeps) << "t=" << sim.time();
    later_substeps += r.substeps - 1;
    held += r.held;
  }
  ASSERT_GT(later_substeps, 0) << "dt=" << dt << ": the case never needed substeps";
  // The resting ball in every later substep; the falling ball only in those
  // where it needed no substeps itself (the magnet induces nothing: not counted).
  EXPECT_GE(held, later_substeps);
  EXPECT_LT(held, 2 * later_substeps);
  expect_resting_on_the_pole(sim, closest, dt);
  EXPECT_NEAR(sim.world().pose(2).position.x, 0.1, 1e-4) << "the resting ball stays where it was";
}

INSTANTIATE_TEST_SUITE_P(TimeSteps, BallOntoMagnetMovingSolve, ::testing::Values(0.001, 0.004, 0.010));

// With the default ("substep") every substep relaxes.
TEST(BallOntoMagnet, EverySubstepRelaxesByDefault) {
  Simulation sim(ball_onto_magnet(0.004));
  while (sim.time() < 0.3) {
    sim.step();
    ASSERT_EQ(sim.records().back().relaxations, sim.records().back().substeps) << "t=" << sim.time();
  }
}

// A magnet free to turn in a uniform field oscillates about it with the
// small-angle period T = 2 pi sqrt(I / (mu0 m H)); the field pushes it nowhere.
// The clearance the substep rule may spend in free flight (docs/simulation.md
// "Substeps"): the gap between axis-aligned bounding boxes, a lower bound of
// the true gap; and a ball dropped from 1 m onto the ground (4.4 m/s at the
// end, 18 mm per 4 ms step against a tenth of its radius, 0.5 mm) falls
// with one substep while it is far from the ground and lands without
// sinking into it.
TEST(FreeFlight, ClearanceBoundsTheGapAndAFallingBallLandsOnTheGround) {
  SceneDescription s;
  s.file = "drop";
  s.materials["steel"] = test_support::steel();
  s.bodies.push_back(body("ball", Sphere{0.005}, "steel", {0, 0, 1.0}));
  s.bodies.push_back(body("other", Sphere{0.005}, "steel", {0.1, 0, 1.2}, true));
  Simulation sim(s);
  const double skin = 0.02 * 0.005;  // each geometry is larger than its shape by its skin
  // Nearest is the other ball: its box is 0.09 m off along x and 0.19 m
  // along z (0.21 m), the ground 0.995 m below.
  const double to_other = std::hypot(0.1 - 0.01 - 2 * skin, 0.2 - 0.01 - 2 * skin);
  EXPECT_NEAR(sim.world().clearance(0), to_other, 1e-12);
  EXPECT_LE(sim.world().clearance(0), std::hypot(0.1, 0.2) - 0.01);
  int far_steps = 0, far_substeps = 0, most = 0;
  double lowest = 1.0;
  while (sim.time() < 1.0) {
    sim.step();
    const double z = sim.world().pose(0).position.z;
    lowest = std::min(lowest, z);
    if (z > 0.2) ++far_steps, far_substeps += sim.records().back().substeps;
    most = std::max(most, sim.records().back().substeps);
  }
  EXPECT_EQ(far_substeps, far_steps) << "one substep each while 0.2 m and more above the ground";
  EXPECT_GE(most, 4) << "more near the ground";
  EXPECT_GT(lowest, 0.005 - 0.3 * 0.005) << "no deeper than the contact allowance";
  EXPECT_NEAR(sim.world().pose(0).position.z, 0.005, 2e-4) << "resting on the ground";
}

// simulation.linear_damping is a factor per rigid step, whatever the number
// of substeps: a ball flying at 20 m/s along a bar 1 mm away (about 20
// substeps a step by the travel bound) keeps 0.99^n of its speed after n
// steps of linear_damping 0.01, as one substep a step would (ODE damps once
// per step it takes, which gave 0.99^(20 n)).
TEST(FreeFlight, DampingPerRigidStepWhateverTheSubsteps) {
  SceneDescription s = test_support::weightless_scene("damping");
  s.materials["wood"] = InertMaterial{};
  s.bodies.push_back(body("ball", Sphere{0.005}, "wood", {0, 0, 0}, false, 7800.0));
  s.bodies.back().velocity = {20.0, 0, 0};
  s.bodies.push_back(body("bar", Box{{3.0, 0.01, 0.01}}, "wood", {1.5, 0.011, 0}, true));
  s.simulation.time_step = 0.001;
  s.simulation.linear_damping = 0.01;
  Simulation sim(s);
  int steps = 0, most = 0;
  while (steps < 40) {
    sim.step();
    ++steps;
    most = std::max(most, sim.records().back().substeps);
  }
  EXPECT_GE(most, 10) << "the bar's clearance keeps the substeps many";
  EXPECT_NEAR(norm(sim.world().velocity(0)), 20.0 * std::pow(0.99, steps), 1e-9 * 20.0);
}

TEST(CompassNeedle, SmallAnglePeriodAndNoNetForce) {
  SceneDescription s = weightless_scene("compass");
  const double M = 8e5, R = 0.005, density = 7500.0, H = 2e3, theta0 = 0.05;
  s.materials["magnet"] = PermanentMaterial{{M, 0, 0}, 0.0};
  BodyDescription needle = body("needle", Sphere{R}, "magnet", {0.1, -0.2, 0.3}, false, density);
  needle.orientation = {std::cos(theta0 / 2), 0, 0, std::sin(theta0 / 2)};  // turned theta0 about z
  s.bodies.push_back(needle);
  s.external_field = {H, 0, 0};
  s.simulation.time_step = 0.0005;
  Simulation sim(s);
  const double volume = 4.0 / 3.0 * kPi * R * R * R, mass = density * volume;
  const double inertia = 0.4 * mass * R * R;
  const double period = 2 * kPi * std::sqrt(inertia / (kMu0 * M * volume * H));
  // Angle of the moment about z; count zero crossings from + to -.
  auto angle = [&] {
    const Vec3 m = sim.magnetics().moment(0);
    return std::atan2(m.y, m.x);
  };
  sim.step();
  std::vector<double> crossings;
  double previous = angle();
  while (sim.time() < 4.5 * period) {
    sim.step();
    const double a = angle();
    if (previous > 0 && a <= 0) crossings.push_back(sim.time() - sim.scene().simulation.time_step * a / (a - previous));
    previous = a;
    EXPECT_EQ(norm(sim.magnetics().force(0)), 0.0);
  }
  ASSERT_GE(crossings.size(), 3u);
  const double measured = (crossings.back() - crossings.front()) / static_cast<double>(crossings.size() - 1);
  EXPECT_NEAR(measured, period, 0.02 * period);
  EXPECT_LT(norm(sim.world().pose(0).position - Vec3{0.1, -0.2, 0.3}), 1e-12);
}

// A crane ball (8 moments, uniaxial anisotropy H_K 3.2e5 A/m) turning in a
// uniform field of 3e5 A/m across its easy axis, weightless and touching
// nothing (benchmarks/anisotropic_ball_turning.json): the field turns it
// faster and slower twice a turn (about 1100 to 1300 rad/s), and nothing else
// acts, so its fastest speed per turn must not grow (a torque update that
// pumped energy would raise it turn by turn; a ball rolling on the crane's
// side face keeps such speeds for a second: docs/benchmarks.md section 4). Compared
// over about 95 turns, after the first 0.05 s in which the magnetization
// leaves its starting state.
TEST(AnisotropicBall, TurnsInAUniformFieldWithoutGainingEnergy) {
  const SceneDescription scene = load_scene(ODEMAG_SOURCE_DIR "/benchmarks/anisotropic_ball_turning.json");
  Simulation sim(scene);
  auto fastest_until = [&](double t) {
    double fastest = 0.0;
    while (sim.time() < t) {
      sim.step();
      fastest = std::max(fastest, norm(sim.world().angular_velocity(0)));
    }
    return fastest;
  };
  fastest_until(0.05);
  const double early = fastest_until(0.1);
  fastest_until(0.45);
  const double late = fastest_until(0.5);
  EXPECT_GT(early, 1000.0);  // it turns, faster than it was started
  EXPECT_LE(late, early * (1.0 + 1e-3));
  const Vec3 omega = sim.world().angular_velocity(0);
  EXPECT_LT(std::hypot(omega.x, omega.z),
            1e-6 * std::abs(omega.y));  // about the axis it was turned about
}

// Two equal permanent balls released at rest attract; before they touch, the
// total momentum stays zero to 1e-9 of either ball's momentum.
TEST(TwoMagnets, AttractWithMomentumConserved) {
  SceneDescription s = weightless_scene("two_magnets");
  s.simulation.time_step = 0.001;
  s.materials["magnet"] = PermanentMaterial{{0, 0, 1e6}, 0.0};
  s.bodies.push_back(body("a", Sphere{0.004}, "magnet", {0, 0, 0}));
  s.bodies.push_back(body("b", Sphere{0.004}, "magnet", {0.002, -0.001, 0.04}));
  Simulation sim(s);
  const double m = sim.world().mass(0);
  double largest = 0.0;
  while (norm(sim.world().pose(1).position - sim.world().pose(0).position) > 0.0085) {
    sim.step();
    const Vec3 pa = m * sim.world().velocity(0), pb = m * sim.world().velocity(1);
    largest = std::max(largest, norm(pa));
    ASSERT_LT(norm(pa + pb), 1e-9 * norm(pa) + 1e-300) << "t=" << sim.time();
    ASSERT_LT(sim.time(), 5.0);
  }
  EXPECT_GT(largest, 1e-6);  // they did move towards each other
  EXPECT_GT(sim.world().velocity(0).z, 0.0);
  EXPECT_LT(sim.world().velocity(1).z, 0.0);
}

// Time-line events happen at their times: a removed body stops interacting;
// a magnetization ramp reaches its end value.
TEST(Timeline, RemovedBodyStopsInteractingAndRampReachesItsEnd) {
  SceneDescription s = weightless_scene("timeline");
  s.simulation.time_step = 0.001;
  s.materials["magnet"] = PermanentMaterial{{0, 0, 1e6}, 0.0};
  s.materials["steel"] = steel();
  s.bodies.push_back(body("magnet", Box{{0.02, 0.01, 0.01}}, "magnet", {0, 0, 0}, true));
  s.bodies.push_back(body("crane", Box{{0.02, 0.01, 0.01}}, "magnet", {0.2, 0, 0}, true));
  s.bodies.push_back(body("ball", Sphere{0.003}, "steel", {0, 0, -0.03}, true));
  TimelineEvent remove;
  remove.kind = TimelineEvent::Kind::remove_body;
  remove.time = remove.end_time = 0.1;
  remove.body = "magnet";
  TimelineEvent ramp;
  ramp.kind = TimelineEvent::Kind::scale_magnetization;
  ramp.time = 0.05;
  ramp.end_time = 0.15;
  ramp.value = 0.25;
  ramp.body = "crane";
  s.timeline = {remove, ramp};
  Simulation sim(s);
  sim.advance_to(0.099);
  EXPECT_GT(norm(sim.magnetics().force(2)), 0.0);
  EXPECT_NEAR(sim.magnetics().magnetization_scale(1), 1.0 - 0.75 * (0.098 - 0.05) / 0.1, 1e-9);
  sim.advance_to(0.101);
  EXPECT_FALSE(sim.magnetics().active(0));
  // The ball now feels only the distant crane magnet, 0.2 m away.
  const double far_force = norm(sim.magnetics().force(2));
  sim.advance_to(0.2);
  EXPECT_EQ(sim.magnetics().magnetization_scale(1), 0.25);
  EXPECT_EQ(norm(sim.magnetics().force(0)), 0.0);
  EXPECT_LT(far_force, 1e-3 * 1.0);
  EXPECT_LT(norm(sim.magnetics().force(2)), far_force);  // the crane got weaker
}

TEST(Timeline, KeyframedBodyFollowsItsTrack) {
  SceneDescription s;
  s.file = "keys";
  s.gravity = {0, 0, 0};
  s.materials["wood"] = InertMaterial{};
  s.bodies.push_back(body("slider", Box{{0.01, 0.01, 0.01}}, "wood", {0, 0, 0.1}, true));
  TimelineEvent keys;
  keys.kind = TimelineEvent::Kind::keyframes;
  keys.body = "slider";
  keys.keys = {{0.0, {0, 0, 0.1}, {}}, {1.0, {0.1, 0, 0.2}, {std::cos(0.5), 0, 0, std::sin(0.5)}}};
  s.timeline = {keys};
  s.simulation.time_step = 0.01;
  Simulation sim(s);
  sim.advance_to(0.5);
  const BodyPose p = sim.world().pose(0);
  EXPECT_NEAR(p.position.x, 0.05, 1e-9);
  EXPECT_NEAR(p.position.z, 0.15, 1e-9);
  // Half-way the orientation is a rotation by 0.5 rad about z.
  EXPECT_NEAR(std::atan2(p.rotation.m[1][0], p.rotation.m[0][0]), 0.5, 1e-6);
}

// A body that is not fixed follows its track while the track runs and is
// free after the last key, with the track's last velocity (it was held at
// the last key for good, a kinematic body without a word).
TEST(Timeline, KeyframedDynamicBodyIsReleasedAfterItsLastKey) {
  SceneDescription s;
  s.file = "throw";
  s.gravity = {0, 0, -9.81};
  s.simulation.ground = false;
  s.simulation.time_step = 0.001;
  s.materials["wood"] = InertMaterial{};
  s.bodies.push_back(body("ball", Sphere{0.01}, "wood", {0, 0, 1.0}, false));
  TimelineEvent keys;
  keys.kind = TimelineEvent::Kind::keyframes;
  keys.body = "ball";
  keys.keys = {{0.0, {0, 0, 1.0}, {}}, {0.2, {0.2, 0, 1.0}, {}}};  // 1 m/s along x, no fall
  keys.time = 0.0;
  keys.end_time = 0.2;
  s.timeline = {keys};
  Simulation sim(s);
  sim.advance_to(0.1);
  EXPECT_NEAR(sim.world().pose(0).position.x, 0.1, 1e-9);
  EXPECT_NEAR(sim.world().pose(0).position.z, 1.0, 1e-9);  // gravity does not act on the track
  sim.advance_to(0.5);
  // Released at t = 0.2 s with v = (1, 0, 0): a throw, 0.3 s of free flight.
  const double t = 0.3;
  EXPECT_NEAR(sim.world().pose(0).position.x, 0.2 + 1.0 * t, 2e-3);
  EXPECT_NEAR(sim.world().pose(0).position.z, 1.0 - 0.5 * 9.81 * t * t, 5e-3);
  EXPECT_NEAR(sim.world().velocity(0).z, -9.81 * t, 2e-2);
  EXPECT_FALSE(sim.world().kinematic(0));
}

// Events at t = 0 hold in the state at t = 0, before the first step (frame 0
// and the first state line of `odemag run`), as apply_events_at_start gives
// `odemag solve`.
TEST(Timeline, EventsAtTimeZeroHoldBeforeTheFirstStep) {
  SceneDescription s = weightless_scene("events_at_zero");
  s.materials["magnet"] = PermanentMaterial{{0, 0, 1e6}, 0.0};
  s.materials["steel"] = steel();
  s.bodies.push_back(body("magnet", Sphere{0.01}, "magnet", {0, 0, 0}, true));
  s.bodies.push_back(body("ball", Sphere{0.005}, "steel", {0, 0, 0.03}, true));
  s.bodies.push_back(body("other", Sphere{0.005}, "steel", {0.05, 0, 0}, true));
  TimelineEvent off;
  off.kind = TimelineEvent::Kind::scale_magnetization;
  off.body = "magnet";
  off.value = 0.0;
  TimelineEvent remove;
  remove.kind = TimelineEvent::Kind::remove_body;
  remove.body = "other";
  TimelineEvent field;
  field.kind = TimelineEvent::Kind::external_field;
  field.field = {0, 0, 1000};
  s.timeline = {off, remove, field};
  Simulation sim(s);
  EXPECT_EQ(sim.magnetics().magnetization_scale(0), 0.0);
  EXPECT_FALSE(sim.magnetics().active(2));
  EXPECT_FALSE(sim.world().enabled(2));
  EXPECT_EQ(sim.magnetics().external_field().z, 1000.0);

  MagneticSystem system = build_magnetic_system(s);
  RelaxOptions options = s.solver.relax;
  apply_events_at_start(s, system, options);
  EXPECT_EQ(system.state.magnetization_scale[0], 0.0);
  EXPECT_EQ(system.state.active[2], 0);
  EXPECT_EQ(system.state.external_field.z, 1000.0);
  // The relaxed moments agree: the ball feels only H_E.
  sim.magnetics().compute();
  auto backend = make_cpu_backend(1);
  magnetic_step(system.model, system.state, options, *backend);
  EXPECT_NEAR(body_moment(system.model, system.state, 1).z, sim.magnetics().moment(1).z,
              1e-6 * std::abs(sim.magnetics().moment(1).z));
  // A sphere of chi -> large in H_E: m = 3 V H_E (its demagnetising factor 1/3).
  const double V = 4.0 / 3.0 * kPi * std::pow(0.005, 3);
  EXPECT_NEAR(body_moment(system.model, system.state, 1).z, 3.0 * V * 1000.0, 0.01 * 3.0 * V * 1000.0);
}

// Zones that would give a ball more than kMaxRefinedCells cells: the ball
// keeps its plain cells, and the scene's notices name it and the cap.
TEST(Simulation, ContactZonesBeyondTheCapLeaveThePlainCellsWithANotice) {
  SceneDescription s;
  s.file = "big";
  s.materials["iron"] = test_support::steel();
  for (const auto& [name, z] : {std::pair{"a", 0.0}, std::pair{"b", 0.0101}}) {
    s.bodies.push_back(body(name, Sphere{0.005}, "iron", {0.0, 0.0, z}));
    s.bodies.back().cell_size = 0.0005;
  }
  ASSERT_TRUE(s.solver.contact_refinement);  // the default
  const std::vector<std::vector<RefinedZone>> zones = scene_contact_zones(s);
  EXPECT_TRUE(zones[0].empty());
  EXPECT_TRUE(zones[1].empty());
  const std::vector<std::string> notices = scene_notices(s);
  ASSERT_EQ(notices.size(), 2u);
  EXPECT_NE(notices[0].find("bodies[0]"), std::string::npos) << notices[0];
  EXPECT_NE(notices[0].find("4000"), std::string::npos) << notices[0];
  // At R/h 4.5 the zones fit.
  for (BodyDescription& b : s.bodies) b.cell_size = 0.005 / 4.5;
  EXPECT_FALSE(scene_contact_zones(s)[0].empty());
  EXPECT_TRUE(scene_notices(s).empty());
}

// Refined contact zones follow the contacts (docs/model.md "Refined contact
// zones"): a lattice ball that slides over another at 3 m/s has its contact
// point move by 1.4 mm and 1.2 mm in the first two steps, in both balls'
// frames, more than kContactZoneFollowDistance h (0.83 mm), so after each
// step both balls get new zones at their contact points, with no notice. The model then is the one
// a fresh build with zones at those points has, and relaxing from the carried-over magnetization
// gives its force. Balls that stay put keep their zones, and without solver.contact_refinement
// nothing moves.
TEST(Simulation, ContactZonesFollowASlidingBall) {
  const auto scene = [](double speed, bool refine) {
    char text[1200];
    std::snprintf(text, sizeof text, R"({
      "gravity": [0, 0, 0],
      "simulation": {"time_step": 0.001},
      "external_field": [0, 0, 1000],
      "materials": {"iron": {"type": "soft", "saturation": 1e9, "susceptibility": 10}},
      "bodies": [{"name": "lower", "shape": {"sphere": 0.005}, "material": "iron", "cell_size": 0.0016667,
                  "fixed": true},
                 {"name": "upper", "shape": {"sphere": 0.005}, "material": "iron", "cell_size": 0.0016667,
                  "position": [0, 0, 0.01025], "velocity": [%g, 0, 0]}],
      "solver": {"contact_refinement": %s}})",
                  speed, refine ? "true" : "false");
    return parse_scene(text, "sliding.json");
  };
  auto rezoned = [](const Simulation& sim) {
    int total = 0;
    for (const StepReport& r : sim.records()) total += r.rezoned;
    return total;
  };
  Simulation sliding(scene(3.0, true));
  for (int s = 0; s < 2; ++s) {
    sliding.step();
    EXPECT_EQ(sliding.records().back().rezoned, 2) << "step " << s;
  }
  EXPECT_TRUE(sliding.notices().empty()) << sliding.notices()[0];

  // A fresh model with zones at the contact points of the final poses
  // (compute() reads them from the ODE bodies).
  ASSERT_TRUE(sliding.magnetics().compute().converged);
  const MagneticState& state = sliding.magnetics().state();
  const SceneDescription& description = sliding.scene();
  MagneticModel fresh;
  for (int b = 0; b < 2; ++b) {
    const double h = description.body_cell_size(b);
    std::vector<RefinedZone> zones;
    for (const Vec3& point : contact_points(description, state.pose, state.active, b))
      zones.push_back({point, default_refinement_radii(h)});
    ASSERT_EQ(zones.size(), 1u);
    fresh.add_body(description.bodies[b].name, description.bodies[b].shape,
                   description.materials.at("iron"), h, zones);
  }
  ASSERT_EQ(sliding.magnetics().model().cell_count(), fresh.cell_count());
  for (int b = 0; b < 2; ++b)
    EXPECT_EQ(sliding.magnetics().model().body(b).pair_tensors, fresh.body(b).pair_tensors) << b;
  MagneticState fresh_state = make_state(fresh, description.seed);
  fresh_state.pose = state.pose;
  fresh_state.external_field = state.external_field;
  auto backend = make_cpu_backend(1);
  ASSERT_TRUE(magnetic_step(fresh, fresh_state, description.solver.relax, *backend).converged);
  EXPECT_LT(norm(sliding.magnetics().force(1) - fresh_state.force[1]),
            2e-3 * norm(fresh_state.force[1]));

  Simulation resting(scene(0.0, true));
  for (int s = 0; s < 2; ++s) resting.step();
  EXPECT_EQ(rezoned(resting), 0);
  EXPECT_TRUE(resting.notices().empty());

  Simulation plain(scene(3.0, false));
  for (int s = 0; s < 2; ++s) plain.step();
  EXPECT_EQ(rezoned(plain), 0);
}

// Rolling and spinning resistance (simulation.contact.rolling_friction,
// spinning_friction; docs/simulation.md "Contacts"): a non-magnetic ball of
// radius R on the ground, spinning about the vertical or rolling without
// slipping. A resistance torque rho m g about the contact normal stops a spin
// at omega' = -rho m g / I = -5 rho g / (2 R^2) (I = 2/5 m R^2); about the
// tangent it decelerates a ball rolling on its contact radius R' (the shape's
// R and its collision skin, 2% of R: docs/simulation.md) at
// a = -rho g R' / (2/5 R^2 + R'^2) (m a = -f, I a / R' = f R' - rho m g).
// Each coefficient acts on its own axis only, and a zero one leaves that
// motion free.
struct ResistanceCase {
  ContactSolver solver;
  double rolling, spinning;  // m; spinning < 0: the default (rolling_friction)
};

class ContactResistance : public ::testing::TestWithParam<ResistanceCase> {
 protected:
  static constexpr double kR = 0.005, kRolling = 1.02 * kR, kG = 9.81;
  // The ball at rest on the ground with the given velocities, stepped for t.
  static std::pair<Vec3, Vec3> run(const ResistanceCase& c, const Vec3& velocity,
                                   const Vec3& angular_velocity, double t) {
    SceneDescription s;
    s.file = "resistance";
    s.materials["wood"] = InertMaterial{};
    s.bodies.push_back(body("ball", Sphere{kR}, "wood", {0, 0, kR}, false, 7800.0));
    s.bodies.back().velocity = velocity;
    s.bodies.back().angular_velocity = angular_velocity;
    s.simulation.time_step = 0.001;
    s.simulation.contact_solver = c.solver;
    s.simulation.contact.rolling_friction = c.rolling;
    s.simulation.contact.spinning_friction = c.spinning;
    Simulation sim(s);
    while (sim.time() < t - 1e-9) sim.step();
    return {sim.world().velocity(0), sim.world().angular_velocity(0)};
  }
};

TEST_P(ContactResistance, SpinStopsAtTheClosedFormRateOfItsCoefficient) {
  const ResistanceCase c = GetParam();
  const double rho = c.spinning < 0.0 ? c.rolling : c.spinning;
  const double omega0 = 20.0, t = 0.5;
  const double omega = run(c, {}, {0, 0, omega0}, t).second.z;
  if (rho == 0.0) {
    EXPECT_NEAR(omega, omega0, 1e-6 * omega0) << "free spin";
  } else {
    const double expected = omega0 - 5.0 * rho * kG / (2.0 * kR * kR) * t;
    EXPECT_NEAR(omega, expected, 0.02 * (omega0 - expected)) << "2% of the spin lost";
  }
}

TEST_P(ContactResistance, RollingBallDeceleratesAtTheClosedFormRateOfItsCoefficient) {
  const ResistanceCase c = GetParam();
  // Along x and along y: the contact's two friction directions (ODE's
  // friction pyramid: a ball rolling along a diagonal of them is held back by
  // up to sqrt(2) times as much, docs/simulation.md "Contacts").
  const double v0 = 0.2, t = 0.5;
  const double deceleration = c.rolling * kG * kRolling / (0.4 * kR * kR + kRolling * kRolling);
  const double expected = v0 - deceleration * t;
  const Vec3 along_x = run(c, {v0, 0, 0}, {0, v0 / kRolling, 0}, t).first;
  const Vec3 along_y = run(c, {0, v0, 0}, {-v0 / kRolling, 0, 0}, t).first;
  for (const auto& [v, across] :
       {std::pair{along_x.x, along_x.y}, std::pair{along_y.y, along_y.x}}) {
    EXPECT_NEAR(across, 0.0, 1e-9 * v0) << "straight on";
    if (c.rolling == 0.0) {
      EXPECT_NEAR(v, v0, 1e-6 * v0) << "free rolling";
    } else {
      EXPECT_NEAR(v, expected, 0.02 * (v0 - expected)) << "2% of the speed lost";
    }
  }
}

// Along the diagonal of the contact's two friction directions (x and y for
// a ball on the ground): ODE bounds each rolling row by rho N on its own (a
// pyramid), so the ball is held back by sqrt(2) times the closed form.
TEST_P(ContactResistance, RollingAlongTheDiagonalOfTheFrictionDirections) {
  const ResistanceCase c = GetParam();
  if (c.rolling == 0.0) GTEST_SKIP() << "no rolling resistance";
  const double v0 = 0.2, t = 0.5;
  const double deceleration = c.rolling * kG * kRolling / (0.4 * kR * kR + kRolling * kRolling);
  const double held_back = std::sqrt(2.0);
  const double u = v0 / std::sqrt(2.0);
  const Vec3 v = run(c, {u, u, 0}, {-u / kRolling, u / kRolling, 0}, t).first;
  const double speed_lost = v0 - std::hypot(v.x, v.y);
  EXPECT_NEAR(speed_lost, held_back * deceleration * t, 0.02 * held_back * deceleration * t);
  EXPECT_NEAR(v.x, v.y, 1e-9 * v0) << "straight on";
}

INSTANTIATE_TEST_SUITE_P(
    Coefficients, ContactResistance,
    ::testing::Values(ResistanceCase{ContactSolver::quick, 1e-5, -1.0},
                      ResistanceCase{ContactSolver::quick, 1e-4, 0.0},
                      ResistanceCase{ContactSolver::quick, 0.0, 1e-5},
                      ResistanceCase{ContactSolver::quick, 0.0, 0.0},
                      ResistanceCase{ContactSolver::quick, 1e-4, 5e-6},
                      ResistanceCase{ContactSolver::exact, 1e-5, -1.0},
                      ResistanceCase{ContactSolver::exact, 1e-4, 0.0},
                      ResistanceCase{ContactSolver::exact, 0.0, 1e-5}));

// The rows each contact asks ODE for: none of rolling or spinning
// resistance when both coefficients are 0 (ODE adds three with
// dContactRolling whatever they are), all three with one coefficient when
// they are equal (the engine's surface before spinning_friction, bit for
// bit), and per axis otherwise, a zero one without its row.
TEST(ContactSurface, AsksForTheResistanceRowsOfNonzeroCoefficientsOnly) {
  ContactSettings c;
  c.rolling_friction = 0.0;
  c.spinning_friction = 0.0;
  EXPECT_EQ(contact_surface(c).mode & dContactRolling, 0);

  c.rolling_friction = 1e-5;
  c.spinning_friction = -1.0;  // the default: rolling_friction
  dSurfaceParameters s = contact_surface(c);
  EXPECT_EQ(s.mode,
            dContactBounce | dContactSoftCFM | dContactSoftERP | dContactApprox1 | dContactRolling);
  EXPECT_EQ(s.rho, 1e-5);
  EXPECT_EQ(s.rho2, 1e-5);
  EXPECT_EQ(s.rhoN, 1e-5);

  c.spinning_friction = 0.0;
  s = contact_surface(c);
  EXPECT_NE(s.mode & dContactAxisDep, 0);
  EXPECT_EQ(s.mu2, s.mu) << "dContactAxisDep reads mu2";
  EXPECT_EQ(s.rho, 1e-5);
  EXPECT_EQ(s.rho2, 1e-5);
  EXPECT_LT(s.rhoN, 0.0) << "no spinning row";

  c.rolling_friction = 0.0;
  c.spinning_friction = 2e-5;
  s = contact_surface(c);
  EXPECT_LT(s.rho, 0.0);
  EXPECT_LT(s.rho2, 0.0);
  EXPECT_EQ(s.rhoN, 2e-5);
}

}  // namespace
}  // namespace odemag
