// Refined contact zones (docs/model.md "Refined contact zones"): a lattice
// ball whose cells near a point are split into cubes of h/2, h/4, h/8
// (make_refined_cells, MagneticModel::add_body with zones). Checked against
// independent references written in the tests: the ball's volume, the
// continuum sphere's moment in a uniform field, and the two-centre series of
// two linear spheres in a uniform field (tests/support/contact_references.h).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <set>
#include <stdexcept>
#include <vector>

#include "magnetics/model/backend.h"
#include "magnetics/model/body_response.h"
#include "magnetics/cells/cells.h"
#include "odemag/constants.h"
#include "magnetics/model/model.h"
#include "magnetics/relax/relax.h"
#include "magnetics/model/state.h"
#include "tests/support/contact_references.h"

namespace odemag {
namespace {

constexpr double kR = 0.005;

SoftMaterial linear_soft(double chi) {
  SoftMaterial mat;
  mat.saturation = 1e12;  // linear at these fields
  mat.susceptibility = chi;
  return mat;
}

// 1. Geometry: the cells' volumes add up to the ball; without zones the cells
// are make_cells'; the cubes nest (each cube's centre lies on the lattice of
// its own edge), do not overlap (their cube volumes add up to no more than
// the lattice's cubes), and the cells at the point are h/8 cubes.
TEST(RefinedZone, CellsTileTheBallOnNestedLattices) {
  const double h = kR / 4.0;
  const Sphere ball{kR};
  const CellSet plain = make_cells(ball, h);
  const CellSet none = make_refined_cells(ball, h, {});
  ASSERT_EQ(none.size(), plain.size());
  for (int i = 0; i < plain.size(); ++i) {
    EXPECT_EQ(none.volumes[i], plain.volumes[i]);
    EXPECT_EQ(norm(none.local_positions[i] - plain.local_positions[i]), 0.0);
    EXPECT_EQ(norm(none.cube_centre(i) - plain.cube_centre(i)), 0.0);
  }
  const Vec3 P{0, 0, kR};
  const CellSet cells = make_refined_cells(ball, h, {{P, default_refinement_radii(h)}});
  EXPECT_TRUE(cells.refined);
  EXPECT_TRUE(cells.mixed_sizes());
  EXPECT_LE(cells.size(), 1000);
  EXPECT_GT(cells.size(), plain.size());
  double volume = 0.0, cubes = 0.0;
  std::set<double> edges;
  for (int i = 0; i < cells.size(); ++i) {
    volume += cells.volumes[i];
    const Vec3 half = cells.cube_half(i);
    const double a = 2.0 * half.x;
    cubes += a * a * a;
    edges.insert(a);
    EXPECT_LE(cells.volumes[i], a * a * a * (1.0 + 1e-12));
    // On the lattice of edge a, whose sites sit at odd multiples of a/2 (the
    // coarse lattice has an even number of points per axis here).
    for (int k = 0; k < 3; ++k) {
      const double u = cells.cube_centre(i)[k] / (0.5 * a);
      EXPECT_NEAR(u, std::round(u), 1e-9) << "cell " << i;
      EXPECT_EQ(std::lround(u) % 2 != 0, true) << "cell " << i;
    }
    // The centroid lies in its cube.
    for (int k = 0; k < 3; ++k)
      EXPECT_LE(std::abs(cells.local_positions[i][k] - cells.cube_centre(i)[k]),
                half[k] * (1.0 + 1e-12));
  }
  EXPECT_NEAR(volume, 4.0 / 3.0 * kPi * kR * kR * kR, 1e-12 * kR * kR * kR);
  EXPECT_LE(cubes, static_cast<double>(plain.size()) * h * h * h * (1.0 + 1e-12));
  EXPECT_EQ(edges.size(), 4u);
  EXPECT_NEAR(*edges.begin(), h / 8.0, 1e-15);
  // The finest cells are those nearest the point.
  double nearest = 1e9;
  int nearest_cell = -1;
  for (int i = 0; i < cells.size(); ++i)
    if (norm(cells.local_positions[i] - P) < nearest)
      nearest = norm(cells.local_positions[i] - P), nearest_cell = i;
  EXPECT_NEAR(2.0 * cells.cube_half(nearest_cell).x, h / 8.0, 1e-15);
}

// 2. Bad zones are refused with a message naming the body: a body less than
// two cells across along some axis (no volume-share cells), bad radii or
// points, too many levels, a one-cell body, point-dipole tensors.
TEST(RefinedZone, BadZonesAreRefused) {
  MagneticModel model;
  const double h = kR / 4.0;
  const Box sheet{{0.01, 0.01, 1.5 * h}};
  EXPECT_THROW(model.add_body("box", sheet, linear_soft(100), h, {{{0, 0, 0}, {h}}}), std::invalid_argument);
  EXPECT_THROW(model.add_body("ball", Sphere{kR}, linear_soft(100), h, {{{0, 0, 0}, {-h}}}),
               std::invalid_argument);
  EXPECT_THROW(model.add_body("ball", Sphere{kR}, linear_soft(100), h, {{{0, 0, NAN}, {h}}}),
               std::invalid_argument);
  EXPECT_THROW(
      model.add_body("ball", Sphere{kR}, linear_soft(100), h, {{{0, 0, 0}, {h, h, h, h, h}}}),
      std::invalid_argument);
  EXPECT_THROW(model.add_body("one cell", Sphere{kR}, linear_soft(100), 0.0, {{{0, 0, 0}, {h}}}),
               std::invalid_argument);
  MagneticModel dipoles(IntraBodyTensor::point_dipole);
  EXPECT_THROW(dipoles.add_body("ball", Sphere{kR}, linear_soft(100), h, {{{0, 0, kR}, {h}}}),
               std::invalid_argument);
  try {
    model.add_body("the box", sheet, linear_soft(100), h, {{{0, 0, 0}, {h}}});
    ADD_FAILURE() << "no exception";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("the box"), std::string::npos) << e.what();
  }
  EXPECT_EQ(model.body_count(), 0);
}

// The force on ball 2 of two linear balls (chi), ball 1 at the origin, ball 2
// at (2 + gap) R along the unit vector line, in the uniform field H0; each
// ball refined towards the other (zones at their nearest points, the default
// radii) when refine is set.
struct PairResult {
  Vec3 force;
  int cells_per_ball = 0;
  int iterations = 0;
  bool converged = false;
};

PairResult refined_pair(double R_over_h, double gap_over_R, const Vec3& line, const Vec3& H0,
                        double chi, bool refine) {
  const double h = kR / R_over_h;
  MagneticModel model;
  std::vector<RefinedZone> lower, upper;
  if (refine) {
    lower = {{kR * line, default_refinement_radii(h)}};
    upper = {{-kR * line, default_refinement_radii(h)}};
  }
  model.add_body("lower", Sphere{kR}, linear_soft(chi), h, lower);
  model.add_body("upper", Sphere{kR}, linear_soft(chi), h, upper);
  MagneticState state = make_state(model, 7);
  state.pose[1] = {Mat3{}, (2.0 + gap_over_R) * kR * line};
  state.external_field = H0;
  auto backend = make_cpu_backend(1);
  const RelaxReport report =
      magnetic_step(model, state, RelaxOptions{}, *backend);  // default iteration cap
  return {state.force[1], model.body(0).cell_count(), report.iterations, report.converged};
}

// 3. Two lattice balls near contact in a field along
// their line of centres, at R/h = 4.5 (565 cells per ball plain). With the
// line along a lattice axis the plain lattice's force is 15% / 7.5% too weak
// at 0.05 R / 0.1 R; along (1, 2, 2) / 3, oblique to the lattice axes, 26% /
// 7% (benchmarks/results/refined_contact.md). With the default zones (915 / 953 cells per ball) the
// force is within 3% of the exact two-centre series: measured +0.8% / +0.4%
// along z, -0.4% / +0.3% along (1, 2, 2) / 3 at chi = 1000, -2.2% at chi =
// 10, with the field across 0.5% (with its z sub-cubes capped: -0.1% /
// +0.1%, -1.1% / -0.2%, -2.6%, 0.5%).
TEST(RefinedZone, TwoBallsNearContactMatchTheExactForce) {
  struct Case {
    double gap;
    Vec3 line;
    double chi;
    bool across;
  };
  const Vec3 axial{0, 0, 1}, tilted = Vec3{1, 2, 2} / 3.0,
                             oblique = Vec3{0.3, 0.5, 0.81} / norm(Vec3{0.3, 0.5, 0.81});
  const Case cases[] = {{0.05, axial, 1000, false},  {0.1, axial, 1000, false},
                        {0.05, tilted, 1000, false}, {0.1, tilted, 1000, false},
                        {0.05, tilted, 1000, true},  {0.05, tilted, 10, false},
                        {0.05, oblique, 1e4, false}};
  for (const Case& c : cases) {
    const Vec3 H0 = c.across ? 1e3 * normalized(cross(c.line, Vec3{0, 0, 1})) : 1e3 * c.line;
    const auto ref = reference::two_linear_spheres_in_uniform_field(
        kR, c.chi, kR, c.chi, {0, 0, 0}, (2.0 + c.gap) * kR * c.line, H0);
    const PairResult r = refined_pair(4.5, c.gap, c.line, H0, c.chi, true);
    const double e = norm(r.force - ref.force_on_2) / norm(ref.force_on_2);
    std::printf(
        "[odemag] refined balls, gap %g R, line (%.2f, %.2f, %.2f), chi %g, field %s: %d cells per "
        "ball,"
        " force error %.3e (%d iterations)\n",
        c.gap, c.line.x, c.line.y, c.line.z, c.chi, c.across ? "across" : "along", r.cells_per_ball,
        e, r.iterations);
    EXPECT_TRUE(r.converged);
    EXPECT_LE(r.cells_per_ball, 1000);
    EXPECT_LT(e, 0.03) << "gap " << c.gap << " R, chi " << c.chi;
  }
}

// 3b. Along the oblique line at R/h = 5 (1065 cells per ball): measured
// +0.67% at 0.05 R (with the exact part on every sub-cube: -1.1%). With
// the boundary correction's local part capped on the sub-cubes too it
// overshoots by +3.0% (+1.4% at R/h = 4): the cap, a
// stability device for coarse cells, added +4% to +6% at the contact
// (docs/model.md "Refined contact zones").
TEST(RefinedZone, ObliqueContactDoesNotOvershootOnFinerLattices) {
  const Vec3 line = Vec3{1, 2, 2} / 3.0, H0 = 1e3 * line;
  const auto ref = reference::two_linear_spheres_in_uniform_field(kR, 1000, kR, 1000, {0, 0, 0},
                                                                  2.05 * kR * line, H0);
  const PairResult r = refined_pair(5.0, 0.05, line, H0, 1000, true);
  const double signed_error = dot(r.force - ref.force_on_2, ref.force_on_2) / dot(ref.force_on_2, ref.force_on_2);
  EXPECT_TRUE(r.converged);
  EXPECT_GT(signed_error, -0.03);
  EXPECT_LT(signed_error, 0.01) << "the refined contact overshoots";
}

// 3c. The sub-cubes' exact boundary correction is not bounded as the cap
// is: with the radii 1.25 h, h, h/4 at R/h = 4 along (1, 2, 2) / 3 it makes
// the ball's operator indefinite (smallest eigenvalue -0.035 at chi -> inf,
// benchmarks/contact_refinement --stability), and the relaxation did not
// converge within the default cap. add_body checks the operator by Cholesky
// and then caps every cell: the body's operator is positive definite, the
// relaxation converges, and the force is within 3% (measured +0.7%).
TEST(RefinedZone, IndefiniteExactCorrectionFallsBackToTheCap) {
  const double h = kR / 4.0;
  const Vec3 line = Vec3{1, 2, 2} / 3.0, H0 = 1e3 * line;
  const std::vector<double> radii{1.25 * h, h, 0.25 * h};
  MagneticModel model;
  model.add_body("lower", Sphere{kR}, linear_soft(1000), h, {{kR * line, radii}});
  model.add_body("upper", Sphere{kR}, linear_soft(1000), h, {{-kR * line, radii}});
  const MagneticBody& lower = model.body(0);
  EXPECT_FALSE(lower.exact_sub_cubes);
  EXPECT_TRUE(body_operator_positive_definite(lower, lower.soft.gamma_D));
  MagneticState state = make_state(model, 7);
  state.pose[1] = {Mat3{}, 2.05 * kR * line};
  state.external_field = H0;
  auto backend = make_cpu_backend(1);
  const RelaxReport report = magnetic_step(model, state, RelaxOptions{}, *backend);
  const auto ref = reference::two_linear_spheres_in_uniform_field(kR, 1000, kR, 1000, {0, 0, 0},
                                                                  2.05 * kR * line, H0);
  EXPECT_TRUE(report.converged) << report.iterations << " iterations";
  EXPECT_LT(norm(state.force[1] - ref.force_on_2) / norm(ref.force_on_2), 0.03);
}

// 3d. With the default zones the exact part stays on the partial sub-cubes
// along both lines tried, z (the contact point on lattice planes) and (1,
// 2, 2) / 3, at R/h 4, 4.5 and 5, for chi = 1000 and 1e4: add_body's
// positivity check passes, so a contact that moves does not switch the
// rule. With the whole sub-cubes taking it too, along z a swirl of M about
// the contact axis in a ring of h/2 cubes goes below zero, so those bodies
// fall back to the cap (-2.3% at R/h 4).
TEST(RefinedZone, DefaultZonesKeepTheExactPartAlongEveryLine) {
  for (const double chi : {1000.0, 1e4})
    for (const double R_over_h : {4.0, 4.5, 5.0})
      for (const Vec3& line : {Vec3{0, 0, 1}, Vec3{1, 2, 2} / 3.0}) {
        const double h = kR / R_over_h;
        MagneticModel model;
        model.add_body("ball", Sphere{kR}, linear_soft(chi), h,
                       {{kR * line, default_refinement_radii(h)}});
        EXPECT_TRUE(model.body(0).exact_sub_cubes)
            << "chi " << chi << ", R/h " << R_over_h << ", line z = " << line.z;
      }
}

// 4. The refinement is what recovers it: the same lattice without zones
// is off by more than 10% at 0.05 R (measured -15.4%).
TEST(RefinedZone, WithoutZonesTheSameLatticeIsFarOff) {
  const Vec3 line{0, 0, 1}, H0{0, 0, 1e3};
  const auto ref = reference::two_linear_spheres_in_uniform_field(kR, 1000, kR, 1000, {0, 0, 0},
                                                                  {0, 0, 2.05 * kR}, H0);
  const PairResult r = refined_pair(4.5, 0.05, line, H0, 1000, false);
  const double e = norm(r.force - ref.force_on_2) / norm(ref.force_on_2);
  EXPECT_GT(e, 0.1);
}

// 5. A refined ball in a uniform field takes the continuum sphere's moment
// (M = 3 chi / (chi + 3) H0: the boundary correction's uniform modes), to
// the relaxation's tolerance.
TEST(RefinedZone, RefinedBallTakesTheSpheresMomentInAUniformField) {
  for (double chi : {10.0, 1000.0}) {
    const double h = kR / 4.0;
    MagneticModel model;
    model.add_body("ball", Sphere{kR}, linear_soft(chi), h,
                   {{{0, 0, kR}, default_refinement_radii(h)}});
    MagneticState state = make_state(model, 3);
    state.external_field = {0, 0, 1e3};
    auto backend = make_cpu_backend(1);
    ASSERT_TRUE(magnetic_step(model, state, RelaxOptions{}, *backend).converged);
    const double exact = 3.0 * chi / (chi + 3.0) * 1e3 * (4.0 / 3.0 * kPi * kR * kR * kR);
    const Vec3 m = body_moment(model, state, 0);
    EXPECT_NEAR(m.z / exact, 1.0, 1e-3) << "chi " << chi;
    EXPECT_LT(std::hypot(m.x, m.y), 1e-3 * exact);
  }
}

// 6. Zones that move with the contact (MagneticModel::refine_body,
// transfer_refined_state): the lower of two balls at R/h = 4.5 has its zone
// where an earlier contact was (towards (1, 2, 2) / 3, as after the ball
// rolled) while the other ball sits on it along z. Moving the zone to the
// contact point gives the model a fresh build at these poses has (the same
// cells and tensors, the other ball's cells renumbered with their state),
// the magnetization the old cells held carries over, and the next
// relaxation ends at the fresh build's force, within 3% of the exact series.
bool same_points(const std::vector<Vec3>& a, const std::vector<Vec3>& b) {
  if (a.size() != b.size()) return false;
  for (size_t i = 0; i < a.size(); ++i)
    if (a[i].x != b[i].x || a[i].y != b[i].y || a[i].z != b[i].z) return false;
  return true;
}

TEST(RefinedZone, MovedZonesMatchAFreshBuild) {
  const double h = kR / 4.5, chi = 1000.0;
  const Vec3 line{0, 0, 1}, H0{0, 0, 1e3}, earlier = Vec3{1, 2, 2} / 3.0;
  const std::vector<double> radii = default_refinement_radii(h);
  const std::vector<RefinedZone> upper{{-kR * line, radii}}, moved{{kR * line, radii}};
  auto backend = make_cpu_backend(1);
  auto place = [&](MagneticState& state) {
    state.pose[1] = {Mat3{}, 2.05 * kR * line};
    state.external_field = H0;
  };

  MagneticModel model;
  model.add_body("lower", Sphere{kR}, linear_soft(chi), h, {{kR * earlier, radii}});
  model.add_body("upper", Sphere{kR}, linear_soft(chi), h, upper);
  MagneticState state = make_state(model, 7);
  place(state);
  ASSERT_TRUE(magnetic_step(model, state, RelaxOptions{}, *backend).converged);
  const Vec3 lower_moment = body_moment(model, state, 0),
             upper_moment = body_moment(model, state, 1);
  const int old_first = model.body(1).first_cell;
  const std::vector<Vec3> upper_magnetization(state.magnetization.begin() + old_first,
                                              state.magnetization.end());

  // Bad requests change nothing.
  const uint64_t generation = model.generation();
  EXPECT_THROW(model.refine_body(2, moved), std::out_of_range);
  EXPECT_THROW(model.refine_body(0, {{kR * line, {-h}}}), std::invalid_argument);
  EXPECT_EQ(model.generation(), generation);
  EXPECT_EQ(model.body(1).first_cell, old_first);

  const MagneticBody old_lower = model.refine_body(0, moved);
  transfer_refined_state(model, 0, old_lower, state);
  EXPECT_NE(model.generation(), generation);

  MagneticModel fresh;
  fresh.add_body("lower", Sphere{kR}, linear_soft(chi), h, moved);
  fresh.add_body("upper", Sphere{kR}, linear_soft(chi), h, upper);
  ASSERT_EQ(model.cell_count(), fresh.cell_count());
  ASSERT_EQ(model.moment_count(), fresh.moment_count());
  EXPECT_EQ(model.body(1).first_cell, fresh.body(1).first_cell);
  EXPECT_TRUE(
      same_points(model.body(0).cells.local_positions, fresh.body(0).cells.local_positions));
  EXPECT_EQ(model.body(0).pair_tensors, fresh.body(0).pair_tensors);
  EXPECT_EQ(model.body(0).self_tensors, fresh.body(0).self_tensors);
  for (int c = 0; c < model.cell_count(); ++c) {
    EXPECT_EQ(model.cell_body(c), fresh.cell_body(c));
    EXPECT_EQ(model.moment_offset(c), fresh.moment_offset(c));
  }
  // The upper ball's cells keep their magnetization, renumbered; the lower
  // ball's moment carries over (the fine cells at the old zone merged, the
  // coarse ones at the new split).
  EXPECT_TRUE(same_points(std::vector<Vec3>(state.magnetization.begin() + model.body(1).first_cell,
                                            state.magnetization.end()),
                          upper_magnetization));
  EXPECT_LT(norm(body_moment(model, state, 1) - upper_moment), 1e-12 * norm(upper_moment));
  const Vec3 carried = body_moment(model, state, 0);
  std::printf("[odemag] moved zone: lower ball's moment carried over to %.3e (relative)\n",
              norm(carried - lower_moment) / norm(lower_moment));
  EXPECT_LT(norm(carried - lower_moment), 0.01 * norm(lower_moment));
  EXPECT_FALSE(state.last_solve.valid);

  const RelaxReport moved_report = magnetic_step(model, state, RelaxOptions{}, *backend);
  MagneticState fresh_state = make_state(fresh, 7);
  place(fresh_state);
  const RelaxReport fresh_report = magnetic_step(fresh, fresh_state, RelaxOptions{}, *backend);
  ASSERT_TRUE(moved_report.converged);
  ASSERT_TRUE(fresh_report.converged);
  const auto ref = reference::two_linear_spheres_in_uniform_field(kR, chi, kR, chi, {0, 0, 0},
                                                                  2.05 * kR * line, H0);
  std::printf(
      "[odemag] moved zone: %d iterations (fresh build %d), force %.4e N, fresh %.4e N, exact %.4e "
      "N\n",
      moved_report.iterations, fresh_report.iterations, state.force[1].z, fresh_state.force[1].z,
      ref.force_on_2.z);
  EXPECT_LT(norm(state.force[1] - fresh_state.force[1]), 2e-3 * norm(fresh_state.force[1]));
  EXPECT_LT(norm(state.force[1] - ref.force_on_2), 0.03 * norm(ref.force_on_2));
}

}  // namespace
}  // namespace odemag
