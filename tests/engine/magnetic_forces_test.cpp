// The embedding API (engine/ode/magnetic_forces.h): bad body indices throw,
// and magnetics built from a scene and bound to ODE bodies (the simulation's
// path) give the same forces as the same bodies attached one by one (an
// embedder's path).
#include <gtest/gtest.h>

#include <ode/ode.h>

#include <stdexcept>

#include "engine/ode/magnetic_forces.h"
#include "engine/scene/scene.h"
#include "engine/sim/magnetic_system.h"

namespace odemag {
namespace {

struct OdeWorld {
  OdeWorld() {
    dInitODE();
    world = dWorldCreate();
  }
  ~OdeWorld() {
    dWorldDestroy(world);
    dCloseODE();
  }
  dBodyID body_at(const Vec3& p) const {
    dBodyID b = dBodyCreate(world);
    dBodySetPosition(b, p.x, p.y, p.z);
    return b;
  }
  dWorldID world;
};

TEST(MagneticForcesApi, BadBodyIndexThrowsNamingTheCall) {
  MagneticForces magnetics;
  magnetics.attach(nullptr, Sphere{0.005}, PermanentMaterial{{0, 0, 1e6}, 0.0});
  for (int bad : {-1, 1, 1000}) {
    EXPECT_THROW(magnetics.set_active(bad, false), std::out_of_range);
    EXPECT_THROW((void)magnetics.active(bad), std::out_of_range);
    EXPECT_THROW(magnetics.set_magnetization_scale(bad, 0.5), std::out_of_range);
    EXPECT_THROW((void)magnetics.magnetization_scale(bad), std::out_of_range);
    EXPECT_THROW(magnetics.set_pose(bad, BodyPose{}), std::out_of_range);
    EXPECT_THROW((void)magnetics.ode_body(bad), std::out_of_range);
    EXPECT_THROW((void)magnetics.moment(bad), std::out_of_range);
    EXPECT_THROW((void)magnetics.force(bad), std::out_of_range);
    EXPECT_THROW((void)magnetics.torque(bad), std::out_of_range);
    EXPECT_THROW(magnetics.bind(bad, nullptr), std::out_of_range);
  }
  try {
    magnetics.set_pose(3, BodyPose{});
    FAIL() << "no exception";
  } catch (const std::out_of_range& e) {
    EXPECT_NE(std::string(e.what()).find("set_pose"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("3"), std::string::npos) << e.what();
  }
  EXPECT_NO_THROW(magnetics.set_active(0, true));
}

TEST(MagneticForcesApi, SceneBuiltAndBoundEqualsAttachedOneByOne) {
  const SceneDescription scene = parse_scene(R"({
    "seed": 5,
    "external_field": [0, 2000, 0],
    "materials": {
      "magnet": {"type": "permanent", "magnetization": [0, 0, 900000]},
      "steel": {"type": "soft", "saturation": 1.6e6, "susceptibility": 1000, "moments_per_cell": 4}
    },
    "bodies": [
      {"name": "magnet", "shape": {"box": [0.01, 0.01, 0.02]}, "material": "magnet", "position": [0, 0, 0.02],
       "cell_size": 0.005},
      {"name": "ball", "shape": {"sphere": 0.004}, "material": "steel", "position": [0.001, 0, 0.0345]},
      {"name": "rod", "shape": {"cylinder": {"radius": 0.003, "length": 0.02}}, "material": "steel",
       "position": [0.012, 0.002, 0.02], "cell_size": 0.0025}
    ]})",
                                               "inline.json");
  OdeWorld ode;
  RelaxOptions options = scene.solver.relax;

  MagneticSystem ms = build_magnetic_system(scene);
  MagneticForces bound(std::move(ms.model), std::move(ms.state), options, make_cpu_backend(1));
  MagneticForces attached(options, make_cpu_backend(1), scene.seed);
  attached.set_external_field(scene.external_field);
  for (int b = 0; b < static_cast<int>(scene.bodies.size()); ++b) {
    const BodyDescription& d = scene.bodies[b];
    dBodyID body = ode.body_at(d.position);
    bound.bind(b, body);
    attached.attach(body, d.shape, scene.materials.at(d.material), scene.body_cell_size(b), d.name);
  }
  ASSERT_EQ(bound.body_count(), attached.body_count());
  ASSERT_EQ(bound.model().cell_count(), attached.model().cell_count());
  const RelaxReport& a = bound.compute();
  const RelaxReport& b = attached.compute();
  EXPECT_TRUE(a.converged);
  EXPECT_EQ(a.iterations, b.iterations);
  for (int i = 0; i < bound.body_count(); ++i) {
    EXPECT_EQ(bound.force(i).x, attached.force(i).x) << i;
    EXPECT_EQ(bound.force(i).y, attached.force(i).y) << i;
    EXPECT_EQ(bound.force(i).z, attached.force(i).z) << i;
    EXPECT_EQ(bound.torque(i).z, attached.torque(i).z) << i;
  }
  EXPECT_GT(norm(bound.force(1)), 0.0);
}

}  // namespace
}  // namespace odemag
