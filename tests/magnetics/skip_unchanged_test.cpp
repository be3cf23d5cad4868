// RelaxOptions::skip_unchanged: a magnetic step is skipped exactly when
// nothing it depends on changed beyond the stated bounds, and the forces it
// keeps are then those of a fresh solve to the stated error.
#include <gtest/gtest.h>

#include <functional>
#include <vector>

#include "magnetics/model/backend.h"
#include "magnetics/model/model.h"
#include "magnetics/relax/relax.h"

using namespace odemag;

namespace {

// A permanent bar (one cell) and two soft balls near it.
struct Bench {
  MagneticModel model;
  MagneticState state;
  std::unique_ptr<MagneticBackend> backend = make_cpu_backend(1);
  RelaxOptions options;
  Bench() {
    model.add_body("magnet", Box{{0.02, 0.01, 0.01}}, PermanentMaterial{{8e5, 0, 0}, 0.0}, 0.0);
    SoftMaterial iron;
    iron.saturation = 1.6e6;
    iron.susceptibility = 1000;
    model.add_body("a", Sphere{0.005}, iron, 0.0);
    model.add_body("b", Sphere{0.005}, iron, 0.0);
    state = make_state(model, 3);
    state.pose[1].position = {0.025, 0.0, 0.0};
    state.pose[2].position = {0.037, 0.002, 0.0};
    options.tolerance = 1e-10;
    options.skip_unchanged = true;
  }
  RelaxReport step() { return magnetic_step(model, state, options, *backend); }
  double radius() const { return model.body(1).cells.contact_radius; }
};

}  // namespace

TEST(SkipUnchanged, SameInputsSkipAndKeepTheForces) {
  Bench b;
  const RelaxReport first = b.step();
  ASSERT_TRUE(first.converged);
  EXPECT_FALSE(first.skipped);
  const Vec3 force = b.state.force[1], moment = b.state.magnetization[1];
  const RelaxReport second = b.step();
  EXPECT_TRUE(second.skipped);
  EXPECT_EQ(second.iterations, 0);
  EXPECT_EQ(b.state.force[1].x, force.x);
  EXPECT_EQ(b.state.magnetization[1].x, moment.x);
}

TEST(SkipUnchanged, OffByDefaultNeverSkips) {
  Bench b;
  b.options.skip_unchanged = false;
  b.step();
  EXPECT_FALSE(b.step().skipped);
}

// Each input the step depends on, changed, makes the next step solve again.
TEST(SkipUnchanged, AnyChangedInputSolvesAgain) {
  const auto changes = std::vector<std::function<void(Bench&)>>{
      [](Bench& b) { b.state.pose[2].position.x += 1e-3 * b.radius(); },
      [](Bench& b) { b.state.pose[2].rotation = {{{1, 0, 0}, {0, 0.99995, -0.0099998}, {0, 0.0099998, 0.99995}}}; },
      [](Bench& b) { b.state.external_field = {1.0, 0, 0}; },
      [](Bench& b) { b.state.magnetization_scale[0] = 0.5; },
      [](Bench& b) { b.state.active[2] = 0; },
      [](Bench& b) { b.options.mutual_induction = false; },
      [](Bench& b) { reset_moments(b.model, b.state, 1); },
  };
  for (size_t k = 0; k < changes.size(); ++k) {
    Bench b;
    b.step();
    changes[k](b);
    EXPECT_FALSE(b.step().skipped) << "change " << k;
  }
}

// Within the bounds (a ball moved by 0.9e-5 of its radius) the step is
// skipped, and the kept forces differ from a fresh solve by less than 1e-4 of
// the force (measured 1.5e-5: the force changes on the scale of the gap).
TEST(SkipUnchanged, KeptForcesAreThoseOfAFreshSolveWithinTheBound) {
  Bench b;
  b.step();
  b.state.pose[1].position.x += 0.9e-5 * b.radius();
  EXPECT_TRUE(b.step().skipped);
  const Vec3 kept = b.state.force[1];
  b.options.skip_unchanged = false;
  b.step();
  const Vec3 fresh = b.state.force[1];
  EXPECT_GT(norm(fresh), 0.0);
  EXPECT_LT(norm(kept - fresh) / norm(fresh), 1e-4);
  // Drift: small moves add up against the pose last solved for.
  b.options.skip_unchanged = true;
  b.step();
  for (int k = 0; k < 3; ++k) {
    b.state.pose[1].position.x += 0.5e-5 * b.radius();
    const bool skipped = b.step().skipped;
    EXPECT_EQ(skipped, k < 1) << "move " << k;
    if (!skipped) break;
  }
}
