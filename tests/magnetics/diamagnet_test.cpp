// Diamagnets and superconductors (docs/model.md "Diamagnets"): linear
// materials with negative susceptibility down to -1, as recoil cells with
// M_r = 0. References written in the tests (tests/support/contact_references.h):
// the exact multipole series of a linear sphere next to a point dipole, and
// its far limit chi_eff V grad(B^2) / (2 mu0) with chi_eff = 3 chi / (3 + chi)
// (the demagnetizing correction of a sphere).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <memory>
#include <stdexcept>

#include "magnetics/model/backend.h"
#include "magnetics/kernels/kernels.h"
#include "odemag/material.h"
#include "magnetics/model/model.h"
#include "magnetics/relax/relax.h"
#include "magnetics/model/state.h"
#include "tests/support/contact_references.h"
#include "tests/support/magnetic_setup.h"

namespace odemag {
namespace {

namespace ref = reference;

constexpr double kR = 0.005;  // both balls, m
const Vec3 kM{0.0, 0.0, 8e5};  // the magnet ball, A/m

using MagnetAndDiamagnet = test_support::MagneticSetup;

MagnetAndDiamagnet pair(double chi, const Vec3& x, double cell_size = 0.0) {
  MagnetAndDiamagnet p;
  p.model.add_body("magnet", Sphere{kR}, PermanentMaterial{kM, 0.0}, 0.0);
  p.model.add_body("diamagnet", Sphere{kR}, PermanentMaterial{{}, chi}, cell_size);
  p.state = make_state(p.model);
  p.state.pose[1].position = x;
  return p;
}

RelaxOptions tight() { return test_support::relax_options(1e-12); }

double ball_volume() { return 4.0 / 3.0 * kPi * kR * kR * kR; }

// Far from the magnet (5 .. 20 radii): the force is the induced dipole's,
// chi_eff V grad(B^2) / (2 mu0), B the magnet's dipole field; here by central
// differences of |B|^2 of the closed-form dipole field.
TEST(Diamagnet, FarForceIsChiEffVGradB2Over2Mu0) {
  const Vec3 m = ball_volume() * kM;
  for (double chi : {-1e-4, -0.5, -1.0})
    for (const Vec3& x : {Vec3{0.0, 0.0, 0.05}, Vec3{0.02, -0.01, 0.04}, Vec3{0.1, 0.0, 0.0}}) {
      MagnetAndDiamagnet p = pair(chi, x);
      ASSERT_TRUE(magnetic_step(p.model, p.state, tight(), *p.backend).converged);
      const double chi_eff = 3.0 * chi / (3.0 + chi);
      auto B2 = [&](const Vec3& y) {
        const Vec3 B = kMu0 * dipole_field(y, m, 0.0);
        return dot(B, B);
      };
      Vec3 F_ref;
      const double d = 1e-6;
      for (int k = 0; k < 3; ++k) {
        Vec3 e;
        e[k] = d;
        F_ref[k] = chi_eff * ball_volume() / (2.0 * kMu0) * (B2(x + e) - B2(x - e)) / (2.0 * d);
      }
      const Vec3 F = p.state.force[1];
      // Repelled: pushed away from the magnet, towards the weaker field.
      EXPECT_GT(dot(F, x), 0.0) << chi;
      // The missing l >= 2 orders and the magnet's field at the second order
      // in the small moment: (R/D)^3 relative at most (1e-3 at 10 R).
      const double D = norm(x);
      EXPECT_LT(norm(F - F_ref), 2.0 * std::pow(kR / D, 3) * norm(F_ref)) << "chi " << chi << " D/R " << D / kR;
      EXPECT_LT(norm(p.state.force[0] + F), 1e-12 * norm(F)) << "Newton's third law";
    }
}

// Near contact: against the exact series of a linear sphere next to a point
// dipole (all multipole orders), gaps 0.05 R .. 4 R on the axis and off it:
// the sphere near field solves the two-centre problem with gamma_l < 0
// (measured worst 9.8e-7; the issue asks 5%).
TEST(Diamagnet, NearForceMatchesTheExactSeries) {
  const Vec3 m = ball_volume() * kM;
  double worst = 0.0;
  for (double chi : {-0.5, -1.0})
    for (double gap : {0.05 * kR, 0.25 * kR, kR, 4.0 * kR})
      for (const Vec3& dir : {Vec3{0.0, 0.0, 1.0}, normalized(Vec3{1.0, 0.0, 1.0}), Vec3{1.0, 0.0, 0.0}}) {
        const Vec3 x = (2.0 * kR + gap) * dir;
        MagnetAndDiamagnet p = pair(chi, x);
        ASSERT_TRUE(magnetic_step(p.model, p.state, tight(), *p.backend).converged);
        const Vec3 F_ref = ref::linear_sphere_force_from_dipole(kR, chi, x, {}, m);
        worst = std::max(worst, norm(p.state.force[1] - F_ref) / norm(F_ref));
        EXPECT_LT(norm(p.state.force[1] - F_ref), 1e-4 * norm(F_ref))
            << "chi " << chi << " gap " << gap / kR << " R, direction " << dir.x << " " << dir.z << ": "
            << p.state.force[1].x << " " << p.state.force[1].z << " vs " << F_ref.x << " " << F_ref.z;
      }
  std::printf("diamagnetic ball next to a dipole, worst force error %.2e\n", worst);
}

// A lattice ball of a perfect diamagnet (chi = -1) in a uniform field: the
// outer iteration converges and the moment is the continuum sphere's,
// V 3 chi / (3 + chi) H = -1.5 V H, within the lattice's staircase error.
TEST(Diamagnet, LatticeSuperconductorBallExpelsTheField) {
  MagneticModel model;
  model.add_body("puck", Sphere{0.01}, PermanentMaterial{{}, -1.0}, 0.01 / 4);
  MagneticState state = make_state(model);
  state.external_field = {0.0, 0.0, 1e4};
  std::unique_ptr<MagneticBackend> backend = make_cpu_backend(1);
  const RelaxReport r = magnetic_step(model, state, tight(), *backend);
  ASSERT_TRUE(r.converged) << r.iterations;
  Vec3 mu;
  for (int c = 0; c < model.cell_count(); ++c) mu += model.cell_volume(c) * state.magnetization[c];
  const double mu_ref = -1.5 * (4.0 / 3.0 * kPi * 1e-6) * 1e4;
  std::printf("lattice superconductor ball: moment %.4f of the continuum sphere's, %d iterations\n", mu.z / mu_ref,
              r.iterations);
  EXPECT_NEAR(mu.z, mu_ref, 0.05 * std::fabs(mu_ref));
  EXPECT_NEAR(mu.x, 0.0, 1e-9 * std::fabs(mu_ref));
}

TEST(Diamagnet, ValidationNamesTheProblem) {
  EXPECT_NE(validate_material(PermanentMaterial{{}, -1.5}), "");
  EXPECT_NE(validate_material(PermanentMaterial{{0.0, 0.0, 1e5}, -0.5}), "");
  EXPECT_EQ(validate_material(PermanentMaterial{{}, -1.0}), "");
}

}  // namespace
}  // namespace odemag
