// Physical constants in SI units (docs/embedding.md "The API in one loop", Units),
// and the largest magnitudes odemag accepts (docs/scene-format.md "Ranges").
#pragma once

#include <limits>

namespace odemag {

inline constexpr double kPi = 3.14159265358979323846;
// Vacuum permeability mu0 = 4 pi 1e-7 T m / A.
inline constexpr double kMu0 = 4.0e-7 * kPi;
// Gyromagnetic ratio in field units gamma0 = 2.2128e5 m / (A s).
inline constexpr double kGamma0 = 2.2128e5;

// The largest magnitude a value of a kind may have, in the scene loader and in
// every control of the APIs (MagneticForces, Simulation, Python): far beyond
// anything physical, and small enough that every product the model forms
// from it (moments M V, fields m / r^3, forces mu0 M^2 L^2, masses rho V)
// stays finite (docs/scene-format.md "Ranges").
struct Magnitude {
  double max = 0.0;  // 0: no bound
  const char* unit = "";
};
namespace ranges {
inline constexpr Magnitude kFieldStrength{1e9, "A/m"};  // about 800 times the strongest magnets' 1.2e6 A/m
inline constexpr Magnitude kLength{1e6, "m"};
inline constexpr Magnitude kSpeed{1e8, "m/s"};
inline constexpr Magnitude kAngularSpeed{1e8, "rad/s"};
inline constexpr Magnitude kAcceleration{1e6, "m/s^2"};
inline constexpr Magnitude kDensity{1e6, "kg/m^3"};
inline constexpr Magnitude kCurrent{1e9, "A"};      // a coil's current; its ampere-turns N I are bounded by kAmpereTurns too
inline constexpr Magnitude kAmpereTurns{1e9, "A"};  // |N I| of a coil: fields up to about kFieldStrength
inline constexpr Magnitude kTurns{1e9, ""};
inline constexpr Magnitude kAngle{1e6, "rad"};
// A rotation matrix is accepted when R^T R differs from the identity by at
// most this in every entry and det R > 0.
inline constexpr double kRotationTolerance = 1e-9;

// The largest |scale| of a body's magnetization scale (the scene's
// scale_magnetization event, MagneticForces::set_magnetization_scale): the
// scaled magnetization or coil field (its largest component, A/m) stays
// within kFieldStrength and the scaled ampere-turns of each of its coils within
// kAmpereTurns. largest_field: the body's largest |component| of M_r or coil
// field; largest_ampere_turns: its largest coil |N I| (0: none).
inline double largest_magnetization_scale(double largest_field, double largest_ampere_turns) {
  double limit = std::numeric_limits<double>::infinity();
  if (largest_field > 0.0) limit = kFieldStrength.max / largest_field;
  if (largest_ampere_turns > 0.0 && kAmpereTurns.max / largest_ampere_turns < limit)
    limit = kAmpereTurns.max / largest_ampere_turns;
  return limit;
}
}  // namespace ranges

}  // namespace odemag
