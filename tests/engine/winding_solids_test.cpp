// The windings of coils as collision solids (engine/simulation/winding_solids.h):
// which points they cover, against the windings' definitions written here,
// and bodies that meet them in a simulation.
#include "engine/simulation/winding_solids.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <random>
#include <variant>

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
  if (s.kind == CollisionSolid::Kind::capsule)  // the distance from its axis segment
    return std::hypot(std::hypot(l.x, l.y), std::max(0.0, std::abs(l.z) - 0.5 * s.size.z)) <= s.size.x;
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

// The distance from a circle of radius r about c in the plane of e1, e2,
// restricted to the azimuths 0 .. angle (from e1 towards e2; either sign).
double distance_from_arc(const Vec3& c, const Vec3& e1, const Vec3& e2, double r, double angle, const Vec3& p) {
  const Vec3 d = p - c;
  const double x = dot(d, e1), y = dot(d, e2), z = dot(d, cross(e1, e2));
  double psi = std::atan2(y, x) * (angle < 0.0 ? -1.0 : 1.0);
  if (psi < 0.0) psi += 2.0 * kPi;
  if (psi <= std::abs(angle)) return std::hypot(std::hypot(x, y) - r, z);
  const Vec3 start = c + r * e1, end = c + r * (std::cos(angle) * e1 + std::sin(angle) * e2);
  return std::min(norm(p - start), norm(p - end));
}

double distance_from_segment(const Vec3& a, const Vec3& b, const Vec3& p) {
  const double t = std::clamp(dot(p - a, b - a) / dot(b - a, b - a), 0.0, 1.0);
  return norm(p - (a + t * (b - a)));
}

// A solenoid's sheet has no solid; a filament's wire of radius a is covered
// by capsules: every point closer than a to its centre line is covered, none
// farther than 1.5 a (twice the chords' sagitta, on the inside of the bend:
// winding_solids.h).
TEST(WindingSolids, FilamentWiresAreCapsulesAndSheetsHaveNone) {
  EXPECT_TRUE(winding_solids(Solenoid{{}, {0, 0, 1}, 0.01, 0.02, 1.0, 1.0}).empty());
  const Vec3 centre{0.01, -0.02, 0.005}, axis = normalized(Vec3{1.0, 1.0, 2.0});
  Vec3 e1, e2, w;
  frame(axis, {1.0, 0.0, 0.0}, e1, e2, w);
  const double R = 0.03;
  const CircularLoop loop{centre, axis, R, 1.0, 1.0, 0.002};
  const Arc arc{centre, axis, R, e1, -2.0, 1.0, 1.0};  // clockwise about the axis: the default wire, 0.3 mm
  const StraightSegment segment{centre, centre + Vec3{0.02, 0.01, -0.01}, 1.0, 1.0};  // 0.24 mm
  struct Case {
    CoilSource source;
    std::function<double(const Vec3&)> distance;
  };
  const std::vector<Case> cases = {
      {loop, [&](const Vec3& p) { return distance_from_arc(centre, e1, e2, R, 2.0 * kPi, p); }},
      {arc, [&](const Vec3& p) { return distance_from_arc(centre, e1, e2, R, -2.0, p); }},
      {segment, [&](const Vec3& p) { return distance_from_segment(segment.a, segment.b, p); }}};
  std::mt19937 random(7);
  for (const Case& c : cases) {
    const std::vector<CollisionSolid> solids = winding_solids(c.source);
    ASSERT_FALSE(solids.empty());
    const double a = filament_wire_radius(c.source);
    int inside = 0, beyond = 0;
    for (int i = 0; i < 200000; ++i) {
      // Points within 2 a of the centre line: a random point of it, a random offset.
      std::uniform_real_distribution<double> unit(-1.0, 1.0);
      const Vec3 offset{unit(random), unit(random), unit(random)};
      Vec3 on;
      if (std::holds_alternative<StraightSegment>(c.source)) {
        on = segment.a + (0.5 + 0.6 * unit(random)) * (segment.b - segment.a);
      } else {
        const double phi = (std::holds_alternative<Arc>(c.source) ? -1.2 : kPi * 1.2) * (1.0 + unit(random));
        on = centre + R * (std::cos(phi) * e1 + std::sin(phi) * e2);
      }
      const Vec3 p = on + (2.0 * a) * offset;
      const double d = c.distance(p);
      if (d < a) {
        ++inside;
        ASSERT_TRUE(covered(solids, p)) << c.source.index() << ": in the wire, " << d / a << " a from its centre line";
      } else if (d > 1.5 * a) {
        ++beyond;
        ASSERT_FALSE(covered(solids, p)) << c.source.index() << ": " << d / a << " a from the centre line";
      }
    }
    EXPECT_GT(inside, 10000);
    EXPECT_GT(beyond, 10000);
  }
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

// A ball wider than a loop, dropped onto it, rests on its wire (a ring
// holding a ball) where it touches the wire's surface: its centre
// sqrt((r + d)^2 - R^2) above the loop's plane, d from r + a (the copper) to
// r + 1.5 a (the capsules' sagitta, winding_solids.h) plus the collision
// skins (2% of the ball's radius and of the frame's half side,
// engine/simulation/rigid_world.cpp), instead of falling through the loop.
TEST(WindingSolids, ABallRestsOnALoopsWire) {
  const double R = 0.005, half_side = 0.002;
  const CircularLoop loop{{0, 0, 0.02}, {0, 0, 1}, R, 1.0, 1.0};  // the default wire: 0.05 mm
  SceneDescription s = coil_frame_scene(loop, true);
  const double r = 0.008;
  s.bodies.push_back(body("ball", Sphere{r}, "wood", {0.0, 0.0, 0.05}));
  Simulation sim(s);
  while (sim.time() < 0.6) sim.step();
  const double a = filament_wire_radius(loop);
  auto height = [&](double d) { return 0.02 + std::sqrt(d * d - R * R); };
  const double z = sim.world().pose(1).position.z;
  EXPECT_GE(z, height(r + a)) << "on the wire, not on the ground at -0.1 m";
  EXPECT_LE(z, height(r + 1.5 * a + 0.02 * (r + half_side)));
  EXPECT_LT(norm(sim.world().velocity(1)), 1e-3);
}

// An iron ball dropped 1 mm beside the wire of a 1000 ampere-turn loop lands
// on the wire and stays on it, rolling about it, and gains no energy: its
// speed stays below the free fall from its start to its lowest point plus
// the magnetic energy it can give up at the wire's surface, (3 / 2) mu0 V H^2
// for an iron sphere (chi -> infinity: M = 3 H) in the wire's field
// H = N I / (2 pi (r + a)) at its centre, 5% added for the curvature and the
// integrator. (With the wire passing through it, it left at 8.9 m/s.)
TEST(WindingSolids, AnIronBallDroppedBesideACoilsWireStaysOnItAndGainsNoEnergy) {
  const double R = 0.05, NI = 1000.0;
  const CircularLoop loop{{0, 0, 0}, {0, 0, 1}, R, 100.0, 10.0};  // the default wire: 0.5 mm
  SceneDescription s = coil_frame_scene(loop, true);
  s.materials["iron"] = test_support::steel();
  const double r = 0.003, z0 = 0.02;
  s.bodies.push_back(body("ball", Sphere{r}, "iron", {R + 0.001, 0.0, z0}));
  Simulation sim(s);
  const double a = filament_wire_radius(loop);
  double fastest = 0.0, lowest = z0, farthest = 0.0;
  while (sim.time() < 0.5) {
    sim.step();
    ASSERT_TRUE(sim.non_finite_message().empty()) << sim.non_finite_message();
    const Vec3 p = sim.world().pose(1).position;
    fastest = std::max(fastest, norm(sim.world().velocity(1)));
    lowest = std::min(lowest, p.z);
    if (sim.time() > 0.2) farthest = std::max(farthest, std::hypot(std::hypot(p.x, p.y) - R, p.z));
  }
  const double V = 4.0 / 3.0 * kPi * r * r * r, mass = 7800.0 * V;
  const double H = NI / (2.0 * kPi * (r + a));
  const double bound = std::sqrt(2.0 * 9.81 * (z0 - lowest) + 3.0 * kMu0 * V * H * H / mass);
  EXPECT_LT(fastest, 1.05 * bound) << "faster than the energy it had";
  EXPECT_LT(farthest, 1.3 * (r + a)) << "it left the wire";
  std::printf("measured: iron ball beside a loop's wire: fastest %.3f m/s, energy bound %.3f m/s\n", fastest, bound);
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
