// The embedding API (engine/embedding/magnetic_forces.h): bad body indices throw,
// and magnetics built from a scene and bound to ODE bodies (the simulation's
// path) give the same forces as the same bodies attached one by one (an
// embedder's path). Input checks (lattice limit, finite poses and fields) and
// the wake-up of bodies ODE put to sleep.
#include "odemag/magnetic_forces.h"
#include "engine/embedding/saved_state.h"

#include <gtest/gtest.h>
#include <ode/ode.h>

#include <chrono>
#include <cmath>
#include <functional>
#include <limits>
#include <map>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "odemag/scene.h"
#include "engine/simulation/magnetic_system.h"
#include "magnetics/model/backend.h"
#include "magnetics/cells/cells.h"
#include "odemag/constants.h"
#include "tests/support/contact_references.h"
#include "tests/support/magnetic_setup.h"
#include "tests/support/mesh_builders.h"

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

// A body whose geom is a trimesh (built here from the mesh's arrays, as an
// embedder does) gets the force of the primitive it approximates: a soft
// meshed ball near a magnet, against the Sphere at the same cell size,
// within 1%; a mesh not centred on the body's origin is refused.
TEST(MagneticForcesApi, TrimeshBodyTakesTheBallsForce) {
  OdeWorld w;
  const double R = 0.005;
  const Mesh ball = test::ellipsoid_mesh(R, R, R, 4);
  std::vector<double> xyz;
  for (const Vec3& v : ball.vertices()) xyz.insert(xyz.end(), {v.x, v.y, v.z, 0.0});
  std::vector<dTriIndex> index;
  for (const auto& t : ball.triangles()) index.insert(index.end(), {static_cast<dTriIndex>(t[0]), static_cast<dTriIndex>(t[1]), static_cast<dTriIndex>(t[2])});
  dSpaceID space = dHashSpaceCreate(nullptr);
  dTriMeshDataID data = dGeomTriMeshDataCreate();
  dGeomTriMeshDataBuildDouble(data, xyz.data(), 4 * sizeof(double), static_cast<int>(ball.vertices().size()),
                              index.data(), static_cast<int>(index.size()), 3 * sizeof(dTriIndex));
  dGeomID geom = dCreateTriMesh(space, data, nullptr, nullptr, nullptr);
  dBodyID meshed = w.body_at({0, 0, 0.012});
  dGeomSetBody(geom, meshed);
  double force[2] = {};
  for (int primitive = 0; primitive < 2; ++primitive) {
    MagneticForces magnetics(test_support::relax_options(1e-8), 1);
    magnetics.attach(nullptr, Cylinder{0.006, 0.01}, PermanentMaterial{{0, 0, 9e5}, 0.0}, 0.002);
    const int b = primitive ? magnetics.attach(w.body_at({0, 0, 0.012}), Sphere{R}, test_support::soft_material(1.6e6, 1000.0), R / 3)
                            : magnetics.attach(meshed, ball, test_support::soft_material(1.6e6, 1000.0), R / 3);
    magnetics.compute();
    force[primitive] = magnetics.force(b).z;
  }
  EXPECT_LT(force[0], 0.0);
  EXPECT_NEAR(force[0] / force[1], 1.0, 0.01);
  std::vector<Vec3> moved = ball.vertices();
  for (Vec3& v : moved) v.x += 0.001;
  MagneticForces magnetics;
  try {
    magnetics.attach(meshed, Mesh(moved, ball.triangles()), PermanentMaterial{{0, 0, 1e6}, 0.0}, 0.002);
    ADD_FAILURE() << "no exception";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("centre of mass is at (0.001, "), std::string::npos) << e.what();
  }
  dSpaceDestroy(space);
  dGeomTriMeshDataDestroy(data);
}

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

// Every index-taking call, with and without bodies attached, throws
// std::out_of_range naming itself and the index (moment() named active()).
TEST(MagneticForcesApi, EveryIndexCallThrowsNamingItselfAndTheIndex) {
  for (int attached : {0, 2}) {
    MagneticForces magnetics;
    for (int b = 0; b < attached; ++b) magnetics.attach(nullptr, Sphere{0.005}, PermanentMaterial{{0, 0, 1e6}, 0.0});
    std::vector<std::pair<std::string, std::function<void(int)>>> calls = {
        {"force", [&](int i) { (void)magnetics.force(i); }},
        {"torque", [&](int i) { (void)magnetics.torque(i); }},
        {"moment", [&](int i) { (void)magnetics.moment(i); }},
        {"set_pose", [&](int i) { magnetics.set_pose(i, BodyPose{}); }},
        {"bind", [&](int i) { magnetics.bind(i, nullptr); }},
        {"set_active", [&](int i) { magnetics.set_active(i, true); }},
        {"active", [&](int i) { (void)magnetics.active(i); }},
        {"set_magnetization_scale", [&](int i) { magnetics.set_magnetization_scale(i, 1.0); }},
        {"magnetization_scale", [&](int i) { (void)magnetics.magnetization_scale(i); }},
        {"ode_body", [&](int i) { (void)magnetics.ode_body(i); }},
    };
    for (const auto& [name, call] : calls)
      for (int bad : {-1, attached, 7, 1000}) {
        try {
          call(bad);
          ADD_FAILURE() << name << "(" << bad << ") with " << attached << " bodies: no exception";
        } catch (const std::out_of_range& e) {
          const std::string what = e.what();
          EXPECT_NE(what.find("MagneticForces::" + name + ":"), std::string::npos) << what;
          EXPECT_NE(what.find("body " + std::to_string(bad) + " "), std::string::npos) << what;
        }
      }
    for (int b = 0; b < attached; ++b)
      for (const auto& [name, call] : calls) EXPECT_NO_THROW(call(b)) << name << "(" << b << ")";
  }
}

// A lattice beyond kMaxBodyLatticePoints is refused before a cell is made:
// a 1 m box at 1 um (1e18 points) would take hours and all memory.
TEST(MagneticForcesApi, LatticeBeyondTheLimitThrowsAtOnce) {
  MagneticForces magnetics;
  const auto t0 = std::chrono::steady_clock::now();
  try {
    magnetics.attach(nullptr, Box{{1.0, 1.0, 1.0}}, PermanentMaterial{{1e6, 0, 0}, 0.0}, 1e-6, "slab");
    FAIL() << "no exception";
  } catch (const std::invalid_argument& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("cell size 1e-06 gives body \"slab\""), std::string::npos) << what;
    EXPECT_NE(what.find("1e+18"), std::string::npos) << what;
    EXPECT_NE(what.find("4194304"), std::string::npos) << what;
  }
  EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count(), 1.0);
  EXPECT_EQ(magnetics.body_count(), 0);
  // Soft and cylindrical bodies too; an inert body gets no cells and passes.
  SoftMaterial iron;
  iron.saturation = 1.7e6;
  auto lattice_error = [](const std::function<void()>& f) {
    try {
      f();
    } catch (const std::invalid_argument& e) {
      return std::string(e.what()).find("lattice") != std::string::npos;
    }
    return false;
  };
  EXPECT_TRUE(lattice_error([&] { magnetics.attach(nullptr, Cylinder{0.5, 1.0}, iron, 1e-5); }));
  EXPECT_NO_THROW(magnetics.attach(nullptr, Box{{1.0, 1.0, 1.0}}, InertMaterial{}, 1e-6));
  MagneticModel model;
  EXPECT_TRUE(lattice_error([&] { model.add_body("slab", Box{{1.0, 1.0, 1.0}}, iron, 1e-6); }));
  EXPECT_EQ(model.body_count(), 0);
}

// The count is the scene loader's: per axis max(1, round(extent / h)).
TEST(MagneticForcesApi, LatticeCountAndLimit) {
  EXPECT_EQ(body_lattice_points(Box{{0.01, 0.02, 0.03}}, 0.01), 6.0);
  EXPECT_EQ(body_lattice_points(Box{{0.01, 0.02, 0.03}}, 0.0), 1.0);
  EXPECT_EQ(body_lattice_points(Sphere{0.01}, 0.003), 7.0 * 7.0 * 7.0);  // round(6.67)
  EXPECT_EQ(body_lattice_points(Box{{0.001, 0.1, 0.1}}, 0.01), 100.0);    // at least 1 per axis
  EXPECT_EQ(validate_body_lattice("b", Box{{1.28, 1.28, 2.56}}, 0.01), "");  // 2^22 exactly
  const std::string e = validate_body_lattice("b", Box{{1.28, 1.28, 2.57}}, 0.01);
  EXPECT_NE(e.find("\"b\""), std::string::npos) << e;
  EXPECT_NE(e.find("4.21e+06"), std::string::npos) << e;
  EXPECT_NE(e.find("at most 4194304"), std::string::npos) << e;
}

// A magnet in a box and an iron ball on an ODE body, for the pose checks.
struct MagnetAndBall {
  MagnetAndBall() : ball_body(ode.body_at({0.03, 0, 0})) {
    const SoftMaterial iron = test_support::soft_material(1.7e6, 5000);
    magnet = magnetics.attach(nullptr, Box{{0.02, 0.01, 0.01}}, PermanentMaterial{{8e5, 0, 0}, 0.0}, 0.005, "bar");
    ball = magnetics.attach(ball_body, Sphere{0.005}, iron, 0.0, "ball");
  }
  OdeWorld ode;
  dBodyID ball_body;
  MagneticForces magnetics{{}, make_cpu_backend(1)};
  int magnet = -1, ball = -1;
};

void expect_names(const std::string& what, const std::string& call, const std::string& body, int index) {
  EXPECT_NE(what.find(call), std::string::npos) << what;
  EXPECT_NE(what.find("body " + std::to_string(index) + " \"" + body + "\""), std::string::npos) << what;
}

TEST(MagneticForcesApi, NonFinitePoseThrowsNamingTheBody) {
  const double nan = std::numeric_limits<double>::quiet_NaN(), inf = std::numeric_limits<double>::infinity();
  MagnetAndBall s;
  s.magnetics.compute();
  const Vec3 force = s.magnetics.force(s.ball);
  ASSERT_GT(norm(force), 0.0);

  // set_pose refuses at once and keeps the pose it had.
  BodyPose pose;
  pose.position = {nan, 0, 0};
  try {
    s.magnetics.set_pose(s.magnet, pose);
    FAIL() << "no exception";
  } catch (const std::invalid_argument& e) {
    expect_names(e.what(), "set_pose", "bar", s.magnet);
  }
  pose.position = {};
  pose.rotation.m[1][2] = inf;
  EXPECT_THROW(s.magnetics.set_pose(s.magnet, pose), std::invalid_argument);
  EXPECT_TRUE(std::isfinite(s.magnetics.state().pose[s.magnet].position.x));
  EXPECT_EQ(s.magnetics.state().pose[s.magnet].rotation.m[1][2], 0.0);

  // An ODE body's position: compute, apply and recompute_forces throw before
  // relaxing; the forces stay the last step's.
  dBodySetPosition(s.ball_body, 0.03, nan, 0);
  for (const char* call : {"compute", "apply", "recompute_forces"}) {
    try {
      if (std::string(call) == "compute") s.magnetics.compute();
      if (std::string(call) == "apply") s.magnetics.apply();
      if (std::string(call) == "recompute_forces") s.magnetics.recompute_forces();
      ADD_FAILURE() << call << ": no exception";
    } catch (const std::domain_error& e) {
      expect_names(e.what(), std::string("MagneticForces::") + (std::string(call) == "apply" ? "compute" : call),
                   "ball", s.ball);
      EXPECT_NE(std::string(e.what()).find("position"), std::string::npos) << e.what();
    }
  }
  EXPECT_EQ(s.magnetics.force(s.ball).x, force.x);
  const dReal* f = dBodyGetForce(s.ball_body);
  EXPECT_EQ(f[0], 0.0);  // apply() added nothing

  // An inactive body's pose is not used: no error.
  s.magnetics.set_active(s.ball, false);
  EXPECT_NO_THROW(s.magnetics.compute());
  s.magnetics.set_active(s.ball, true);
  dBodySetPosition(s.ball_body, 0.03, 0, 0);
  EXPECT_NO_THROW(s.magnetics.compute());

  // A static pose made non-finite through state(): rotation.
  s.magnetics.state().pose[s.magnet].rotation.m[0][0] = nan;
  try {
    s.magnetics.compute();
    FAIL() << "no exception";
  } catch (const std::domain_error& e) {
    expect_names(e.what(), "MagneticForces::compute", "bar", s.magnet);
    EXPECT_NE(std::string(e.what()).find("rotation"), std::string::npos) << e.what();
  }
  s.magnetics.state().pose[s.magnet].rotation = Mat3{};
  EXPECT_NO_THROW(s.magnetics.compute());
}

TEST(MagneticForcesApi, NonFiniteFieldAndScaleThrow) {
  const double nan = std::numeric_limits<double>::quiet_NaN(), inf = std::numeric_limits<double>::infinity();
  MagnetAndBall s;
  EXPECT_THROW(s.magnetics.set_external_field({0, inf, 0}), std::invalid_argument);
  EXPECT_THROW(s.magnetics.set_external_field({nan, 0, 0}), std::invalid_argument);
  EXPECT_EQ(s.magnetics.external_field().y, 0.0);
  EXPECT_NO_THROW(s.magnetics.set_external_field({0, 100, 0}));
  EXPECT_THROW(s.magnetics.set_magnetization_scale(s.magnet, nan), std::invalid_argument);
  EXPECT_EQ(s.magnetics.magnetization_scale(s.magnet), 1.0);
  s.magnetics.state().external_field = {0, 0, -inf};
  try {
    s.magnetics.compute();
    FAIL() << "no exception";
  } catch (const std::domain_error& e) {
    EXPECT_NE(std::string(e.what()).find("external field"), std::string::npos) << e.what();
  }
}

// The controls take the scene loader's ranges (odemag/constants.h): a
// magnetization scaled beyond 1e9 A/m (the bar's 8e5 A/m: scale 1250), a
// field beyond 1e9 A/m, a position beyond 1e6 m, a rotation that is not one
// (2 I, a reflection, off by 1e-8) are refused naming the call and the body,
// changing nothing; within them they are taken.
TEST(MagneticForcesApi, ControlsTakeTheScenesRanges) {
  MagnetAndBall s;
  for (double scale : {1e300, -1e6, 1251.0}) {
    try {
      s.magnetics.set_magnetization_scale(s.magnet, scale);
      ADD_FAILURE() << "scale " << scale << ": no exception";
    } catch (const std::invalid_argument& e) {
      expect_names(e.what(), "set_magnetization_scale", "bar", s.magnet);
      EXPECT_NE(std::string(e.what()).find("at most 1250"), std::string::npos) << e.what();
    }
  }
  EXPECT_EQ(s.magnetics.magnetization_scale(s.magnet), 1.0);
  EXPECT_NO_THROW(s.magnetics.set_magnetization_scale(s.magnet, -1250.0));
  EXPECT_NO_THROW(s.magnetics.set_magnetization_scale(s.ball, 1e300));  // no magnetization to scale

  EXPECT_THROW(s.magnetics.set_external_field({1e160, 0, 0}), std::invalid_argument);
  EXPECT_THROW(s.magnetics.set_external_field({6e8, 6e8, 6e8}), std::invalid_argument);  // |H| = 1.04e9
  EXPECT_EQ(s.magnetics.external_field().x, 0.0);
  EXPECT_NO_THROW(s.magnetics.set_external_field({1e9, 0, 0}));

  BodyPose far;
  far.position = {0, 0, 1.1e6};
  Mat3 twice;
  for (int i = 0; i < 3; ++i) twice.m[i][i] = 2.0;
  Mat3 mirror;
  mirror.m[2][2] = -1.0;
  Mat3 skewed;
  skewed.m[0][1] = 1e-8;
  for (const auto& [pose, what] : {std::pair{far, "position"}, std::pair{BodyPose{twice, {}}, "not orthonormal"},
                                   std::pair{BodyPose{mirror, {}}, "reflection"},
                                   std::pair{BodyPose{skewed, {}}, "not orthonormal"}}) {
    try {
      s.magnetics.set_pose(s.magnet, pose);
      ADD_FAILURE() << what << ": no exception";
    } catch (const std::invalid_argument& e) {
      expect_names(e.what(), "set_pose", "bar", s.magnet);
      EXPECT_NE(std::string(e.what()).find(what), std::string::npos) << e.what();
    }
  }
  EXPECT_EQ(s.magnetics.state().pose[s.magnet].rotation.m[0][0], 1.0);
  Mat3 nearly;
  nearly.m[0][1] = 1e-10;  // within 1e-9: ODE's own rotations drift this much
  EXPECT_NO_THROW(s.magnetics.set_pose(s.magnet, BodyPose{nearly, {0, 0, 1e6}}));
}

// field_at_points refuses a point beyond the length bound, naming its index
// (a point 1e300 m away gave NaN).
TEST(MagneticForcesApi, FieldPointBeyondTheLengthBoundThrowsNamingIt) {
  MagnetAndBall s;
  s.magnetics.compute();
  std::vector<Vec3> B, H;
  try {
    s.magnetics.field_at_points({{0, 0, 0.1}, {1e300, 0, 0}}, B, H);
    FAIL() << "no exception";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("point 1 "), std::string::npos) << e.what();
  }
  s.magnetics.field_at_points({{0, 0, 0.1}, {1e6, 0, 0}}, B, H);
  EXPECT_TRUE(is_finite(H[1]));
}

// attach names the call and the body (the index and name it would get) when
// it refuses a shape or a material.
TEST(MagneticForcesApi, AttachRefusalNamesTheCallAndTheBody) {
  MagneticForces magnetics({}, make_cpu_backend(1));
  magnetics.attach(nullptr, Sphere{0.01}, test_support::soft_material(1e6, 100), 0.0, "first");
  try {
    magnetics.attach(nullptr, Sphere{-1}, test_support::soft_material(1e6, 100));
    FAIL() << "no exception";
  } catch (const std::invalid_argument& e) {
    expect_names(e.what(), "MagneticForces::attach", "body1", 1);
  }
  try {
    magnetics.attach(nullptr, Sphere{0.01}, PermanentMaterial{{std::nan(""), 0, 0}, 0.0}, 0.0, "bar");
    FAIL() << "no exception";
  } catch (const std::invalid_argument& e) {
    expect_names(e.what(), "MagneticForces::attach", "bar", 1);
  }
  EXPECT_EQ(magnetics.body_count(), 1);
}

// An ODE world with auto-disable on: a ground plane and an iron ball resting
// on it, stepped with contacts.
struct SleepyWorld {
  static constexpr double kRadius = 0.005, kStep = 1e-3;
  SleepyWorld() {
    dInitODE();
    world = dWorldCreate();
    space = dSimpleSpaceCreate(nullptr);
    contacts = dJointGroupCreate(0);
    dWorldSetGravity(world, 0, 0, -9.81);
    dWorldSetContactSurfaceLayer(world, 1e-4);
    dWorldSetAutoDisableFlag(world, 1);  // bodies created from now on may sleep
    dCreatePlane(space, 0, 0, 1, 0);
    ball = dBodyCreate(world);
    dMass m;
    dMassSetSphere(&m, 7800.0, kRadius);
    dBodySetMass(ball, &m);
    dBodySetPosition(ball, 0, 0, kRadius);
    dGeomSetBody(dCreateSphere(space, kRadius), ball);
    const SoftMaterial iron = test_support::soft_material(1.7e6, 5000);
    magnetics.attach(ball, Sphere{kRadius}, iron, 0.0, "ball");
  }
  ~SleepyWorld() {
    dJointGroupDestroy(contacts);
    dSpaceDestroy(space);
    dWorldDestroy(world);
    dCloseODE();
  }
  static void near(void* data, dGeomID a, dGeomID b) {
    auto* w = static_cast<SleepyWorld*>(data);
    dContact c[4];
    const int n = dCollide(a, b, 4, &c[0].geom, sizeof(dContact));
    for (int i = 0; i < n; ++i) {
      c[i].surface.mode = 0;
      c[i].surface.mu = 0.5;
      dJointAttach(dJointCreateContact(w->world, w->contacts, &c[i]), dGeomGetBody(a), dGeomGetBody(b));
    }
  }
  void step() {
    magnetics.apply();
    dSpaceCollide(space, this, &near);
    dWorldQuickStep(world, kStep);
    dJointGroupEmpty(contacts);
  }
  // Steps until the ball is asleep (at most n steps); whether it is.
  bool sleep(int n) {
    for (int i = 0; i < n && dBodyIsEnabled(ball); ++i) step();
    return !dBodyIsEnabled(ball);
  }
  dWorldID world;
  dSpaceID space;
  dJointGroupID contacts;
  dBodyID ball;
  MagneticForces magnetics{{}, make_cpu_backend(1)};
};

BodyPose at(const Vec3& p) {
  BodyPose pose;
  pose.position = p;
  return pose;
}

// A magnet (static, with a body-less geom) moved toward a sleeping ball wakes
// it, and the ball rolls to it.
TEST(MagneticForcesWake, ApproachingMagnetWakesASleepingBall) {
  SleepyWorld w;
  const int magnet =
      w.magnetics.attach(nullptr, Box{{0.02, 0.02, 0.02}}, PermanentMaterial{{1e6, 0, 0}, 0.0}, 0.01, "magnet");
  dGeomID geom = dCreateBox(w.space, 0.02, 0.02, 0.02);
  auto place = [&](double x) {
    w.magnetics.set_pose(magnet, at({x, 0, 0.01}));
    dGeomSetPosition(geom, x, 0, 0.01);
  };
  place(0.3);
  ASSERT_TRUE(w.sleep(2000));
  for (int i = 0; i < 100; ++i) w.step();
  ASSERT_FALSE(dBodyIsEnabled(w.ball)) << "a far magnet that does not move leaves it asleep";
  int woke = -1;
  for (int i = 0; i < 3000; ++i) {
    place(std::max(0.08, 0.3 - 0.5 * SleepyWorld::kStep * i));  // 0.5 m/s, then held 8 cm away
    w.step();
    if (woke < 0 && dBodyIsEnabled(w.ball)) woke = i;
  }
  EXPECT_GE(woke, 0);
  EXPECT_LT(woke, 440) << "woken while the magnet approached";
  // Rolled to the magnet and touching it: x = 0.08 - 0.01 - R.
  EXPECT_NEAR(dBodyGetPosition(w.ball)[0], 0.08 - 0.01 - SleepyWorld::kRadius, 1e-3);
}

// A ball held to the ground by a magnet under it (a steady force, over 100
// times its weight) falls asleep and stays asleep.
TEST(MagneticForcesWake, BallInASteadyFieldStaysAsleep) {
  SleepyWorld w;
  const int magnet =
      w.magnetics.attach(nullptr, Box{{0.02, 0.02, 0.02}}, PermanentMaterial{{0, 0, 1e6}, 0.0}, 0.01, "magnet");
  w.magnetics.set_pose(magnet, at({0, 0, -0.012}));
  w.magnetics.set_external_field({0, 0, 1000});
  ASSERT_TRUE(w.sleep(3000));
  dMass m;
  dBodyGetMass(w.ball, &m);
  EXPECT_GT(norm(w.magnetics.force(0)), 5.0 * m.mass * 9.81);
  const Vec3 p0{dBodyGetPosition(w.ball)[0], dBodyGetPosition(w.ball)[1], dBodyGetPosition(w.ball)[2]};
  for (int i = 0; i < 500; ++i) {
    w.step();
    ASSERT_FALSE(dBodyIsEnabled(w.ball)) << "woken at step " << i;
  }
  EXPECT_EQ(dBodyGetPosition(w.ball)[2], p0.z);
  // A change of the field well above the tolerance wakes it.
  w.magnetics.set_magnetization_scale(magnet, 0.5);
  w.step();
  EXPECT_TRUE(dBodyIsEnabled(w.ball));
}

// Bodies whose auto-disable flag is off were disabled by the program (the
// scene simulation's removed bodies): never woken.
TEST(MagneticForcesWake, DisabledByTheProgramStaysDisabled) {
  SleepyWorld w;
  dBodySetAutoDisableFlag(w.ball, 0);
  const int magnet =
      w.magnetics.attach(nullptr, Box{{0.02, 0.02, 0.02}}, PermanentMaterial{{1e6, 0, 0}, 0.0}, 0.01, "magnet");
  w.magnetics.set_pose(magnet, at({0.3, 0, 0.01}));
  w.step();
  dBodyDisable(w.ball);
  for (int i = 0; i < 200; ++i) {
    w.magnetics.set_pose(magnet, at({0.3 - 0.001 * i, 0, 0.01}));
    w.step();
  }
  EXPECT_FALSE(dBodyIsEnabled(w.ball));
  EXPECT_THROW(w.magnetics.set_wake_tolerance(-1.0), std::invalid_argument);
}

// Saving and restoring the magnetic state (docs/embedding.md "Saving and
// restoring"): a nail with anisotropy (a remanent soft body) magnetized by a
// field along its easy axis keeps a moment when the field is gone; a reverse
// field takes it away; restoring the saved state brings it back exactly, and
// the next compute() gives the forces of a run that was never demagnetized.
// Bit for bit.
void expect_same(const Vec3& a, const Vec3& b) {
  EXPECT_EQ(a.x, b.x);
  EXPECT_EQ(a.y, b.y);
  EXPECT_EQ(a.z, b.z);
}

struct RemanentNail {
  RemanentNail() {
    const SoftMaterial steel = test_support::anisotropic_steel(1.6e6, 1000, 8e4, 8);
    nail = magnetics.attach(nullptr, Cylinder{0.002, 0.02}, steel, 0.002, "nail");
    magnetics.set_pose(nail, BodyPose{Mat3{}, {0, 0, 0}});
    const SoftMaterial iron = test_support::soft_material(1.7e6, 5000);
    ball = magnetics.attach(nullptr, Sphere{0.003}, iron, 0.0, "ball");
    magnetics.set_pose(ball, BodyPose{Mat3{}, {0, 0, 0.0135}});  // 0.5 mm beyond the nail's tip
  }
  // A field H along z held for n steps, then removed for n steps.
  void pulse(double H, int n = 20) {
    magnetics.set_external_field({0, 0, H});
    for (int i = 0; i < n; ++i) magnetics.compute();
    magnetics.set_external_field({});
    for (int i = 0; i < n; ++i) magnetics.compute();
  }
  MagneticForces magnetics{{}, make_cpu_backend(1)};
  int nail = 0, ball = 0;
};

TEST(MagneticForcesState, RemanenceSurvivesSaveAndRestore) {
  RemanentNail a, b;  // b: the run that is never demagnetized
  a.pulse(3e5);
  b.pulse(3e5);
  const Vec3 remanent = a.magnetics.moment(a.nail);
  ASSERT_GT(remanent.z, 0.1 * 1.6e6 * kPi * 0.002 * 0.002 * 0.02) << "magnetized: a remanent moment";
  const SavedMagneticState saved = a.magnetics.save_state();
  a.pulse(-3e5);  // reversed
  ASSERT_LT(a.magnetics.moment(a.nail).z, 0.0);
  a.magnetics.restore_state(saved);
  expect_same(a.magnetics.moment(a.nail), remanent);
  EXPECT_EQ(a.magnetics.external_field().z, 0.0);
  a.magnetics.compute();
  b.magnetics.compute();
  for (int i : {a.nail, a.ball}) {
    expect_same(a.magnetics.force(i), b.magnetics.force(i));
    expect_same(a.magnetics.torque(i), b.magnetics.torque(i));
  }
  EXPECT_LT(a.magnetics.force(a.ball).z, 0.0) << "pulled to the nail by its remanence";
}

TEST(MagneticForcesState, RestoreIntoOtherMagneticsThrows) {
  RemanentNail a;
  const SavedMagneticState saved = a.magnetics.save_state();
  MagneticForces fewer;  // one body
  fewer.attach(nullptr, Sphere{0.003}, PermanentMaterial{{0, 0, 1e6}});
  EXPECT_THROW(fewer.restore_state(saved), std::invalid_argument);
  MagneticForces coarser;  // two bodies, the nail in other cells
  const SoftMaterial steel = test_support::soft_material(1.6e6, 1000);
  coarser.attach(nullptr, Cylinder{0.002, 0.02}, steel, 0.004, "nail");
  coarser.attach(nullptr, Sphere{0.003}, steel, 0.0, "ball");
  try {
    coarser.restore_state(saved);
    FAIL() << "no exception";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("\"nail\""), std::string::npos) << e.what();
  }
  SavedMagneticState edited = saved;  // arrays that do not fit
  edited.data().state.moments.pop_back();
  EXPECT_THROW(a.magnetics.restore_state(edited), std::invalid_argument);
  SavedMagneticState unpredicted = saved;  // the predicted warm start's changes missing
  unpredicted.data().state.previous_relaxation_change.clear();
  EXPECT_THROW(a.magnetics.restore_state(unpredicted), std::invalid_argument);
  EXPECT_NO_THROW(a.magnetics.restore_state(saved));
}

// Refined contact zones through the embedding API (docs/embedding.md
// "Refined contact zones"): two lattice balls attached without zones, 0.05 R
// apart in a field along their line (the plain lattice 15% off the exact
// series); refine_body gives each a zone at its contact point and the force
// comes within 3%. Bad calls throw and change nothing; a state saved before
// a refine_body no longer restores, even where the cell counts agree.
TEST(MagneticForcesRefine, ZonesThroughTheApiReachTheExactForce) {
  const double R = 0.005, h = R / 4.5;
  const SoftMaterial iron = test_support::soft_material(1e12, 1000);  // linear at these fields
  MagneticForces magnetics(RelaxOptions{}, make_cpu_backend(1));
  magnetics.attach(nullptr, Sphere{R}, iron, h, "lower");
  magnetics.attach(nullptr, Sphere{R}, iron, h, "upper");
  magnetics.set_pose(1, {Mat3{}, {0, 0, 2.05 * R}});
  magnetics.set_external_field({0, 0, 1e3});
  ASSERT_TRUE(magnetics.compute().converged);
  const auto ref = reference::two_linear_spheres_in_uniform_field(R, 1000, R, 1000, {0, 0, 0},
                                                                  {0, 0, 2.05 * R}, {0, 0, 1e3});
  const Vec3 exact = ref.force_on_2;
  EXPECT_GT(norm(magnetics.force(1) - exact), 0.1 * norm(exact));

  const SavedMagneticState plain = magnetics.save_state();
  EXPECT_THROW(magnetics.refine_body(2, {}), std::out_of_range);
  EXPECT_THROW(magnetics.refine_body(0, {{{0, 0, R}, {-h}}}), std::invalid_argument);
  EXPECT_NO_THROW(magnetics.restore_state(plain));  // nothing changed

  const std::vector<RefinedZone> lower{{{0, 0, R}, default_refinement_radii(h)}};
  magnetics.refine_body(0, lower);
  magnetics.refine_body(1, {{{0, 0, -R}, default_refinement_radii(h)}});
  ASSERT_TRUE(magnetics.compute().converged);
  EXPECT_LT(norm(magnetics.force(1) - exact), 0.03 * norm(exact));

  const SavedMagneticState refined = magnetics.save_state();
  magnetics.refine_body(0, lower);  // the same cells, built anew
  try {
    magnetics.restore_state(refined);
    FAIL() << "no exception";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("\"lower\" got new refined zones"), std::string::npos)
        << e.what();
  }
}

// A scene file's materials on an embedder's own ODE bodies (docs/embedding.md
// "Materials from a scene file"): the same force as the materials built in C++.
TEST(MagneticForcesMaterials, SceneMaterialGivesTheSameForceAsOneBuiltInCpp) {
  const SceneDescription scene = parse_scene(R"({
    "materials": {
      "magnet": {"type": "permanent", "magnetization": [0, 0, 900000]},
      "steel": {"type": "soft", "saturation": 1.6e6, "susceptibility": 1000, "anisotropy_field": 80000,
                "easy_axis": [0, 0, 1], "moments_per_cell": 4}
    },
    "bodies": [{"name": "unused", "shape": {"sphere": 0.001}, "material": "magnet"}]
  })", "materials.json");
  const SoftMaterial steel = test_support::anisotropic_steel(1.6e6, 1000, 8e4, 4);
  const PermanentMaterial magnet{{0, 0, 9e5}};
  OdeWorld w;
  Vec3 force[2], torque[2];
  for (int run = 0; run < 2; ++run) {
    MagneticForces magnetics({}, make_cpu_backend(1));
    dBodyID bar = w.body_at({0, 0, 0});
    dBodyID rod = w.body_at({0.002, 0, 0.0205});
    if (run == 0) {
      magnetics.attach(bar, Box{{0.01, 0.01, 0.02}}, scene.materials, "magnet", 0.005);
      magnetics.attach(rod, Cylinder{0.002, 0.02}, scene.materials, "steel", 0.002);
    } else {
      magnetics.attach(bar, Box{{0.01, 0.01, 0.02}}, magnet, 0.005);
      magnetics.attach(rod, Cylinder{0.002, 0.02}, steel, 0.002);
    }
    magnetics.compute();
    force[run] = magnetics.force(1);
    torque[run] = magnetics.torque(1);
  }
  EXPECT_GT(norm(force[0]), 0.0);
  expect_same(force[0], force[1]);
  expect_same(torque[0], torque[1]);
}

TEST(MagneticForcesMaterials, UnknownMaterialThrowsNamingIt) {
  const std::map<std::string, Material> materials{{"iron", SoftMaterial{}}, {"magnet", PermanentMaterial{}}};
  MagneticForces magnetics;
  try {
    magnetics.attach(nullptr, Sphere{0.003}, materials, "steel");
    FAIL() << "no exception";
  } catch (const std::invalid_argument& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("\"steel\""), std::string::npos) << what;
    EXPECT_NE(what.find("\"iron\", \"magnet\""), std::string::npos) << what;
  }
  EXPECT_EQ(magnetics.body_count(), 0);
}

}  // namespace
}  // namespace odemag
