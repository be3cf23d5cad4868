// The predicted warm start of the two-level relaxation (magnetics/relax/relax.cpp,
// docs/model.md "Predicted warm start"): a relaxation starts from its first
// iterate plus the change of the applied field the last relaxation found,
// where the last two relaxations changed it alike (a steady drift). It may
// change how many iterations a relaxation takes, never what it converges to
// beyond the tolerance, and it must add nothing after a jump or a failure.
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

// Steel balls as in the crane: anisotropic, eight moments a cell, remanent.
SoftMaterial crane_steel() { return test_support::anisotropic_steel(1.6e6, 1000, 3.2e5, 8); }

// A bar magnet and a chain of three steel balls below it that moves towards
// it by the same small distance before every relaxation, as a clump carried
// by a crane does from substep to substep.
struct MovingChain : test_support::MagneticSetup {
  RelaxOptions options;
  explicit MovingChain(bool predict) {
    model.add_body("magnet", Box{{0.02, 0.02, 0.01}}, PermanentMaterial{{0, 0, 9e5}, 0.0}, 0.0);
    for (const char* name : {"a", "b", "c"})
      model.add_body(name, Sphere{0.005}, crane_steel(), 0.0);
    state = make_state(model, 3);
    for (int k = 0; k < 3; ++k)
      state.pose[1 + k].position = {0.0005 * k, 0.0, -0.0152 - 0.0101 * k};
    options.tolerance = 1e-6;
    options.predict_warm_start = predict;
  }
  // Moves the chain up by dz (m) and relaxes; returns the outer iterations.
  int step(double dz) {
    for (int k = 0; k < 3; ++k) state.pose[1 + k].position.z += dz;
    const RelaxReport r = magnetic_step(model, state, options, *backend);
    EXPECT_TRUE(r.converged);
    return r.iterations;
  }
};

TEST(PredictedWarmStart, SteadyDriftTakesFewerIterationsToTheSameMagnetization) {
  MovingChain predicted(true), plain(false);
  ASSERT_TRUE(magnetic_step(predicted.model, predicted.state, predicted.options, *predicted.backend)
                  .converged);
  ASSERT_TRUE(magnetic_step(plain.model, plain.state, plain.options, *plain.backend).converged);
  int with = 0, without = 0;
  for (int s = 0; s < 40; ++s) {
    with += predicted.step(2e-6);
    without += plain.step(2e-6);
  }
  std::printf(
      "40 relaxations, the chain moving 2 um each: %d outer iterations predicted, %d plain\n", with,
      without);
  EXPECT_LE(with, 0.8 * without);
  // The same solution to within the tolerance's reach.
  double worst = 0.0, scale = 0.0;
  for (size_t c = 0; c < plain.state.magnetization.size(); ++c) {
    worst = std::max(worst, norm(predicted.state.magnetization[c] - plain.state.magnetization[c]));
    scale = std::max(scale, norm(plain.state.magnetization[c]));
  }
  std::printf("largest difference of a cell's M: %.2e of the largest M\n", worst / scale);
  EXPECT_LT(worst, 1e-5 * scale);
}

// A cold start is a jump, not a drift: the relaxation after it starts from
// the plain warm start, bit for bit as without the prediction.
TEST(PredictedWarmStart, NothingIsAddedAfterAJump) {
  MovingChain predicted(true), plain(false);
  for (MovingChain* c : {&predicted, &plain})
    ASSERT_TRUE(magnetic_step(c->model, c->state, c->options, *c->backend).converged);
  bool moved = false;
  for (const Vec3& d : predicted.state.relaxation_change) moved = moved || norm(d) > 0.0;
  ASSERT_TRUE(moved) << "the cold relaxation changed the applied field";
  EXPECT_EQ(predicted.step(2e-6), plain.step(2e-6));
  for (size_t c = 0; c < plain.state.magnetization.size(); ++c)
    for (int a = 0; a < 3; ++a)
      EXPECT_EQ(predicted.state.magnetization[c][a], plain.state.magnetization[c][a])
          << "cell " << c << ", component " << a;
}

// A relaxation that does not converge predicts nothing for the next one.
TEST(PredictedWarmStart, AFailedRelaxationForgetsTheChange) {
  MovingChain chain(true);
  ASSERT_TRUE(magnetic_step(chain.model, chain.state, chain.options, *chain.backend).converged);
  chain.step(2e-6);
  chain.options.max_iterations = 1;
  chain.options.tolerance = 1e-15;
  for (int k = 0; k < 3; ++k) chain.state.pose[1 + k].position.z += 1e-4;
  ASSERT_FALSE(magnetic_step(chain.model, chain.state, chain.options, *chain.backend).converged);
  for (size_t c = 0; c < chain.state.relaxation_change.size(); ++c) {
    EXPECT_EQ(norm(chain.state.relaxation_change[c]), 0.0) << "cell " << c;
    EXPECT_EQ(norm(chain.state.previous_relaxation_change[c]), 0.0) << "cell " << c;
  }
}

}  // namespace
