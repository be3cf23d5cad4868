#include "magnetics/model/state.h"

#include <algorithm>
#include <cmath>
#include <cstddef>

#include "odemag/constants.h"
#include "magnetics/kernels/kernels.h"
#include "magnetics/kernels/rng.h"

namespace odemag {

void reset_moments(const MagneticModel& model, MagneticState& state, int b) {
  state.last_solve.valid = false;
  const MagneticBody& body = model.body(b);
  for (int i = 0; i < body.cell_count(); ++i)
    state.relaxation_change[body.first_cell + i] =
        state.previous_relaxation_change[body.first_cell + i] = {};
  if (body.kind != CellKind::soft) return;
  for (int i = 0; i < body.cell_count(); ++i) {
    const int c = body.first_cell + i;
    const int off = model.moment_offset(c);
    for (int k = 0; k < body.soft.n; k += 2) {
      const Vec3 d = random_unit_vector(hash_key(state.seed, 0x4d4f4d454e54ULL, c, k));
      state.moments[off + k] = d;
      state.moments[off + k + 1] = -d;
    }
    for (int k = 0; k < body.soft.n; ++k) state.moment_hc_prev[off + k] = {};
    state.llg_history[c] = 0;
    state.magnetization[c] = {};
  }
}

void extend_state(const MagneticModel& model, MagneticState& state) {
  const int old_bodies = static_cast<int>(state.pose.size());
  state.pose.resize(model.body_count());
  state.active.resize(model.body_count(), 1);
  state.magnetization_scale.resize(model.body_count(), 1.0);
  state.force.resize(model.body_count());
  state.torque.resize(model.body_count());
  state.cell_position.resize(model.cell_count());
  state.magnetization.resize(model.cell_count());
  state.applied_field.resize(model.cell_count());
  state.relaxation_change.resize(model.cell_count());
  state.previous_relaxation_change.resize(model.cell_count());
  state.llg_history.resize(model.cell_count(), 0);
  state.noise_counter.resize(model.cell_count(), 0);
  state.moments.resize(model.moment_count());
  state.moment_hc_prev.resize(model.moment_count());
  for (int b = old_bodies; b < model.body_count(); ++b) reset_moments(model, state, b);
}

namespace {

// The old cell of a refined body each new cell takes its state from
// (transfer_refined_state).
std::vector<int> source_cells(const CellSet& old_cells, const CellSet& cells) {
  std::vector<int> source(cells.size());
  for (int i = 0; i < cells.size(); ++i) {
    const Vec3 p = cells.cube_centre(i);
    int best = -1, nearest = 0;
    double best_edge = 0.0, nearest_distance = 0.0;
    for (int j = 0; j < old_cells.size(); ++j) {
      const Vec3 d = p - old_cells.cube_centre(j), half = old_cells.cube_half(j);
      const double slack = 1e-9 * half.x;
      if (std::abs(d.x) <= half.x + slack && std::abs(d.y) <= half.y + slack &&
          std::abs(d.z) <= half.z + slack && (best < 0 || half.x < best_edge))
        best = j, best_edge = half.x;
      const double distance = norm(p - old_cells.local_positions[j]);
      if (j == 0 || distance < nearest_distance) nearest = j, nearest_distance = distance;
    }
    source[i] = best >= 0 ? best : nearest;
  }
  return source;
}

// v with the block of old_count * width entries at first replaced by, for
// each new cell i, the width entries of old cell source[i].
template <class T>
std::vector<T> remapped(const std::vector<T>& v, size_t first, size_t width, size_t old_count,
                        const std::vector<int>& source) {
  std::vector<T> out(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(first));
  for (const int s : source)
    for (size_t k = 0; k < width; ++k) out.push_back(v[first + s * width + k]);
  out.insert(out.end(), v.begin() + static_cast<std::ptrdiff_t>(first + old_count * width),
             v.end());
  return out;
}

}  // namespace

void transfer_refined_state(const MagneticModel& model, int b, const MagneticBody& old_body,
                            MagneticState& state) {
  const MagneticBody& body = model.body(b);
  const std::vector<int> source = source_cells(old_body.cells, body.cells);
  const size_t first = static_cast<size_t>(body.first_cell),
               old_count = static_cast<size_t>(old_body.cell_count());
  state.cell_position = remapped(state.cell_position, first, 1, old_count, source);
  state.magnetization = remapped(state.magnetization, first, 1, old_count, source);
  state.applied_field = remapped(state.applied_field, first, 1, old_count, source);
  // The warm-start changes of body b's cells are cleared (the old cells' do
  // not predict the new ones'); the arrays only take the new count.
  state.relaxation_change = remapped(state.relaxation_change, first, 1, old_count, source);
  state.previous_relaxation_change =
      remapped(state.previous_relaxation_change, first, 1, old_count, source);
  std::fill_n(state.relaxation_change.begin() + static_cast<std::ptrdiff_t>(first), source.size(),
              Vec3{});
  std::fill_n(state.previous_relaxation_change.begin() + static_cast<std::ptrdiff_t>(first),
              source.size(), Vec3{});
  state.llg_history = remapped(state.llg_history, first, 1, old_count, source);
  state.noise_counter = remapped(state.noise_counter, first, 1, old_count, source);
  if (body.kind == CellKind::soft && body.cell_count() > 0) {
    const size_t n = static_cast<size_t>(body.soft.n),
                 first_moment = static_cast<size_t>(model.moment_offset(body.first_cell));
    state.moments = remapped(state.moments, first_moment, n, old_count, source);
    state.moment_hc_prev = remapped(state.moment_hc_prev, first_moment, n, old_count, source);
  }
  state.last_solve.valid = false;
  place_cells(model, state);
}

MagneticState make_state(const MagneticModel& model, uint64_t seed) {
  MagneticState state;
  state.seed = seed;
  extend_state(model, state);
  place_cells(model, state);
  return state;
}

Vec3 soft_cell_magnetization(const MagneticModel& model, const MagneticState& state, int c) {
  const MagneticBody& body = model.body(model.cell_body(c));
  const Vec3 m = mean_moment(&state.moments[model.moment_offset(c)], body.soft.n);
  return state.pose[model.cell_body(c)].rotation * (body.soft.Ms * m);
}

void place_cells(const MagneticModel& model, MagneticState& state) {
  for (int b = 0; b < model.body_count(); ++b) {
    const MagneticBody& body = model.body(b);
    const BodyPose& pose = state.pose[b];
    const Vec3 remanent = pose.rotation * (state.magnetization_scale[b] * body.remanence);
    for (int i = 0; i < body.cell_count(); ++i) {
      const int c = body.first_cell + i;
      state.cell_position[c] = pose.position + pose.rotation * body.cells.local_positions[i];
      switch (body.kind) {
        case CellKind::fixed_permanent:
          state.magnetization[c] = remanent;
          break;
        case CellKind::recoil_permanent:
          state.magnetization[c] =
              recoil_magnetization(remanent, body.recoil, state.applied_field[c]);
          break;
        case CellKind::soft:
          state.magnetization[c] = soft_cell_magnetization(model, state, c);
          break;
      }
    }
  }
}

namespace {

// Calls visit(i, mu_i, dH_i) with the body-frame moment and boundary-correction
// field of each of body b's cells; two passes over the cells (the uniform mode
// needs every moment first), each moment computed afresh, so nothing is
// allocated on this per-iteration path.
template <class Visit>
void visit_boundary_field(const MagneticModel& model, const MagneticState& state, int b,
                          Visit&& visit) {
  const MagneticBody& body = model.body(b);
  const Mat3& R = state.pose[b].rotation;
  const int n = body.cell_count();
  auto moment = [&](int i) {
    return R.transpose_times(body.cells.volumes[i] * state.magnetization[body.first_cell + i]);
  };
  Vec3 sum_pi, sum_beta;
  for (int i = 0; i < n; ++i) {
    const Vec3 mu = moment(i);
    sum_pi += symmetric_times(&body.uniform_tensors[12u * i], mu);
    sum_beta += symmetric_times(&body.uniform_tensors[12u * i + 6], mu);
  }
  const Vec3 u_pi = body.uniform_inverse[0] * sum_pi, u_beta = body.uniform_inverse[1] * sum_beta;
  for (int i = 0; i < n; ++i) {
    const Vec3 mu = moment(i);
    visit(i, mu,
          symmetric_times(&body.self_tensors[6u * i], mu) +
              symmetric_times(&body.uniform_tensors[12u * i], u_pi) -
              symmetric_times(&body.uniform_tensors[12u * i + 6], u_beta));
  }
}

}  // namespace

void add_boundary_field(const MagneticModel& model, const MagneticState& state,
                        std::vector<Vec3>& H) {
  for (int b = 0; b < model.body_count(); ++b) {
    const MagneticBody& body = model.body(b);
    if (body.self_tensors.empty() || !state.active[b]) continue;
    const Mat3& R = state.pose[b].rotation;
    visit_boundary_field(model, state, b, [&](int i, const Vec3&, const Vec3& dH) {
      H[body.first_cell + i] += R * dH;
    });
  }
}

double boundary_field_energy(const MagneticModel& model, const MagneticState& state) {
  double e = 0.0;
  for (int b = 0; b < model.body_count(); ++b) {
    const MagneticBody& body = model.body(b);
    if (body.self_tensors.empty() || !state.active[b]) continue;
    visit_boundary_field(model, state, b, [&](int, const Vec3& mu, const Vec3& dH) {
      e -= 0.5 * kMu0 * dot(mu, dH);
    });
  }
  return e;
}

std::vector<int> active_responsive_cells(const MagneticModel& model, const MagneticState& state) {
  std::vector<int> cells;
  for (int b = 0; b < model.body_count(); ++b) {
    const MagneticBody& body = model.body(b);
    if (!body.responsive() || !state.active[b]) continue;
    for (int i = 0; i < body.cell_count(); ++i) cells.push_back(body.first_cell + i);
  }
  return cells;
}

Vec3 body_moment(const MagneticModel& model, const MagneticState& state, int b) {
  const MagneticBody& body = model.body(b);
  Vec3 mu;
  if (body.cells.whole_cells) {  // every cell stands for cell_volume
    for (int i = 0; i < body.cell_count(); ++i) mu += state.magnetization[body.first_cell + i];
    return body.cells.cell_volume * mu;
  }
  for (int i = 0; i < body.cell_count(); ++i)
    mu += body.cells.volumes[i] * state.magnetization[body.first_cell + i];
  return mu;
}

}  // namespace odemag
