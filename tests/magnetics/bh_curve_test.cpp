// B-H curves (magnetics/materials/bh_curve.h, docs/model.md "B-H curves"): the monotone
// interpolation of a table, and a soft cell of such a material in a uniform
// field, against M = M(H0 - M/3) solved here by bisection on the analytic
// curve the table was sampled from (M = Ms tanh(H / H1)), not on the table.
#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <stdexcept>
#include <vector>

#include "magnetics/model/backend.h"
#include "magnetics/materials/bh_curve.h"
#include "odemag/constants.h"
#include "magnetics/model/model.h"
#include "magnetics/relax/relax.h"
#include "magnetics/model/state.h"

namespace odemag {
namespace {

constexpr double kMs = 1.6e6, kH1 = 1e5;  // A/m: chi_0 = Ms / H1 = 16, a curve that matters below saturation
double analytic_M(double H) { return kMs * std::tanh(H / kH1); }

// The table: (H, B = mu0 (H + M)) at n points up to 20 H1 (M within 1e-17 of Ms there).
std::vector<std::array<double, 2>> tanh_table(int n) {
  std::vector<std::array<double, 2>> t;
  for (int i = 0; i < n; ++i) {
    const double H = 20.0 * kH1 * std::pow(static_cast<double>(i) / (n - 1), 2.0);  // denser near 0
    t.push_back({H, kMu0 * (H + analytic_M(H))});
  }
  return t;
}

TEST(BhCurve, InterpolatesMonotonicallyAndSaturatesPastTheTable) {
  const auto table = tanh_table(12);
  const BhCurve curve(table);
  for (const auto& p : table) EXPECT_NEAR(curve.magnetization(p[0]), p[1] / kMu0 - p[0], 1e-6 * kMs);
  double last = -1.0;
  for (int i = 0; i <= 4000; ++i) {
    const double H = 25.0 * kH1 * i / 4000.0;
    const double M = curve.magnetization(H);
    EXPECT_GE(M, last - 1e-12 * kMs) << H;  // monotone to round-off
    EXPECT_GE(curve.slope(H), 0.0) << H;
    last = M;
  }
  EXPECT_DOUBLE_EQ(curve.magnetization(1e9), curve.saturation());
  EXPECT_EQ(curve.slope(1e9), 0.0);  // dB/dH = mu0 beyond the table
  EXPECT_NEAR(curve.saturation(), kMs, 1e-9 * kMs);
}

TEST(BhCurve, ConvergesToTheSampledCurve) {
  double previous = 1e300;
  for (int n : {12, 40, 160}) {
    const BhCurve curve(tanh_table(n));
    double worst = 0.0;
    for (int i = 1; i <= 2000; ++i) {
      const double H = 20.0 * kH1 * i / 2000.0;
      worst = std::max(worst, std::fabs(curve.magnetization(H) - analytic_M(H)) / kMs);
    }
    EXPECT_LT(worst, previous / 4.0) << n << " points";  // at least second order in the spacing
    previous = worst;
  }
  EXPECT_LT(previous, 1e-4);
}

TEST(BhCurve, RejectsBadTables) {
  EXPECT_NE(bh_curve_error({{0.0, 0.0}}), "");
  EXPECT_NE(bh_curve_error({{0.0, 0.1}, {100.0, 1.0}}), "");           // remanence at H = 0
  EXPECT_NE(bh_curve_error({{0.0, 0.0}, {100.0, 1.0}, {50.0, 1.2}}), "");  // H decreasing
  EXPECT_NE(bh_curve_error({{0.0, 0.0}, {100.0, 1.0}, {200.0, 1.0}}), "");  // B flat
  // dB/dH below mu0: M = B/mu0 - H falls.
  EXPECT_NE(bh_curve_error({{0.0, 0.0}, {1e3, 1.0}, {1e7, 1.0 + 0.5 * kMu0 * (1e7 - 1e3)}}), "");
  EXPECT_NE(bh_curve_error({{0.0, 0.0}, {NAN, 1.0}}), "");
  EXPECT_EQ(bh_curve_error(tanh_table(10)), "");
  EXPECT_THROW(BhCurve({{0.0, 0.0}}), std::invalid_argument);
}

// One-cell sphere (self field -M/3) in a uniform field H0: M = M(H0 - M/3).
double sphere_reference(double H0) {
  double lo = 0.0, hi = 3.0 * H0;
  for (int i = 0; i < 200; ++i) {
    const double M = 0.5 * (lo + hi);
    (M - analytic_M(H0 - M / 3.0) < 0.0 ? lo : hi) = M;
  }
  return 0.5 * (lo + hi);
}

TEST(BhCurve, SoftSphereInAUniformFieldSitsOnTheCurve) {
  SoftMaterial steel;
  steel.bh_curve = tanh_table(160);
  MagneticModel model;
  model.add_body("ball", Sphere{0.005}, steel, 0.0);
  EXPECT_NEAR(model.body(0).soft.Ms, kMs, 1e-9 * kMs);
  std::unique_ptr<MagneticBackend> backend = make_cpu_backend(1);
  for (double H0 : {1e3, 3e4, 1e5, 3e5, 1e6, 3e6}) {
    MagneticState state = make_state(model);
    state.external_field = {0.0, H0, 0.0};
    RelaxOptions o;
    o.tolerance = 1e-10;
    ASSERT_TRUE(magnetic_step(model, state, o, *backend).converged) << H0;
    const double M_ref = sphere_reference(H0);
    // The table's interpolation error (1e-4 of Ms at worst) bounds the difference.
    EXPECT_NEAR(state.magnetization[0].y, M_ref, 2e-4 * kMs + 1e-6 * M_ref) << "H0 = " << H0;
    EXPECT_NEAR(state.magnetization[0].x, 0.0, 1e-6 * M_ref);
    // (The linear material of chi_0 = 16 gives 3 chi/(chi+3) H0: at H0 = 3e5
    // 7.58e5 against the curve's 7.48e5, 6e-3 Ms apart: the check above tells them apart.)
  }
}

// A lattice cube of the material (4 x 4 x 4 cells) converges with the default
// iteration cap at fields across the curve's knee (the secant gamma_D is a
// function of each cell's applied field, so the outer fixed point is one of
// fields as before), with a mean magnetization along the field, at most Ms.
TEST(BhCurve, LatticeCubeConvergesAcrossTheKnee) {
  SoftMaterial steel;
  steel.bh_curve = tanh_table(160);
  MagneticModel model;
  model.add_body("cube", Box{{0.02, 0.02, 0.02}}, steel, 0.005);
  std::unique_ptr<MagneticBackend> backend = make_cpu_backend(1);
  for (double H0 : {3e4, 3e5, 3e6}) {
    MagneticState state = make_state(model);
    state.external_field = {0.0, 0.0, H0};
    RelaxOptions o;  // defaults
    const RelaxReport r = magnetic_step(model, state, o, *backend);
    EXPECT_TRUE(r.converged) << H0 << ": " << r.iterations << " iterations";
    double Mz = 0.0;
    for (int c = 0; c < model.cell_count(); ++c) Mz += state.magnetization[c].z / model.cell_count();
    EXPECT_GT(Mz, 0.0);
    EXPECT_LE(Mz, kMs * (1.0 + 1e-9));
  }
}

TEST(BhCurve, MaterialValidation) {
  SoftMaterial m;
  m.bh_curve = tanh_table(10);
  EXPECT_EQ(validate_material(m), "");
  m.saturation = 1e6;
  EXPECT_NE(validate_material(m), "");  // the curve sets Ms
  m.saturation = 0.0;
  m.susceptibility = 100.0;
  EXPECT_NE(validate_material(m), "");
  m.susceptibility = std::numeric_limits<double>::infinity();
  m.bh_curve = {{0.0, 0.0}};
  EXPECT_NE(validate_material(m), "");
}

}  // namespace
}  // namespace odemag
