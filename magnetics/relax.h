// Relaxation of the magnetization for bodies held in place (docs/model.md
// "Relaxation: two levels instead of Algorithm 1"; paper Algorithm 1), and the
// rest of a magnetic step.
#pragma once

#include <functional>
#include <vector>

#include "magnetics/backend.h"
#include "magnetics/llg.h"
#include "magnetics/model.h"
#include "magnetics/state.h"

namespace odemag {

enum class RelaxScheme {
  // Outer loop over the exo field (one field evaluation per iteration,
  // Anderson-accelerated); inner loop relaxes each cell locally under the
  // frozen applied field with LLG steps and a Newton polish. Default.
  two_level,
  // The paper's Algorithm 1: every iteration evaluates the field and moves
  // every moment by one LLG step.
  paper,
};

struct RelaxReport;

struct RelaxOptions {
  RelaxScheme scheme = RelaxScheme::two_level;
  // Converged when every responsive cell's applied field changes by less than
  // tolerance times its field scale |H_A| + gamma_D |M| (two_level), or every
  // soft cell's relative torque is below tolerance (paper).
  double tolerance = 1e-6;
  int max_iterations = 200;
  // Stored differences of Anderson mixing; 0: plain fixed-point iteration.
  // docs/model.md: depth 20 needs 45% fewer iterations than 6 on high-chi
  // lattice bodies and is fastest in wall time; 40 gains little more.
  int anderson_depth = 20;
  double mixing = 1.0;      // Anderson beta
  // false: induced (responsive) cells feel only H_E and the fixed permanent
  // magnets, not each other (the paper's Fig. 12c comparison).
  bool mutual_induction = true;
  // Opening parameter of the far-field approximation of the responsive field
  // (docs/model.md "Far field"; CPU backend, 512 responsive cells or more):
  // 0 sums every pair exactly; the error falls as theta^2.
  double far_field_theta = 0.0;
  // magnetic_step returns at once, keeping the magnetization, forces and
  // torques, when nothing changed since the last converged step: the same
  // active bodies, magnetization scales, H_E and options, and every magnetic
  // body within 1e-5 of its cell radius and 1e-5 rad of the pose then solved
  // (docs/model.md "Skipping unchanged steps").
  bool skip_unchanged = false;
  // Near-field corrections where bodies touch (docs/model.md "The near
  // field"): induced higher multipoles of one-cell spheres, cell-averaged
  // coupling of aligned lattice cells. false: point dipoles only (the paper).
  bool near_field = true;
  // Block preconditioner of the outer loop: high-chi isotropic lattice bodies
  // below saturation get a Newton step for their own linear response
  // (magnetics/body_response.h, docs/model.md "Block preconditioner").
  // false: Anderson on the plain residual, as before.
  bool precondition_bodies = true;
  // The outer loop starts from the warm start's applied field plus what the
  // last relaxation added to it, where the last two relaxations added alike
  // (MagneticState::relaxation_change, docs/model.md "Predicted warm
  // start"). false: from the warm start's field, as before.
  bool predict_warm_start = true;
  // Bodies whose magnetization is kept, turned with the body but not solved
  // for (by body index, kHeld: held; empty: none): their cells act as sources
  // and feel forces, and the relaxation converges on the others' cells.
  // kHeldKeepForce: held, and its force and torque are not needed (a body
  // that the rigid step moved whole): they keep their values, and a backend
  // may skip what only they need (the near-field pairs of two such bodies).
  // The scene simulation's magnetic_solve "moving" holds, in a rigid step's
  // later substeps, every body that neither needs the substeps nor touches
  // one that does, and rigid_substeps "moving" keeps the forces of the bodies
  // that took the step whole (docs/simulation.md "Substeps"). Non-empty: one
  // entry (0, kHeld or kHeldKeepForce) per body, or relax, magnetic_step and
  // magnetic_forces_at_held_magnetization throw std::invalid_argument
  // before they change anything.
  static constexpr uint8_t kHeld = 1, kHeldKeepForce = 2;
  std::vector<uint8_t> held_bodies;
  LocalRelaxOptions local;
  // Called after every outer iteration with the report so far (iterations,
  // residual_history): progress lines of a long `odemag solve`. Empty: none.
  std::function<void(const RelaxReport&)> progress;
};

struct RelaxReport {
  int iterations = 0;         // outer iterations (paper scheme: LLG iterations)
  int field_evaluations = 0;  // responsive-field evaluations, O(N^2) each
  double residual = 0.0;      // final value of the convergence measure
  bool converged = false;
  bool skipped = false;       // skip_unchanged: nothing changed, nothing computed
  long llg_steps = 0;         // per-cell LLG steps, summed over cells
  long newton_steps = 0;      // per-cell Newton steps, summed over cells
  std::vector<double> residual_history;  // the convergence measure after each iteration
};

// Relaxes the magnetization of every active responsive cell at the current
// poses, starting from the state's moments (warm start: this temporal
// coherence is what makes remanence possible). Updates magnetization,
// moments and applied_field.
RelaxReport relax(const MagneticModel& model, MagneticState& state, const RelaxOptions& options,
                  MagneticBackend& backend);

// relax, then per-body forces and torques (docs/architecture.md "One magnetic step").
RelaxReport magnetic_step(const MagneticModel& model, MagneticState& state,
                          const RelaxOptions& options, MagneticBackend& backend);

// Forces and torques at the current poses with the magnetization held: the
// cells placed and the backend's step begun, then the forces (stages 1 and 4
// of magnetic_step, no relaxation). Soft cells keep their moments in their
// bodies' frames (place_cells turns them with the bodies), recoil magnets
// their last applied field.
void magnetic_forces_at_held_magnetization(const MagneticModel& model, MagneticState& state,
                                           const RelaxOptions& options, MagneticBackend& backend);

// B (T) and H (A/m) at world points after a relaxation. Inside a magnetic body
// B = mu0 (H + M) with M of the body's nearest cell.
void field_at_points(const MagneticModel& model, const MagneticState& state,
                     MagneticBackend& backend, const std::vector<Vec3>& points,
                     std::vector<Vec3>& B, std::vector<Vec3>& H);

// Total magnetic energy (J) of the configuration with the current
// magnetizations: pair interactions, H_E and, for soft cells, the cell free
// energies. Used by tests (App. B) and diagnostics.
// near_field: include the near-field corrections (magnetics/near_field.h).
double magnetic_energy(const MagneticModel& model, const MagneticState& state, bool near_field = true);

}  // namespace odemag
