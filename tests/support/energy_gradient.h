// Expectations of the tests (tests/support/): a body's force and torque
// against the magnetic energy's derivatives by central differences, the
// magnetization held, each component within 1e-6 of the vector's length.
#pragma once

#include <gtest/gtest.h>

#include "magnetics/relax/relax.h"
#include "tests/support/magnetic_checks.h"

namespace odemag::test_support {

// U of magnetic_energy with the cells placed at the state's poses.
inline auto placed_energy(const MagneticModel& model, MagneticState& state) {
  return [&model, &state] {
    place_cells(model, state);
    return magnetic_energy(model, state);
  };
}

// F = -dU/dx of body `body`, steps of dx (m).
inline void expect_force_is_minus_energy_gradient(const MagneticModel& model, MagneticState& state, int body,
                                                  const Vec3& F, double dx) {
  const Vec3 dF = minus_position_gradient(state.pose[body], placed_energy(model, state), dx);
  for (int a = 0; a < 3; ++a) EXPECT_NEAR(F[a], dF[a], 1e-6 * norm(F)) << "body " << body << " force axis " << a;
}

// tau = -dU/dtheta of body `body`, turns of dtheta (rad).
inline void expect_torque_is_minus_energy_gradient(const MagneticModel& model, MagneticState& state, int body,
                                                   const Vec3& T, double dtheta) {
  const Vec3 dT = minus_rotation_gradient(state.pose[body], placed_energy(model, state), dtheta);
  for (int a = 0; a < 3; ++a) EXPECT_NEAR(T[a], dT[a], 1e-6 * norm(T)) << "body " << body << " torque axis " << a;
}

}  // namespace odemag::test_support
