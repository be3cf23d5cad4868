// Near field of one-cell spheres (magnetics/near_field/sphere_near_field.cpp,
// docs/model.md "The near field"): forces between a one-cell soft ball and a
// magnet ball, and between two one-cell soft balls in a uniform field,
// against the exact linear solutions of tests/support/contact_references.h
// (written independently of the engine); continuity down to contact and
// through overlap; F = -grad U; saturation; the switch.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "magnetics/model/backend.h"
#include "magnetics/relax/relax.h"
#include "tests/support/contact_references.h"
#include "tests/support/energy_gradient.h"
#include "tests/support/magnetic_checks.h"
#include "tests/support/magnetic_setup.h"

namespace odemag {
namespace {

constexpr double kR = 0.01;  // ball radius, m

RelaxOptions tight(bool near_field = true) { return test_support::relax_options(1e-10, near_field); }

// Saturation far above any field here: linear.
SoftMaterial linear_iron(double chi) { return test_support::soft_material(1e12, chi); }

using test_support::axis_rotation;

struct Pair : test_support::MagneticSetup {
  RelaxReport solve(const RelaxOptions& o) { return magnetic_step(model, state, o, *backend); }
};

// A permanent ball (magnetization M along direction dir) at the origin and a
// soft ball at centre distance D along `axis`.
Pair magnet_and_ball(double chi, double D, const Vec3& axis, const Vec3& magnetization) {
  Pair p;
  p.model.add_body("magnet", Sphere{kR}, PermanentMaterial{magnetization, 0.0}, 0.0);
  p.model.add_body("ball", Sphere{kR}, linear_iron(chi), 0.0);
  p.state = make_state(p.model);
  p.state.pose[1].position = D * normalized(axis);
  return p;
}

double rel(const Vec3& a, const Vec3& b) { return norm(a - b) / norm(b); }

// A one-cell soft ball next to a magnet ball: the exact force on a linear
// sphere in a point dipole's field (the magnet ball's field outside it),
// axial, transverse and oblique magnetization, chi 10 .. 1e4, gaps 0.05 R ..
// 4 R. Asked: within 5%; the two-centre solve is exact here (the magnet has
// no higher orders), so the tolerance is 1e-4 (measured <= 2e-6).
TEST(SphereNearField, BallNextToMagnetBallHasTheExactForce) {
  double worst = 0.0, worst_dipole_only = 0.0;
  for (double chi : {10.0, 100.0, 1000.0, 1e4})
    for (double gap : {0.05, 0.1, 0.25, 0.5, 1.0, 2.0, 4.0})
      for (const Vec3 dir : {Vec3{0, 0, 1}, Vec3{1, 0, 0}, Vec3{0.6, 0.3, 0.74}}) {
        const double D = 2 * kR + gap * kR;
        const Vec3 axis{0.2, -0.3, 0.93};
        const Vec3 M = 8e5 * normalized(dir);
        const Vec3 m = (4.0 / 3.0 * kPi * kR * kR * kR) * M;
        const Vec3 exact = reference::linear_sphere_force_from_dipole(kR, chi, D * normalized(axis), {}, m);
        Pair p = magnet_and_ball(chi, D, axis, M);
        ASSERT_TRUE(p.solve(tight()).converged);
        const double e = rel(p.state.force[1], exact);
        EXPECT_LT(e, 1e-4) << "chi " << chi << " gap " << gap << " dir " << dir.x;
        worst = std::max(worst, e);
        Pair q = magnet_and_ball(chi, D, axis, M);
        ASSERT_TRUE(q.solve(tight(false)).converged);
        worst_dipole_only = std::max(worst_dipole_only, rel(q.state.force[1], exact));
        // Newton's third law for the pair.
        EXPECT_LT(norm(p.state.force[0] + p.state.force[1]), 1e-9 * norm(exact));
      }
  std::printf("[odemag] one-cell ball next to a magnet ball: worst force error %.2e (dipoles only: %.2e)\n", worst,
              worst_dipole_only);
}

// Two one-cell soft balls in a uniform field, along and across the line of
// centres and oblique, against the two-centre re-expansion of the reference
// (to convergence). Asked: within 5% at every gap from 0.05 R to 4 R; the
// engine's solve (order 48, splines) is tested to 1e-3: measured 2.4e-6 for
// equal balls; for unequal balls (0.6 R, chi 50, next to chi) at a gap of
// 4 R the pair is in the taper (x = d / (R_a + R_b) = 3.5 > 3), 2.2e-4.
TEST(SphereNearField, TwoBallsInUniformFieldMatchTheExactSolution) {
  double worst = 0.0, worst_dipole_only = 0.0;
  for (double chi : {10.0, 100.0, 1000.0, 1e4})
    for (double gap : {0.05, 0.1, 0.25, 0.5, 1.0, 2.0, 4.0})
      for (const Vec3 dir : {Vec3{0, 0, 1}, Vec3{1, 0, 0}, Vec3{0.5, 0, 0.8}}) {
        const Vec3 H0 = 1e3 * normalized(dir);
        const Vec3 xb{0, 0, 2 * kR + gap * kR};
        for (bool unequal : {false, true}) {
        const double R2 = unequal ? 0.6 * kR : kR, chi2 = unequal ? 50.0 : chi;
        const Vec3 x2{0, 0, kR + R2 + gap * kR};
        const reference::TwoSphereResult exact =
            reference::two_linear_spheres_in_uniform_field(kR, chi, R2, chi2, {}, unequal ? x2 : xb, H0);
        ASSERT_TRUE(std::isfinite(exact.force_on_2.z)) << "reference did not converge";
        for (bool near : {true, false}) {
          Pair p;
          p.model.add_body("a", Sphere{kR}, linear_iron(chi), 0.0);
          p.model.add_body("b", Sphere{R2}, linear_iron(chi2), 0.0);
          p.state = make_state(p.model);
          p.state.pose[1].position = unequal ? x2 : xb;
          p.state.external_field = H0;
          ASSERT_TRUE(p.solve(tight(near)).converged);
          const double e = rel(p.state.force[1], exact.force_on_2);
          if (near) {
            EXPECT_LT(e, 1e-3) << "chi " << chi << " gap " << gap << " dir " << dir.x << " unequal " << unequal;
            EXPECT_LT(rel(body_moment(p.model, p.state, 1), exact.moment_2), 1e-3);
            EXPECT_LT(rel(body_moment(p.model, p.state, 0), exact.moment_1), 1e-3);
            worst = std::max(worst, e);
          } else {
            worst_dipole_only = std::max(worst_dipole_only, e);
          }
        }
        }
      }
  std::printf("[odemag] two one-cell balls in a uniform field: worst force error %.2e (dipoles only: %.2e)\n", worst,
              worst_dipole_only);
}

// Force along the line of centres from 0.05 R down to contact and through
// overlap to coincident centres: finite everywhere, and continuous: at every
// sample (and at contact, where the overlap continuation begins) a step of
// 1e-7 R changes the force by less than 1e-4 of the largest force (a jump
// of the correction's size would be tens of percent).
TEST(SphereNearField, ForceIsFiniteAndContinuousDownToContactAndThroughOverlap) {
  for (double chi : {10.0, 1000.0, 1e4})
    for (const Vec3 H0 : {Vec3{0, 0, 1e3}, Vec3{1e3, 0, 0}}) {
      auto force = [&](double D) {
        Pair p;
        p.model.add_body("a", Sphere{kR}, linear_iron(chi), 0.0);
        p.model.add_body("b", Sphere{kR}, linear_iron(chi), 0.0);
        p.state = make_state(p.model);
        p.state.pose[1].position = {0, 0, D};
        p.state.external_field = H0;
        p.solve(tight());
        return p.state.force[1].z;
      };
      std::vector<double> D;
      for (int i = 0; i <= 100; ++i) D.push_back((2.05 - 2.05 * i / 100) * kR);  // 2.05 R .. 0
      D.push_back(2.0 * kR);                                                   // contact
      D.push_back(2.0 * kR * (1.0 - 1e-3));
      std::vector<double> F;
      double largest = 0.0;
      for (double d : D) {
        F.push_back(force(d));
        ASSERT_TRUE(std::isfinite(F.back())) << "D/R " << d / kR;
        largest = std::max(largest, std::fabs(F.back()));
      }
      for (size_t i = 0; i < D.size(); ++i) {
        const double step = 1e-7 * kR;
        EXPECT_LT(std::fabs(force(D[i] + step) - F[i]), 1e-4 * largest)
            << "chi " << chi << " D/R " << D[i] / kR;
      }
    }
}

// F = -grad U (central differences of magnetic_energy, which includes the
// near-field energy) on each body, and tau = -dU/dtheta on the magnet ball
// (relaxed isotropic soft balls carry no torque), for a magnet ball and two
// soft balls at contact distances with frozen moments, relative 1e-6.
TEST(SphereNearField, ForcesAndTorquesAreMinusEnergyGradient) {
  Pair p;
  p.model.add_body("magnet", Sphere{kR}, PermanentMaterial{{2e5, 1e5, 7e5}, 0.0}, 0.0);
  p.model.add_body("a", Sphere{kR}, linear_iron(1000), 0.0);
  p.model.add_body("b", Sphere{0.7 * kR}, linear_iron(50), 0.0);
  p.state = make_state(p.model);
  p.state.pose[1].position = {0.003, 0.001, 2.1 * kR};
  p.state.pose[2].position = {0.004, 0.0165, 2.3 * kR};
  p.state.pose[2].rotation = axis_rotation({1, 2, 3}, 0.7);
  p.state.external_field = {0, 2e3, 1e3};
  ASSERT_TRUE(p.solve(tight()).converged);
  for (int body : {0, 1, 2}) {
    place_cells(p.model, p.state);
    p.backend->begin_step(p.model, p.state);
    p.backend->forces(p.model, p.state);
    const Vec3 F = p.state.force[body], T = p.state.torque[body];
    test_support::expect_force_is_minus_energy_gradient(p.model, p.state, body, F, 1e-8);
    if (body != 0) continue;
    ASSERT_GT(norm(T), 0.0);
    test_support::expect_torque_is_minus_energy_gradient(p.model, p.state, body, T, 1e-6);
  }
}

// A closed system (no H_E): net force zero, total torque about the origin
// zero (angular momentum balanced), with the near field acting.
TEST(SphereNearField, ClosedSystemHasZeroNetForceAndTorque) {
  Pair p;
  p.model.add_body("magnet", Sphere{kR}, PermanentMaterial{{0, 3e5, 8e5}, 0.0}, 0.0);
  p.model.add_body("a", Sphere{kR}, linear_iron(1000), 0.0);
  p.model.add_body("b", Sphere{kR}, linear_iron(1000), 0.0);
  p.state = make_state(p.model);
  p.state.pose[1].position = {0.002, 0, 2.05 * kR};
  p.state.pose[2].position = {0.004, 0.003, 4.15 * kR};
  ASSERT_TRUE(p.solve(tight()).converged);
  const test_support::NetForceAndTorque net = test_support::net_force_and_torque(p.model, p.state);
  EXPECT_LT(norm(net.force), 1e-10 * net.force_scale);
  EXPECT_LT(norm(net.torque), 1e-10 * net.force_scale * kR);
}

// Carried-over pairs (magnetics/near_field/sphere_near_field.cpp): a soft ball 0.1 R
// from a magnet ball, magnetization held, moved by 0.9 of the reuse
// tolerance (1e-2 of the gap) keeps its pair's last evaluation carried to
// second order: force within 2e-5 and torque within 2e-8 of a fresh
// evaluation (measured 6.4e-6 and 6.1e-9; at a tenth of the move 6.4e-8 and
// 6.1e-12: the force's error is O(tolerance^2) of the correction, which is
// about half the force here, the field's O(tolerance^3); both far below the
// relaxation's tolerance), not bit-equal (so it was carried); moved back, it
// is bit-equal to the first evaluation; moved past the tolerance, bit-equal
// to a fresh one.
TEST(SphereNearField, PairsCarriedOverWithinTheToleranceMatchAFreshEvaluation) {
  Pair p = magnet_and_ball(1000, 2.1 * kR, {0.2, 0.3, 1.0}, {2e5, 1e5, 7e5});
  ASSERT_TRUE(p.solve(tight()).converged);
  const Vec3 x0 = p.state.pose[1].position;
  const double gap = norm(x0) - 2.0 * kR;
  const Vec3 move =
      0.9e-2 * gap * normalized(x0);  // along the line of centres: d changes by all of it
  auto kept = [&](const Vec3& x, Vec3& F, Vec3& T) {
    p.state.pose[1].position = x;
    magnetic_forces_at_held_magnetization(p.model, p.state, tight(), *p.backend);
    F = p.state.force[1];
    T = p.state.torque[0];
  };
  auto fresh = [&](const Vec3& x, Vec3& F, Vec3& T) {
    const MagneticModel model = p.model;  // a copy: a new model generation, nothing to carry
    MagneticState state = p.state;
    state.pose[1].position = x;
    const std::unique_ptr<MagneticBackend> backend = make_cpu_backend(1);
    magnetic_forces_at_held_magnetization(model, state, tight(), *backend);
    F = state.force[1];
    T = state.torque[0];
  };
  Vec3 F0, T0, F, T, F_ref, T_ref;
  kept(x0, F0, T0);
  kept(x0 + move, F, T);
  fresh(x0 + move, F_ref, T_ref);
  std::printf("carried over %.2e of the gap: force %.2e, torque %.2e of a fresh evaluation\n", norm(move) / gap,
              rel(F, F_ref), rel(T, T_ref));
  ASSERT_GT(norm(T_ref), 0.0);
  EXPECT_NE(F.z, F_ref.z);  // carried over, not evaluated again
  EXPECT_LT(rel(F, F_ref), 2e-5);
  EXPECT_LT(rel(T, T_ref), 2e-8);
  kept(x0, F, T);
  EXPECT_EQ(F.x, F0.x);
  EXPECT_EQ(F.z, F0.z);
  EXPECT_EQ(T.y, T0.y);
  const Vec3 far = x0 + 1.2e-2 * gap * normalized(x0);
  kept(far, F, T);
  fresh(far, F_ref, T_ref);
  EXPECT_EQ(F.x, F_ref.x);
  EXPECT_EQ(F.y, F_ref.y);
  EXPECT_EQ(F.z, F_ref.z);
  EXPECT_EQ(T.x, T_ref.x);
}

// The pair list (magnetics/near_field/sphere_near_field.cpp): pairs within (4 + 0.2)
// (R_a + R_b), made anew once a sphere has moved 0.2 R_min. A soft ball
// starts beyond it (4.5 (R_a + R_b) from a magnet ball: no correction) and
// comes in along a line in steps of 0.13 R, wobbling across it,
// magnetization held (relaxed at 2.5 R), to 0.1 R from contact, then goes
// back out; at every step its force and the
// magnet's torque match a fresh backend's within the carry-over's error
// (each step is past the carry tolerance near contact, below it far out).
// A list that was not made anew would miss the pair on the way in (the
// force would be the point dipoles', off by up to half); one that kept a
// pair past the cutoff would keep a correction the fresh backend has not.
TEST(SphereNearField, PairListFollowsAMovingBall) {
  Pair p = magnet_and_ball(1000, 2.5 * kR, {0.2, 0.3, 1.0}, {2e5, 1e5, 7e5});
  ASSERT_TRUE(p.solve(tight()).converged);  // the soft ball's magnetization, then held
  const Vec3 axis = normalized(Vec3{0.2, 0.3, 1.0}),
             side = normalized(cross(axis, Vec3{1.0, 0.0, 0.0}));
  auto force_at = [&](MagneticModel& model, MagneticState& state, MagneticBackend& backend,
                      const Vec3& x, Vec3& F, Vec3& T) {
    state.pose[1].position = x;
    magnetic_forces_at_held_magnetization(model, state, tight(), backend);
    F = state.force[1];
    T = state.torque[0];
  };
  std::vector<double> distances;  // centre distance / R
  for (double D = 9.0; D > 2.1; D -= 0.13) distances.push_back(D);
  for (int i = static_cast<int>(distances.size()) - 1; i >= 0; --i)
    distances.push_back(distances[i]);
  double worst_F = 0.0, worst_T = 0.0, largest_correction = 0.0;
  for (std::size_t k = 0; k < distances.size(); ++k) {
    // Off the line of centres a little, so that the direction turns too.
    const Vec3 x =
        distances[k] * kR * axis + 0.02 * kR * std::sin(0.7 * static_cast<double>(k)) * side;
    Vec3 F, T, F_ref, T_ref, F_dipole;
    force_at(p.model, p.state, *p.backend, x, F, T);
    {
      MagneticModel model = p.model;  // a copy: a new generation, nothing carried over
      MagneticState state = p.state;
      const std::unique_ptr<MagneticBackend> backend = make_cpu_backend(1);
      force_at(model, state, *backend, x, F_ref, T_ref);
      MagneticState plain = p.state;  // the point dipoles alone
      plain.pose[1].position = x;
      magnetic_forces_at_held_magnetization(model, plain, tight(false), *make_cpu_backend(1));
      F_dipole = plain.force[1];
    }
    worst_F = std::max(worst_F, rel(F, F_ref));
    worst_T = std::max(worst_T, norm(T - T_ref) / std::max(norm(T_ref), 1e-30));
    largest_correction = std::max(largest_correction, rel(F_dipole, F_ref));
    ASSERT_LT(rel(F, F_ref), 1e-4) << "at " << distances[k] << " R, step " << k;
  }
  std::printf(
      "ball in and out over %zu steps: force within %.2e, torque within %.2e of a fresh evaluation "
      "(the correction: up to %.2f of the force)\n",
      distances.size(), worst_F, worst_T, largest_correction);
  EXPECT_GT(largest_correction, 0.1);  // the correction matters at the closest steps
  EXPECT_LT(worst_T, 1e-6);
}

// Pairs of two held cells (RelaxOptions::held_bodies) are left out of the
// field sums at the build (nothing reads their fields); once the backend
// holds nothing again, before any new build, the sums take every pair
// again. Three touching soft balls, b and c held: a's field is the same to
// the last bit as with nothing held, and after the held set is cleared
// every cell's field is a fresh backend's, bit for bit (a sum that kept
// leaving out the pair b-c would miss its correction at b and c).
TEST(SphereNearField, PairsOfHeldCellsAreLeftOutOnlyWhileHeld) {
  MagneticModel model;
  for (const char* name : {"a", "b", "c"}) model.add_body(name, Sphere{kR}, linear_iron(1000), 0.0);
  MagneticState state = make_state(model);
  state.pose[1].position = {2.1 * kR, 0.0, 0.0};
  state.pose[2].position = {4.2 * kR, 0.1 * kR, 0.0};
  state.external_field = {1e3, 0.0, 3e2};
  ASSERT_TRUE(magnetic_step(model, state, tight(), *make_cpu_backend(1)).converged);
  auto fields = [&](MagneticBackend& backend, bool build) {
    if (build) backend.begin_step(model, state);
    std::vector<Vec3> H(model.cell_count());
    backend.responsive_field(model, state, H);
    return H;
  };
  const std::unique_ptr<MagneticBackend> fresh = make_cpu_backend(1), held = make_cpu_backend(1);
  fresh->set_near_field(true, true);
  held->set_near_field(true, true);
  const std::vector<Vec3> H_ref = fields(*fresh, true);
  ASSERT_TRUE(held->set_held_bodies({0, 1, 1}));
  const std::vector<Vec3> H_held = fields(*held, true);
  EXPECT_EQ(H_held[0].x, H_ref[0].x);
  EXPECT_EQ(H_held[0].y, H_ref[0].y);
  EXPECT_EQ(H_held[0].z, H_ref[0].z);
  held->set_held_bodies({});
  const std::vector<Vec3> H_after = fields(*held, false);
  for (int c = 0; c < 3; ++c) {
    EXPECT_EQ(H_after[c].x, H_ref[c].x) << "cell " << c;
    EXPECT_EQ(H_after[c].y, H_ref[c].y) << "cell " << c;
    EXPECT_EQ(H_after[c].z, H_ref[c].z) << "cell " << c;
  }
  // The pair b-c carries a correction of its own: without the near field
  // the field at b differs.
  const std::unique_ptr<MagneticBackend> plain = make_cpu_backend(1);
  plain->set_near_field(false, true);
  EXPECT_GT(norm(fields(*plain, true)[1] - H_ref[1]), 1e-3 * norm(H_ref[1]));
}

// A saturated ball is uniformly magnetized: exactly a dipole, so the
// correction must vanish; unsaturated but with a saturating contact point it
// is scaled down (between the dipole and the linear force).
TEST(SphereNearField, SaturationTurnsTheCorrectionOff) {
  SoftMaterial steel;
  steel.saturation = 1.6e6;
  steel.susceptibility = 1000;
  const double D = 2.1 * kR;
  auto force = [&](double H, bool near) {
    Pair p;
    p.model.add_body("a", Sphere{kR}, steel, 0.0);
    p.model.add_body("b", Sphere{kR}, steel, 0.0);
    p.state = make_state(p.model);
    p.state.pose[1].position = {0, 0, D};
    p.state.external_field = {0, 0, H};
    EXPECT_TRUE(p.solve(tight(near)).converged);
    return p.state.force[1].z;
  };
  // Saturated (H far above gamma_D Ms): the same force with and without.
  EXPECT_NEAR(force(5e6, true), force(5e6, false), 1e-9 * std::fabs(force(5e6, false)));
  // Weak field: the linear enhancement (2.78 at 0.1 R for chi = 1000).
  const double weak = force(1e3, true) / force(1e3, false);
  EXPECT_GT(weak, 2.7);
  // Strong but unsaturated field: less enhancement than the linear one.
  const double strong = force(2e5, true) / force(2e5, false);
  EXPECT_GT(strong, 1.0);
  EXPECT_LT(strong, weak);
}

// Without mutual induction induced balls feel only fixed magnets: two soft
// balls in a uniform field keep their Clausius-Mossotti moments and interact
// as dipoles; a ball next to a magnet ball still gets the magnet's exact
// (induced) force.
TEST(SphereNearField, WithoutMutualInductionOnlyFixedMagnetsInduceHigherOrders) {
  auto force = [](bool near) {
    Pair p;
    p.model.add_body("a", Sphere{kR}, linear_iron(1000), 0.0);
    p.model.add_body("b", Sphere{kR}, linear_iron(1000), 0.0);
    p.state = make_state(p.model);
    p.state.pose[1].position = {0, 0, 2.1 * kR};
    p.state.external_field = {0, 0, 1e3};
    RelaxOptions o = tight(near);
    o.mutual_induction = false;
    EXPECT_TRUE(p.solve(o).converged);
    return p.state.force[1];
  };
  EXPECT_LT(norm(force(true) - force(false)), 1e-12 * norm(force(false)));
  const Vec3 M{0, 0, 8e5};
  Pair p = magnet_and_ball(1000, 2.1 * kR, {0, 0, 1}, M);
  RelaxOptions o = tight();
  o.mutual_induction = false;
  ASSERT_TRUE(p.solve(o).converged);
  const Vec3 m = (4.0 / 3.0 * kPi * kR * kR * kR) * M;
  EXPECT_LT(rel(p.state.force[1], reference::linear_sphere_force_from_dipole(kR, 1000, {0, 0, 2.1 * kR}, {}, m)),
            1e-4);
}

// near_field = false is the paper's point-dipole model: the force on a
// soft ball next to a magnet ball is the dipole force of its
// Clausius-Mossotti moment.
TEST(SphereNearField, SwitchedOffGivesThePointDipoleForce) {
  const double chi = 1000, D = 2.1 * kR;
  const Vec3 M{0, 0, 8e5};
  Pair p = magnet_and_ball(chi, D, {0, 0, 1}, M);
  ASSERT_TRUE(p.solve(tight(false)).converged);
  const double V = 4.0 / 3.0 * kPi * kR * kR * kR, m = V * M.z;
  const double gamma_1 = chi / (chi + 3.0);  // (mu - 1) / (mu + 2)
  // Induced moment 4 pi R^3 gamma_1 H, H = 2 m / (4 pi D^3); F = 3 mu0 m p / (2 pi D^4).
  const double p_ind = 4 * kPi * kR * kR * kR * gamma_1 * 2 * m / (4 * kPi * D * D * D);
  const double F = -3 * kMu0 * m * p_ind / (2 * kPi * D * D * D * D);
  EXPECT_NEAR(p.state.force[1].z, F, 1e-8 * std::fabs(F));
}

}  // namespace
}  // namespace odemag
