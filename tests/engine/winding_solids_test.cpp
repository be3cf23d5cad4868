// The windings of coils as collision solids (engine/simulation/winding_solids.h):
// which points they cover, against the windings' definitions written here,
// and bodies that meet them in a simulation.
#include "engine/simulation/winding_solids.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>

#include "odemag/simulation.h"
#include "odemag/constants.h"
#include "tests/support/scene_builders.h"
#include "tests/support/windings.h"
#include "engine/simulation/rigid_world.h"

namespace odemag {
namespace {

using test_support::body;
using test_support::core_rectangle_distance;
using test_support::distance_from_copper;
using test_support::weightless_scene;

// How far beyond the copper the boxes of round parts may reach, relative to
// the radius: 1 - cos(7.5 deg), with a little room for rounding.
constexpr double kReach = 1.0 - 0.99144486137 + 1e-9;

bool covers(const CollisionSolid& s, const Vec3& p) {
  const Vec3 l = s.axes.transpose_times(p - s.centre);
  if (s.kind == CollisionSolid::Kind::cylinder)
    return std::hypot(l.x, l.y) <= s.size.x && std::abs(l.z) <= 0.5 * s.size.z;
  return std::abs(l.x) <= 0.5 * s.size.x && std::abs(l.y) <= 0.5 * s.size.y &&
         std::abs(l.z) <= 0.5 * s.size.z;
}

bool covered(const std::vector<CollisionSolid>& solids, const Vec3& p) {
  return std::any_of(solids.begin(), solids.end(),
                     [&](const CollisionSolid& s) { return covers(s, p); });
}

// An orthonormal frame with w along `axis` and u along `first` normal to it.
void frame(const Vec3& axis, const Vec3& first, Vec3& u, Vec3& v, Vec3& w) {
  w = normalized(axis);
  u = normalized(first - dot(first, w) * w);
  v = cross(w, u);
}

TEST(WindingSolids, CoverACircularCoilsCopperAndLeaveItsBoreOpen) {
  CircularCoil c;
  c.centre = {0.01, -0.02, 0.03};
  c.axis = {1.0, 1.0, 2.0};
  c.inner_radius = 0.02;
  c.outer_radius = 0.035;
  c.length = 0.025;
  c.current = 1.0;
  const std::vector<CollisionSolid> solids = winding_solids(c);
  Vec3 u, v, w;
  frame(c.axis, {0.0, 0.0, 1.0}, u, v, w);  // any u normal to the axis
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  int copper = 0, outside = 0;
  for (int i = 0; i < 40000; ++i) {
    const double rho = 1.3 * c.outer_radius * unit(rng), phi = 2.0 * kPi * unit(rng);
    const double z = c.length * (2.0 * unit(rng) - 1.0);
    const Vec3 p = c.centre + rho * (std::cos(phi) * u + std::sin(phi) * v) + z * w;
    if (rho >= c.inner_radius && rho <= c.outer_radius && std::abs(z) <= 0.5 * c.length) {
      ++copper;
      ASSERT_TRUE(covered(solids, p)) << "copper at rho " << rho << " z " << z;
    } else if (rho < c.inner_radius * (1.0 - kReach) || rho > c.outer_radius * (1.0 + kReach) ||
               std::abs(z) > 0.5 * c.length * (1.0 + 1e-9)) {
      ++outside;
      ASSERT_FALSE(covered(solids, p)) << "off the copper at rho " << rho << " z " << z;
    }
  }
  EXPECT_GT(copper, 5000);
  EXPECT_GT(outside, 20000);

  c.inner_radius = 0.0;  // no bore: the cylinder itself
  const std::vector<CollisionSolid> full = winding_solids(c);
  ASSERT_EQ(full.size(), 1u);
  EXPECT_TRUE(full[0].kind == CollisionSolid::Kind::cylinder);
  EXPECT_TRUE(covered(full, c.centre + 0.99 * c.outer_radius * u + 0.49 * c.length * w));
  EXPECT_FALSE(covered(full, c.centre + 1.01 * c.outer_radius * v));
}

// The rounded rectangle: the points at distance inner..outer corner radius
// from the core rectangle, |w| <= height / 2 (magnetics/sources/coil.h).
TEST(WindingSolids, CoverARoundedRectangleCoilsCopperAndLeaveItsCoreFree) {
  RoundedRectangleCoil c;
  c.centre = {0.0, 0.01, -0.02};
  c.axis = {0.0, 0.3, -1.0};
  c.width_direction = {1.0, 0.2, 0.0};
  c.core_half_width = 0.03;
  c.core_half_depth = 0.015;
  c.inner_corner_radius = 0.004;
  c.outer_corner_radius = 0.024;
  c.height = 0.04;
  c.current = 1.0;
  const std::vector<CollisionSolid> solids = winding_solids(c);
  Vec3 u, v, w;
  frame(c.axis, c.width_direction, u, v, w);
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  int copper = 0, outside = 0, core = 0;
  for (int i = 0; i < 60000; ++i) {
    const double pu = 0.07 * unit(rng), pv = 0.05 * unit(rng), pw = c.height * unit(rng);
    const Vec3 p = c.centre + pu * u + pv * v + pw * w;
    const double d = core_rectangle_distance(c, pu, pv);
    if (d >= c.inner_corner_radius && d <= c.outer_corner_radius &&
        std::abs(pw) <= 0.5 * c.height) {
      ++copper;
      ASSERT_TRUE(covered(solids, p)) << "copper at u " << pu << " v " << pv << " w " << pw;
    } else if (d < c.inner_corner_radius * (1.0 - kReach) ||
               d > c.outer_corner_radius * (1.0 + kReach) ||
               std::abs(pw) > 0.5 * c.height * (1.0 + 1e-9)) {
      ++outside;
      if (d == 0.0) ++core;
      ASSERT_FALSE(covered(solids, p))
          << "off the copper at u " << pu << " v " << pv << " w " << pw;
    }
  }
  EXPECT_GT(copper, 10000);
  EXPECT_GT(outside, 20000);
  EXPECT_GT(core, 2000);
}

TEST(WindingSolids, FilamentsAndSheetsHaveNone) {
  EXPECT_TRUE(winding_solids(CircularLoop{{}, {0, 0, 1}, 0.01, 1.0, 1.0}).empty());
  EXPECT_TRUE(winding_solids(Solenoid{{}, {0, 0, 1}, 0.01, 0.02, 1.0, 1.0}).empty());
  EXPECT_TRUE(winding_solids(StraightSegment{{}, {0.01, 0, 0}, 1.0, 1.0}).empty());
}

// A fixed inert frame carrying a coil (its current is immaterial here: the
// balls are inert) and inert balls of radius kR.
constexpr double kR = 0.005;

SceneDescription coil_frame_scene(const CoilSource& coil, bool gravity) {
  SceneDescription s = weightless_scene("winding");
  if (gravity) {
    s.gravity = {0.0, 0.0, -9.81};
    s.simulation.ground = true;
    s.simulation.ground_height = -0.1;
  }
  s.materials["wood"] = InertMaterial{};
  s.bodies.push_back(body("frame", Box{{0.004, 0.004, 0.004}}, "wood", {0, 0, 0}, true));
  s.bodies.back().coils.push_back(coil);
  s.simulation.time_step = 0.001;
  return s;
}

// Dropped onto the copper a ball rests on the winding's end face; dropped
// into the bore it falls through to the ground.
TEST(WindingSolids, ABallRestsOnTheWindingAndFallsThroughTheBore) {
  CircularCoil c;
  c.inner_radius = 0.02;
  c.outer_radius = 0.03;
  c.length = 0.02;
  c.current = 1.0;
  SceneDescription s = coil_frame_scene(c, true);
  s.bodies.push_back(body("on_copper", Sphere{kR}, "wood", {0.0, 0.025, 0.03}));
  s.bodies.push_back(body("in_bore", Sphere{kR}, "wood", {0.01, 0.0, 0.03}));
  Simulation sim(s);
  while (sim.time() < 0.6) sim.step();
  EXPECT_NEAR(sim.world().pose(1).position.z, 0.5 * c.length + kR, 0.02 * kR) << "on the end face";
  EXPECT_NEAR(sim.world().pose(2).position.z, -0.1 + kR, 0.02 * kR)
      << "on the ground below the bore";
}

// Balls sent at the outer side, at a rounded corner and, from the bore, at
// the inner side of a rounded-rectangle winding stay outside its copper.
TEST(WindingSolids, BallsSentAtARoundedRectangleWindingStayOutOfTheCopper) {
  RoundedRectangleCoil c;
  c.core_half_width = 0.01;
  c.core_half_depth = 0.01;
  c.inner_corner_radius = 0.012;
  c.outer_corner_radius = 0.022;
  c.height = 0.03;
  c.current = 1.0;
  SceneDescription s = coil_frame_scene(c, false);
  const double speed = 0.1;
  const double diagonal = 1.0 / std::sqrt(2.0);
  s.bodies.push_back(body("side", Sphere{kR}, "wood", {0.06, 0.0, 0.0}));
  s.bodies.back().velocity = {-speed, 0.0, 0.0};
  s.bodies.push_back(body("corner", Sphere{kR}, "wood", {0.05, 0.05, 0.005}));
  s.bodies.back().velocity = {-speed * diagonal, -speed * diagonal, 0.0};
  s.bodies.push_back(body("bore", Sphere{kR}, "wood",
                          {-0.012, 0.0, -0.004}));  // between the frame and the winding
  s.bodies.back().velocity = {0.0, speed, 0.0};
  Simulation sim(s);
  double closest[4] = {1.0, 1.0, 1.0, 1.0};
  while (sim.time() < 0.6) {
    sim.step();
    for (int i = 1; i <= 3; ++i) {  // the coil's frame is the world's
      const Vec3 p = sim.world().pose(i).position;
      closest[i] = std::min(closest[i], distance_from_copper(c, p.x, p.y, p.z));
    }
  }
  for (int i = 1; i <= 3; ++i) {
    EXPECT_GT(closest[i], 0.95 * kR)
        << s.bodies[i].name << ": at most 5% of the radius into the copper";
    EXPECT_LT(closest[i], 1.02 * kR + kReach * c.outer_corner_radius)
        << s.bodies[i].name
        << ": it reached the winding (its boxes reach up to kReach beyond round parts)";
  }
}

}  // namespace
}  // namespace odemag
