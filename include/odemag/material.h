// Magnetic materials (docs/scene-format.md "Materials"). All values in SI units.
#pragma once

#include <array>
#include <vector>

#include <limits>
#include <string>
#include <variant>

#include "odemag/vec3.h"

namespace odemag {

// The most unit moments a soft cell holds (SoftMaterial::moments_per_cell).
inline constexpr int kMaxMomentsPerCell = 8;

// Hard magnet: fixed magnetization M_r in the body frame, optional recoil
// susceptibility chi_r so that M = M_r + chi_r * H_inside.
struct PermanentMaterial {
  Vec3 magnetization;                 // M_r, A/m, body frame
  // chi_r, dimensionless, >= -1; below 0 a diamagnet (magnetization 0): -1 a
  // perfect one (a superconductor in the Meissner state, as a linear medium)
  double recoil_susceptibility = 0.0;
};

// Ferromagnet magnetized by the field: n unit moments per cell evolved by LLG.
struct SoftMaterial {
  double saturation = 0.0;                                          // Ms, A/m, > 0
  double susceptibility = std::numeric_limits<double>::infinity();  // chi, > 0, may be infinite
  double anisotropy_field = 0.0;                                    // H_K, A/m, >= 0
  Vec3 easy_axis{0.0, 0.0, 1.0};                                    // body frame, normalised on use
  double damping = 1.0;                                             // Gilbert alpha, > 0
  int moments_per_cell = 2;                                         // n, even, 2..kMaxMomentsPerCell
  // An electromagnet: the field of its coil inside the core (A/m, body
  // frame), added to the applied field of the body's own cells and scaled
  // like a permanent magnet's remanence (time-line scale_magnetization).
  // The coil's own field outside the core is neglected: the magnetized
  // core's is what acts on other bodies.
  Vec3 coil_field;
  // An anhysteretic B-H curve (H in A/m, B in T; magnetics/materials/bh_curve.h): empty
  // for the linear-to-saturation material above. With a curve, Ms is the
  // curve's last M and chi its initial slope; `saturation` and
  // `susceptibility` must be left at their defaults.
  std::vector<std::array<double, 2>> bh_curve;

  // Demagnetising factor of a spherical cell including the intrinsic
  // susceptibility: gamma_D = 1/3 + 1/chi (docs/model.md "Summary of choices", self term);
  // with a B-H curve at zero field (chi_0), cells take the secant per field.
  double demag_factor() const;
  bool anisotropic() const { return anisotropy_field > 0.0; }
};

// No cells, no magnetic cost (wood, glass, floors).
struct InertMaterial {};

using Material = std::variant<InertMaterial, PermanentMaterial, SoftMaterial>;


// Empty when the material is valid; otherwise a message naming the offending
// parameter by its scene-file key (e.g. "saturation must be positive").
std::string validate_material(const Material& material);

bool is_inert(const Material& material);

// A soft material, or a permanent one with recoil susceptibility > 0: its
// magnetization grows along an applied field (not inert, not rigid, not a
// diamagnet).
bool has_positive_susceptibility(const Material& material);

}  // namespace odemag
