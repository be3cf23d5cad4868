// The relaxation when every field falls towards zero (a coil or H_E switched
// off with no remanence left): the solution is M = 0, and a residual taken
// only relative to the cells' own field scales never meets the tolerance
// there (an iterate that shrinks every field by one factor keeps its
// relative residual). The scale is floored at a millionth of the largest
// field scale the state has converged at (MagneticState::peak_field_scale,
// magnetics/relax/relax.cpp): such relaxations end in a few iterations, with the
// fields resolved to tolerance x that floor.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <memory>

#include "magnetics/model/backend.h"
#include "magnetics/model/model.h"
#include "magnetics/relax/relax.h"
#include "tests/support/magnetic_setup.h"

using namespace odemag;

namespace {

SoftMaterial soft_iron() { return test_support::soft_material(1.6e6, 1000); }  // isotropic: keeps no moment

// An iron cube of 4 x 4 x 4 cells with two iron balls against its top face.
struct IronGroup : test_support::MagneticSetup {
  RelaxOptions options;
  IronGroup() {
    model.add_body("core", Box{{0.04, 0.04, 0.04}}, soft_iron(), 0.01);
    model.add_body("a", Sphere{0.005}, soft_iron(), 0.0);
    model.add_body("b", Sphere{0.005}, soft_iron(), 0.0);
    state = make_state(model, 5);
    state.pose[1].position = {0.0, 0.0, 0.0251};
    state.pose[2].position = {0.011, 0.0, 0.0251};
    options.tolerance = 1e-5;
  }
  double largest_magnetization() const {
    double m = 0.0;
    for (const Vec3& M : state.magnetization) m = std::max(m, norm(M));
    return m;
  }
};

TEST(WeakField, FieldSwitchedOffConvergesToZeroMagnetization) {
  IronGroup g;
  g.state.external_field = {0.0, 2e3, 1e4};
  const RelaxReport on = magnetic_step(g.model, g.state, g.options, *g.backend);
  ASSERT_TRUE(on.converged);
  const double M_on = g.largest_magnetization();
  ASSERT_GT(M_on, 1e4);
  g.state.external_field = {};
  for (int step = 0; step < 3; ++step) {
    const RelaxReport off = magnetic_step(g.model, g.state, g.options, *g.backend);
    std::printf("step %d after switch-off: %d iterations, residual %.2e, largest M %.2e of the field-on value\n", step,
                off.iterations, off.residual, g.largest_magnetization() / M_on);
    // The switch-off itself is a cold change (measured: 57 iterations; the
    // cap is 200, and before the floor it ran to the cap and 134 more); the
    // steps after it start from the converged zero (measured: 1 each).
    EXPECT_TRUE(off.converged) << "step " << step;
    EXPECT_LE(off.iterations, step == 0 ? 80 : 3) << "step " << step;
    // Resolved to tolerance x the floor (1e-6 of the field-on scale).
    EXPECT_LT(g.largest_magnetization(), 1e-6 * M_on) << "step " << step;
  }
}

// A weak field is still resolved relative to its own scale: the floor is a
// millionth of the peak, so a field a thousandth of the peak keeps (nearly)
// the full relative accuracy. Against a fresh state's solve at the weak field
// alone (no floor from a peak): the magnetizations agree to the tolerance.
TEST(WeakField, WeakFieldAfterAStrongOneKeepsItsRelativeAccuracy) {
  IronGroup strong_first, fresh;
  strong_first.state.external_field = {0.0, 2e3, 1e4};
  ASSERT_TRUE(magnetic_step(strong_first.model, strong_first.state, strong_first.options, *strong_first.backend)
                  .converged);
  const Vec3 weak{0.0, 2.0, 10.0};
  strong_first.state.external_field = weak;
  fresh.state.external_field = weak;
  strong_first.options.tolerance = fresh.options.tolerance = 1e-8;
  ASSERT_TRUE(magnetic_step(strong_first.model, strong_first.state, strong_first.options, *strong_first.backend)
                  .converged);
  ASSERT_TRUE(magnetic_step(fresh.model, fresh.state, fresh.options, *fresh.backend).converged);
  double worst = 0.0, scale = fresh.largest_magnetization();
  for (size_t c = 0; c < fresh.state.magnetization.size(); ++c)
    worst = std::max(worst, norm(strong_first.state.magnetization[c] - fresh.state.magnetization[c]) / scale);
  std::printf("weak field after a strong one: largest difference %.2e of the largest M\n", worst);
  EXPECT_LT(worst, 1e-5);
}

}  // namespace
