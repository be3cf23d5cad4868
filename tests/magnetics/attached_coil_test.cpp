// Coils carried by bodies (MagneticModel::add_coil, magnetics/relax/relax.cpp): the
// field they add to the applied field, the force and torque they exert on
// magnets and iron, and the reaction on the carrying body. References written
// here: the on-axis field of a loop, H_z = N I R^2 / (2 (R^2 + z^2)^(3/2)),
// and its derivative; the Lorentz force on the coil's current elements in the
// magnet's dipole field (coil_wrench: an independent quadrature of I dl x B).
#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <stdexcept>

#include "magnetics/model/backend.h"
#include "magnetics/sources/coil.h"
#include "magnetics/kernels/kernels.h"
#include "magnetics/model/model.h"
#include "magnetics/relax/relax.h"
#include "magnetics/model/state.h"
#include "tests/support/magnetic_setup.h"
#include "tests/support/test_math.h"

namespace odemag {
namespace {

constexpr double kLoopRadius = 0.02;  // m
constexpr double kNI = 500.0;         // A (current 50 A, 10 turns)
constexpr double kBallRadius = 0.003;

CircularLoop loop() {
  CircularLoop l;
  l.radius = kLoopRadius;
  l.current = 50.0;
  l.turns = 10.0;
  return l;
}

// On-axis field of the loop at height z and its derivative dH_z/dz.
double loop_axis_H(double z) { return kNI * kLoopRadius * kLoopRadius / (2.0 * std::pow(kLoopRadius * kLoopRadius + z * z, 1.5)); }
double loop_axis_dH(double z) {
  return -1.5 * kNI * kLoopRadius * kLoopRadius * z / std::pow(kLoopRadius * kLoopRadius + z * z, 2.5);
}

double ball_volume() { return 4.0 / 3.0 * kPi * kBallRadius * kBallRadius * kBallRadius; }

// Body 0: an inert frame carrying the loop (at the origin, axis z, unless
// posed otherwise); body 1: a one-cell ball of the given material at x.
using CoilAndBall = test_support::MagneticSetup;

CoilAndBall coil_and_ball(const Material& ball, const Vec3& x) {
  CoilAndBall s;
  s.model.add_body("frame", Box{{0.01, 0.01, 0.01}}, InertMaterial{}, 0.0);
  s.model.add_coil(0, loop());
  s.model.add_body("ball", Sphere{kBallRadius}, ball, 0.0);
  s.state = make_state(s.model);
  s.state.pose[1].position = x;
  return s;
}

RelaxOptions tight() { return test_support::relax_options(1e-12); }

// A permanent ball on the axis: F_z = mu0 m dH_z/dz, the frame takes -F, and
// the Lorentz force on the loop's current elements in the ball's dipole field
// is the same -F (an independent quadrature: 1e-9 with 64 elements per turn).
TEST(AttachedCoil, ForceOnAMagnetOnTheAxisIsTheClosedFormAndReturnsToTheCoil) {
  const double Mz = 8e5;
  for (double z : {0.005, 0.02, 0.06}) {
    CoilAndBall s = coil_and_ball(PermanentMaterial{{0.0, 0.0, Mz}, 0.0}, {0.0, 0.0, z});
    magnetic_forces_at_held_magnetization(s.model, s.state, tight(), *s.backend);
    const double m = Mz * ball_volume();
    const double F_ref = kMu0 * m * loop_axis_dH(z);
    EXPECT_NEAR(s.state.force[1].z, F_ref, 1e-7 * std::fabs(F_ref)) << "z = " << z;
    EXPECT_NEAR(s.state.force[1].x, 0.0, 1e-9 * std::fabs(F_ref));
    EXPECT_NEAR(s.state.force[0].z, -F_ref, 1e-7 * std::fabs(F_ref));
    // The loop in the ball's field: F = sum I dl x B, B = mu0 T(r) m.
    const Vec3 mu{0.0, 0.0, m};
    const Wrench w = coil_wrench(
        loop(), [&](const Vec3& p) { return kMu0 * dipole_field(p - Vec3{0.0, 0.0, z}, mu, 0.0); }, Vec3{});
    EXPECT_NEAR(w.force.z, -F_ref, 1e-6 * std::fabs(F_ref)) << "Lorentz force on the loop, z = " << z;
  }
}

// Off the axis with a tilted moment: the pair's total force and total torque
// about the origin vanish (momentum and angular momentum conserved).
TEST(AttachedCoil, ClosedSystemHasZeroNetForceAndTorque) {
  CoilAndBall s = coil_and_ball(PermanentMaterial{{3e5, -2e5, 6e5}, 0.0}, {0.011, -0.004, 0.013});
  s.state.pose[0].position = {0.001, 0.002, -0.003};
  s.state.pose[0].rotation = test_support::axis_rotation({1.0, 2.0, 0.5}, 0.4);
  magnetic_forces_at_held_magnetization(s.model, s.state, tight(), *s.backend);
  const Vec3 F = s.state.force[0] + s.state.force[1];
  const Vec3 tau = s.state.torque[0] + cross(s.state.pose[0].position, s.state.force[0]) + s.state.torque[1] +
                   cross(s.state.pose[1].position, s.state.force[1]);
  EXPECT_LT(norm(F), 1e-12 * norm(s.state.force[1]));
  EXPECT_LT(norm(tau), 1e-12 * norm(s.state.torque[1]) + 1e-12 * norm(s.state.force[1]) * 0.02);
  EXPECT_GT(norm(s.state.torque[1]), 0.0);
}

// A soft ball (linear, chi = 100) at the loop's centre is magnetized by the
// coil alone: mu = V 3 chi / (chi + 3) H(0), H(0) = N I / (2 R); at half the
// current (magnetization_scale of the carrying body) half the moment; the
// coil's field is in field_at_points.
TEST(AttachedCoil, CoilMagnetizesASoftBallAndScalesWithItsBody) {
  const SoftMaterial iron = test_support::soft_material(1e12, 100.0);
  for (double scale : {1.0, 0.5}) {
    CoilAndBall s = coil_and_ball(iron, {0.0, 0.0, 0.0});
    s.state.magnetization_scale[0] = scale;
    ASSERT_TRUE(magnetic_step(s.model, s.state, tight(), *s.backend).converged);
    const double H0 = scale * kNI / (2.0 * kLoopRadius);
    const double M_ref = 3.0 * 100.0 / 103.0 * H0;
    EXPECT_NEAR(s.state.magnetization[0].z, M_ref, 1e-8 * M_ref);
    EXPECT_NEAR(s.state.magnetization[0].x, 0.0, 1e-8 * M_ref);
    std::vector<Vec3> B, H;
    field_at_points(s.model, s.state, *s.backend, {{0.0, 0.0, 0.05}}, B, H);
    // The coil's field plus the ball's dipole at 0.05 m.
    const double H_ref = scale * loop_axis_H(0.05) + M_ref * ball_volume() / (2.0 * kPi * std::pow(0.05, 3));
    EXPECT_NEAR(H[0].z, H_ref, 1e-9 * H_ref);
  }
}

// An iron ball passing through the wire of a 1000 ampere-turn loop (wire
// radius a = 0.5 mm, the default 1% of R = 5 cm): its force and torque stay
// bounded, |F| <= mu0 |mu| 3.3 N I / (2 pi a^2) (the bound of |grad H|,
// magnetics/coil_test.cpp FilamentWire) and |tau| <= mu0 |mu| N I / (2 pi a) +
// |r x F| over the positions across the wire, 1 um from the centre line
// included (with a wire of no thickness: 1.4e7 N there).
TEST(AttachedCoil, ForceOnABallPassingThroughTheWireStaysBounded) {
  const double R = 0.05, NI = 1000.0, a = 0.01 * R;
  const SoftMaterial iron = test_support::soft_material(1.7e6, 1000.0);
  double largest_F = 0.0, bound_F = 0.0;
  for (double d : {-2e-3, -6e-4, -4e-4, -2e-4, -1e-6, 0.0, 1e-6, 1e-5, 1e-4, 3e-4, 5e-4, 1e-3}) {
    CoilAndBall s;
    s.model.add_body("frame", Box{{0.01, 0.01, 0.01}}, InertMaterial{}, 0.0);
    CircularLoop l;
    l.radius = R;
    l.current = 100.0;
    l.turns = 10.0;
    s.model.add_coil(0, l);
    s.model.add_body("ball", Sphere{0.003}, iron, 0.0);
    s.state = make_state(s.model);
    s.state.pose[1].position = {R + 0.3 * d, 0.0, d};
    ASSERT_TRUE(magnetic_step(s.model, s.state, tight(), *s.backend).converged) << d;
    const double mu = norm(s.state.magnetization[0]) * ball_volume();
    const double F_bound = kMu0 * mu * 3.3 * NI / (2.0 * kPi * a * a);
    EXPECT_TRUE(is_finite(s.state.force[1]));
    EXPECT_LE(norm(s.state.force[1]), F_bound + 1e-12) << "d = " << d;
    EXPECT_LE(norm(s.state.torque[1]), kMu0 * mu * 1.1 * NI / (2.0 * kPi * a) + 1e-12) << "d = " << d;
    largest_F = std::max(largest_F, norm(s.state.force[1]));
    bound_F = std::max(bound_F, F_bound);
  }
  std::printf("measured: ball through a loop's wire, largest |F| %.3g N (bound %.3g N)\n", largest_F, bound_F);
}

// The coil moves with its body: a loop turned by 90 degrees about x (axis
// now -y) and shifted gives a ball on its new axis the same force, turned.
TEST(AttachedCoil, CoilMovesWithItsBody) {
  const Vec3 shift{0.01, 0.02, -0.03};
  const Mat3 R = test_support::axis_rotation({1.0, 0.0, 0.0}, 0.5 * kPi);
  const double z = 0.015, My = -7e5;  // moment along the turned axis
  CoilAndBall s = coil_and_ball(PermanentMaterial{{0.0, My, 0.0}, 0.0}, shift + R * Vec3{0.0, 0.0, z});
  s.state.pose[0].position = shift;
  s.state.pose[0].rotation = R;
  magnetic_forces_at_held_magnetization(s.model, s.state, tight(), *s.backend);
  const double F_ref = kMu0 * (-My) * ball_volume() * loop_axis_dH(z);  // along the turned axis -y
  const Vec3 expected = R * Vec3{0.0, 0.0, F_ref};
  EXPECT_LT(norm(s.state.force[1] - expected), 1e-7 * std::fabs(F_ref));
}

// F = -grad U with U from magnetic_energy, by central differences.
TEST(AttachedCoil, ForceIsMinusEnergyGradient) {
  const Vec3 x{0.007, 0.004, 0.012};
  CoilAndBall s = coil_and_ball(PermanentMaterial{{2e5, 1e5, 7e5}, 0.0}, x);
  magnetic_forces_at_held_magnetization(s.model, s.state, tight(), *s.backend);
  const Vec3 F = s.state.force[1];
  const double d = 1e-6;
  for (int k = 0; k < 3; ++k) {
    double U[2];
    for (int side = 0; side < 2; ++side) {
      CoilAndBall t = coil_and_ball(PermanentMaterial{{2e5, 1e5, 7e5}, 0.0}, x);
      t.state.pose[1].position[k] += side ? d : -d;
      place_cells(t.model, t.state);
      U[side] = magnetic_energy(t.model, t.state);
    }
    EXPECT_NEAR(F[k], -(U[1] - U[0]) / (2.0 * d), 1e-6 * norm(F)) << "component " << k;
  }
}

TEST(AttachedCoil, BadIndexOrGeometryThrows) {
  MagneticModel model;
  model.add_body("frame", Box{{0.01, 0.01, 0.01}}, InertMaterial{}, 0.0);
  EXPECT_THROW(model.add_coil(1, loop()), std::invalid_argument);
  CircularLoop bad = loop();
  bad.radius = -1.0;
  EXPECT_THROW(model.add_coil(0, bad), std::invalid_argument);
  EXPECT_TRUE(model.coils().empty());
}

}  // namespace
}  // namespace odemag
