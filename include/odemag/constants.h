// Physical constants in SI units (docs/embedding.md "The API in one loop", Units).
#pragma once

namespace odemag {

inline constexpr double kPi = 3.14159265358979323846;
// Vacuum permeability mu0 = 4 pi 1e-7 T m / A.
inline constexpr double kMu0 = 4.0e-7 * kPi;
// Gyromagnetic ratio in field units gamma0 = 2.2128e5 m / (A s).
inline constexpr double kGamma0 = 2.2128e5;

}  // namespace odemag
