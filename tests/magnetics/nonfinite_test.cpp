// Non-finite cells fail a relaxation: a NaN in the external field,
// a moment or a body's field makes every relaxation scheme report itself not
// converged with a non-finite residual, never converged. The residual maxima
// (std::max, fmax, OpenMP's max reduction) drop NaN, so without the explicit
// checks in cpu_backend.cpp and relax.cpp such a relaxation looked converged.
// The CUDA backend does the same (tests/gpu/parity_test.cpp
// NonFiniteCellsFailTheRelaxation); this file needs no device.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <limits>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "magnetics/model/backend.h"
#include "magnetics/model/model.h"
#include "magnetics/relax/relax.h"
#include "tests/support/magnetic_setup.h"

using namespace odemag;

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

SoftMaterial iron() { return test_support::soft_material(1.6e6, 1000); }

// A permanent bar, a recoil magnet, 24 one-cell soft balls (more than the 16
// cells from which the CPU backend's relax_cells runs in parallel), one of
// them with 8 anisotropic moments, and a soft lattice plate.
struct Bench {
  MagneticModel model;
  MagneticState state;
  int first_ball = 0, plate = 0, recoil = 0;
  explicit Bench(bool with_soft = true) {
    model.add_body("magnet", Box{{0.02, 0.01, 0.01}}, PermanentMaterial{{8e5, 0, 0}, 0.0}, 0.0);
    recoil = model.add_body("recoil", Sphere{0.004}, PermanentMaterial{{0, 0, 6e5}, 0.2}, 0.0);
    if (with_soft) {
      SoftMaterial steel = iron();
      steel.anisotropy_field = 3e5;
      steel.moments_per_cell = 8;
      first_ball = model.add_body("steel", Sphere{0.004}, steel, 0.0);
      for (int i = 1; i < 24; ++i) model.add_body("ball" + std::to_string(i), Sphere{0.004}, iron(), 0.0);
      plate = model.add_body("plate", Box{{0.02, 0.02, 0.004}}, iron(), 0.004);
    }
    state = make_state(model, 3);
    state.external_field = {1e3, 0, 2e3};
    state.pose[recoil].position = {-0.03, 0.0, 0.0};
    for (int b = first_ball; b < first_ball + (with_soft ? 24 : 0); ++b)
      state.pose[b].position = {0.02 + 0.009 * ((b - first_ball) % 6), 0.009 * ((b - first_ball) / 6), 0.0};
    if (with_soft) state.pose[plate].position = {0.0, 0.0, -0.02};
  }
  void nan_moment(int body) { state.moments[model.moment_offset(model.body(body).first_cell)].y = kNaN; }
};

RelaxOptions scheme(RelaxScheme s, bool mutual_induction = true) {
  RelaxOptions o;
  o.scheme = s;
  o.mutual_induction = mutual_induction;
  o.max_iterations = 50;
  return o;
}

struct Case {
  const char* name;
  RelaxOptions options;
};

std::vector<Case> cases() {
  return {{"two-level", scheme(RelaxScheme::two_level)},
          {"one pass (no mutual induction)", scheme(RelaxScheme::two_level, false)},
          {"paper", scheme(RelaxScheme::paper)}};
}

void expect_failed(const RelaxReport& r, const std::string& what) {
  EXPECT_FALSE(r.converged) << what;
  EXPECT_FALSE(std::isfinite(r.residual)) << what << ": residual " << r.residual;
  EXPECT_FALSE(r.skipped) << what;
}

}  // namespace

// The same scenes without a NaN: converged (the paper scheme, one LLG step
// per iteration, is only run for its first 50 iterations here), every
// residual finite.
TEST(NonFiniteCells, FiniteScenesStillConverge) {
  for (const Case& c : cases()) {
    Bench b;
    RelaxOptions o = c.options;
    o.max_iterations = c.options.scheme == RelaxScheme::paper ? 50 : 200;
    auto backend = make_cpu_backend(2);
    const RelaxReport r = relax(b.model, b.state, o, *backend);
    if (c.options.scheme != RelaxScheme::paper) {
      EXPECT_TRUE(r.converged) << c.name;
    } else {
      EXPECT_EQ(r.iterations, 50) << c.name;  // ran to the cap: no early stop on a finite residual
    }
    EXPECT_TRUE(std::isfinite(r.residual)) << c.name;
    for (double h : r.residual_history) EXPECT_TRUE(std::isfinite(h)) << c.name;
  }
}

TEST(NonFiniteCells, NaNExternalFieldFails) {
  for (const Case& c : cases()) {
    for (int threads : {1, 2}) {
      Bench b;
      b.state.external_field.z = kNaN;
      auto backend = make_cpu_backend(threads);
      const RelaxReport r = relax(b.model, b.state, c.options, *backend);
      expect_failed(r, std::string(c.name) + ", threads " + std::to_string(threads));
      // It stops at the first iteration that sees the NaN instead of running
      // to the iteration cap.
      EXPECT_LE(r.iterations, 1) << c.name;
    }
  }
}

TEST(NonFiniteCells, OneNaNMomentFails) {
  for (const Case& c : cases()) {
    Bench b;
    b.nan_moment(b.first_ball);  // the anisotropic 8-moment ball
    auto backend = make_cpu_backend(2);
    expect_failed(relax(b.model, b.state, c.options, *backend), std::string(c.name) + ", 8-moment ball");
  }
  // An isotropic cell's local relaxation ends at its exact minimum
  // (isotropic_minimum, magnetics/kernels/llg.h), which replaces a NaN moment when
  // the applied field is finite: without mutual induction (one pass under
  // the fixed field) that heals the cell, and the result is finite and
  // converged. With mutual induction the NaN magnetization reaches every
  // other cell's field first, and the relaxation fails.
  for (const Case& c : cases()) {
    Bench b;
    b.nan_moment(b.first_ball + 5);
    auto backend = make_cpu_backend(2);
    const RelaxReport r = relax(b.model, b.state, c.options, *backend);
    const std::string what = std::string(c.name) + ", 1-moment ball";
    if (!c.options.mutual_induction) {
      EXPECT_TRUE(r.converged) << what;
      for (int cell : active_responsive_cells(b.model, b.state))
        EXPECT_TRUE(is_finite(b.state.magnetization[cell])) << what << ", cell " << cell;
    } else {
      expect_failed(r, what);
    }
  }
}

TEST(NonFiniteCells, NaNInALatticeCellFails) {
  Bench b;
  b.nan_moment(b.plate);
  auto backend = make_cpu_backend(2);
  expect_failed(relax(b.model, b.state, scheme(RelaxScheme::two_level), *backend), "plate");
}

// Recoil magnets have no residual of their own: a NaN magnetization counts.
TEST(NonFiniteCells, RecoilMagnetsAloneFail) {
  for (const Case& c : cases()) {
    Bench b(false);
    b.state.external_field.x = kNaN;
    auto backend = make_cpu_backend(1);
    expect_failed(relax(b.model, b.state, c.options, *backend), c.name);
  }
}

// The backend call itself: the largest residual is NaN, however many finite
// cells the reduction meets after it.
TEST(NonFiniteCells, RelaxCellsReportsNaNResidual) {
  for (int threads : {1, 2}) {
    for (int bad : {0, 1, 12, 25}) {  // the recoil magnet, the 8-moment ball, a ball, a plate cell
      Bench b;
      auto backend = make_cpu_backend(threads);
      place_cells(b.model, b.state);
      backend->begin_step(b.model, b.state);
      std::vector<Vec3> H(b.model.cell_count()), H_resp(b.model.cell_count());
      backend->fixed_field(b.model, b.state, H);
      const std::vector<int> cells = active_responsive_cells(b.model, b.state);
      ASSERT_GT(cells.size(), 16u);
      const LocalStats finite = backend->relax_cells(b.model, b.state, H, LocalRelaxOptions{});
      EXPECT_TRUE(std::isfinite(finite.max_residual));
      H[cells[bad]].y = kNaN;
      const LocalStats s = backend->relax_cells(b.model, b.state, H, LocalRelaxOptions{});
      EXPECT_TRUE(std::isnan(s.max_residual)) << "threads " << threads << ", cell " << cells[bad];
    }
  }
}

// A failed step is not remembered as solved: skip_unchanged solves again.
TEST(NonFiniteCells, FailedStepIsNotSkippedNext) {
  Bench b;
  b.state.external_field.y = kNaN;
  RelaxOptions o = scheme(RelaxScheme::two_level);
  o.skip_unchanged = true;
  auto backend = make_cpu_backend(1);
  expect_failed(magnetic_step(b.model, b.state, o, *backend), "first");
  EXPECT_FALSE(b.state.last_solve.valid);
  expect_failed(magnetic_step(b.model, b.state, o, *backend), "second");
}

// MagneticModel::generation (the CUDA backend's cache key): unique per model
// object, new on every copy, move and add_body.
TEST(ModelGeneration, NewForEveryModelCopyAndChange) {
  MagneticModel a;
  const uint64_t g0 = a.generation();
  EXPECT_NE(g0, 0u);
  a.add_body("ball", Sphere{0.003}, iron(), 0.0);
  const uint64_t g1 = a.generation();
  EXPECT_NE(g1, g0);
  EXPECT_EQ(a.generation(), g1);  // reading does not change it
  MagneticModel b = a;
  EXPECT_NE(b.generation(), a.generation());
  EXPECT_EQ(a.generation(), g1);
  EXPECT_EQ(b.body_count(), 1);
  const uint64_t gb = b.generation();
  b = a;
  EXPECT_NE(b.generation(), gb);
  EXPECT_NE(b.generation(), a.generation());
  MagneticModel c = std::move(b);
  EXPECT_NE(c.generation(), a.generation());
  EXPECT_NE(b.generation(), c.generation());  // the emptied source is other contents too
  EXPECT_NE(b.generation(), gb);
  MagneticModel d(IntraBodyTensor::point_dipole);
  EXPECT_NE(d.generation(), a.generation());
  EXPECT_NE(d.generation(), c.generation());
  const uint64_t gd = d.generation();
  EXPECT_THROW(d.add_body("bad", Sphere{-1.0}, iron(), 0.0), std::invalid_argument);
  EXPECT_EQ(d.generation(), gd);  // a refused body changes nothing
}
