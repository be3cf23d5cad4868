// A high-susceptibility soft cube on a lattice against the converged
// boundary-element reference of tests/support/contact_references.h (the
// magnetometric demagnetizing factor N_m(chi), Richardson-extrapolated): the
// mean magnetization in a uniform field, chi H0 / (1 + N_m chi).
//
// Finding (issue: "within 1% at <= 1000 cells"), not met: the lattice
// converges to the reference from below as h^1.5 (the magnetization of a
// high-chi cube is singular at its edges): -5.8% at 64 cells, -3.2% at 216,
// -2.1% at 512, -1.5% at 1000, -1.1% at 1728 (chi = 1000; docs/validation.md
// "Contact"). The test pins the convergence: below the reference, the error
// falling with h at about that order.
#include <gtest/gtest.h>

#include <cmath>

#include "magnetics/backend.h"
#include "magnetics/relax.h"
#include "tests/support/contact_references.h"

namespace odemag {
namespace {

double mean_magnetization_error(int n, double chi, double N_m) {
  const double c = 0.01, H0 = 1e3;
  MagneticModel model;
  SoftMaterial s;
  s.saturation = 1e12;
  s.susceptibility = chi;
  model.add_body("cube", Box{{c, c, c}}, s, c / n);
  MagneticState state = make_state(model);
  state.external_field = {0, 0, H0};
  auto backend = make_cpu_backend(1);
  RelaxOptions o;
  o.tolerance = 1e-8;
  o.max_iterations = 1000;
  EXPECT_TRUE(relax(model, state, o, *backend).converged) << n;
  const double M = body_moment(model, state, 0).z / (c * c * c);
  return M / (chi * H0 / (1.0 + N_m * chi)) - 1.0;
}

TEST(SoftCube, LatticeConvergesToTheBoundaryElementReference) {
  const double chi = 1000;
  const double N_m = reference::cube_magnetometric_demag_factor_extrapolated(chi);
  ASSERT_NEAR(N_m, 0.2746, 2e-4);  // literature value (Chen, Pardo, Sanchez)
  const double e4 = mean_magnetization_error(4, chi, N_m), e6 = mean_magnetization_error(6, chi, N_m),
               e8 = mean_magnetization_error(8, chi, N_m);
  EXPECT_LT(e4, e6);
  EXPECT_LT(e6, e8);
  EXPECT_LT(e8, 0.0);
  // Observed order from 6 to 8 cells per edge: 1.3 .. 1.8 (measured 1.5).
  const double order = std::log(e6 / e8) / std::log(8.0 / 6.0);
  EXPECT_GT(order, 1.3);
  EXPECT_LT(order, 1.8);
  EXPECT_LT(std::fabs(e8), 0.025);  // measured 2.1% at 512 cells
}

}  // namespace
}  // namespace odemag
