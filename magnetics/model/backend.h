// The solver interface: the parts of a magnetic step whose cost grows with the
// number of cells (fields, local relaxation, forces). The CPU backend
// (magnetics/relax/cpu_backend.cpp) and the CUDA backend (gpu/) implement it; the
// relaxation driver (magnetics/relax/relax.h) runs on top of either.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "magnetics/kernels/llg.h"
#include "magnetics/model/model.h"
#include "magnetics/model/state.h"

namespace odemag {

struct LocalStats {
  long llg_steps = 0;
  long newton_steps = 0;
  double max_residual = 0.0;  // largest relative torque of a soft cell
};

// Per-cell vectors below have model.cell_count() entries, indexed by cell;
// entries of cells a call does not concern are left untouched.
class MagneticBackend {
 public:
  virtual ~MagneticBackend() = default;
  virtual std::string name() const = 0;

  // New rigid step: cell positions, active flags or fixed magnetizations
  // changed (call after place_cells).
  virtual void begin_step(const MagneticModel& model, const MagneticState& state) = 0;

  // Far-field approximation of the inter-body responsive field (docs/model.md
  // "Far field"), taking effect at the next begin_step: theta = 0 sums every
  // pair exactly. A backend without the approximation always sums exactly.
  virtual void set_far_field(double theta) { (void)theta; }

  // Near-field corrections between touching bodies (magnetics/near_field/near_field.h),
  // taking effect at the next begin_step: on = false keeps the point dipoles
  // of the paper's model; mutual_induction as RelaxOptions::mutual_induction.
  virtual void set_near_field(bool on, bool mutual_induction) = 0;

  // Bodies whose magnetization the next relaxations keep (RelaxOptions::
  // held_bodies; by body, 1: held, 2: held and its force not needed; empty:
  // none), taking effect at once; relax and magnetic_step set it and reset it
  // to none when they end. A backend that returns true neither relaxes their
  // cells nor needs their rows of the responsive field, and may leave the
  // forces of bodies held with 2 at any value (the caller keeps theirs); the
  // default relaxes every cell, a held one under its last applied field (the
  // relaxation passes that), which keeps it where it was up to the body's turn.
  virtual bool set_held_bodies(const std::vector<uint8_t>& held) {
    (void)held;
    return false;
  }

  // H_E plus the field of every fixed permanent cell, at each active
  // responsive cell. Constant during a relaxation.
  virtual void fixed_field(const MagneticModel& model, const MagneticState& state,
                           std::vector<Vec3>& H) = 0;

  // Field of the responsive cells (their state.magnetization) at each active
  // responsive cell: the intra-body part from the cached tensors, the
  // inter-body part from the dipole kernel and the near-field corrections.
  virtual void responsive_field(const MagneticModel& model, const MagneticState& state,
                                std::vector<Vec3>& H) = 0;

  // Relaxes every active responsive cell under its applied field H_A and
  // updates moments and state.magnetization.
  virtual LocalStats relax_cells(const MagneticModel& model, MagneticState& state,
                                 const std::vector<Vec3>& H_A, const LocalRelaxOptions& options) = 0;

  // state.force and state.torque of every body from the magnetizations.
  virtual void forces(const MagneticModel& model, MagneticState& state) = 0;

  // H (A/m) at world points from H_E and every active cell, each cell the
  // uniformly magnetized solid it stands for (magnetics/relax/field_probe.h).
  virtual void probe_field(const MagneticModel& model, const MagneticState& state,
                           const std::vector<Vec3>& points, std::vector<Vec3>& H) = 0;
};

// threads <= 0: all cores (OpenMP default).
std::unique_ptr<MagneticBackend> make_cpu_backend(int threads = 0);

}  // namespace odemag
