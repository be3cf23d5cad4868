#include "engine/ode/magnetic_forces.h"

#include <stdexcept>
#include <utility>

namespace odemag {

BodyPose ode_pose(dBodyID body) {
  BodyPose pose;
  const dReal* p = dBodyGetPosition(body);
  const dReal* R = dBodyGetRotation(body);  // 3 x 4, row-major
  pose.position = {p[0], p[1], p[2]};
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) pose.rotation.m[i][j] = R[4 * i + j];
  return pose;
}

MagneticForces::MagneticForces(const RelaxOptions& options, std::unique_ptr<MagneticBackend> backend,
                               uint64_t seed, IntraBodyTensor intra_tensor)
    : model_(intra_tensor), backend_(backend ? std::move(backend) : make_cpu_backend()), options_(options) {
  state_ = make_state(model_, seed);
}

MagneticForces::MagneticForces(MagneticModel model, MagneticState state, const RelaxOptions& options,
                               std::unique_ptr<MagneticBackend> backend)
    : model_(std::move(model)),
      state_(std::move(state)),
      bodies_(static_cast<size_t>(model_.body_count()), nullptr),
      backend_(backend ? std::move(backend) : make_cpu_backend()),
      options_(options) {}

int MagneticForces::body_index(int index, const char* call) const {
  if (index < 0 || index >= model_.body_count())
    throw std::out_of_range(std::string("MagneticForces::") + call + ": no magnetic body " + std::to_string(index) +
                            " (" + std::to_string(model_.body_count()) + " attached)");
  return index;
}

void MagneticForces::bind(int index, dBodyID body) {
  bodies_[body_index(index, "bind")] = body;
  if (body) state_.pose[index] = ode_pose(body);
}

int MagneticForces::attach(dBodyID body, const Shape& shape, const Material& material,
                           double cell_size, const std::string& name) {
  const int index = model_.add_body(name.empty() ? "body" + std::to_string(model_.body_count()) : name,
                                    shape, material, cell_size);
  extend_state(model_, state_);
  bodies_.push_back(body);
  if (body) state_.pose[index] = ode_pose(body);
  return index;
}

void MagneticForces::read_poses() {
  for (int b = 0; b < model_.body_count(); ++b)
    if (bodies_[b]) state_.pose[b] = ode_pose(bodies_[b]);
}

const RelaxReport& MagneticForces::compute() {
  read_poses();
  report_ = magnetic_step(model_, state_, options_, *backend_);
  return report_;
}

void MagneticForces::recompute_forces() {
  read_poses();
  magnetic_forces_at_held_magnetization(model_, state_, options_, *backend_);
}

const RelaxReport& MagneticForces::apply() {
  compute();
  add_forces();
  return report_;
}

void MagneticForces::add_forces() {
  for (int b = 0; b < model_.body_count(); ++b) {
    dBodyID body = bodies_[b];
    if (!body || !state_.active[b] || model_.body(b).inert() || dBodyIsKinematic(body) ||
        !dBodyIsEnabled(body))
      continue;
    const Vec3& f = state_.force[b];
    const Vec3& t = state_.torque[b];
    dBodyAddForce(body, f.x, f.y, f.z);
    dBodyAddTorque(body, t.x, t.y, t.z);
  }
}

}  // namespace odemag
