// Trimesh contacts (docs/simulation.md "Meshes"): meshed and primitive
// bodies dropped onto meshed and primitive plates come to rest on them,
// never fall through, and never gain energy.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>

#include "engine/simulation/rigid_world.h"
#include "odemag/simulation.h"
#include "tests/support/mesh_builders.h"
#include "tests/support/scene_builders.h"

namespace odemag {
namespace {

using test_support::body;

struct Drop {
  const char* name;
  Shape falling;
  Shape plate;
  double bottom;  // distance from the falling body's centre to its lowest point, m
};

const double kR = 0.005, kPlateTop = 0.002;

std::vector<Drop> drops() {
  const Mesh ball = test::ellipsoid_mesh(kR, kR, kR, 3);
  const Mesh plate = test::box_surface_mesh({0.06, 0.06, 0.004}, 4);
  const Box box_plate{{0.06, 0.06, 0.004}};
  // The icosphere's lowest point: its vertices lie on the sphere, and with
  // no vertex at the bottom its lowest face is a little above -R.
  double low = 0.0;
  for (const Vec3& v : ball.vertices()) low = std::min(low, v.z);
  return {{"mesh ball on mesh plate", ball, plate, -low},
          {"mesh ball on box plate", ball, box_plate, -low},
          {"sphere on mesh plate", Sphere{kR}, plate, kR},
          {"box on mesh plate", Box{{0.008, 0.008, 0.006}}, plate, 0.003},
          {"cylinder on mesh plate", Cylinder{kR, 0.01}, plate, 0.005},
          {"mesh box on mesh plate", test::box_surface_mesh({0.008, 0.008, 0.006}, 2), plate, 0.003}};
}

TEST(MeshContact, BodiesComeToRestOnPlatesWithoutFallingThroughOrGainingEnergy) {
  for (const Drop& d : drops()) {
    SCOPED_TRACE(d.name);
    SceneDescription s;
    s.file = d.name;
    s.simulation.ground = false;
    s.materials["wood"] = InertMaterial{};
    s.bodies.push_back(body("plate", d.plate, "wood", {0, 0, 0}, true));
    s.bodies.push_back(body("falling", d.falling, "wood", {0.001, -0.002, 0.03}, false, 700.0));
    s.simulation.time_step = 0.001;
    Simulation sim(s);
    const double g = 9.81, z0 = 0.03;
    double lowest = 1.0, highest_energy = -1.0;
    bool touched = false;
    for (int k = 0; k < 1500; ++k) {
      sim.step();
      const BodyPose p = sim.world().pose(1);
      const Vec3 v = sim.world().velocity(1);
      lowest = std::min(lowest, p.position.z);
      // Energy per unit mass, relative to the start (translation; the
      // bodies fall flat and barely turn).
      highest_energy = std::max(highest_energy, 0.5 * squared_norm(v) + g * (p.position.z - z0));
      touched = touched || sim.world().in_contact(1);
    }
    const BodyPose p = sim.world().pose(1);
    std::printf("[odemag] %s: rests at %.3f mm above the plate (expected %.3f), lowest %.3f mm\n", d.name,
                (p.position.z - kPlateTop) * 1e3, d.bottom * 1e3, (lowest - kPlateTop) * 1e3);
    EXPECT_TRUE(touched);
    EXPECT_NEAR(p.position.z - kPlateTop, d.bottom, 0.05 * d.bottom);
    EXPECT_GT(lowest - kPlateTop, 0.7 * d.bottom);  // never through the plate
    EXPECT_LT(norm(sim.world().velocity(1)), 1e-2);
    EXPECT_LT(highest_energy, 1e-3 * g * z0);  // no energy from the contacts
  }
}

// A compound of two boxes (one geom per part) lands on a mesh plate on both.
TEST(MeshContact, CompoundRestsOnItsParts) {
  SceneDescription s;
  s.file = "compound";
  s.simulation.ground = false;
  s.materials["wood"] = InertMaterial{};
  std::vector<CompoundPart> parts(2);
  parts[0].shape = Box{{0.01, 0.01, 0.004}};
  parts[0].position = {-0.008, 0, 0};
  parts[1].shape = test::box_surface_mesh({0.01, 0.01, 0.004}, 1);
  parts[1].position = {0.008, 0, 0};
  s.bodies.push_back(body("plate", test::box_surface_mesh({0.06, 0.06, 0.004}, 4), "wood", {0, 0, 0}, true));
  s.bodies.push_back(body("pair", Compound(parts), "wood", {0, 0, 0.02}, false, 700.0));
  Simulation sim(s);
  // Mass from the union's volume and the density.
  EXPECT_NEAR(sim.world().mass(1), 700.0 * 2 * 0.01 * 0.01 * 0.004, 1e-12);
  for (int k = 0; k < 1000; ++k) sim.step();
  const BodyPose p = sim.world().pose(1);
  EXPECT_NEAR(p.position.z - kPlateTop, 0.002, 1e-4);
  EXPECT_NEAR(p.rotation.m[2][2], 1.0, 1e-3);  // flat on both parts
}

}  // namespace
}  // namespace odemag
