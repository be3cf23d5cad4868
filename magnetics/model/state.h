// The magnetic state: everything that changes during a simulation.
#pragma once

#include <cstdint>
#include <vector>

#include "magnetics/model/model.h"
#include "odemag/vec3.h"

namespace odemag {

// What the last converged magnetic step solved for (RelaxOptions::skip_unchanged).
struct SolvedInputs {
  bool valid = false;
  std::vector<BodyPose> pose;
  std::vector<uint8_t> active;
  std::vector<double> magnetization_scale;
  Vec3 external_field;
  bool mutual_induction = true;
  double far_field_theta = 0.0;
  bool near_field = true;
};

struct MagneticState {
  Vec3 external_field;  // uniform H_E, A/m

  // Per body.
  std::vector<BodyPose> pose;
  std::vector<uint8_t> active;               // 0: removed from the scene (no field, no force)
  std::vector<double> magnetization_scale;   // multiplies M_r of permanent magnets
  std::vector<Vec3> force;                   // world, N
  std::vector<Vec3> torque;                  // world, N m, about the centre of mass

  // Per cell.
  std::vector<Vec3> cell_position;   // world, m
  std::vector<Vec3> magnetization;   // world, A/m
  std::vector<Vec3> applied_field;   // H_A = H_E + H_exo at responsive cells, world, A/m
  // What the last two-level relaxation added to H_A after its first iterate
  // (the field of the magnetization change it found), and what the one
  // before it added; world, A/m; zero where a relaxation did not reach or
  // did not converge. Where the two agree (a steady drift) the next
  // relaxation starts from its first iterate plus the last
  // (magnetics/relax/relax.cpp, docs/model.md "Predicted warm start").
  std::vector<Vec3> relaxation_change, previous_relaxation_change;
  std::vector<uint8_t> llg_history;  // Hc^(i-1) is valid (paper Algorithm 1 scheme)
  std::vector<uint64_t> noise_counter;

  // Per moment of soft cells (model.moment_offset), body frame.
  std::vector<Vec3> moments;         // unit vectors m_k
  std::vector<Vec3> moment_hc_prev;  // Hc^(i-1) for the extrapolation

  uint64_t seed = 1;

  // Inputs of the last converged magnetic step; invalidate (valid = false)
  // after editing moments or magnetizations by hand.
  SolvedInputs last_solve;

  // The largest cell field scale |H_A| + gamma |M| (A/m) any converged
  // relaxation of this state reached: a millionth of it floors the scale of
  // the relaxation's residual, so that fields falling to zero converge
  // (magnetics/relax/relax.cpp, docs/model.md "Relaxation").
  double peak_field_scale = 0.0;
};

// A state for the model: identity poses at the origin, all bodies active,
// soft moments in opposite pairs along random directions (so M = 0).
MagneticState make_state(const MagneticModel& model, uint64_t seed = 1);

// Extends a state made for a smaller model to every body of the model (bodies
// added to the model later, e.g. by the embedding API).
void extend_state(const MagneticModel& model, MagneticState& state);

// After MagneticModel::refine_body(b) returned old_body: the state for the
// model's new cells. The other bodies' cells keep theirs (renumbered). A new
// cell of body b takes the moments, magnetization, applied field, LLG history
// and noise counter of the old cell whose cube holds its cube's centre (the
// smallest such cube; the old cell point nearest it where none does), so the
// magnetization carries over as the old cells held it; the warm-start
// changes of b's cells are cleared and last_solve is invalidated (the next
// magnetic step relaxes). Cell positions and magnetizations are placed
// again (place_cells).
void transfer_refined_state(const MagneticModel& model, int b, const MagneticBody& old_body,
                            MagneticState& state);

// Soft cells back to the unmagnetized random opposite pairs of make_state.
void reset_moments(const MagneticModel& model, MagneticState& state, int body);

// World cell positions from the body poses, and the magnetization of every
// cell that follows from its material and pose (docs/architecture.md "One magnetic step", 1).
void place_cells(const MagneticModel& model, MagneticState& state);

// Magnetization of one cell from the state (soft: Ms mean(m_k) rotated to world).
Vec3 soft_cell_magnetization(const MagneticModel& model, const MagneticState& state, int cell);

// The cells a relaxation solves for: those of the active responsive (soft and
// recoil) bodies, in cell order.
std::vector<int> active_responsive_cells(const MagneticModel& model, const MagneticState& state);

// Total moment of a body, sum of M V over its cells, world, A m^2.
Vec3 body_moment(const MagneticModel& model, const MagneticState& state, int body);

// Adds the boundary correction of the intra-body field (MagneticBody::
// self_tensors, uniform_tensors; docs/model.md "Cells") at the current
// magnetizations to every cell of the active responsive bodies that have one.
// Both backends call it from responsive_field; O(cells).
void add_boundary_field(const MagneticModel& model, const MagneticState& state, std::vector<Vec3>& H);

// Its share of the magnetic energy, J: -mu0/2 sum over those cells of mu . dH.
double boundary_field_energy(const MagneticModel& model, const MagneticState& state);

}  // namespace odemag
