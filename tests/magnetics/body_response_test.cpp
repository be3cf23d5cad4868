// The outer loop's block preconditioner (magnetics/model/body_response.h): the
// factored linear self-response of a high-chi isotropic lattice body.
//  - The factor inverts I - J for the operator the backend really applies:
//    J y is computed here by the CPU backend's responsive field of the body
//    magnetized as M_j = y_j / gamma_D (intra-body tensors and, for
//    volume-share cells, the boundary correction), not from the tensors the
//    factor was built from.
//  - Relaxations with and without it end on the same magnetization (the
//    fixed point is unchanged: only the steps towards it differ), the
//    preconditioned one in fewer outer iterations.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <memory>
#include <random>
#include <vector>

#include "magnetics/model/backend.h"
#include "magnetics/model/body_response.h"
#include "magnetics/model/model.h"
#include "magnetics/relax/relax.h"

using namespace odemag;

namespace {

SoftMaterial iron(double chi) {
  SoftMaterial m;
  m.saturation = 1.6e6;
  m.susceptibility = chi;
  return m;
}

// |(I - J) y - r| / |r| for y = factor^-1 r, with J y from the backend's
// responsive field of the body alone (one body, identity pose).
double response_residual(const MagneticModel& model, int b) {
  const MagneticBody& body = model.body(b);
  const int n = body.cell_count();
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  std::vector<double> r(3 * n), y;
  for (double& v : r) v = 1e4 * u(rng);
  y = r;
  solve_body_response(*body.response, y.data());
  MagneticState state = make_state(model, 3);
  std::unique_ptr<MagneticBackend> backend = make_cpu_backend(1);
  place_cells(model, state);
  backend->begin_step(model, state);
  for (int i = 0; i < n; ++i)
    state.magnetization[body.first_cell + i] = (1.0 / body.soft.gamma_D) * Vec3{y[3 * i], y[3 * i + 1], y[3 * i + 2]};
  std::vector<Vec3> H(model.cell_count());
  backend->responsive_field(model, state, H);
  double err = 0.0, ref = 0.0;
  for (int i = 0; i < n; ++i)
    for (int a = 0; a < 3; ++a) {
      const double lhs = y[3 * i + a] - H[body.first_cell + i][a];
      err += (lhs - r[3 * i + a]) * (lhs - r[3 * i + a]);
      ref += r[3 * i + a] * r[3 * i + a];
    }
  return std::sqrt(err / ref);
}

}  // namespace

TEST(BodyResponse, TakenByHighChiIsotropicLatticeBodiesOnly) {
  MagneticModel model;
  const int plate = model.add_body("plate", Box{{0.04, 0.04, 0.01}}, iron(1000), 0.005);      // 8 x 8 x 2
  const int weak = model.add_body("weak", Box{{0.04, 0.04, 0.01}}, iron(20), 0.005);          // chi < 100
  const int ball = model.add_body("ball", Sphere{0.005}, iron(1000), 0.0);                    // one cell
  SoftMaterial steel = iron(1000);
  steel.anisotropy_field = 3e5;
  const int hard = model.add_body("anisotropic", Box{{0.04, 0.04, 0.01}}, steel, 0.005);     // H_K > 0
  const int big = model.add_body("big", Box{{0.1, 0.1, 0.02}}, iron(1000), 0.005);            // 800 cells
  EXPECT_TRUE(model.body(plate).response);
  EXPECT_FALSE(model.body(weak).response);
  EXPECT_FALSE(model.body(ball).response);
  EXPECT_FALSE(model.body(hard).response);
  EXPECT_FALSE(model.body(big).response);  // over kMaxResponseCells
}

TEST(BodyResponse, InvertsTheBackendsIntraBodyOperator) {
  {
    MagneticModel model;  // whole cells: offset tensors only
    const int b = model.add_body("plate", Box{{0.04, 0.03, 0.01}}, iron(1000), 0.005);
    ASSERT_TRUE(model.body(b).response);
    EXPECT_LT(response_residual(model, b), 1e-12);
  }
  {
    MagneticModel model;  // volume-share cells: the boundary correction too
    const int b = model.add_body("ball", Sphere{0.02}, iron(5000), 0.01);
    ASSERT_TRUE(model.body(b).response);
    ASSERT_FALSE(model.body(b).self_tensors.empty());
    EXPECT_LT(response_residual(model, b), 1e-12);
  }
}

namespace {

// An iron plate of 8 x 8 x 2 cells (chi = 1000) in a uniform field with an
// iron ball on it and a permanent magnet ball below: relaxed from scratch,
// with or without the preconditioner.
struct PlateScene {
  MagneticModel model;
  MagneticState state;
  std::unique_ptr<MagneticBackend> backend = make_cpu_backend(1);
  RelaxOptions options;
  explicit PlateScene(bool precondition, const Vec3& H_E) {
    model.add_body("plate", Box{{0.04, 0.04, 0.01}}, iron(1000), 0.005);
    model.add_body("ball", Sphere{0.004}, iron(1000), 0.0);
    PermanentMaterial magnet;
    magnet.magnetization = {0.0, 0.0, 9e5};
    model.add_body("magnet", Sphere{0.004}, magnet, 0.0);
    state = make_state(model, 5);
    state.pose[0].rotation = Mat3{{{0.8, -0.6, 0.0}, {0.6, 0.8, 0.0}, {0.0, 0.0, 1.0}}};  // turned 36.9 deg
    state.pose[1].position = {0.01, 0.0, 0.0091};
    state.pose[2].position = {-0.012, 0.004, -0.0091};
    state.external_field = H_E;
    options.tolerance = 1e-8;
    options.precondition_bodies = precondition;
  }
};

double largest_difference(const MagneticState& a, const MagneticState& b) {
  double d = 0.0, m = 0.0;
  for (size_t c = 0; c < a.magnetization.size(); ++c) {
    d = std::max(d, norm(a.magnetization[c] - b.magnetization[c]));
    m = std::max(m, norm(a.magnetization[c]));
  }
  return d / m;
}

// The plate scene relaxed without (plain) and with the preconditioner at H_E.
struct PlainAndPreconditioned {
  PlateScene plain, pre;
  RelaxReport a, b;  // plain, preconditioned
  explicit PlainAndPreconditioned(const Vec3& H_E) : plain(false, H_E), pre(true, H_E) {
    a = relax(plain.model, plain.state, plain.options, *plain.backend);
    b = relax(pre.model, pre.state, pre.options, *pre.backend);
  }
};

}  // namespace

TEST(BodyResponse, SameMagnetizationInFewerIterations) {
  const PlainAndPreconditioned r({2e3, 0.0, 1e4});
  ASSERT_TRUE(r.a.converged);
  ASSERT_TRUE(r.b.converged);
  std::printf("iterations: plain %d, preconditioned %d\n", r.a.iterations, r.b.iterations);
  // Both resolve the fixed point to tolerance 1e-8 of the field scales.
  EXPECT_LT(largest_difference(r.plain.state, r.pre.state), 1e-6);
  EXPECT_LT(r.b.iterations, r.a.iterations);
}

TEST(BodyResponse, SaturatingBodiesGoWithoutAndStillConverge) {
  // 1.5e6 A/m: the plate's cells are past kLinearShare of saturation, so the
  // loop runs on the plain residual and must agree with the plain run exactly.
  const PlainAndPreconditioned r({0.0, 0.0, 1.5e6});
  ASSERT_TRUE(r.a.converged);
  ASSERT_TRUE(r.b.converged);
  EXPECT_EQ(r.a.iterations, r.b.iterations);
  EXPECT_EQ(largest_difference(r.plain.state, r.pre.state), 0.0);
}
