#include "engine/simulation/rigid_world.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <stdexcept>
#include <string>
#include <variant>

#include "odemag/magnetic_forces.h"
#include "engine/simulation/winding_solids.h"

namespace odemag {

namespace {

// dInitODE2 once per process, dCloseODE at exit.
struct OdeLibrary {
  OdeLibrary() {
    dInitODE2(0);
    throw_ode_internal_errors();  // ODE's internal errors end a run with a message, not abort()
  }
  ~OdeLibrary() { dCloseODE(); }
};

void ensure_ode_initialised() { static OdeLibrary library; }

constexpr int kMaxContacts = 8;

// Collision skin: each body's collision geometry is larger than its shape by
// this fraction of its smallest half extent, and contact depths are reduced
// by the skins. Two bodies closer than their skins therefore touch through a
// contact that stops further approach without pushing them apart: a body held
// against a magnet stays in contact even when it lifts off by a hair, instead
// of falling freely into the magnet during the next substep (docs/simulation.md).
constexpr double kSkinFraction = 0.02;

// "auto" uses ODE's direct solver up to this many dynamic bodies (its cost
// grows with the cube of the contacts of an island).
constexpr long kExactSolverBodies = 32;

}  // namespace

dSurfaceParameters contact_surface(const ContactSettings& c) {
  dSurfaceParameters s{};
  s.mode = dContactBounce | dContactSoftCFM | dContactSoftERP | dContactApprox1;
  s.mu = c.friction;
  s.bounce = c.restitution;
  s.bounce_vel = 0.01;
  s.soft_cfm = c.softness;
  s.soft_erp = c.erp;
  const double rolling = c.rolling_friction, spinning = c.spinning();
  if (rolling == 0.0 && spinning == 0.0) return s;
  s.mode |= dContactRolling;
  if (rolling == spinning) {
    s.rho = s.rho2 = s.rhoN = rolling;
    return s;
  }
  s.mode |= dContactAxisDep;  // the same bit as dContactMu2: mu2 is read too
  s.mu2 = s.mu;
  s.rho = s.rho2 = rolling > 0.0 ? rolling : -1.0;
  s.rhoN = spinning > 0.0 ? spinning : -1.0;
  return s;
}

RigidWorld::RigidWorld(const SceneDescription& scene)
    : surface_(contact_surface(scene.simulation.contact)) {
  const long dynamic = std::count_if(scene.bodies.begin(), scene.bodies.end(),
                                     [](const BodyDescription& b) { return !b.fixed; });
  const ContactSolver solver = scene.simulation.contact_solver;
  exact_solver_ = solver == ContactSolver::exact || (solver == ContactSolver::automatic && dynamic <= kExactSolverBodies);
  ensure_ode_initialised();
  world_ = dWorldCreate();
  space_ = dHashSpaceCreate(nullptr);
  contacts_ = dJointGroupCreate(0);
  dWorldSetGravity(world_, scene.gravity.x, scene.gravity.y, scene.gravity.z);
  dWorldSetQuickStepNumIterations(world_, scene.simulation.solver_iterations);
  dWorldSetERP(world_, scene.simulation.contact.erp);
  dWorldSetCFM(world_, scene.simulation.contact.softness);
  // Penetration is resolved at a bounded speed, so strong magnetic pulls
  // into a contact do not make bodies jump apart (see also the skin below).
  dWorldSetContactMaxCorrectingVel(world_, 0.1);
  linear_damping_ = scene.simulation.linear_damping;
  angular_damping_ = scene.simulation.angular_damping;
  time_step_ = scene.simulation.time_step;
  if (scene.simulation.ground)
    ground_ = dCreatePlane(space_, 0, 0, 1, scene.simulation.ground_height);

  for (const BodyDescription& d : scene.bodies) {
    Body b;
    b.body = dBodyCreate(world_);
    const Vec3 half = shape_half_extents(d.shape);
    // Trimeshes have no skin (docs/simulation.md "Meshes"), nor do compounds.
    const bool primitive = !std::holds_alternative<Mesh>(d.shape) && !std::holds_alternative<Compound>(d.shape);
    b.skin = primitive ? kSkinFraction * std::min({half.x, half.y, half.z}) : 0.0;
    const double skin = b.skin;
    dMass m;
    dMassSetZero(&m);
    if (const auto* s = std::get_if<Sphere>(&d.shape)) {
      dMassSetSphere(&m, d.density, s->radius);
      b.geom = dCreateSphere(space_, s->radius + skin);
    } else if (const auto* x = std::get_if<Box>(&d.shape)) {
      dMassSetBox(&m, d.density, x->size.x, x->size.y, x->size.z);
      b.geom = dCreateBox(space_, x->size.x + 2 * skin, x->size.y + 2 * skin, x->size.z + 2 * skin);
    } else if (const auto* c = std::get_if<Cylinder>(&d.shape)) {
      dMassSetCylinder(&m, d.density, 3, c->radius, c->length);
      b.geom = dCreateCylinder(space_, c->radius + skin, c->length + 2 * skin);
    } else {
      // Meshes and compounds: mass and inertia from the exact integrals
      // (magnetics/cells/mesh.h), the centre of mass at the body's origin.
      const double volume = shape_volume(d.shape);
      const Mat3 J = shape_unit_inertia(d.shape);
      dMassSetParameters(&m, d.density * volume, 0, 0, 0, d.density * J.m[0][0], d.density * J.m[1][1],
                         d.density * J.m[2][2], d.density * J.m[0][1], d.density * J.m[0][2], d.density * J.m[1][2]);
      if (const auto* mesh = std::get_if<Mesh>(&d.shape)) {
        b.geom = trimesh_geom(*mesh);
      } else {
        // One geom per part, placed by its offset in the body frame.
        const auto& parts = std::get<Compound>(d.shape).parts();
        for (size_t k = 0; k < parts.size(); ++k) {
          const dGeomID g = part_geom(parts[k].shape, 0.0);
          dGeomSetBody(g, b.body);
          dGeomSetOffsetPosition(g, parts[k].position.x, parts[k].position.y, parts[k].position.z);
          dMatrix3 R{};
          for (int i = 0; i < 3; ++i)
            for (int j = 0; j < 3; ++j) R[4 * i + j] = parts[k].orientation.m[i][j];
          dGeomSetOffsetRotation(g, R);
          if (k == 0) b.geom = g;
          else b.windings.push_back(g);
        }
      }
    }
    dBodySetMass(b.body, &m);
    b.mass = m.mass;
    if (!dGeomGetBody(b.geom)) dGeomSetBody(b.geom, b.body);
    // The windings of its coils collide like its shape (winding_solids.h),
    // enlarged by the same skin.
    for (const CoilSource& coil : d.coils)
      for (const CollisionSolid& w : winding_solids(coil)) {
        const dGeomID g =
            w.kind == CollisionSolid::Kind::box
                ? dCreateBox(space_, w.size.x + 2 * skin, w.size.y + 2 * skin, w.size.z + 2 * skin)
            : w.kind == CollisionSolid::Kind::cylinder ? dCreateCylinder(space_, w.size.x + skin, w.size.z + 2 * skin)
                                                       : dCreateCapsule(space_, w.size.x + skin, w.size.z);
        dGeomSetBody(g, b.body);
        dGeomSetOffsetPosition(g, w.centre.x, w.centre.y, w.centre.z);
        dMatrix3 R{};
        for (int i = 0; i < 3; ++i)
          for (int j = 0; j < 3; ++j) R[4 * i + j] = w.axes.m[i][j];
        dGeomSetOffsetRotation(g, R);
        b.windings.push_back(g);
      }
    dBodySetData(b.body, reinterpret_cast<void*>(static_cast<intptr_t>(bodies_.size())));
    dBodySetPosition(b.body, d.position.x, d.position.y, d.position.z);
    const dQuaternion q = {d.orientation.w, d.orientation.x, d.orientation.y, d.orientation.z};
    dBodySetQuaternion(b.body, q);
    dBodySetLinearVel(b.body, d.velocity.x, d.velocity.y, d.velocity.z);
    dBodySetAngularVel(b.body, d.angular_velocity.x, d.angular_velocity.y, d.angular_velocity.z);
    if (d.fixed) {
      dBodySetKinematic(b.body);
      b.kinematic = true;
    }
    bodies_.push_back(b);
    if (!d.present) set_enabled(body_count() - 1, false);
  }
  for (const JointDescription& j : scene.joints) add_joint(scene, j);
  for (const Body& b : bodies_) ode_bodies_.push_back(b.body);
  if (exact_solver_) exact_step_ = std::make_unique<ExactStep>(world_);
}

void RigidWorld::add_joint(const SceneDescription& scene, const JointDescription& j) {
  dBodyID a = bodies_[scene.find_body(j.bodies[0])].body;
  dBodyID b = j.bodies.size() > 1 ? bodies_[scene.find_body(j.bodies[1])].body : nullptr;
  const Vec3 &p = j.anchor, &n = j.axis;
  dJointID joint = nullptr;
  switch (j.type) {
    case JointDescription::Type::hinge:
      joint = dJointCreateHinge(world_, nullptr);
      dJointAttach(joint, a, b);
      dJointSetHingeAnchor(joint, p.x, p.y, p.z);
      dJointSetHingeAxis(joint, n.x, n.y, n.z);
      break;
    case JointDescription::Type::ball:
      joint = dJointCreateBall(world_, nullptr);
      dJointAttach(joint, a, b);
      dJointSetBallAnchor(joint, p.x, p.y, p.z);
      break;
    case JointDescription::Type::slider:
      joint = dJointCreateSlider(world_, nullptr);
      dJointAttach(joint, a, b);
      dJointSetSliderAxis(joint, n.x, n.y, n.z);
      break;
    case JointDescription::Type::fixed:
      joint = dJointCreateFixed(world_, nullptr);
      dJointAttach(joint, a, b);
      dJointSetFixed(joint);
      break;
  }
  if (j.limits) {
    // The low stop first: ODE ignores a low stop above the current high one.
    const auto set = j.type == JointDescription::Type::hinge ? dJointSetHingeParam : dJointSetSliderParam;
    set(joint, dParamLoStop, (*j.limits)[0]);
    set(joint, dParamHiStop, (*j.limits)[1]);
  }
  has_joints_ = true;
}

RigidWorld::~RigidWorld() {
  exact_step_.reset();  // gives the world back ODE's threading before it goes
  dJointGroupDestroy(contacts_);
  dSpaceDestroy(space_);  // destroys the geoms it holds
  for (const auto& t : trimeshes_) dGeomTriMeshDataDestroy(t->data);
  dWorldDestroy(world_);  // destroys the bodies
}

dGeomID RigidWorld::trimesh_geom(const Mesh& mesh) {
  auto store = std::make_unique<TriMeshStore>();
  for (const Vec3& v : mesh.vertices()) store->vertices.insert(store->vertices.end(), {v.x, v.y, v.z, 0.0});
  for (const auto& t : mesh.triangles())
    for (int k = 0; k < 3; ++k) store->indices.push_back(static_cast<dTriIndex>(t[k]));
  store->data = dGeomTriMeshDataCreate();
  dGeomTriMeshDataBuildDouble(store->data, store->vertices.data(), 4 * sizeof(double),
                              static_cast<int>(mesh.vertices().size()), store->indices.data(),
                              static_cast<int>(store->indices.size()), 3 * sizeof(dTriIndex));
  const dGeomID g = dCreateTriMesh(space_, store->data, nullptr, nullptr, nullptr);
  trimeshes_.push_back(std::move(store));
  return g;
}

dGeomID RigidWorld::part_geom(const PartShape& shape, double skin) {
  return std::visit(Overloaded{
                        [&](const Sphere& s) { return dCreateSphere(space_, s.radius + skin); },
                        [&](const Box& x) {
                          return dCreateBox(space_, x.size.x + 2 * skin, x.size.y + 2 * skin, x.size.z + 2 * skin);
                        },
                        [&](const Cylinder& c) { return dCreateCylinder(space_, c.radius + skin, c.length + 2 * skin); },
                        [&](const Mesh& m) { return trimesh_geom(m); },
                    },
                    shape);
}

double RigidWorld::skin_of(dGeomID geom) const {
  dBodyID body = dGeomGetBody(geom);
  return body ? bodies_[index_of(body)].skin : 0.0;
}

int RigidWorld::index_of(dBodyID body) const {
  return static_cast<int>(reinterpret_cast<intptr_t>(dBodyGetData(body)));
}

void RigidWorld::set_enabled(int i, bool enabled) {
  Body& b = bodies_[i];
  b.enabled = enabled;
  if (enabled) {
    dBodyEnable(b.body);
    dGeomEnable(b.geom);
    for (dGeomID g : b.windings) dGeomEnable(g);
  } else {
    dBodyDisable(b.body);
    dGeomDisable(b.geom);
    for (dGeomID g : b.windings) dGeomDisable(g);
  }
}

void RigidWorld::set_kinematic(int i, bool kinematic) {
  Body& b = bodies_[i];
  if (b.kinematic == kinematic) return;
  b.kinematic = kinematic;
  if (kinematic) {
    dBodySetKinematic(b.body);
  } else {
    dBodySetDynamic(b.body);
  }
}

void RigidWorld::set_kinematic_state(int i, const BodyPose& pose, const Vec3& v, const Vec3& w) {
  dBodyID body = bodies_[i].body;
  dBodySetPosition(body, pose.position.x, pose.position.y, pose.position.z);
  dMatrix3 R;
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) R[4 * r + c] = pose.rotation.m[r][c];
    R[4 * r + 3] = 0.0;
  }
  dBodySetRotation(body, R);
  dBodySetLinearVel(body, v.x, v.y, v.z);
  dBodySetAngularVel(body, w.x, w.y, w.z);
}

void RigidWorld::update_forces(double time, double dt) {
  for (ForceAccumulator* a : accumulators_) a->update(time, dt);
}

void RigidWorld::integrate(double h) {
  for (ForceAccumulator* a : accumulators_) a->add_forces();
  for (Body& b : bodies_) b.in_contact = false, b.contacts = 0;
  touching_.clear();
  touching_kinematic_.clear();
  // ODE's random numbers (dWorldQuickStep reorders constraints randomly) come
  // from one seed per process: each world keeps its own sequence, so a run
  // does not depend on the worlds stepped before it in the same process (a
  // Python session, a sweep worker) and matches a fresh `odemag run`.
  const unsigned long process_seed = dRandGetSeed();
  dRandSetSeed(random_seed_);
  dSpaceCollide(space_, this, &RigidWorld::near_callback);
  // ODE damps once per step it takes: scaled so that the substeps of a rigid
  // step damp together by the scene's factor, whatever their count (each
  // body keeps the values it was given; set again when h changes).
  if ((linear_damping_ > 0.0 || angular_damping_ > 0.0) && h != damped_step_) {
    const double share = h / time_step_;
    const double linear = 1.0 - std::pow(1.0 - linear_damping_, share);
    const double angular = 1.0 - std::pow(1.0 - angular_damping_, share);
    for (Body& b : bodies_) {
      dBodySetLinearDamping(b.body, linear);
      dBodySetAngularDamping(b.body, angular);
    }
    damped_step_ = h;
  }
  if (exact_solver_) {
    exact_step_->step(ode_bodies_, h);  // QuickStep where ODE's exact solver fails
  } else {
    dWorldQuickStep(world_, h);
  }
  dJointGroupEmpty(contacts_);
  random_seed_ = dRandGetSeed();
  dRandSetSeed(process_seed);
}

double RigidWorld::clearance(int i) const {
  if (!bodies_[i].geom) return 0.0;
  dReal own[6], other[6];  // min x, max x, min y, max y, min z, max z
  dGeomGetAABB(bodies_[i].geom, own);
  for (dGeomID w : bodies_[i].windings) {  // the box around all its geoms
    dGeomGetAABB(w, other);
    for (int k = 0; k < 3; ++k) {
      own[2 * k] = std::min(own[2 * k], other[2 * k]);
      own[2 * k + 1] = std::max(own[2 * k + 1], other[2 * k + 1]);
    }
  }
  double nearest = std::numeric_limits<double>::infinity();
  const int n = dSpaceGetNumGeoms(space_);
  for (int g = 0; g < n; ++g) {  // in order: ODE's spaces are fast at sequential access
    const dGeomID geom = dSpaceGetGeom(space_, g);
    if (geom == bodies_[i].geom ||
        (!bodies_[i].windings.empty() && dGeomGetBody(geom) == bodies_[i].body))
      continue;
    dGeomGetAABB(geom, other);
    double gap2 = 0.0;
    for (int k = 0; k < 3; ++k) {
      const double gap = std::max({other[2 * k] - own[2 * k + 1], own[2 * k] - other[2 * k + 1], 0.0});
      gap2 += gap * gap;
    }
    nearest = std::min(nearest, gap2);
  }
  return std::sqrt(nearest);
}

void RigidWorld::near_callback(void* data, dGeomID a, dGeomID b) {
  auto* self = static_cast<RigidWorld*>(data);
  dBodyID ba = dGeomGetBody(a), bb = dGeomGetBody(b);
  // Nothing to resolve between immovable things (the ground, static geoms,
  // kinematic bodies).
  const bool a_moves = ba && !dBodyIsKinematic(ba);
  const bool b_moves = bb && !dBodyIsKinematic(bb);
  if (!a_moves && !b_moves) return;
  // Jointed bodies do not collide with each other (a needle on its pivot).
  if (self->has_joints_ && ba && bb && dAreConnectedExcluding(ba, bb, dJointTypeContact)) return;
  dContact contact[kMaxContacts];
  const int n = dCollide(a, b, kMaxContacts, &contact[0].geom, sizeof(dContact));
  if (n == 0) return;
  for (dBodyID body : {ba, bb})
    if (body) {
      Body& touched = self->bodies_[self->index_of(body)];
      touched.in_contact = true;
      touched.contacts += n;
    }
  if (a_moves && b_moves) {
    self->touching_.emplace_back(self->index_of(ba), self->index_of(bb));
  } else if (ba && bb) {  // one of them kinematic
    const int moving = self->index_of(a_moves ? ba : bb);
    self->touching_kinematic_.emplace_back(moving, self->index_of(a_moves ? bb : ba));
  }
  const double skins = self->skin_of(a) + self->skin_of(b);
  for (int i = 0; i < n; ++i) {
    contact[i].geom.depth = std::max(0.0, contact[i].geom.depth - skins);
    contact[i].surface = self->surface_;
    dJointID j = dJointCreateContact(self->world_, self->contacts_, &contact[i]);
    dJointAttach(j, ba, bb);
  }
}

BodyPose RigidWorld::pose(int i) const { return ode_pose(bodies_[i].body); }

Vec3 RigidWorld::velocity(int i) const {
  const dReal* v = dBodyGetLinearVel(bodies_[i].body);
  return {v[0], v[1], v[2]};
}

Vec3 RigidWorld::angular_velocity(int i) const {
  const dReal* w = dBodyGetAngularVel(bodies_[i].body);
  return {w[0], w[1], w[2]};
}

}  // namespace odemag
