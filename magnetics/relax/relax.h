// Relaxation of the magnetization for bodies held in place (docs/model.md
// "Relaxation: two levels instead of Algorithm 1"; paper Algorithm 1), and the
// rest of a magnetic step.
#pragma once

#include <functional>
#include <vector>

#include "magnetics/model/backend.h"
#include "magnetics/model/model.h"
#include "magnetics/model/state.h"
#include "odemag/settings.h"

namespace odemag {

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
// near_field: include the near-field corrections (magnetics/near_field/near_field.h).
double magnetic_energy(const MagneticModel& model, const MagneticState& state, bool near_field = true);

}  // namespace odemag
