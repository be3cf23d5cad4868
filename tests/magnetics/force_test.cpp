// Forces and torques (docs/model.md "Forces and torques"; docs/hard-cases.md
// "Overlapping cells: the bounded core"):
// F = -grad U and tau = -dU/dtheta for fixed moments, zero net force and
// balanced angular momentum for a closed system, bounded overlap kernel.
#include <gtest/gtest.h>

#include <cmath>

#include "magnetics/model/backend.h"
#include "magnetics/kernels/kernels.h"
#include "magnetics/relax/relax.h"
#include "tests/support/magnetic_checks.h"

namespace odemag {
namespace {

using test_support::axis_rotation;

struct TwoMagnets {
  MagneticModel model;
  MagneticState state;
  std::unique_ptr<MagneticBackend> backend = make_cpu_backend(2);
  // Two permanent magnets on lattices, tilted, a few cell sizes apart.
  explicit TwoMagnets(double gap) {
    model.add_body("a", Box{{0.02, 0.01, 0.01}}, PermanentMaterial{{3e5, 1e5, 8e5}, 0.0}, 0.005);
    model.add_body("b", Cylinder{0.006, 0.012}, PermanentMaterial{{-2e5, 6e5, 1e5}, 0.0}, 0.004);
    state = make_state(model);
    state.pose[0].rotation = axis_rotation({1, 2, 3}, 0.4);
    state.pose[1].position = {0.013 + gap, 0.004, -0.003};
    state.pose[1].rotation = axis_rotation({-1, 0.5, 2}, 1.1);
  }
  double energy() {
    place_cells(model, state);
    return magnetic_energy(model, state);
  }
  void forces() {
    place_cells(model, state);
    backend->begin_step(model, state);
    backend->forces(model, state);
  }
};

// Central differences of the pair energy against the computed force and torque
// on body b (relative 1e-6 of the magnitude).
void check_gradient(TwoMagnets& sys) {
  sys.forces();
  const Vec3 F = sys.state.force[1], T = sys.state.torque[1];
  ASSERT_GT(norm(F), 0.0);
  auto energy = [&] { return sys.energy(); };
  const double dx = 1e-7;
  const Vec3 dF = test_support::minus_position_gradient(sys.state.pose[1], energy, dx);
  for (int a = 0; a < 3; ++a) EXPECT_NEAR(F[a], dF[a], 1e-6 * norm(F)) << "force axis " << a;
  const double dtheta = 1e-6;
  const Vec3 dT = test_support::minus_rotation_gradient(sys.state.pose[1], energy, dtheta);
  for (int a = 0; a < 3; ++a) EXPECT_NEAR(T[a], dT[a], 1e-6 * norm(T)) << "torque axis " << a;
}

TEST(Forces, AreMinusEnergyGradientApart) {
  TwoMagnets sys(0.01);
  check_gradient(sys);
}

TEST(Forces, AreMinusEnergyGradientWhenCellsOverlap) {
  // Bodies interpenetrate: cell spheres of the two bodies overlap, the bounded
  // kernel applies, and the forces are still the energy's gradient.
  TwoMagnets sys(-0.008);
  check_gradient(sys);
}

TEST(Forces, ClosedSystemHasZeroNetForceAndBalancedTorque) {
  MagneticModel model;
  model.add_body("magnet", Box{{0.03, 0.01, 0.01}}, PermanentMaterial{{8e5, 0, 0}, 0.0}, 0.005);
  SoftMaterial iron;
  iron.saturation = 1.7e6;
  iron.susceptibility = 5000;
  model.add_body("plate", Box{{0.02, 0.02, 0.004}}, iron, 0.004);
  model.add_body("ball", Sphere{0.004}, iron, 0.0);
  SoftMaterial nail = iron;
  nail.anisotropy_field = 8e5;
  nail.easy_axis = {0, 0, 1};
  model.add_body("nail", Cylinder{0.002, 0.02}, nail, 0.002);
  MagneticState state = make_state(model);
  state.pose[0].position = {0, 0, 0.03};
  state.pose[1].position = {0.004, 0.002, 0.015};
  state.pose[1].rotation = axis_rotation({1, 1, 0}, 0.3);
  state.pose[2].position = {-0.01, 0.003, 0.005};
  state.pose[3].position = {0.02, -0.01, 0.02};
  state.pose[3].rotation = axis_rotation({0, 1, 0}, 0.7);
  auto backend = make_cpu_backend(2);
  const RelaxReport r = magnetic_step(model, state, RelaxOptions{}, *backend);
  EXPECT_TRUE(r.converged);
  // Angular momentum balance about the origin: sum of x_b x F_b + tau_b.
  const test_support::NetForceAndTorque net = test_support::net_force_and_torque(model, state);
  ASSERT_GT(net.force_scale, 0.0);
  EXPECT_LT(norm(net.force), 1e-12 * net.force_scale);
  EXPECT_LT(norm(net.torque), 1e-12 * net.torque_scale);
}

TEST(Forces, UniformFieldGivesTorqueButNoForce) {
  MagneticModel model;
  model.add_body("m", Box{{0.02, 0.01, 0.01}}, PermanentMaterial{{8e5, 0, 0}, 0.0}, 0.005);
  MagneticState state = make_state(model);
  state.external_field = {0, 2e4, 0};
  auto backend = make_cpu_backend(1);
  magnetic_step(model, state, RelaxOptions{}, *backend);
  const Vec3 mu = body_moment(model, state, 0);
  EXPECT_EQ(norm(state.force[0]), 0.0);
  const Vec3 expected = kMu0 * cross(mu, state.external_field);
  EXPECT_LT(norm(state.torque[0] - expected), 1e-12 * norm(expected));
}

// docs/hard-cases.md "Overlapping cells: the bounded core": two one-cell
// magnets swept from three contact radii to coincident: the force stays finite
// and continuous and equals the exact dipole force beyond contact.
TEST(Forces, OverlapSweepIsBoundedContinuousAndExactBeyondContact) {
  const double R = 0.005, s = 2 * R;
  const Vec3 mu_a{0.1, 0.05, 0.3}, mu_b{-0.2, 0.1, 0.25};
  const Vec3 dir = normalized(Vec3{0.3, -0.2, 1.0});
  Vec3 previous;
  double largest_jump = 0.0, largest = 0.0;
  const int steps = 3000;
  for (int i = steps; i >= 0; --i) {
    const double r = 3.0 * s * i / steps;
    const Vec3 F = dipole_force(r * dir, mu_a, mu_b, s * s);
    ASSERT_TRUE(is_finite(F)) << "r=" << r;
    if (r >= s) {
      const Vec3 exact = dipole_force(r * dir, mu_a, mu_b, 0.0);
      EXPECT_LT(norm(F - exact), 1e-12 * norm(exact)) << "r=" << r;
    }
    if (i < steps) largest_jump = std::max(largest_jump, norm(F - previous));
    largest = std::max(largest, norm(F));
    previous = F;
  }
  // Continuity: no step of the sweep changes the force by more than a small
  // multiple of (largest force) * (step / contact distance).
  EXPECT_LT(largest_jump, 20.0 * largest * (3.0 / steps));
  // Bounded: the largest force is of the order of the contact force.
  const Vec3 contact = dipole_force(s * dir, mu_a, mu_b, 0.0);
  EXPECT_LT(largest, 10.0 * (norm(contact) + 3 * kMu0 * norm(mu_a) * norm(mu_b) / (4 * kPi * std::pow(s, 4))));
}

}  // namespace
}  // namespace odemag
