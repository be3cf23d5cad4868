// The stability suite's scenes and measurements (docs/hard-cases.md),
// shared by tests/engine/stability_test.cpp, which asserts on them, and
// benchmarks/stability_report.cpp, which tabulates them: both run the same
// scenes.
#pragma once

#include <ode/ode.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <limits>
#include <stdexcept>
#include <string>
#include <variant>
#include <vector>

#include "odemag/simulation.h"
#include "odemag/constants.h"
#include "magnetics/kernels/kernels.h"
#include "magnetics/near_field/near_field.h"
#include "magnetics/relax/relax.h"
#include "tests/support/scene_builders.h"
#include "engine/simulation/rigid_world.h"

namespace odemag::stability {

// What one run of a case did. Energies in J, speeds in m/s, forces in N.
struct CaseResult {
  std::string name;
  int bodies = 0, cells = 0;
  double time_step = 0.0, duration = 0.0;
  long steps = 0;
  int max_substeps = 0;
  int max_substeps_wanted = 0;  // before the cap max_substeps (StepReport::substeps_wanted)
  long iterations = 0;          // outer relaxation iterations, all steps and substeps
  int max_step_iterations = 0;
  bool converged = true;  // every relaxation converged
  double max_speed = 0.0, max_angular_speed = 0.0;
  double max_force = 0.0, max_torque = 0.0;
  // Energy E = kinetic (translation + rotation) + gravity + magnetic (when
  // has_magnetic_energy) of the dynamic bodies; its largest rise above the
  // initial value, and its lowest value.
  bool has_magnetic_energy = false;
  double initial_energy = 0.0, max_energy_rise = 0.0, min_energy = 0.0;
  double initial_magnetic_energy = 0.0, max_magnetic_energy = 0.0;
  // Lowest potential energy V = gravity + magnetic over the run: E(0) - V_min
  // is the energy that motion can physically take up.
  double min_potential = 0.0;
  double max_kinetic = 0.0;  // of all dynamic bodies together
  // Lowest point of any dynamic body above the ground, in units of that
  // body's smallest half extent (a ball's radius), over the whole run:
  // -0.05 means a ball's centre was 5% of its radius below R (sunk into the floor).
  double min_ground_clearance = std::numeric_limits<double>::infinity();
  // Deepest interpenetration of two bodies (ODE's contact depth less the
  // collision skins) in units of the smaller one's smallest half extent, over
  // the run and at its end (scenes of at most kPenetrationBodies bodies).
  double max_penetration = 0.0, final_penetration = 0.0;
  double largest_magnetization_ratio = 0.0;  // max over soft cells of |M| / Ms
  bool finite = true;
  std::string non_finite;  // the guard's message when not finite
  double wall_seconds = 0.0;
  std::vector<Vec3> final_moments;    // per body, A m^2, world
  std::vector<Vec3> final_positions;  // per body, m
};

struct RunOptions {
  double duration = 0.5;        // simulated time, s
  bool magnetic_energy = true;  // track the magnetic energy (when consistent, see below)
};

using test_support::steel;  // tests/support/scene_builders.h

// NdFeB: remanence about 1.3 T, M_r = 1.0e6 A/m.
inline PermanentMaterial ndfeb(const Vec3& direction = {0, 0, 1}) {
  return PermanentMaterial{1.0e6 * normalized(direction), 0.0};
}

using test_support::body;

inline SceneDescription empty_scene(const std::string& name, double time_step = 0.004) {
  SceneDescription s;
  s.file = name;
  s.title = name;
  s.simulation.time_step = time_step;
  return s;
}

// Whether relaxed_free_energy below applies: every magnetic body is a fixed
// permanent magnet or soft (no recoil), no electromagnet, mutual induction on.
inline bool free_energy_available(const SceneDescription& s) {
  if (!s.solver.relax.mutual_induction) return false;
  for (const BodyDescription& d : s.bodies) {
    const Material& m = s.materials.at(d.material);
    if (const auto* soft = std::get_if<SoftMaterial>(&m); soft && norm(soft->coil_field) > 0.0)
      return false;
    if (const auto* hard = std::get_if<PermanentMaterial>(&m);
        hard && hard->recoil_susceptibility > 0.0)
      return false;
  }
  return true;
}

// The magnetic free energy (J) that the relaxation minimises, so that the
// magnetic forces are minus its gradient: with the intra-body tensors the
// relaxation uses (odemag::magnetic_energy takes point dipoles inside a
// body, which is another energy for lattice soft bodies):
//   U = sum over fixed permanent cells a of -mu0 mu_a . H_E
//     + sum over pairs of fixed permanent cells of different bodies of the pair energy
//     + sum over soft cells c of mu0 V (-M_c . H_fixed,c - M_c . H_soft,c / 2 + Ms g_c),
// H_fixed: H_E and the fixed magnets at c (backend fixed_field); H_soft: the
// other soft cells (responsive_field); g_c: the cell's self and anisotropy
// free energy (cell_free_energy at H_A = 0). The constant pair energies
// inside a permanent body are left out. Needs free_energy_available and a
// backend that last saw the current poses (right after a magnetic step).
inline double relaxed_free_energy(MagneticForces& magnetics) {
  const MagneticModel& model = magnetics.model();
  const MagneticState& state = magnetics.state();
  std::vector<Vec3> H_fixed(model.cell_count()), H_soft(model.cell_count());
  magnetics.backend().fixed_field(model, state, H_fixed);
  magnetics.backend().responsive_field(model, state, H_soft);
  std::vector<int> fixed;
  double u = 0.0;
  for (int b = 0; b < model.body_count(); ++b) {
    const MagneticBody& body = model.body(b);
    if (!state.active[b] || body.inert()) continue;
    const double V = body.cells.cell_volume;
    for (int i = 0; i < body.cell_count(); ++i) {
      const int c = body.first_cell + i;
      const Vec3& M = state.magnetization[c];
      if (body.kind == CellKind::fixed_permanent) {
        u -= kMu0 * V * dot(M, state.external_field);
        fixed.push_back(c);
      } else {
        u += kMu0 * V *
             (-dot(M, H_fixed[c]) - 0.5 * dot(M, H_soft[c]) +
              body.soft.Ms *
                  cell_free_energy(body.soft, Vec3{}, &state.moments[model.moment_offset(c)]));
      }
    }
  }
  // Near-field energy of the fixed magnets alone (their reflection in the
  // spheres' higher orders; the soft cells' share is in H_fixed and H_soft):
  // the state with every responsive magnetization zero. Approximate where a
  // sphere's contact saturates (its saturation factor then differs).
  {
    MagneticState fixed_only = state;
    for (int c = 0; c < model.cell_count(); ++c)
      if (model.body(model.cell_body(c)).responsive()) fixed_only.magnetization[c] = {};
    NearField near;
    near.build(model, fixed_only, magnetics.options().near_field, magnetics.options().mutual_induction);
    u += near.energy(model, fixed_only);
  }
  for (size_t i = 0; i < fixed.size(); ++i) {
    const int a = fixed[i], ba = model.cell_body(a);
    const MagneticBody& body_a = model.body(ba);
    for (size_t j = i + 1; j < fixed.size(); ++j) {
      const int c = fixed[j], bc = model.cell_body(c);
      if (bc == ba) continue;
      const MagneticBody& body_c = model.body(bc);
      const double s = body_a.cells.contact_radius + body_c.cells.contact_radius;
      u += dipole_energy(state.cell_position[c] - state.cell_position[a],
                         body_a.cells.cell_volume * state.magnetization[a],
                         body_c.cells.cell_volume * state.magnetization[c], s * s);
    }
  }
  return u;
}

// Kinetic energy of translation and rotation of an ODE body, J.
inline double kinetic_energy(dBodyID body) {
  dMass m;
  dBodyGetMass(body, &m);
  const dReal* v = dBodyGetLinearVel(body);
  const dReal* w = dBodyGetAngularVel(body);
  const dReal* R = dBodyGetRotation(body);
  // Angular velocity in the body frame: R^T w.
  double wb[3];
  for (int j = 0; j < 3; ++j)
    wb[j] = R[0 * 4 + j] * w[0] + R[1 * 4 + j] * w[1] + R[2 * 4 + j] * w[2];
  double rot = 0.0;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) rot += wb[i] * m.I[4 * i + j] * wb[j];
  return 0.5 * m.mass * (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]) + 0.5 * rot;
}

// Height of a body's lowest point above the plane z = ground.
inline double lowest_point_clearance(const Shape& shape, const BodyPose& pose, double ground) {
  double reach = 0.0;  // how far the shape reaches below its centre
  if (const auto* s = std::get_if<Sphere>(&shape)) {
    reach = s->radius;
  } else if (const auto* b = std::get_if<Box>(&shape)) {
    for (int j = 0; j < 3; ++j) {
      const double half[3] = {b->size.x / 2, b->size.y / 2, b->size.z / 2};
      reach += std::abs(pose.rotation.m[2][j]) * half[j];
    }
  } else if (const auto* c = std::get_if<Cylinder>(&shape)) {
    const double az = std::abs(pose.rotation.m[2][2]);
    reach = c->radius * std::sqrt(std::max(0.0, 1.0 - az * az)) + 0.5 * c->length * az;
  }
  return pose.position.z - reach - ground;
}

// The energy that motion can take up: the potential energy fallen through,
// E(0) - V_min, and for bodies started inside each other the work of the
// contact solver that pushes them apart against the attraction of the
// overlap core, at most U_max - U(0) (it separates them slowly, at 0.1 m/s,
// so that work ends up as magnetic energy). The energy's rise above E(0)
// (numerical heating) is measured against it.
inline double available_energy(const CaseResult& r, bool started_overlapping) {
  double a = std::max(0.0, r.initial_energy - r.min_potential);
  if (started_overlapping) a += std::max(0.0, r.max_magnetic_energy - r.initial_magnetic_energy);
  return a;
}

// Bodies beyond which the pairwise penetration check is skipped (it is O(n^2)).
inline constexpr int kPenetrationBodies = 64;

// How much larger than its shape a body's collision geometry is (the
// collision skin of engine/simulation/rigid_world.cpp), read back from ODE.
inline double collision_skin(dGeomID g, const Shape& shape) {
  if (const auto* s = std::get_if<Sphere>(&shape)) return dGeomSphereGetRadius(g) - s->radius;
  if (const auto* b = std::get_if<Box>(&shape)) {
    dVector3 lengths;
    dGeomBoxGetLengths(g, lengths);
    return 0.5 * (lengths[0] - b->size.x);
  }
  if (const auto* c = std::get_if<Cylinder>(&shape)) {
    dReal radius, length;
    dGeomCylinderGetParams(g, &radius, &length);
    return radius - c->radius;
  }
  return 0.0;
}

// Deepest interpenetration of two enabled bodies, at least one of them
// dynamic, relative to the smaller one's smallest half extent.
inline double deepest_penetration(const Simulation& sim, const std::vector<double>& size) {
  const RigidWorld& world = sim.world();
  const int n = world.body_count();
  if (n > kPenetrationBodies) return 0.0;
  double worst = 0.0;
  dContactGeom contacts[8];
  for (int a = 0; a < n; ++a) {
    if (!world.enabled(a)) continue;
    const dGeomID ga = dBodyGetFirstGeom(world.body(a));
    for (int b = a + 1; b < n; ++b) {
      if (!world.enabled(b) || (world.kinematic(a) && world.kinematic(b))) continue;
      const dGeomID gb = dBodyGetFirstGeom(world.body(b));
      const int k = dCollide(ga, gb, 8, contacts, sizeof(dContactGeom));
      const double skins = collision_skin(ga, sim.scene().bodies[a].shape) +
                           collision_skin(gb, sim.scene().bodies[b].shape);
      for (int i = 0; i < k; ++i)
        worst = std::max(worst, (contacts[i].depth - skins) / std::min(size[a], size[b]));
    }
  }
  return worst;
}

// Samples a running simulation at every substep: registered as the last
// force accumulator, its update() runs after the magnetic relaxation of each
// substep, so poses, velocities, moments and forces belong together.
class Sampler : public ForceAccumulator {
 public:
  Sampler(Simulation& sim, CaseResult& r, bool magnetic_energy)
      : sim_(sim), r_(r), magnetic_energy_(magnetic_energy) {
    for (const BodyDescription& d : sim.scene().bodies) {
      const Vec3 half = shape_half_extents(d.shape);
      size_.push_back(std::min({half.x, half.y, half.z}));
    }
  }
  void update(double, double) override { sample(); }
  void add_forces() override {}

  void sample() {
    const RigidWorld& world = sim_.world();
    MagneticForces& magnetics = sim_.magnetics();
    const SceneDescription& scene = sim_.scene();
    double kinetic = 0.0, potential = 0.0;
    for (int b = 0; b < world.body_count(); ++b) {
      if (!sim_.finite_state(b)) {
        r_.finite = false;
        continue;
      }
      r_.max_force = std::max(r_.max_force, norm(magnetics.force(b)));
      r_.max_torque = std::max(r_.max_torque, norm(magnetics.torque(b)));
      if (world.kinematic(b) || !world.enabled(b)) continue;
      r_.max_speed = std::max(r_.max_speed, norm(world.velocity(b)));
      r_.max_angular_speed = std::max(r_.max_angular_speed, norm(world.angular_velocity(b)));
      if (scene.simulation.ground)
        r_.min_ground_clearance = std::min(
            r_.min_ground_clearance, lowest_point_clearance(scene.bodies[b].shape, world.pose(b),
                                                            scene.simulation.ground_height) /
                                         size_[b]);
      kinetic += kinetic_energy(world.body(b));
      potential -= world.mass(b) * dot(scene.gravity, world.pose(b).position);
    }
    const MagneticModel& model = magnetics.model();
    for (const MagneticBody& mb : model.bodies()) {
      if (mb.kind != CellKind::soft) continue;
      for (int i = 0; i < mb.cell_count(); ++i)
        r_.largest_magnetization_ratio =
            std::max(r_.largest_magnetization_ratio,
                     norm(magnetics.state().magnetization[mb.first_cell + i]) / mb.soft.Ms);
    }
    if (magnetic_energy_) {
      const double u = relaxed_free_energy(magnetics);
      if (first_) r_.initial_magnetic_energy = r_.max_magnetic_energy = u;
      r_.max_magnetic_energy = std::max(r_.max_magnetic_energy, u);
      potential += u;
    }
    r_.final_penetration = deepest_penetration(sim_, size_);
    r_.max_penetration = std::max(r_.max_penetration, r_.final_penetration);
    const double e = kinetic + potential;
    if (!std::isfinite(e)) r_.finite = false;
    r_.max_kinetic = std::max(r_.max_kinetic, kinetic);
    if (first_) {
      r_.initial_energy = r_.min_energy = e;
      r_.min_potential = potential;
      first_ = false;
    }
    r_.min_potential = std::min(r_.min_potential, potential);
    r_.min_energy = std::min(r_.min_energy, e);
    r_.max_energy_rise = std::max(r_.max_energy_rise, e - r_.initial_energy);
  }

 private:
  Simulation& sim_;
  CaseResult& r_;
  bool magnetic_energy_;
  bool first_ = true;
  std::vector<double> size_;
};

// Runs a scene for options.duration and measures it at every substep
// (Sampler). Stops at the first non-finite state.
inline CaseResult run_case(const std::string& name, const SceneDescription& scene,
                           const RunOptions& options) {
  CaseResult r;
  r.name = name;
  r.duration = options.duration;
  r.time_step = scene.simulation.time_step;
  r.has_magnetic_energy = options.magnetic_energy && free_energy_available(scene);
  const auto started = std::chrono::steady_clock::now();
  Simulation sim(scene);
  r.bodies = sim.world().body_count();
  r.cells = sim.magnetics().model().cell_count();
  Sampler sampler(sim, r, r.has_magnetic_energy);
  sim.world().add_accumulator(&sampler);
  while (sim.time() + 0.5 * scene.simulation.time_step < options.duration) {
    sim.step();
    const StepReport& rec = sim.records().back();
    r.max_substeps = std::max(r.max_substeps, rec.substeps);
    r.max_substeps_wanted = std::max(r.max_substeps_wanted, rec.substeps_wanted);
    r.iterations += rec.iterations;
    r.max_step_iterations = std::max(r.max_step_iterations, rec.iterations);
    r.converged = r.converged && rec.converged;
    r.non_finite = sim.non_finite_message();
    if (!r.non_finite.empty()) r.finite = false;
    if (!r.finite) break;
  }
  // The end state, relaxed at the final poses (a non-finite pose throws).
  if (r.finite) sim.magnetics().compute();
  sampler.sample();
  r.steps = sim.steps();
  for (int b = 0; b < sim.world().body_count(); ++b) {
    r.final_moments.push_back(sim.magnetics().moment(b));
    r.final_positions.push_back(sim.world().pose(b).position);
  }
  r.wall_seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
  return r;
}

// ---------------------------------------------------------------------------
// Scenes. Lengths in m; the default ball is steel, R = 5 mm.

// Two permanent magnets created at the same centre, moments at right angles:
// the cell pair sits at r = 0, inside the bounded core.
inline SceneDescription coincident_magnets() {
  SceneDescription s = empty_scene("coincident_magnets");
  s.materials["up"] = ndfeb({0, 0, 1});
  s.materials["side"] = ndfeb({1, 0, 0});
  s.bodies.push_back(body("magnet_a", Sphere{0.005}, "up", {0, 0, 0.02}));
  s.bodies.push_back(body("magnet_b", Sphere{0.005}, "side", {0, 0, 0.02}));
  return s;
}

// A permanent magnet and a steel ball at the same centre.
inline SceneDescription coincident_magnet_and_ball() {
  SceneDescription s = empty_scene("coincident_magnet_and_ball");
  s.materials["magnet"] = ndfeb();
  s.materials["steel"] = steel();
  s.bodies.push_back(body("magnet", Sphere{0.006}, "magnet", {0, 0, 0.02}));
  s.bodies.push_back(body("ball", Sphere{0.005}, "steel", {0, 0, 0.02}));
  return s;
}

// Two lattice magnets (8 cells each) at the same centre and orientation:
// every cell of one coincides with a cell of the other.
inline SceneDescription coincident_lattice_magnets() {
  SceneDescription s = empty_scene("coincident_lattice_magnets");
  s.materials["up"] = ndfeb({0, 0, 1});
  s.materials["tilted"] = ndfeb({1, 0, 1});
  s.cell_size = 0.005;
  s.bodies.push_back(body("magnet_a", Box{{0.01, 0.01, 0.01}}, "up", {0, 0, 0.02}));
  s.bodies.push_back(body("magnet_b", Box{{0.01, 0.01, 0.01}}, "tilted", {0, 0, 0.02}));
  // The substep rule wants up to 98 substeps while the cores push the cubes
  // apart; above the default cap of 64 its bounds do not hold, and in some
  // builds (ASan, AVX2 rounding) a cube was driven 0.33 mm into the floor
  // (6.6% of its half extent). The documented remedy: a higher cap.
  s.simulation.max_substeps = 128;
  return s;
}

// A steel ball started with its centre on the top face of a fixed lattice
// magnet (20 mm cube, 64 cells): half of the ball is inside the magnet.
inline SceneDescription ball_half_inside_magnet() {
  SceneDescription s = empty_scene("ball_half_inside_magnet");
  s.materials["magnet"] = ndfeb();
  s.materials["steel"] = steel();
  s.cell_size = 0.005;
  s.bodies.push_back(body("magnet", Box{{0.02, 0.02, 0.02}}, "magnet", {0, 0, 0.01}, true));
  s.bodies.push_back(body("ball", Sphere{0.005}, "steel", {0.003, 0.001, 0.02}));
  return s;
}

// Two free lattice magnets (10 mm cubes, 8 cells each) overlapping by half
// their width, like poles facing: the core repels them.
inline SceneDescription overlapping_magnets() {
  SceneDescription s = empty_scene("overlapping_magnets");
  s.materials["up"] = ndfeb({0, 0, 1});
  s.materials["down"] = ndfeb({0, 0, -1});
  s.cell_size = 0.005;
  s.bodies.push_back(body("magnet_a", Box{{0.01, 0.01, 0.01}}, "up", {0, 0, 0.02}));
  s.bodies.push_back(body("magnet_b", Box{{0.01, 0.01, 0.01}}, "down", {0.005, 0.001, 0.02}));
  // ODE's exact solver (dWorldStep, what "auto" picks for two bodies) fails
  // on the 8 redundant contacts of this deep overlap ("LCP internal error")
  // and adds energy, in whichever build meets the degenerate contact set;
  // QuickStep has no pivoting to fail (docs/hard-cases.md "Deep box-box
  // overlaps").
  s.simulation.contact_solver = ContactSolver::quick;
  return s;
}

// 10 ms steps with NdFeB: a fixed 20 mm cube magnet on the floor, four steel
// balls and a free 12 mm spherical magnet dropped around it; a steel ball
// on the floor above a magnet buried 2 mm under it (pulled into the floor
// at 95 times its weight).
inline SceneDescription strong_magnets(double time_step) {
  SceneDescription s = empty_scene("strong_magnets", time_step);
  s.materials["magnet"] = ndfeb();
  s.materials["steel"] = steel();
  s.cell_size = 0.005;
  s.bodies.push_back(body("magnet", Box{{0.02, 0.02, 0.02}}, "magnet", {0, 0, 0.01}, true));
  s.bodies.push_back(body("ball_1", Sphere{0.005}, "steel", {0.004, 0.002, 0.040}));
  s.bodies.push_back(body("ball_2", Sphere{0.005}, "steel", {0.022, 0.0, 0.030}));
  s.bodies.push_back(body("ball_3", Sphere{0.005}, "steel", {-0.02, 0.015, 0.006}));
  s.bodies.push_back(body("ball_4", Sphere{0.006}, "steel", {0.0, -0.03, 0.02}));
  s.bodies.push_back(body("free_magnet", Sphere{0.006}, "magnet", {-0.03, -0.02, 0.03}));
  s.bodies.push_back(body("buried", Sphere{0.008}, "magnet", {0.1, 0, -0.010}, true));
  s.bodies.push_back(body("ball_floor", Sphere{0.005}, "steel", {0.1, 0, 0.0051}));
  return s;
}

// A steel ball dropped onto a spherical magnet, everything scaled by
// `scale`: magnet R = 0.5 m and ball R = 0.3 m at scale 1 (1 m objects),
// 0.5 mm and 0.3 mm at 1e-3.
inline SceneDescription scaled_ball_onto_magnet(double scale) {
  SceneDescription s = empty_scene("scaled_ball_onto_magnet");
  s.materials["magnet"] = ndfeb();
  s.materials["steel"] = steel();
  const double Rm = 0.5 * scale, Rb = 0.3 * scale;
  s.bodies.push_back(body("magnet", Sphere{Rm}, "magnet", {0, 0, Rm}, true));
  s.bodies.push_back(body("ball", Sphere{Rb}, "steel", {0.2 * Rb, 0.1 * Rb, 2 * Rm + 2 * Rb}));
  return s;
}

// A soft (or permanent, tilted 0.5 rad from the field) ball alone in a
// uniform field H along z, without gravity.
inline SceneDescription ball_in_field(double H, bool permanent, double susceptibility = 5000.0,
                                      double cell_size = 0.0) {
  SceneDescription s = empty_scene(permanent ? "magnet_in_field" : "soft_ball_in_field");
  s.gravity = {0, 0, 0};
  s.simulation.ground = false;
  s.external_field = {0, 0, H};
  SoftMaterial iron;
  iron.saturation = 1.7e6;
  iron.susceptibility = susceptibility;
  s.materials["iron"] = iron;
  s.materials["magnet"] = ndfeb({std::sin(0.5), 0, std::cos(0.5)});
  BodyDescription b = body("ball", Sphere{0.005}, permanent ? "magnet" : "iron", {0, 0, 0});
  if (cell_size > 0.0) b.cell_size = cell_size;
  s.bodies.push_back(b);
  return s;
}

// A soft ball (one cell, or a lattice) of susceptibility chi dropped onto a
// fixed NdFeB magnet.
inline SceneDescription soft_ball_onto_magnet(double chi, double cell_size) {
  SceneDescription s = empty_scene("soft_ball_onto_magnet");
  SoftMaterial iron;
  iron.saturation = 1.7e6;
  iron.susceptibility = chi;
  s.materials["iron"] = iron;
  s.materials["magnet"] = ndfeb();
  s.bodies.push_back(body("magnet", Sphere{0.008}, "magnet", {0, 0, 0.008}, true));
  BodyDescription b = body("ball", Sphere{0.006}, "iron", {0.002, 0.001, 0.035});
  if (cell_size > 0.0) b.cell_size = cell_size;
  s.bodies.push_back(b);
  return s;
}

// The crane scene (paper Fig. 17) from its generator,
// demos/scenes/tools/make_crane.py, with `balls` steel balls. Throws when the
// generator fails.
inline SceneDescription crane_scene(int balls, const std::string& source_dir) {
  const std::filesystem::path out =
      std::filesystem::temp_directory_path() /
      ("odemag_crane_" + std::to_string(balls) + "_" + std::to_string(::getpid()) + ".json");
  const std::string command = "python3 '" + source_dir +
                              "/demos/scenes/tools/make_crane.py' --balls " +
                              std::to_string(balls) + " --out '" + out.string() + "' > /dev/null";
  if (std::system(command.c_str()) != 0) throw std::runtime_error("cannot run " + command);
  SceneDescription s = load_scene(out.string());
  std::filesystem::remove(out);
  return s;
}

}  // namespace odemag::stability
