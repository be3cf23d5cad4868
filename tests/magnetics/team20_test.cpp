// TEAM workshop problem 20 (tests/support/team20.h, docs/validation.md
// "TEAM 20"): the steel pole in the steel yoke inside the coil, solved on the
// FFT lattices (magnetics/static/lattice_fft.h; every cell all steel: cubes of h =
// 5 mm and layers of thinner cells at the pole's top and the bar's ends, 2375
// cells) with the Newton-GMRES B-H solve (magnetics/static/bh_lattice_solve.h),
// against the measured force and gap flux density (COMPEL 14(2/3), 1995, the
// references in team20.h).
//
// What is asserted is what the model meets at this resolution, against the
// measured values with the 5%: the force at 3000 and 5000
// ampere-turns and Bz at P1 at 5000 AT (4500 AT, met with +0.1%, is left out
// to keep the test short: about 7 s of CPU in Release, with one solve in the
// Newton variable H beside the default b = H + M). Not met
// (docs/validation.md section 6): the force at 1000 AT (-18% here; -3.4% at
// h = 2.5 mm, too slow for a test), so it is not asserted.
#include <gtest/gtest.h>

#include <cmath>

#include "tests/support/team20.h"

namespace odemag {
namespace {

TEST(Team20, ForceOnThePoleAgainstTheMeasuredValues) {
  const team20::Problem problem(5.0, true);
  ASSERT_EQ(problem.demag.cells(), 2375);
  BhSolveOptions options;
  options.tolerance = 1e-4;  // the force is converged to 5 digits (docs/validation.md section 6)
  double previous = 0.0;
  for (int e : {1, 3}) {  // 3000 and 5000 AT
    const team20::Measured& m = team20::kMeasured[e];
    std::vector<Vec3> M(problem.demag.cells());
    const team20::Result r = team20::solve(problem, m.ampere_turns, M, options);
    EXPECT_TRUE(r.report.converged) << m.ampere_turns;
    // In b = H + M the Newton steps are few (4 and 6; in H 14 and 15).
    EXPECT_LE(r.report.newton_iterations, 8) << m.ampere_turns;
    // Momentum balance of the magnetic part: the pole on the yoke and back.
    EXPECT_LT(norm(r.force_from_yoke + r.force_on_yoke), 1e-10 * norm(r.force_from_yoke)) << m.ampere_turns;
    const double force = -r.force_pole.z;  // toward the bar
    EXPECT_GT(force, previous) << m.ampere_turns;
    previous = force;
    // By the mirror symmetries x = 0 and y = 0 the force is along z.
    EXPECT_LT(std::hypot(r.force_pole.x, r.force_pole.y), 1e-6 * force) << m.ampere_turns;
    EXPECT_NEAR(force, m.force, 0.05 * m.force) << m.ampere_turns;
    // Bz in the gap, under the pole, has the measured sign and order; at 5000 AT within 5%.
    EXPECT_GT(r.Bz_P1, 0.5 * m.Bz_P1) << m.ampere_turns;
    if (e == 3) {
      EXPECT_NEAR(r.Bz_P1, m.Bz_P1, 0.05 * m.Bz_P1);
    }
    if (e == 1) {  // the Newton variable H reaches the same solution
      BhSolveOptions in_field = options;
      in_field.variable = BhNewtonVariable::field;
      std::vector<Vec3> M_field(problem.demag.cells());
      const team20::Result f = team20::solve(problem, m.ampere_turns, M_field, in_field);
      EXPECT_TRUE(f.report.converged);
      EXPECT_NEAR(-f.force_pole.z, force, 1e-3 * force);
    }
  }
}

// The quarter model with the mirror planes x = 0 and y = 0 (team20::
// GradedProblem, magnetics/static/cuboid_demag.h), uniform cells of about 5 mm
// (grading 5/1/5: 720 unknown cells for 2880 in all): at 3000 AT the force
// within 5% of the measured value (+1.5%), along z by construction, and the
// magnetic forces balance; the faces graded toward the refined faces.
TEST(Team20, QuarterModelWithMirrorPlanes) {
  const std::vector<double> faces = team20::graded_faces(0.0, 12.5, {12.5}, {1.0, 1.5, 10.0});
  ASSERT_GE(faces.size(), 4u);
  EXPECT_DOUBLE_EQ(faces.front(), 0.0);
  EXPECT_DOUBLE_EQ(faces.back(), 12.5);
  for (size_t k = 2; k < faces.size(); ++k)  // the edges shrink toward the refined face
    EXPECT_LT(faces[k] - faces[k - 1], faces[k - 1] - faces[k - 2]) << k;
  const team20::GradedProblem problem({5.0, 1.0, 5.0}, true);
  ASSERT_EQ(problem.demag.cells(), 720);
  const team20::Measured& m = team20::kMeasured[1];
  BhSolveOptions options;
  options.tolerance = 1e-4;
  std::vector<Vec3> M(problem.demag.cells());
  const team20::Result r = team20::solve(problem, m.ampere_turns, M, options);
  EXPECT_TRUE(r.report.converged);
  EXPECT_LT(norm(r.force_from_yoke + r.force_on_yoke), 1e-10 * norm(r.force_from_yoke));
  EXPECT_EQ(r.force_pole.x, 0.0);
  EXPECT_EQ(r.force_pole.y, 0.0);
  EXPECT_NEAR(-r.force_pole.z, m.force, 0.05 * m.force);
}

// The settings of the quarter model's fastest solve (docs/validation.md
// "TEAM 20": the operator compressed in single precision, Newton to 1e-3)
// against the dense operator in double precision solved to 1e-4: the same
// force and Bz(P1) to 1e-4 at 3000 and 5000 AT, 5 mm cells.
TEST(Team20, QuarterModelFastSettingsKeepTheForce) {
  const team20::GradedProblem dense({5.0, 1.0, 5.0}, false, team20::GradedProblem::Storage::dense);
  const team20::GradedProblem fast({5.0, 1.0, 5.0}, false, team20::GradedProblem::Storage::compressed_single);
  BhSolveOptions tight, loose;
  tight.tolerance = 1e-4;
  loose.tolerance = 1e-3;
  for (const int k : {1, 3}) {
    const double ampere_turns = team20::kMeasured[k].ampere_turns;
    std::vector<Vec3> Md(dense.demag.cells()), Mf(fast.demag.cells());
    const team20::Result rd = team20::solve(dense, ampere_turns, Md, tight);
    const team20::Result rf = team20::solve(fast, ampere_turns, Mf, loose);
    ASSERT_TRUE(rd.report.converged);
    ASSERT_TRUE(rf.report.converged);
    EXPECT_NEAR(rf.force_pole.z, rd.force_pole.z, 1e-4 * std::abs(rd.force_pole.z)) << ampere_turns;
    EXPECT_NEAR(rf.Bz_P1, rd.Bz_P1, 1e-4 * std::abs(rd.Bz_P1)) << ampere_turns;
  }
}

}  // namespace
}  // namespace odemag
