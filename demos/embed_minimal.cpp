// odemag in a plain ODE program (docs/embedding.md): an iron ball dropped
// beside a bar magnet lying on the ground is pulled to the magnet's pole.
// The steps are split into substeps as in `odemag run` (MagneticStepper,
// docs/embedding.md "Substeps"). Exits 0 when the ball rests on the magnet
// (in the last second touching it, within a thousandth of its radius, in at
// least 800 of the 1000 steps and never thrown off), 1 otherwise.
#include <ode/ode.h>

#include <algorithm>
#include <cmath>
#include <cstdio>

#include <odemag/odemag.h>

static dWorldID world;
static dJointGroupID contacts;

static void near_callback(void*, dGeomID a, dGeomID b) {
  if (!dGeomGetBody(a) && !dGeomGetBody(b)) return;  // magnet on the ground: both static
  dContact contact[4] = {};
  const int n = dCollide(a, b, 4, &contact[0].geom, sizeof(dContact));
  for (int i = 0; i < n; ++i) {
    contact[i].surface.mode = dContactBounce;
    contact[i].surface.mu = 0.5;
    contact[i].surface.bounce = 0.1;
    dJointAttach(dJointCreateContact(world, contacts, &contact[i]), dGeomGetBody(a), dGeomGetBody(b));
  }
}

int main() {
  dInitODE();
  world = dWorldCreate();
  dWorldSetGravity(world, 0, 0, -9.81);
  dSpaceID space = dHashSpaceCreate(nullptr);
  contacts = dJointGroupCreate(0);
  dCreatePlane(space, 0, 0, 1, 0);  // the ground, z = 0

  // A 4 x 1 x 1 cm bar magnet on the ground, north pole at +x: a static geom
  // (no ODE body), placed for the magnetics with set_pose.
  dGeomID bar = dCreateBox(space, 0.04, 0.01, 0.01);
  dGeomSetPosition(bar, 0, 0, 0.005);
  odemag::MagneticForces magnetics;
  const int magnet = magnetics.attach(nullptr, odemag::Box{{0.04, 0.01, 0.01}},
                                      odemag::PermanentMaterial{{8e5, 0, 0}}, 0.005, "bar");
  magnetics.set_pose(magnet, odemag::BodyPose{odemag::Mat3{}, {0, 0, 0.005}});

  // An iron ball of radius 5 mm, 2 cm beyond the north pole, 3 cm up: one cell.
  const double radius = 0.005;
  dBodyID ball = dBodyCreate(world);
  dMass mass;  // steel, 7870 kg/m^3
  dMassSetSphere(&mass, 7870, radius);
  dBodySetMass(ball, &mass);
  dBodySetPosition(ball, 0.04, 0, 0.03);
  dGeomSetBody(dCreateSphere(space, radius), ball);
  odemag::SoftMaterial iron_material;  // Ms 1.7e6 A/m, chi 5000
  iron_material.saturation = 1.7e6;
  iron_material.susceptibility = 5000;
  const int iron = magnetics.attach(ball, odemag::Sphere{radius}, iron_material);

  // Per substep: relax, add the magnetic forces, collide, dWorldQuickStep,
  // empty the contacts.
  odemag::MagneticStepper stepper(magnetics, world, space, near_callback, nullptr, contacts);
  int most = 1;  // substeps of a step
  // Ball surface to the magnet's surface, m (negative: inside).
  const auto gap = [&] {
    const dReal* p = dBodyGetPosition(ball);
    const double dx = std::max(std::abs(p[0]) - 0.02, 0.0), dy = std::max(std::abs(p[1]) - 0.005, 0.0),
                 dz = std::max(std::abs(p[2] - 0.005) - 0.005, 0.0);
    return std::sqrt(dx * dx + dy * dy + dz * dz) - radius;
  };
  // Over the last second: steps touching the magnet (within a thousandth of
  // the radius), and the deepest and farthest excursions. Without a contact
  // surface layer ODE drops a resting contact now and then, and the pull then
  // moves the ball a h^2 (1.8 mm at 1 ms) into the magnet for one step
  // before the contact pushes it out (docs/embedding.md "Substeps").
  int touching = 0;
  double deepest = 0.0, farthest = 0.0;
  for (int step = 0; step < 2000; ++step) {  // 2 s of 1 ms steps
    most = std::max(most, stepper.step(0.001).substeps);
    if (step < 1000) continue;
    const double g = gap();
    touching += std::abs(g) < 1e-3 * radius ? 1 : 0;
    deepest = std::min(deepest, g), farthest = std::max(farthest, g);
  }
  const dReal* p = dBodyGetPosition(ball);
  std::printf("ball at (%.4f, %.4f, %.4f) m, %.1e mm from the magnet, force on it %.3f N, up to %d substeps; "
              "last second: touching in %d of 1000 steps, %.2f mm deepest, %.2f mm farthest\n",
              p[0], p[1], p[2], gap() * 1e3, odemag::norm(magnetics.force(iron)), most, touching, -deepest * 1e3,
              farthest * 1e3);
  dJointGroupDestroy(contacts);
  dSpaceDestroy(space);  // and its geoms
  dWorldDestroy(world);
  dCloseODE();
  // Resting: touching in most steps, never thrown off.
  return touching >= 800 && farthest < 0.1 * radius ? 0 : 1;
}
