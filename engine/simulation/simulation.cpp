#include "odemag/simulation.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <stdexcept>


#include "engine/simulation/magnetic_system.h"
#include "engine/simulation/outcomes.h"
#include "engine/simulation/rigid_world.h"
#include "engine/simulation/timeline.h"
#include "gpu/backend_choice.h"
#include "magnetics/model/model.h"
#include "magnetics/model/state.h"

namespace odemag {

namespace {

double elapsed_ms(std::chrono::steady_clock::time_point since) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - since).count();
}

}  // namespace

namespace {

class TimelineOnWorld : public TimelineTarget {
 public:
  TimelineOnWorld(RigidWorld& world, MagneticForces& magnetics) : world_(world), magnetics_(magnetics) {}
  void set_present(int body, bool present) override {
    world_.set_enabled(body, present);
    magnetics_.set_active(body, present);
  }
  double magnetization_scale(int body) const override { return magnetics_.magnetization_scale(body); }
  void set_magnetization_scale(int body, double scale) override { magnetics_.set_magnetization_scale(body, scale); }
  Vec3 external_field() const override { return magnetics_.external_field(); }
  void set_external_field(const Vec3& H) override { magnetics_.set_external_field(H); }
  void set_mutual_induction(bool enabled) override { magnetics_.options().mutual_induction = enabled; }
  void follow_track(int body, bool on_track, const BodyPose& pose, const Vec3& velocity,
                    const Vec3& angular_velocity) override {
    world_.set_kinematic(body, on_track);
    if (on_track) world_.set_kinematic_state(body, pose, velocity, angular_velocity);
  }

 private:
  RigidWorld& world_;
  MagneticForces& magnetics_;
};

}  // namespace

struct Simulation::Parts {
  Parts(const SceneDescription& scene, RigidWorld& world, MagneticForces& magnetics)
      : timeline(scene), target(world, magnetics), outcomes(scene) {}
  Timeline timeline;
  TimelineOnWorld target;
  OutcomeRecorder outcomes;
  std::vector<std::vector<RefinedZone>> contact_zones;  // by body
  std::vector<uint8_t> contact_zones_failed;            // by body: its notice was given
  std::vector<std::string> notices;
};

Simulation::Simulation(const SceneDescription& scene)
    : Simulation(scene, make_backend(scene.solver.backend, scene.solver.threads, nullptr, cpu_only_feature(scene))) {}

Simulation::Simulation(const SceneDescription& scene, std::unique_ptr<MagneticBackend> backend) : scene_(scene) {
  world_ = std::make_unique<RigidWorld>(scene_);
  // The magnetic model of the scene, built as for solve and field
  // (build_magnetic_system), then tied to the ODE bodies.
  MagneticSystem ms = build_magnetic_system(scene_);
  std::vector<std::vector<RefinedZone>> contact_zones = std::move(ms.contact_zones);
  magnetics_ = std::make_unique<MagneticForces>(
      std::move(ms.model), std::move(ms.state), scene_.solver.relax,
      backend ? std::move(backend) : make_cpu_backend(scene_.solver.threads));
  for (size_t b = 0; b < scene_.bodies.size(); ++b) magnetics_->bind(static_cast<int>(b), world_->body(static_cast<int>(b)));
  world_->add_accumulator(magnetics_.get());
  StepperSettings settings;
  settings.substeps = {scene_.simulation.max_substeps, scene_.simulation.stiffness_limit};
  settings.magnetic_solve = scene_.simulation.magnetic_solve;
  stepper_ = std::make_unique<MagneticStepper>(*magnetics_, world_->world(), *world_, settings);
  // Events at t = 0 hold already in the state at t = 0 (frame 0, the first
  // state line), as in `odemag solve`; the first step() applies them again,
  // which changes nothing.
  parts_ = std::make_unique<Parts>(scene_, *world_, *magnetics_);
  parts_->contact_zones = std::move(contact_zones);
  parts_->contact_zones_failed.assign(scene_.bodies.size(), 0);
  parts_->notices = scene_notices(scene_);
  parts_->timeline.apply(0.0, scene_.simulation.time_step, parts_->target);
}

Simulation::~Simulation() = default;

void Simulation::step() {
  if (stepper_->non_finite_body() >= 0) throw std::runtime_error(non_finite_message());
  const auto started = std::chrono::steady_clock::now();
  const double dt = scene_.simulation.time_step;
  parts_->timeline.apply(time(), dt, parts_->target);
  stepper_->begin_step(dt);
  if (steps() == 0) parts_->outcomes.sample(scene_, time(), dt, *world_, *magnetics_);  // t = 0, relaxed
  records_.push_back(stepper_->finish_step());
  parts_->outcomes.sample(scene_, time(), dt, *world_, *magnetics_);
  if (scene_.solver.contact_refinement) follow_contact_zones(records_.back());
  records_.back().wall_ms = elapsed_ms(started);
}

void Simulation::follow_contact_zones(StepReport& record) {
  const auto t0 = std::chrono::steady_clock::now();
  // The poses at the step's end (the magnetic state holds the last substep's).
  std::vector<BodyPose> poses(scene_.bodies.size());
  for (size_t b = 0; b < poses.size(); ++b) poses[b] = world_->pose(static_cast<int>(b));
  const std::vector<uint8_t>& active = magnetics_->state().active;
  for (size_t b = 0; b < scene_.bodies.size(); ++b) {
    if (parts_->contact_zones_failed[b] || !active[b]) continue;
    // The zones the scene would place at these poses (scene_contact_zones).
    std::vector<RefinedZone> zones = contact_zones(scene_, poses, active, static_cast<int>(b));
    const double h = scene_.body_cell_size(static_cast<int>(b));
    bool covered = true;
    for (const RefinedZone& wanted : zones) {
      bool near_zone = false;
      for (const RefinedZone& zone : parts_->contact_zones[b])
        near_zone = near_zone || norm(wanted.point - zone.point) <= kContactZoneFollowDistance * h;
      covered = covered && near_zone;
    }
    if (covered) continue;
    try {
      magnetics_->refine_body(static_cast<int>(b), zones);
      parts_->contact_zones[b] = std::move(zones);
      ++record.rezoned;
    } catch (const std::invalid_argument& e) {  // more than kMaxRefinedCells cells
      parts_->contact_zones_failed[b] = 1;
      char t[32];
      std::snprintf(t, sizeof t, "%.4f", time());
      parts_->notices.push_back(scene_.file + ": body '" + scene_.bodies[b].name + "' (bodies[" +
                         std::to_string(b) + "]): at t = " + t +
                         " s its refined contact zones could not follow its contacts (" + e.what() +
                         "), so its force there has the plain lattice's error");
    }
  }
  if (record.rezoned > 0) record.magnetic_ms += elapsed_ms(t0);
}

void Simulation::advance_to(double t) {
  const double dt = scene_.simulation.time_step;
  while (time() + 0.5 * dt < t) step();
}

void Simulation::finish() { parts_->outcomes.finish(scene_, *world_, *magnetics_); }

const std::map<std::string, double>& Simulation::outcomes() const { return parts_->outcomes.values(); }

const std::vector<std::string>& Simulation::notices() const { return parts_->notices; }

BodyPose Simulation::pose(int body) const { return world_->pose(body); }
Vec3 Simulation::velocity(int body) const { return world_->velocity(body); }
Vec3 Simulation::angular_velocity(int body) const { return world_->angular_velocity(body); }

bool Simulation::finite_state(int b) const {
  const BodyPose p = world_->pose(b);
  return is_finite(p.position) && is_finite(world_->velocity(b)) &&
         is_finite(world_->angular_velocity(b)) && is_finite(magnetics_->force(b)) &&
         is_finite(magnetics_->torque(b)) && is_finite(magnetics_->moment(b));
}

std::string Simulation::non_finite_message() const {
  int body = stepper_->non_finite_body();
  long step = stepper_->non_finite_step();
  double t = stepper_->non_finite_time();
  for (int b = 0; body < 0 && b < world_->body_count(); ++b)
    if (!finite_state(b)) body = b, step = steps(), t = time();
  if (body < 0) return {};
  return scene_.file + ": body '" + scene_.bodies[body].name + "' has a non-finite state at step " +
         std::to_string(step) + " (t = " + std::to_string(t) + " s); stopped";
}

}  // namespace odemag
