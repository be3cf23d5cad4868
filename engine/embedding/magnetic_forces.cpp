#include "odemag/magnetic_forces.h"

#include "engine/embedding/saved_state.h"
#include "magnetics/model/backend.h"
#include "magnetics/model/model.h"
#include "magnetics/model/state.h"
#include "magnetics/relax/relax.h"
#include "odemag/constants.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <sstream>
#include <stdexcept>
#include <utility>

namespace odemag {

namespace {

bool finite(const Mat3& m) {
  for (int i = 0; i < 3; ++i)
    if (!is_finite(Vec3{m.m[i][0], m.m[i][1], m.m[i][2]})) return false;
  return true;
}

std::string format(const Vec3& v) {
  std::ostringstream s;
  s << "(" << v.x << ", " << v.y << ", " << v.z << ")";
  return s.str();
}

std::string format(const Mat3& m) {
  std::ostringstream s;
  s << "[";
  for (int i = 0; i < 3; ++i) s << (i ? ", " : "") << format(Vec3{m.m[i][0], m.m[i][1], m.m[i][2]});
  s << "]";
  return s.str();
}

// Why a rotation is not one (docs/embedding.md "Checks"): R^T R = I within
// ranges::kRotationTolerance in every entry and det R > 0; "" when it is.
std::string rotation_error(const Mat3& R) {
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) {
      double dot_ij = 0.0;
      for (int k = 0; k < 3; ++k) dot_ij += R.m[k][i] * R.m[k][j];
      if (std::abs(dot_ij - (i == j ? 1.0 : 0.0)) > ranges::kRotationTolerance) {
        std::ostringstream why;
        why << "is not orthonormal (entry (" << i << ", " << j << ") of R^T R is " << dot_ij << ", not within "
            << ranges::kRotationTolerance << " of " << (i == j ? 1 : 0) << ")";
        return why.str();
      }
    }
  const double det = R.m[0][0] * (R.m[1][1] * R.m[2][2] - R.m[1][2] * R.m[2][1]) -
                     R.m[0][1] * (R.m[1][0] * R.m[2][2] - R.m[1][2] * R.m[2][0]) +
                     R.m[0][2] * (R.m[1][0] * R.m[2][1] - R.m[1][1] * R.m[2][0]);
  if (!(det > 0.0)) return "is a reflection (det R = " + std::to_string(det) + "), not a rotation";
  return "";
}

std::string format_number(double x) {
  std::ostringstream s;
  s << x;
  return s.str();
}

}  // namespace

SavedMagneticState::SavedMagneticState() : data_(std::make_unique<Data>()) {}
SavedMagneticState::~SavedMagneticState() = default;
SavedMagneticState::SavedMagneticState(const SavedMagneticState& other)
    : data_(std::make_unique<Data>(*other.data_)) {}
SavedMagneticState& SavedMagneticState::operator=(const SavedMagneticState& other) {
  if (this != &other) *data_ = *other.data_;
  return *this;
}
SavedMagneticState::SavedMagneticState(SavedMagneticState&& other) noexcept
    : data_(std::exchange(other.data_, std::make_unique<Data>())) {}
SavedMagneticState& SavedMagneticState::operator=(SavedMagneticState&& other) noexcept {
  std::swap(data_, other.data_);
  return *this;
}
const RelaxReport& SavedMagneticState::report() const { return data_->report; }

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
    : model_(std::make_unique<MagneticModel>(intra_tensor)),
      state_(std::make_unique<MagneticState>()),
      backend_(backend ? std::move(backend) : make_cpu_backend()),
      options_(options) {
  *state_ = make_state(*model_, seed);
}

MagneticForces::MagneticForces(const RelaxOptions& options, int threads, uint64_t seed,
                               IntraBodyTensor intra_tensor)
    : MagneticForces(options, make_cpu_backend(threads), seed, intra_tensor) {}

MagneticForces::MagneticForces(MagneticModel model, MagneticState state,
                               const RelaxOptions& options,
                               std::unique_ptr<MagneticBackend> backend)
    : model_(std::make_unique<MagneticModel>(std::move(model))),
      state_(std::make_unique<MagneticState>(std::move(state))),
      bodies_(static_cast<size_t>(model_->body_count()), nullptr),
      backend_(backend ? std::move(backend) : make_cpu_backend()),
      options_(options),
      reference_force_(bodies_.size()),
      reference_torque_(bodies_.size()),
      reference_known_(bodies_.size(), 0),
      refinements_(bodies_.size(), 0) {}

MagneticForces::~MagneticForces() = default;

Vec3 MagneticForces::external_field() const { return state_->external_field; }
void MagneticForces::set_active(int index, bool active) {
  state_->active[body_index(index, "set_active")] = active ? 1 : 0;
}
bool MagneticForces::active(int index) const { return state_->active[body_index(index, "active")] != 0; }
double MagneticForces::magnetization_scale(int index) const {
  return state_->magnetization_scale[body_index(index, "magnetization_scale")];
}
int MagneticForces::body_count() const { return model_->body_count(); }
Vec3 MagneticForces::force(int index) const { return state_->force[body_index(index, "force")]; }
Vec3 MagneticForces::torque(int index) const { return state_->torque[body_index(index, "torque")]; }

void MagneticForces::field_at_points(const std::vector<Vec3>& points, std::vector<Vec3>& B,
                                     std::vector<Vec3>& H) {
  for (size_t p = 0; p < points.size(); ++p) {
    if (!is_finite(points[p]))
      throw std::invalid_argument("MagneticForces::field_at_points: point " + std::to_string(p) + " " +
                                  format(points[p]) + " is not finite");
    if (norm(points[p]) > ranges::kLength.max)
      throw std::invalid_argument("MagneticForces::field_at_points: point " + std::to_string(p) + " " +
                                  format(points[p]) + " is farther than " + format_number(ranges::kLength.max) +
                                  " m from the origin");
  }
  odemag::field_at_points(*model_, *state_, *backend_, points, B, H);
}

int MagneticForces::body_index(int index, const char* call) const {
  if (index < 0 || index >= model_->body_count())
    throw std::out_of_range(std::string("MagneticForces::") + call + ": no magnetic body " + std::to_string(index) +
                            " (" + std::to_string(model_->body_count()) + " attached)");
  return index;
}

void MagneticForces::bind(int index, dBodyID body) {
  bodies_[body_index(index, "bind")] = body;
  reference_known_[index] = 0;
  if (body) state_->pose[index] = ode_pose(body);
}

void MagneticForces::refine_body(int index, const std::vector<RefinedZone>& zones) {
  const MagneticBody old_body = model_->refine_body(body_index(index, "refine_body"), zones);
  transfer_refined_state(*model_, index, old_body, *state_);
  ++refinements_[index];
}

int MagneticForces::attach(dBodyID body, const Shape& shape, const Material& material,
                           double cell_size, const std::string& name) {
  const int next = model_->body_count();
  const std::string body_name = name.empty() ? "body" + std::to_string(next) : name;
  const std::string where = "MagneticForces::attach: body " + std::to_string(next) + " \"" + body_name + "\": ";
  // A mesh or compound is given in the body frame, whose origin ODE puts at
  // the centre of mass (docs/embedding.md "Meshes").
  if (std::holds_alternative<Mesh>(shape) || std::holds_alternative<Compound>(shape)) {
    if (std::string e = validate_shape(shape); !e.empty()) throw std::invalid_argument(where + e);
    const double size = norm(shape_half_extents(shape));
    Vec3 c;
    if (const Mesh* m = std::get_if<Mesh>(&shape)) mesh_centred(*m, &c);
    else compound_centred(std::get<Compound>(shape), &c);
    if (norm(c) > 1e-6 * size) {
      char text[160];
      std::snprintf(text, sizeof text, "(%.6g, %.6g, %.6g) m", c.x, c.y, c.z);
      throw std::invalid_argument(where + "the " + shape_kind(shape) + "'s centre of mass is at " + text +
                                  ", not at the body's origin: pass mesh_centred(mesh) (compound_centred) and put "
                                  "the ODE body at the centre of mass");
    }
  }
  int index = -1;
  try {
    index = model_->add_body(body_name, shape, material, cell_size);
  } catch (const std::invalid_argument& e) {
    throw std::invalid_argument(where + e.what());
  }
  extend_state(*model_, *state_);
  bodies_.push_back(body);
  reference_force_.emplace_back();
  reference_torque_.emplace_back();
  reference_known_.push_back(0);
  refinements_.push_back(0);
  if (body) state_->pose[index] = ode_pose(body);
  return index;
}

int MagneticForces::attach(dBodyID body, const Shape& shape, const std::map<std::string, Material>& materials,
                           const std::string& material, double cell_size, const std::string& name) {
  const auto found = materials.find(material);
  if (found == materials.end()) {
    std::string known;
    for (const auto& [key, value] : materials) known += (known.empty() ? "\"" : ", \"") + key + "\"";
    throw std::invalid_argument("MagneticForces::attach: no material \"" + material + "\" (known: " +
                                (known.empty() ? "none" : known) + ")");
  }
  return attach(body, shape, found->second, cell_size, name);
}

namespace {

// Cells and soft moments of each body of the model.
void count_cells(const MagneticModel& model, std::vector<int>& cells, std::vector<int>& moments) {
  cells.assign(static_cast<size_t>(model.body_count()), 0);
  moments.assign(static_cast<size_t>(model.body_count()), 0);
  for (int b = 0; b < model.body_count(); ++b) {
    const MagneticBody& body = model.body(b);
    cells[b] = body.cell_count();
    if (body.kind == CellKind::soft) moments[b] = body.cell_count() * body.soft.n;
  }
}

}  // namespace

SavedMagneticState MagneticForces::save_state() const {
  SavedMagneticState result;
  SavedMagneticState::Data& saved = result.data();
  saved.state = *state_;
  saved.report = report_;
  count_cells(*model_, saved.body_cells, saved.body_moments);
  saved.body_refinements = refinements_;
  return result;
}

void MagneticForces::restore_state(const SavedMagneticState& saved_state) {
  const SavedMagneticState::Data& saved = saved_state.data();
  const std::string where = "MagneticForces::restore_state: ";
  std::vector<int> cells, moments;
  count_cells(*model_, cells, moments);
  if (saved.body_cells.size() != cells.size() || saved.body_moments.size() != moments.size())
    throw std::invalid_argument(where + "the state was saved from " + std::to_string(saved.body_cells.size()) +
                                " bodies, these magnetics have " + std::to_string(cells.size()));
  for (size_t b = 0; b < cells.size(); ++b)
    if (saved.body_cells[b] != cells[b] || saved.body_moments[b] != moments[b])
      throw std::invalid_argument(where + "body " + std::to_string(b) + " \"" +
                                  model_->body(static_cast<int>(b)).name + "\" has " + std::to_string(cells[b]) +
                                  " cells and " + std::to_string(moments[b]) + " moments, the saved state " +
                                  std::to_string(saved.body_cells[b]) + " and " + std::to_string(saved.body_moments[b]));
  for (size_t b = 0; b < cells.size() && saved.body_refinements.size() == cells.size(); ++b)
    if (saved.body_refinements[b] != refinements_[b])
      throw std::invalid_argument(
          where + "body " + std::to_string(b) + " \"" + model_->body(static_cast<int>(b)).name +
          "\" got new refined zones (refine_body) since the state was saved");
  // The state's own arrays (a saved state edited by hand).
  const MagneticState& s = saved.state;
  const size_t nb = cells.size(), nc = static_cast<size_t>(model_->cell_count()),
               nm = static_cast<size_t>(model_->moment_count());
  const bool sized = s.pose.size() == nb && s.active.size() == nb && s.magnetization_scale.size() == nb &&
                     s.force.size() == nb && s.torque.size() == nb && s.cell_position.size() == nc &&
                     s.magnetization.size() == nc && s.applied_field.size() == nc &&
                     s.relaxation_change.size() == nc && s.previous_relaxation_change.size() == nc &&
                     s.llg_history.size() == nc &&
                     s.noise_counter.size() == nc && s.moments.size() == nm && s.moment_hc_prev.size() == nm;
  if (!sized)
    throw std::invalid_argument(where + "the saved state's arrays do not match its " + std::to_string(nb) +
                                " bodies, " + std::to_string(nc) + " cells and " + std::to_string(nm) + " moments");
  *state_ = s;
  report_ = saved.report;
}

void MagneticForces::set_external_field(const Vec3& H) {
  if (!is_finite(H))
    throw std::invalid_argument("MagneticForces::set_external_field: the field " + format(H) + " is not finite");
  if (norm(H) > ranges::kFieldStrength.max)
    throw std::invalid_argument("MagneticForces::set_external_field: the field " + format(H) +
                                " A/m is stronger than the largest accepted, " +
                                format_number(ranges::kFieldStrength.max) + " A/m");
  state_->external_field = H;
}

void MagneticForces::set_wake_tolerance(double tolerance) {
  if (!(tolerance >= 0.0))
    throw std::invalid_argument("MagneticForces::set_wake_tolerance: the tolerance must be >= 0");
  wake_tolerance_ = tolerance;
}

void MagneticForces::set_magnetization_scale(int index, double scale) {
  const int b = body_index(index, "set_magnetization_scale");
  const std::string where = "MagneticForces::set_magnetization_scale: the scale " + format_number(scale) +
                            " of body " + std::to_string(b) + " \"" + model_->body(b).name + "\"";
  if (!std::isfinite(scale)) throw std::invalid_argument(where + " is not finite");
  // The scene's rule for scale_magnetization events (odemag/constants.h).
  const MagneticBody& body = model_->body(b);
  const Vec3 field = body.kind == CellKind::soft ? body.coil_field : body.remanence;
  double largest_ni = 0.0;
  for (const AttachedCoil& k : model_->coils())
    if (k.body == b) largest_ni = std::max(largest_ni, std::abs(ampere_turns(k.source)));
  const double limit = ranges::largest_magnetization_scale(
      std::max({std::abs(field.x), std::abs(field.y), std::abs(field.z)}), largest_ni);
  if (std::abs(scale) > limit)
    throw std::invalid_argument(where + " scales its magnetization or its coils' ampere-turns beyond the largest "
                                "accepted, " + format_number(ranges::kFieldStrength.max) + " A/m and " +
                                format_number(ranges::kAmpereTurns.max) + " A (at most " + format_number(limit) +
                                " for this body)");
  state_->magnetization_scale[b] = scale;
}

void MagneticForces::set_pose(int index, const BodyPose& pose) {
  const int b = body_index(index, "set_pose");
  const std::string where =
      "MagneticForces::set_pose: the pose of body " + std::to_string(b) + " \"" + model_->body(b).name + "\"";
  if (!is_finite(pose.position) || !finite(pose.rotation))
    throw std::invalid_argument(where + " is not finite (position " + format(pose.position) + ", rotation " +
                                format(pose.rotation) + ")");
  if (norm(pose.position) > ranges::kLength.max)
    throw std::invalid_argument(where + ": the position " + format(pose.position) + " is farther than " +
                                format_number(ranges::kLength.max) + " m from the origin");
  if (const std::string why = rotation_error(pose.rotation); !why.empty())
    throw std::invalid_argument(where + ": the rotation " + format(pose.rotation) + " " + why);
  state_->pose[b] = pose;
}

Vec3 MagneticForces::moment(int index) const {
  const int b = body_index(index, "moment");
  return state_->active[b] ? body_moment(*model_, *state_, b) : Vec3{};
}

void MagneticForces::read_poses() {
  for (int b = 0; b < model_->body_count(); ++b)
    if (bodies_[b]) state_->pose[b] = ode_pose(bodies_[b]);
}

void MagneticForces::check_inputs(const char* call) const {
  const std::string where = std::string("MagneticForces::") + call + ": ";
  if (!is_finite(state_->external_field))
    throw std::domain_error(where + "the external field " + format(state_->external_field) + " is not finite");
  for (int b = 0; b < model_->body_count(); ++b) {
    if (!state_->active[b]) continue;  // neither makes nor feels a field
    const BodyPose& pose = state_->pose[b];
    const char* what = !is_finite(pose.position) ? "position" : !finite(pose.rotation) ? "rotation" : nullptr;
    if (what)
      throw std::domain_error(where + "body " + std::to_string(b) + " \"" + model_->body(b).name + "\" has a " +
                              (bodies_[b] ? "non-finite ODE " : "non-finite ") + what + " (position " +
                              format(pose.position) + ", rotation " + format(pose.rotation) + ")");
    if (!std::isfinite(state_->magnetization_scale[b]))
      throw std::domain_error(where + "body " + std::to_string(b) + " \"" + model_->body(b).name +
                              "\" has a non-finite magnetization scale");
  }
}

const RelaxReport& MagneticForces::compute() {
  read_poses();
  check_inputs("compute");
  report_ = magnetic_step(*model_, *state_, options_, *backend_);
  return report_;
}

void MagneticForces::recompute_forces() {
  read_poses();
  check_inputs("recompute_forces");
  magnetic_forces_at_held_magnetization(*model_, *state_, options_, *backend_);
}

const RelaxReport& MagneticForces::apply() {
  compute();
  add_forces();
  return report_;
}

bool MagneticForces::wakes(int b) const {
  dBodyID body = bodies_[b];
  if (!dBodyGetAutoDisableFlag(body)) return false;  // disabled by the program, not asleep
  dMass mass;
  dBodyGetMass(body, &mass);
  dVector3 g;
  dWorldGetGravity(dBodyGetWorld(body), g);
  const Vec3 f0 = reference_force_[b], t0 = reference_torque_[b];
  const double load = norm(f0) + mass.mass * norm(Vec3{g[0], g[1], g[2]});
  const double r = norm(shape_half_extents(model_->body(b).shape));
  return norm(state_->force[b] - f0) > wake_tolerance_ * load ||
         norm(state_->torque[b] - t0) > wake_tolerance_ * (norm(t0) + r * load);
}

void MagneticForces::note_reference(int b) {
  reference_force_[b] = state_->force[b];
  reference_torque_[b] = state_->torque[b];
  reference_known_[b] = 1;
}

void MagneticForces::add_forces() {
  for (int b = 0; b < model_->body_count(); ++b) add_forces_of(b);
}

void MagneticForces::add_forces_to(dBodyID body) {
  for (int b = 0; b < model_->body_count(); ++b)
    if (bodies_[b] == body) add_forces_of(b);
}

void MagneticForces::add_forces_of(int b) {
  dBodyID body = bodies_[b];
  if (!body || !state_->active[b] || model_->body(b).inert() || dBodyIsKinematic(body)) return;
  if (!dBodyIsEnabled(body)) {
    if (!reference_known_[b]) note_reference(b);  // never seen awake: its forces now are the reference
    if (!wakes(b)) return;
    dBodyEnable(body);
  }
  note_reference(b);
  const Vec3& f = state_->force[b];
  const Vec3& t = state_->torque[b];
  dBodyAddForce(body, f.x, f.y, f.z);
  dBodyAddTorque(body, t.x, t.y, t.z);
}

}  // namespace odemag
