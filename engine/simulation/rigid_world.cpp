#include "engine/simulation/rigid_world.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <stdexcept>
#include <string>
#include <variant>

#include "engine/embedding/magnetic_forces.h"
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

void align_rolling_row(dContact& contact, const Vec3& relative_omega) {
  dSurfaceParameters& s = contact.surface;
  if (!(s.mode & dContactRolling) || s.rho <= 0.0) return;
  const Vec3 n{contact.geom.normal[0], contact.geom.normal[1], contact.geom.normal[2]};
  const Vec3 omega_t = relative_omega - dot(relative_omega, n) * n;
  const double rolling_rate = norm(omega_t);
  if (!(rolling_rate > kRollingAxisMinimum)) return;
  const Vec3 axis = omega_t / rolling_rate;
  // Without dContactAxisDep all three rows took rho: spinning as rolling.
  const double spinning = (s.mode & dContactAxisDep) ? s.rhoN : s.rho;
  s.mode |= dContactAxisDep | dContactFDir1;  // dContactAxisDep reads mu2 too
  s.mu2 = s.mu;
  s.rho2 = -1.0;  // no row about n x axis, the direction the contact rolls along
  s.rhoN = spinning > 0.0 ? spinning : -1.0;
  contact.fdir1[0] = axis.x;
  contact.fdir1[1] = axis.y;
  contact.fdir1[2] = axis.z;
}

RigidWorld::RigidWorld(const SceneDescription& scene)
    : surface_(contact_surface(scene.simulation.contact)),
      rolling_axis_aligned_(scene.simulation.contact.rolling_axes == "rolling"),
      sleep_(scene.simulation.sleep),
      gravity_(norm(scene.gravity)) {
  const long dynamic = std::count_if(scene.bodies.begin(), scene.bodies.end(),
                                     [](const BodyDescription& b) { return !b.fixed; });
  const std::string& solver = scene.simulation.contact_solver;
  exact_solver_ = solver == "exact" || (solver == "auto" && dynamic <= kExactSolverBodies);
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
    b.skin = kSkinFraction * std::min({half.x, half.y, half.z});
    const double skin = b.skin;
    dMass m;
    dMassSetZero(&m);
    if (const auto* s = std::get_if<Sphere>(&d.shape)) {
      dMassSetSphere(&m, d.density, s->radius);
      b.geom = dCreateSphere(space_, s->radius + skin);
      b.radius = s->radius;
    } else if (const auto* x = std::get_if<Box>(&d.shape)) {
      dMassSetBox(&m, d.density, x->size.x, x->size.y, x->size.z);
      b.geom = dCreateBox(space_, x->size.x + 2 * skin, x->size.y + 2 * skin, x->size.z + 2 * skin);
      b.radius = norm(half);
    } else if (const auto* c = std::get_if<Cylinder>(&d.shape)) {
      dMassSetCylinder(&m, d.density, 3, c->radius, c->length);
      b.geom = dCreateCylinder(space_, c->radius + skin, c->length + 2 * skin);
      b.radius = std::hypot(c->radius, 0.5 * c->length);
    }
    dBodySetMass(b.body, &m);
    b.mass = m.mass;
    dGeomSetBody(b.geom, b.body);
    // The windings of its coils collide like its shape (winding_solids.h),
    // enlarged by the same skin.
    for (const CoilSource& coil : d.coils)
      for (const CollisionSolid& w : winding_solids(coil)) {
        const dGeomID g =
            w.kind == CollisionSolid::Kind::box
                ? dCreateBox(space_, w.size.x + 2 * skin, w.size.y + 2 * skin, w.size.z + 2 * skin)
                : dCreateCylinder(space_, w.size.x + skin, w.size.z + 2 * skin);
        dGeomSetBody(g, b.body);
        dGeomSetOffsetPosition(g, w.centre.x, w.centre.y, w.centre.z);
        dMatrix3 R{};
        for (int i = 0; i < 3; ++i)
          for (int j = 0; j < 3; ++j) R[4 * i + j] = w.axes.m[i][j];
        dGeomSetOffsetRotation(g, R);
        b.windings.push_back(g);
        b.radius = std::max(b.radius, norm(w.centre) + 0.5 * norm(w.size));
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
  for (const std::string& name : j.bodies) bodies_[scene.find_body(name)].jointed = true;
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
  dWorldDestroy(world_);  // destroys the bodies
}

double RigidWorld::skin_of(dGeomID geom) const {
  dBodyID body = dGeomGetBody(geom);
  return body ? bodies_[index_of(body)].skin : 0.0;
}

int RigidWorld::index_of(dBodyID body) const {
  return static_cast<int>(reinterpret_cast<intptr_t>(dBodyGetData(body)));
}

void RigidWorld::set_enabled(int i, bool enabled) {
  // A body that appears or goes may change what holds the others up.
  for (int k = 0; k < body_count(); ++k)
    if (bodies_[k].sleeping) wake(k);
  Body& b = bodies_[i];
  b.enabled = enabled;
  b.idle = 0.0;
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
  if (b.sleeping) wake(i);
  b.kinematic = kinematic;
  if (kinematic) {
    dBodySetKinematic(b.body);
  } else {
    dBodySetDynamic(b.body);
  }
}

void RigidWorld::set_kinematic_state(int i, const BodyPose& pose, const Vec3& v, const Vec3& w) {
  if (bodies_[i].sleeping) wake(i);
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

bool RigidWorld::can_ride(int i) const {
  const Body& b = bodies_[i];
  return b.rides || (b.enabled && !b.kinematic && !b.jointed && !b.sleeping);
}

void RigidWorld::ride(const std::vector<uint8_t>& by_body) {
  if (!by_body.empty() && by_body.size() != bodies_.size())
    throw std::invalid_argument("RigidWorld::ride: " + std::to_string(by_body.size()) + " entries for " +
                                std::to_string(bodies_.size()) + " bodies");
  for (int i = 0; i < body_count(); ++i) {
    Body& b = bodies_[i];
    const bool rides = !by_body.empty() && by_body[i] && can_ride(i);
    if (rides == b.rides) continue;
    b.rides = rides;
    if (rides) {
      dBodySetKinematic(b.body);
    } else {
      dBodySetDynamic(b.body);
    }
  }
  rider_touching_.clear();
  rider_touching_kinematic_.clear();
  riders_in_contact_.clear();
  ride_start_touching_.clear();
  if (by_body.empty()) return;
  for (const auto& [a, b] : touching_) {
    ride_start_touching_.emplace_back(std::min(a, b), std::max(a, b));
    if (bodies_[a].rides && bodies_[b].rides) rider_touching_.emplace_back(a, b);
  }
  std::sort(ride_start_touching_.begin(), ride_start_touching_.end());
  for (const auto& [a, k] : touching_kinematic_)
    if (bodies_[a].rides) rider_touching_kinematic_.emplace_back(a, k);
  for (int i = 0; i < body_count(); ++i)
    if (bodies_[i].rides && bodies_[i].in_contact) riders_in_contact_.push_back(i);
}

RigidWorld::Motion RigidWorld::motion(int i) const {
  Motion m;
  const dBodyID b = bodies_[i].body;
  std::copy_n(dBodyGetPosition(b), 3, m.position);
  std::copy_n(dBodyGetQuaternion(b), 4, m.orientation);
  m.velocity = velocity(i);
  m.angular_velocity = angular_velocity(i);
  return m;
}

void RigidWorld::set_motion(int i, const Motion& m) {
  const dBodyID b = bodies_[i].body;
  dBodySetPosition(b, m.position[0], m.position[1], m.position[2]);
  dBodySetQuaternion(b, m.orientation);
  dBodySetLinearVel(b, m.velocity.x, m.velocity.y, m.velocity.z);
  dBodySetAngularVel(b, m.angular_velocity.x, m.angular_velocity.y, m.angular_velocity.z);
}

void RigidWorld::integrate(double h, bool move_kinematic) {
  // Sleeping bodies are enabled while the accumulators add their forces, so
  // that a change of those forces can wake them (wake_on_force_change).
  for (Body& b : bodies_)
    if (b.sleeping) dBodyEnable(b.body);
  for (ForceAccumulator* a : accumulators_) a->add_forces();
  for (Body& b : bodies_) b.in_contact = false, b.contacts = 0, b.touches_kinematic = false;
  touching_ = rider_touching_;  // riders are not collided with each other (ride)
  touching_kinematic_ = rider_touching_kinematic_;
  for (int i : riders_in_contact_) bodies_[i].in_contact = true;
  if (sleep_.time > 0.0) wake_on_force_change();
  // ODE's random numbers (dWorldQuickStep reorders constraints randomly) come
  // from one seed per process: each world keeps its own sequence, so a run
  // does not depend on the worlds stepped before it in the same process (a
  // Python session, a sweep worker) and matches a fresh `odemag run`.
  const unsigned long process_seed = dRandGetSeed();
  dRandSetSeed(random_seed_);
  dSpaceCollide(space_, this, &RigidWorld::near_callback);
  if (!leaving_ride_.empty()) stop_riding_where_hit();
  create_contact_joints();
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
  std::vector<std::pair<int, Motion>> kinematic_motions;  // put back after the step
  if (!move_kinematic)
    for (int i = 0; i < body_count(); ++i)
      if (bodies_[i].kinematic) kinematic_motions.emplace_back(i, motion(i));
  if (exact_solver_) {
    exact_step_->step(ode_bodies_, h);  // QuickStep where ODE's exact solver fails
  } else {
    dWorldQuickStep(world_, h);
  }
  for (const auto& [i, m] : kinematic_motions) set_motion(i, m);
  dJointGroupEmpty(contacts_);
  if (sleep_.time > 0.0) update_sleep(h);
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

void RigidWorld::stop_riding_where_hit() {
  std::vector<int> leaving;
  leaving.swap(leaving_ride_);
  for (size_t k = 0; k < leaving.size(); ++k) {
    Body& b = bodies_[leaving[k]];
    b.rides = false;
    b.recollide_rank = static_cast<int>(k);
    b.leaves_ride = false;
    dBodySetDynamic(b.body);  // with its path velocity
    for (ForceAccumulator* a : accumulators_) a->add_forces_to(b.body);
  }
  // Their pairs with riders came from before the riding (ride) and are
  // collided again below.
  auto left = [this](int i) { return bodies_[i].recollide_rank >= 0; };
  auto from_ride = [&](const std::pair<int, int>& p) {
    return (left(p.first) || left(p.second)) && (left(p.first) || bodies_[p.first].rides) &&
           (left(p.second) || bodies_[p.second].rides);
  };
  std::erase_if(touching_, from_ride);
  std::erase_if(rider_touching_, from_ride);
  std::erase_if(touching_kinematic_, [&](const auto& p) { return left(p.first); });
  std::erase_if(rider_touching_kinematic_, [&](const auto& p) { return left(p.first); });
  std::erase_if(riders_in_contact_, left);
  // The pass above collided them with dynamic bodies only.
  for (int i : leaving) {
    recollided_ = i;
    dSpaceCollide2(bodies_[i].geom, reinterpret_cast<dGeomID>(space_), this, &RigidWorld::near_callback);
    for (dGeomID w : bodies_[i].windings)
      dSpaceCollide2(w, reinterpret_cast<dGeomID>(space_), this, &RigidWorld::near_callback);
  }
  recollided_ = -1;
  for (int i : leaving) bodies_[i].recollide_rank = -1;
}

void RigidWorld::near_callback(void* data, dGeomID a, dGeomID b) {
  auto* self = static_cast<RigidWorld*>(data);
  dBodyID ba = dGeomGetBody(a), bb = dGeomGetBody(b);
  if (self->recollided_ >= 0) {
    // A rider that stopped riding in this pass (stop_riding_where_hit) against
    // what the pass skipped: the ground and static geoms, kinematic bodies,
    // riders, and those that stopped riding after it.
    const Body& own = self->bodies_[self->recollided_];
    if (a == b) return;
    const dBodyID other = dGeomGetBody(a) == own.body ? bb : ba;
    if (other == own.body) return;
    if (other && !dBodyIsKinematic(other)) {
      const int rank = self->bodies_[self->index_of(other)].recollide_rank;
      if (rank < 0 || rank < own.recollide_rank) return;
    }
  }
  // Nothing to resolve between immovable things (kinematic in ODE: riders too).
  if (!(ba && !dBodyIsKinematic(ba)) && !(bb && !dBodyIsKinematic(bb))) return;
  // Dynamic bodies of the scene (a rider is one): for touching().
  const bool a_moves = ba && (!dBodyIsKinematic(ba) || self->bodies_[self->index_of(ba)].rides);
  const bool b_moves = bb && (!dBodyIsKinematic(bb) || self->bodies_[self->index_of(bb)].rides);
  // Jointed bodies do not collide with each other (a needle on its pivot).
  if (self->has_joints_ && ba && bb && dAreConnectedExcluding(ba, bb, dJointTypeContact)) return;
  dContact contact[kMaxContacts];
  const int n = dCollide(a, b, kMaxContacts, &contact[0].geom, sizeof(dContact));
  if (n == 0) return;
  // A rider that a dynamic body runs into, having not touched it at the
  // step's start, rides no more from this substep on: as a sleeping body
  // would (create_contact_joints), it would stop the other like a wall.
  if (self->recollided_ < 0 && a_moves && b_moves && dBodyIsKinematic(ba) != dBodyIsKinematic(bb)) {
    const int rider = self->index_of(dBodyIsKinematic(ba) ? ba : bb);
    const int other = self->index_of(dBodyIsKinematic(ba) ? bb : ba);
    const std::pair<int, int> pair{std::min(rider, other), std::max(rider, other)};
    Body& r = self->bodies_[rider];
    if (!self->bodies_[other].sleeping && !r.leaves_ride &&
        !std::binary_search(self->ride_start_touching_.begin(), self->ride_start_touching_.end(), pair)) {
      r.leaves_ride = true;
      self->leaving_ride_.push_back(rider);
    }
  }
  for (dBodyID body : {ba, bb})
    if (body) {
      Body& touched = self->bodies_[self->index_of(body)];
      touched.in_contact = true;
      touched.contacts += n;
    }
  if (a_moves && b_moves) {
    self->touching_.emplace_back(self->index_of(ba), self->index_of(bb));
  } else if (ba && bb) {  // one of them kinematic: it may move, so the other is awake
    const int moving = self->index_of(a_moves ? ba : bb);
    self->touching_kinematic_.emplace_back(moving, self->index_of(a_moves ? bb : ba));
    self->bodies_[moving].touches_kinematic = true;
    if (self->bodies_[moving].sleeping) self->wake(moving);
  }
  const double skins = self->skin_of(a) + self->skin_of(b);
  for (int i = 0; i < n; ++i) {
    contact[i].geom.depth = std::max(0.0, contact[i].geom.depth - skins);
    contact[i].surface = self->surface_;
    self->found_.push_back({contact[i], ba, bb});
  }
}

void RigidWorld::create_contact_joints() {
  if (sleep_.time > 0.0) {
    // A sleeping body that touches nothing any more wakes (it would hang in
    // the air), and one that a faster body runs into wakes before the step,
    // so that the impact moves it (asleep it would stop the other like a wall).
    for (int i = 0; i < body_count(); ++i)
      if (bodies_[i].sleeping && !bodies_[i].in_contact) wake(i);
    for (const auto& [a, b] : touching_) {
      if (bodies_[a].sleeping != bodies_[b].sleeping && speed(bodies_[a].sleeping ? b : a) > sleep_.speed)
        wake(bodies_[a].sleeping ? a : b);
    }
  }
  // A sleeping body is a fixed support for the bodies awake around it.
  auto sleeps = [this](dBodyID b) { return b && bodies_[index_of(b)].sleeping; };
  // Neither of two such bodies moves in this step (a rider only along its path: ride).
  auto fixed = [this](dBodyID b, bool asleep) { return asleep || !b || bodies_[index_of(b)].rides; };
  // Zero for the ground and static geoms (no body).
  auto omega = [this](dBodyID b) {
    return b ? angular_velocity(index_of(b)) : Vec3{0.0, 0.0, 0.0};
  };
  for (const FoundContact& f : found_) {
    const bool a_sleeps = sleeps(f.a), b_sleeps = sleeps(f.b);
    if (fixed(f.a, a_sleeps) && fixed(f.b, b_sleeps)) continue;
    const dContact* contact = &f.contact;
    dContact aligned;
    if (rolling_axis_aligned_) {
      aligned = f.contact;
      align_rolling_row(aligned, omega(f.a) - omega(f.b));
      contact = &aligned;
    }
    dJointID j = dJointCreateContact(world_, contacts_, contact);
    dJointAttach(j, a_sleeps ? nullptr : f.a, b_sleeps ? nullptr : f.b);
  }
  found_.clear();
}

double RigidWorld::speed(int i) const {
  const Body& b = bodies_[i];
  const dReal* v = dBodyGetLinearVel(b.body);
  const dReal* w = dBodyGetAngularVel(b.body);
  return norm(Vec3{v[0], v[1], v[2]}) + norm(Vec3{w[0], w[1], w[2]}) * b.radius;
}

int RigidWorld::sleeping_count() const {
  return static_cast<int>(std::count_if(bodies_.begin(), bodies_.end(), [](const Body& b) { return b.sleeping; }));
}

void RigidWorld::wake(int i) {
  Body& b = bodies_[i];
  b.sleeping = false;
  b.idle = 0.0;
  dBodyEnable(b.body);
}

void RigidWorld::wake_on_force_change() {
  for (int i = 0; i < body_count(); ++i) {
    Body& b = bodies_[i];
    const dReal* f = dBodyGetForce(b.body);
    const dReal* t = dBodyGetTorque(b.body);
    b.force = {f[0], f[1], f[2]};
    b.torque = {t[0], t[1], t[2]};
    if (!b.sleeping) continue;
    // The scale: the body's weight, and its weight's torque at its radius.
    const double allowed = sleep_.wake_force * b.mass * gravity_;
    if (norm(b.force - b.rest_force) > allowed || norm(b.torque - b.rest_torque) > allowed * b.radius) {
      wake(i);
    } else {
      dBodySetForce(b.body, 0, 0, 0);
      dBodySetTorque(b.body, 0, 0, 0);
      dBodyDisable(b.body);
    }
  }
}

void RigidWorld::update_sleep(double h) {
  const int n = body_count();
  std::vector<double> speeds(n, 0.0);
  for (int i = 0; i < n; ++i) {
    Body& b = bodies_[i];
    if (b.sleeping || b.rides) continue;
    speeds[i] = speed(i);
    const bool candidate = b.enabled && !b.kinematic && !b.jointed && b.in_contact && !b.touches_kinematic;
    b.idle = candidate && speeds[i] <= sleep_.speed ? b.idle + h : 0.0;
  }
  // A sleeping body wakes when a body touching it moves faster than the
  // sleep speed; a body falls asleep only among slow neighbours.
  std::vector<char> fast_neighbour(n, 0);
  for (const auto& [a, b] : touching_) {
    if (speeds[b] > sleep_.speed) fast_neighbour[a] = 1;
    if (speeds[a] > sleep_.speed) fast_neighbour[b] = 1;
  }
  for (int i = 0; i < n; ++i) {
    Body& b = bodies_[i];
    if (b.sleeping) {
      if (fast_neighbour[i]) wake(i);
      continue;
    }
    if (b.rides || b.idle < sleep_.time || fast_neighbour[i]) continue;
    b.sleeping = true;
    b.rest_force = b.force;
    b.rest_torque = b.torque;
    dBodySetLinearVel(b.body, 0, 0, 0);
    dBodySetAngularVel(b.body, 0, 0, 0);
    dBodyDisable(b.body);
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
