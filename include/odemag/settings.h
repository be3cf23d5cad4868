// Settings: of the relaxation of the magnetization and its report
// (docs/model.md), of the step loop (docs/simulation.md "Substeps") and the
// choices of a scene's solver. Plain structs and enums with their defaults,
// so that no header includes a solver for a setting.
#pragma once

#include <cstdint>
#include <functional>
#include <vector>

namespace odemag {

// One cell's relaxation under a frozen applied field (magnetics/kernels/llg.h).
struct LocalRelaxOptions {
  // Pseudo time step dt = tau (1 + alpha^2) / (gamma0 S), S = gamma_D Ms + H_K + |H_A|.
  // docs/model.md: the free energy falls monotonically for tau <= 0.6 and
  // rises at 0.8; tau = 2 diverges. 0.5 keeps a margin.
  double time_step_factor = 0.5;
  int max_llg_steps = 60;          // LLG steps per inner relaxation
  double llg_switch = 1e-2;        // relative torque below which Newton takes over
  bool newton = true;              // Newton polish after the LLG steps
  int max_newton_steps = 40;
  double tolerance = 1e-12;        // relative torque at which a cell is relaxed
  double noise_ratio = 1e-6;       // |H_noise| / |H_eff| (paper Sec. 4.6)
  bool single_step = false;        // exactly one LLG step (paper Algorithm 1)
};

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
  // (magnetics/model/body_response.h, docs/model.md "Block preconditioner").
  // Always on in scenes; false (Anderson on the plain residual) only to
  // measure what it saves (benchmarks/relax_iterations.cpp).
  bool precondition_bodies = true;
  // The outer loop starts from the warm start's applied field plus what the
  // last relaxation added to it, where the last two relaxations added alike
  // (MagneticState::relaxation_change, docs/model.md "Predicted warm
  // start"). Always on in scenes; false (from the warm start's field) only
  // to measure what it saves.
  bool predict_warm_start = true;
  // Bodies whose magnetization is kept, turned with the body but not solved
  // for (by body index, kHeld: held; empty: none): their cells act as sources
  // and feel forces, and the relaxation converges on the others' cells.
  // MagneticSolve::moving holds, in a rigid step's later substeps, every body
  // that neither needs the substeps nor touches one that does
  // (docs/simulation.md "Substeps"). Non-empty: one entry (0 or kHeld) per
  // body, or relax, magnetic_step and magnetic_forces_at_held_magnetization
  // throw std::invalid_argument before they change anything.
  static constexpr uint8_t kHeld = 1;
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

// The coupling of two cells of one body (docs/model.md): the cell-averaged
// cube-cube (Newell) tensor, or the paper's point-dipole tensor D(r).
enum class IntraBodyTensor {
  cell_average,  // Newell cube-cube tensor (default)
  point_dipole,  // the paper's point-function tensor D(r)
};

// The substep rule (docs/simulation.md "Substeps").
struct SubstepSettings {
  // Cap on the count; 1 disables substepping (scene simulation.max_substeps).
  int max_substeps = 64;
  // Bound on omega h for the magnetic force and torque (scene simulation.stiffness_limit).
  double stiffness_limit = 1.0;
};

// When the magnetization is relaxed within a rigid step (scene
// simulation.magnetic_solve, docs/simulation.md "Substeps"): substep, at
// every substep for every body; moving, at every substep for the bodies that
// need the substeps and those touching them, the others' magnetization held
// (RelaxOptions::held_bodies) in the later substeps.
enum class MagneticSolve { substep, moving };

// The step loop (MagneticStepper).
struct StepperSettings {
  SubstepSettings substeps;
  MagneticSolve magnetic_solve = MagneticSolve::substep;
  bool exact_solver = false;  // embedders: dWorldStep instead of dWorldQuickStep
};

// The magnetic backend (scene solver.backend, docs/gpu.md): automatic, the
// CUDA backend where a device is usable and the scene needs nothing it lacks,
// else the CPU backend.
enum class BackendKind { automatic, cpu, cuda };

// ODE's constraint solver for contacts (scene simulation.contact_solver,
// docs/simulation.md "Contacts"): automatic, exact up to 32 dynamic bodies
// and quick beyond.
enum class ContactSolver { automatic, exact, quick };

}  // namespace odemag
