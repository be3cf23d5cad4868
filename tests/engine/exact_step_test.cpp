// ODE's exact solver on a contact set it fails on (engine/embedding/exact_step.h,
// docs/simulation.md "Contacts"): three steel balls in a row on the floor,
// the middle one touched from above by a kinematic body, as the
// nail_and_balls scene met them (recorded from that run, every number as
// it was). dWorldStep meets a zero pivot there ('assertion "d[i] !=
// dReal(0.0)" failed in dxLDLTRemove()') and, left to ODE's handlers, ends
// the process. ExactStep takes the step with QuickStep instead: the same
// state as QuickStep from the same start, bit for bit, and the world steps
// on and is destroyed without ODE's checks failing.
#include <gtest/gtest.h>

#include <ode/ode.h>

#include <array>
#include <cmath>
#include <vector>

#include "engine/embedding/exact_step.h"

namespace odemag {
namespace {

struct RecordedBody {
  bool kinematic;
  double mass, inertia_xx, inertia_zz;  // diagonal inertia (xx = yy), kg m^2
  std::array<double, 3> position;
  std::array<double, 4> orientation;  // w, x, y, z
  std::array<double, 3> velocity, angular_velocity, force, torque;
};

const RecordedBody kBodies[] = {
    {true, 0.003, 2.5e-07, 5.0000000000000004e-08, {0, 0, 0.014999999999999999}, {1, 0, 0, 0}, {}, {}, {}, {}},
    {true, 0.00035342917352885171, 7.3829881728620757e-08, 3.9760782021995817e-10, {0.12, 0, 0.033500000000000002},
     {1, 0, 0, 0}, {}, {}, {}, {}},
    {false, 0.0021044481988846827, 1.346846847286197e-08, 1.346846847286197e-08,
     {0.1200045116546429, -4.8437946352637432e-19, 0.0045002479885748658},
     {0.99999914734688233, 8.8629700974886457e-19, 0.0013058734657154837, -3.541559905259202e-20},
     {-1.2468441992184108e-09, 9.2675138934400732e-25, -2.3582936804375459e-05},
     {4.7959551724971338e-20, -5.1581574383983727e-12, 2.8968989887986189e-24},
     {0.00059939468191798633, 2.0030687949229207e-17, 0.10738597255320224},
     {-1.2301113055843774e-20, 9.4954123720549959e-13, -8.0424950401394252e-23}},
    {false, 0.0021044481988846827, 1.346846847286197e-08, 1.346846847286197e-08,
     {0.12810539265493501, -9.5139172952910972e-18, 0.0039999967667195173},
     {0.99999799087486174, -1.3950820274802523e-18, -0.0020045563699374836, -2.6466309692497547e-20},
     {1.3141645690529001e-06, -1.1640568300991536e-21, -9.2736916425731119e-09},
     {1.9717084847499432e-19, 0.00031075625423501193, 2.1381651160242219e-24},
     {-0.009086080744800544, 1.1979037235056488e-17, -0.00053097757913498885},
     {1.3145368630431547e-21, 9.8335783500270603e-12, -1.4406162742311218e-20}},
    {false, 0.0021044481988846827, 1.346846847286197e-08, 1.346846847286197e-08,
     {0.11190095308573121, 1.341693982700577e-17, 0.0039999968133824296},
     {0.99999663958192098, 1.5354845724391655e-18, 0.0025924553739147603, -3.0863221401394429e-20},
     {-1.3236262445999643e-06, 1.7031012767026674e-21, -9.1383243908355217e-09},
     {-2.451304376440214e-19, -0.00031374704112266985, 2.5968882798413669e-24},
     {0.0086360571159493065, -1.7147288987984544e-17, -0.0004677297904243384},
     {-2.1342046507572314e-21, -9.4702207807027847e-12, -1.9639847704726077e-20}},
};

struct RecordedContact {
  int a, b;  // body indices, -1: the floor
  std::array<double, 3> position, normal;
  double depth;
};

const RecordedContact kContacts[] = {
    {1, 2, {0.1200045116546429, -4.8437946352637432e-19, 0.008580247988574867}, {0, 0, 1}, 2.4798857486427542e-07},
    {3, 2, {0.12405495215478896, -4.9991483794087363e-18, 0.0042501223776471916},
     {0.99809873839161156, -1.1125173074161597e-15, -0.061635285519523325}, 0},
    {2, 4, {0.11595273237018705, 6.4662801817396972e-18, 0.0042501224009786481},
     {0.998099991384924, -1.7121992203954181e-15, 0.061614991661240598}, 0},
    {3, -1, {0.12810539265493501, -9.5139172952910972e-18, -8.000323328048297e-05}, {0, 0, 1}, 3.2332804829636247e-09},
    {4, -1, {0.11190095308573121, 1.341693982700577e-17, -8.0003186617570721e-05}, {0, 0, 1}, 3.1866175707141514e-09},
};

constexpr double kStep = 0.0025;  // the substep, s

// The recorded world: the scene's settings (docs/simulation.md "Contacts").
struct RecordedWorld {
  RecordedWorld() {
    world = dWorldCreate();
    dWorldSetGravity(world, 0, 0, -9.81);
    dWorldSetERP(world, 0.2);
    dWorldSetCFM(world, 1e-5);
    dWorldSetContactMaxCorrectingVel(world, 0.1);
    contacts = dJointGroupCreate(0);
    for (const RecordedBody& r : kBodies) {
      const dBodyID b = dBodyCreate(world);
      dMass m;
      dMassSetZero(&m);
      m.mass = r.mass;
      m.I[0] = m.I[5] = r.inertia_xx;
      m.I[10] = r.inertia_zz;
      dBodySetMass(b, &m);
      dBodySetPosition(b, r.position[0], r.position[1], r.position[2]);
      const dQuaternion q = {r.orientation[0], r.orientation[1], r.orientation[2], r.orientation[3]};
      dBodySetQuaternion(b, q);
      dBodySetLinearVel(b, r.velocity[0], r.velocity[1], r.velocity[2]);
      dBodySetAngularVel(b, r.angular_velocity[0], r.angular_velocity[1], r.angular_velocity[2]);
      if (r.kinematic) dBodySetKinematic(b);
      bodies.push_back(b);
    }
    add_forces();
    add_contacts();
  }
  ~RecordedWorld() {
    dJointGroupDestroy(contacts);
    dWorldDestroy(world);
  }
  void add_forces() {
    for (size_t i = 0; i < bodies.size(); ++i) {
      const RecordedBody& r = kBodies[i];
      dBodyAddForce(bodies[i], r.force[0], r.force[1], r.force[2]);
      dBodyAddTorque(bodies[i], r.torque[0], r.torque[1], r.torque[2]);
    }
  }
  void add_contacts() {
    for (const RecordedContact& c : kContacts) {
      dContact contact{};
      dSurfaceParameters& s = contact.surface;
      s.mode = dContactBounce | dContactSoftCFM | dContactSoftERP | dContactApprox1 | dContactRolling;
      s.mu = 0.5;
      s.rho = s.rho2 = s.rhoN = 1e-5;
      s.bounce = 0.1;
      s.bounce_vel = 0.01;
      s.soft_erp = 0.2;
      s.soft_cfm = 1e-5;
      for (int k = 0; k < 3; ++k) contact.geom.pos[k] = c.position[k], contact.geom.normal[k] = c.normal[k];
      contact.geom.depth = c.depth;
      const dJointID j = dJointCreateContact(world, contacts, &contact);
      dJointAttach(j, c.a >= 0 ? bodies[c.a] : nullptr, c.b >= 0 ? bodies[c.b] : nullptr);
    }
  }
  std::vector<double> state() const {
    std::vector<double> s;
    for (const dBodyID b : bodies)
      for (const dReal* v : {dBodyGetPosition(b), dBodyGetQuaternion(b), dBodyGetLinearVel(b), dBodyGetAngularVel(b)})
        s.insert(s.end(), v, v + (v == dBodyGetQuaternion(b) ? 4 : 3));
    return s;
  }
  dWorldID world;
  dJointGroupID contacts;
  std::vector<dBodyID> bodies;
};

TEST(ExactStep, FailedExactStepIsTakenByQuickStepAndTheWorldStepsOn) {
  dInitODE2(0);
  {
    RecordedWorld quick;
    dRandSetSeed(1);
    dWorldQuickStep(quick.world, kStep);

    RecordedWorld recorded;
    ExactStep exact(recorded.world);
    dRandSetSeed(1);
    EXPECT_FALSE(exact.step(recorded.bodies, kStep)) << "ODE's exact solver no longer fails here";
    EXPECT_EQ(exact.failures(), 1);
    EXPECT_NE(exact.last_failure().find("dxLDLTRemove"), std::string::npos) << exact.last_failure();
    EXPECT_EQ(recorded.state(), quick.state()) << "not put back as it was before QuickStep";

    // Stepping on: the contacts again; every step either exact or taken by QuickStep.
    for (int step = 0; step < 20; ++step) {
      dJointGroupEmpty(recorded.contacts);
      recorded.add_forces();
      recorded.add_contacts();
      exact.step(recorded.bodies, kStep);
      for (double v : recorded.state()) ASSERT_TRUE(std::isfinite(v));
    }
  }  // ExactStep and the world go: ODE checks its threading's job lists
  dCloseODE();
}

// Where ODE's exact solver succeeds ExactStep is dWorldStep, bit for bit:
// the same balls with their contacts on the floor only.
TEST(ExactStep, SucceedingStepIsDWorldStep) {
  dInitODE2(0);
  {
    RecordedWorld plain, stepped;
    ExactStep exact(stepped.world);
    for (int step = 0; step < 5; ++step) {
      for (RecordedWorld* w : {&plain, &stepped}) {
        if (step > 0) w->add_forces();
        dJointGroupEmpty(w->contacts);
      }
      dWorldStep(plain.world, kStep);
      EXPECT_TRUE(exact.step(stepped.bodies, kStep));
      EXPECT_EQ(plain.state(), stepped.state());
    }
    EXPECT_EQ(exact.failures(), 0);
  }
  dCloseODE();
}

}  // namespace
}  // namespace odemag
