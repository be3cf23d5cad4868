// The embedder's substepping (engine/embedding/magnetic_stepper.h, docs/embedding.md
// "Substeps"): the world of demos/embed_minimal.cpp, an iron ball pulled to a
// bar magnet's pole, stepped with MagneticStepper ends with the ball resting
// on the magnet, where the plain loop (apply(); collide; quickstep) either
// sinks it by the contact surface layer or, without one, throws it away;
// with one substep the stepper is that plain loop, bit for bit.
#include <gtest/gtest.h>

#include <ode/ode.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

#include "odemag/magnetic_forces.h"
#include "odemag/stepper.h"
#include "engine/embedding/substeps.h"
#include "odemag/constants.h"
#include "magnetics/model/backend.h"

namespace odemag {
namespace {

constexpr double kRadius = 0.005;  // the ball's, m
constexpr double kStep = 0.001;    // rigid step, s

// demos/embed_minimal.cpp's world: a 4 x 1 x 1 cm bar magnet (M_r 8e5 A/m
// along x) lying on the ground as a static geom, and an iron ball of radius
// 5 mm released 2 cm beyond its north pole, 3 cm up.
struct EmbedWorld {
  explicit EmbedWorld(double surface_layer) {
    dInitODE();
    world = dWorldCreate();
    dWorldSetGravity(world, 0, 0, -9.81);
    dWorldSetContactSurfaceLayer(world, surface_layer);
    space = dHashSpaceCreate(nullptr);
    contacts = dJointGroupCreate(0);
    dCreatePlane(space, 0, 0, 1, 0);
    dGeomSetPosition(dCreateBox(space, 0.04, 0.01, 0.01), 0, 0, 0.005);
    const int bar = magnetics.attach(nullptr, Box{{0.04, 0.01, 0.01}}, PermanentMaterial{{8e5, 0, 0}}, 0.005, "bar");
    magnetics.set_pose(bar, BodyPose{Mat3{}, {0, 0, 0.005}});
    ball = dBodyCreate(world);
    dMass mass;
    dMassSetSphere(&mass, 7870, kRadius);
    dBodySetMass(ball, &mass);
    dBodySetPosition(ball, 0.04, 0, 0.03);
    dGeomSetBody(dCreateSphere(space, kRadius), ball);
    SoftMaterial iron;
    iron.saturation = 1.7e6;
    iron.susceptibility = 5000;
    magnetics.attach(ball, Sphere{kRadius}, iron, 0.0, "ball");
  }
  ~EmbedWorld() {
    dJointGroupDestroy(contacts);
    dSpaceDestroy(space);
    dWorldDestroy(world);
    dCloseODE();
  }
  static void near_callback(void* data, dGeomID a, dGeomID b) {
    auto* w = static_cast<EmbedWorld*>(data);
    if (!dGeomGetBody(a) && !dGeomGetBody(b)) return;
    dContact contact[4] = {};
    const int n = dCollide(a, b, 4, &contact[0].geom, sizeof(dContact));
    for (int i = 0; i < n; ++i) {
      contact[i].surface.mode = dContactBounce;
      contact[i].surface.mu = 0.5;
      contact[i].surface.bounce = 0.1;
      dJointAttach(dJointCreateContact(w->world, w->contacts, &contact[i]), dGeomGetBody(a), dGeomGetBody(b));
    }
  }
  // The loop of docs/embedding.md "The API in one loop", one substep per step.
  void plain_step() {
    magnetics.apply();
    dSpaceCollide(space, this, &near_callback);
    dWorldQuickStep(world, kStep);
    dJointGroupEmpty(contacts);
  }
  MagneticStepper stepper(const StepperSettings& settings = {}) {
    return MagneticStepper(magnetics, world, space, &near_callback, this, contacts, settings);
  }
  // Ball surface to the magnet's surface, m (negative: inside).
  double gap() const {
    const dReal* p = dBodyGetPosition(ball);
    const double dx = std::max(std::abs(p[0]) - 0.02, 0.0), dy = std::max(std::abs(p[1]) - 0.005, 0.0),
                 dz = std::max(std::abs(p[2] - 0.005) - 0.005, 0.0);
    return std::sqrt(dx * dx + dy * dy + dz * dz) - kRadius;
  }
  dWorldID world;
  dSpaceID space;
  dJointGroupID contacts;
  dBodyID ball;
  MagneticForces magnetics{{}, make_cpu_backend(1)};
};

// Touching within a thousandth of the ball's radius counts as resting on the
// magnet (ODE's contacts leave F h CFM / ERP, well under a micrometre here).
constexpr double kTouching = 1e-3 * kRadius;

// Resting: in the last second the ball touches the magnet in most steps and
// is never thrown off. Without a contact surface layer ODE drops the resting
// contact now and then (in 79 of 1000 steps here), and the pull then moves the
// ball a h^2 into the magnet for one step (1.7 mm at 1 ms, about a third of
// its radius) before the contact pushes it out: the substep rule allows that
// travel for a body in contact (0.3 of its size, engine/embedding/substeps.cpp).
TEST(MagneticStepper, EmbedMinimalBallRestsOnTheMagnet) {
  EmbedWorld w(0.0);
  MagneticStepper stepper = w.stepper();
  int most = 1, touching = 0;
  double deepest = 0.0, farthest = 0.0;
  for (int i = 0; i < 2000; ++i) {
    most = std::max(most, stepper.step(kStep).substeps);
    if (i < 1000) continue;
    touching += std::abs(w.gap()) < kTouching ? 1 : 0;
    deepest = std::min(deepest, w.gap()), farthest = std::max(farthest, w.gap());
  }
  EXPECT_GE(touching, 800) << "steps touching in the last second";
  EXPECT_LT(farthest, kTouching) << "never off the magnet";
  EXPECT_GT(deepest, -0.4 * kRadius) << "sinks at most a h^2 for a step";
  EXPECT_GT(norm(w.magnetics.force(1)), 100.0 * 7870 * 4.0 / 3.0 * kPi * std::pow(kRadius, 3) * 9.81)
      << "held by the pole";
  EXPECT_GT(most, 1) << "the rule split the steps of the approach";
  EXPECT_NEAR(stepper.time(), 2.0, 1e-9);
}

TEST(MagneticStepper, PlainLoopSinksOrThrowsTheBallAway) {
  {
    // As demos/embed_minimal.cpp did: the surface layer keeps the contact
    // but lets the ball sink in by its thickness, 0.1 mm.
    EmbedWorld w(1e-4);
    for (int i = 0; i < 2000; ++i) w.plain_step();
    EXPECT_LT(w.gap(), -0.9e-4);
  }
  {
    // Without it the contact flickers and the pull throws the ball out.
    EmbedWorld w(0.0);
    for (int i = 0; i < 2000; ++i) w.plain_step();
    EXPECT_GT(w.gap(), 1e-3);
  }
}

// max_substeps 1: the stepper is the plain loop, bit for bit. (Each run from
// the same seed of ODE's random number generator, which dWorldQuickStep
// uses to order the constraints.)
TEST(MagneticStepper, OneSubstepIsThePlainLoop) {
  EmbedWorld plain(1e-4), stepped(1e-4);
  dRandSetSeed(1);
  for (int i = 0; i < 300; ++i) plain.plain_step();
  StepperSettings one;
  one.substeps.max_substeps = 1;
  MagneticStepper stepper = stepped.stepper(one);
  dRandSetSeed(1);
  for (int i = 0; i < 300; ++i) {
    const StepReport& r = stepper.step(kStep);
    ASSERT_EQ(r.substeps, 1);
    ASSERT_EQ(r.relaxations, 1);
  }
  for (int k = 0; k < 3; ++k) {
    EXPECT_EQ(dBodyGetPosition(plain.ball)[k], dBodyGetPosition(stepped.ball)[k]);
    EXPECT_EQ(dBodyGetLinearVel(plain.ball)[k], dBodyGetLinearVel(stepped.ball)[k]);
  }
  EXPECT_LT(plain.gap(), 0.0) << "touching after 0.3 s";
}

// MagneticSolve::moving: every substep relaxes, but a later substep holds
// the magnetization of the bodies that neither need the substeps nor touch
// one that does. A second iron ball resting on the ground 30 cm from the
// magnet is held whenever the falling one takes substeps; the falling one
// still comes to rest on the magnet and the resting one stays where it is.
TEST(MagneticStepper, MovingSolveHoldsTheRestingBall) {
  EmbedWorld w(0.0);
  dBodyID resting = dBodyCreate(w.world);
  dMass mass;
  dMassSetSphere(&mass, 7870, kRadius);
  dBodySetMass(resting, &mass);
  dBodySetPosition(resting, -0.3, 0, kRadius);
  dGeomSetBody(dCreateSphere(w.space, kRadius), resting);
  SoftMaterial iron;
  iron.saturation = 1.7e6;
  iron.susceptibility = 5000;
  w.magnetics.attach(resting, Sphere{kRadius}, iron, 0.0, "resting");
  StepperSettings settings;
  settings.magnetic_solve = MagneticSolve::moving;
  MagneticStepper stepper = w.stepper(settings);
  int later_substeps = 0, held = 0;
  for (int i = 0; i < 2000; ++i) {
    const StepReport& r = stepper.step(kStep);
    ASSERT_EQ(r.relaxations, r.substeps);
    later_substeps += r.substeps - 1;
    held += r.held;
  }
  ASSERT_GT(later_substeps, 0) << "the fall never needed substeps";
  EXPECT_GE(held, later_substeps) << "the resting ball in every later substep";
  EXPECT_NEAR(w.gap(), 0.0, kTouching);
  EXPECT_NEAR(dBodyGetPosition(resting)[0], -0.3, 1e-4);
}

// A force that turns non-finite (here: the magnet's magnetization scaled to
// NaN is refused, so a NaN velocity is given to the ball) ends the step at
// the substep that made it, and the next step() throws naming the body,
// before ODE's collision sees the NaN.
TEST(MagneticStepper, ANonFiniteStateStopsTheStepAndTheNextThrows) {
  EmbedWorld w(0.0);
  MagneticStepper stepper = w.stepper();
  for (int i = 0; i < 10; ++i) stepper.step(kStep);
  dBodySetLinearVel(w.ball, std::numeric_limits<double>::quiet_NaN(), 0, 0);
  const StepReport& r = stepper.step(kStep);
  EXPECT_EQ(r.non_finite_body, 1);
  EXPECT_EQ(stepper.non_finite_step(), 11);
  try {
    stepper.step(kStep);
    FAIL() << "no exception";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("body 1 ('ball') has a non-finite state at step 11"), std::string::npos)
        << e.what();
  }
}

// The rule for one free steel ball of 5 mm radius and 4 g, at rest.
void one_free_ball(SubstepRule& rule, std::vector<SubstepMotion>& motion) {
  rule.add_body({0.005, 0.0, 1e-9, false});
  motion.assign(1, SubstepMotion{});
  motion[0].free = true;
  motion[0].mass = 0.004;
}

// The rule: a body at rest far from anything needs one substep; a fast one
// near its size's travel more; the count falls only at a step's start after
// the hold time 2 pi dt / stiffness_limit.
TEST(SubstepRule, TravelBoundAndHold) {
  SubstepRule rule;
  std::vector<SubstepMotion> motion;
  one_free_ball(rule, motion);
  EXPECT_EQ(rule.needed(0.001, motion, 0.0, 0.0), 1);
  motion[0].velocity = {5.0, 0, 0};  // 5 mm per step: ten substeps of 0.5 mm
  EXPECT_EQ(rule.needed(0.001, motion, 0.0, 0.0), 10);
  // In contact the allowance is 0.3 of the size for what the contact holds
  // back (1.5 mm under 3000 m/s^2: h = sqrt(2 L / a) = 1 ms), but the
  // velocity's own travel stays 0.1 of it: a body sliding or pushed off at
  // speed gets the free-flight count (the 0.3 allowance gave 4 substeps).
  motion[0].in_contact = true;
  EXPECT_EQ(rule.needed(0.001, motion, 0.0, 0.0), 10);
  motion[0].velocity = {};
  motion[0].force = {3000.0 * 0.004 * 0.999, 0, 0};
  EXPECT_EQ(rule.needed(0.001, motion, 0.0, 0.0), 1) << "held by the contact (omega h = 0.77)";
  motion[0].in_contact = false;
  EXPECT_EQ(rule.needed(0.001, motion, 0.0, 0.0), 2) << "free: sqrt(2 * 0.5 mm / a) = 0.58 ms";
  motion[0].free = false;  // kinematic or disabled: not counted
  EXPECT_EQ(rule.needed(0.001, motion, 0.0, 0.0), 1);
  EXPECT_EQ(rule.update(10, 0.0, 0.001, true), 10);
  EXPECT_EQ(rule.update(2, 0.001, 0.001, true), 10) << "held";
  EXPECT_EQ(rule.update(1, 0.001, 0.001, false), 10);
  EXPECT_EQ(rule.update(1, 2.0 * kPi * 0.001, 0.001, false), 10) << "only at a step's start";
  EXPECT_EQ(rule.update(1, 2.0 * kPi * 0.001, 0.001, true), 2) << "the largest needed meanwhile";
  EXPECT_EQ(rule.update(1000, 0.01, 0.001, false), 64) << "capped at max_substeps";
}

// A body in free flight may also cover half its clearance per substep: a
// ball falling at 5 m/s (ten substeps of 0.5 mm by the tenth of its size)
// with 7 mm to the nearest other body needs two (0.5 + 3.5 mm each); the
// clearance is asked for only when the travel bound would bind, and neither
// for a body in contact nor for one pulled by a magnetic force above its
// weight (it grows steeply as the body nears the magnet).
TEST(SubstepRule, FreeFlightMayCoverHalfItsClearance) {
  SubstepRule rule;
  std::vector<SubstepMotion> motion;
  one_free_ball(rule, motion);
  const double g = 9.81;
  int asked = 0;
  double gap = 0.007;
  auto clearance = [&](int b) {
    EXPECT_EQ(b, 0);
    ++asked;
    return gap;
  };
  EXPECT_EQ(rule.needed(0.001, motion, g, 0.0, clearance), 1);
  EXPECT_EQ(asked, 0) << "at rest: nothing to bound";
  motion[0].velocity = {5.0, 0, 0};
  EXPECT_EQ(rule.needed(0.001, motion, g, 0.0, clearance), 2);
  EXPECT_EQ(asked, 1);
  gap = 0.0;  // touching its bounding box: the tenth alone (10 substeps, 11 with gravity)
  EXPECT_EQ(rule.needed(0.001, motion, g, 0.0, clearance), rule.needed(0.001, motion, g, 0.0));
  EXPECT_GE(rule.needed(0.001, motion, g, 0.0), 10);
  gap = 1.0;
  EXPECT_EQ(rule.needed(0.001, motion, g, 0.0, clearance), 1);
  motion[0].in_contact = true;
  EXPECT_EQ(rule.needed(0.001, motion, g, 0.0, clearance), 10) << "in contact: the clearance does not count";
  EXPECT_EQ(asked, 3);
  motion[0].in_contact = false;
  motion[0].force = {0.004 * g * 0.99, 0, 0};  // below its weight: counts
  EXPECT_EQ(rule.needed(0.001, motion, g, 0.0, clearance), 1);
  EXPECT_EQ(asked, 4);
  motion[0].force = {0.004 * g * 1.01, 0, 0};  // above: the tenth alone
  EXPECT_EQ(rule.needed(0.001, motion, g, 0.0, clearance), rule.needed(0.001, motion, g, 0.0));
  EXPECT_EQ(asked, 4);
}

// What each body needs alone (needed_by, which magnetic_solve "moving" asks):
// the count needed() gives is the largest of them.
TEST(SubstepRule, EachBodysNeedAndTheLargest) {
  SubstepRule rule;
  std::vector<SubstepMotion> motion;
  one_free_ball(rule, motion);
  rule.add_body({0.005, 0.0, 1e-9, false});
  motion.push_back(motion[0]);
  motion[1].velocity = {5.0, 0, 0};  // ten substeps of 0.5 mm
  EXPECT_EQ(rule.needed_by(0, 0.001, motion[0], 0.0, 0.0), 1);
  EXPECT_EQ(rule.needed_by(1, 0.001, motion[1], 0.0, 0.0), 10);
  EXPECT_EQ(rule.needed(0.001, motion, 0.0, 0.0), 10);
  motion[0].velocity = {0, 0, 2.0};
  EXPECT_EQ(rule.needed_by(0, 0.001, motion[0], 0.0, 0.0), 4);
  EXPECT_EQ(rule.needed(0.001, motion, 0.0, 0.0), 10);
  motion[1].free = false;  // not counted
  EXPECT_EQ(rule.needed_by(1, 0.001, motion[1], 0.0, 0.0), 1);
  EXPECT_EQ(rule.needed(0.001, motion, 0.0, 0.0), 4);
}

TEST(MagneticStepper, BadArgumentsThrow) {
  EmbedWorld w(0.0);
  EXPECT_THROW(MagneticStepper(w.magnetics, nullptr, w.space, &EmbedWorld::near_callback, &w, w.contacts),
               std::invalid_argument);
  EXPECT_THROW(MagneticStepper(w.magnetics, w.world, w.space, nullptr, &w, w.contacts), std::invalid_argument);
  MagneticStepper stepper = w.stepper();
  for (double dt : {0.0, -0.001, std::numeric_limits<double>::infinity(), std::nan("")})
    EXPECT_THROW(stepper.step(dt), std::invalid_argument) << dt;
}

}  // namespace
}  // namespace odemag
