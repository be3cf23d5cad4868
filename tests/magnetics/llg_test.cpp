// Tests of the per-cell LLG physics (magnetics/kernels/llg.h): docs/model.md "LLG
// integration" and the paper's App. B, App. C, Figs. 10 and 11.
#include "magnetics/kernels/llg.h"

#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <vector>

#include "magnetics/relax/relax.h"

namespace odemag {
namespace {

SoftCellParams iron(double Ms = 1.7e6, double chi = 5000.0, double H_K = 0.0, int n = 2) {
  SoftCellParams p;
  p.Ms = Ms;
  p.gamma_D = 1.0 / 3.0 + 1.0 / chi;
  p.H_K = H_K;
  p.easy_axis = {0, 0, 1};
  p.alpha = 1.0;
  p.n = n;
  return p;
}


TEST(CayleyStep, KeepsUnitLengthOver10000Updates) {
  SoftCellParams p = iron(1.7e6, 5000.0, 3e5);
  std::vector<Vec3> m = {normalized(Vec3{1, 2, 3}), normalized(Vec3{-3, 1, 0.5})};
  Vec3 hc_prev[2];
  bool history = false;
  const Vec3 H_A{2e5, -1e5, 7e4};
  const double c = cayley_coefficient(p, H_A, 0.8);
  double worst = 0.0;
  for (int i = 0; i < 10000; ++i) {
    llg_step(p, H_A, m.data(), hc_prev, history, c, 1e-6, static_cast<uint64_t>(i));
    for (const Vec3& v : m) worst = std::max(worst, std::abs(norm(v) - 1.0));
  }
  EXPECT_LT(worst, 1e-12);
}

TEST(CayleyStep, EqualsDirectSolveOfMidpointEquation) {
  // m' - m = a x (m' + m)  <=>  (I - [a]x) m' = (I + [a]x) m.
  for (const Vec3& a : {Vec3{0.1, -0.2, 0.3}, Vec3{2.0, 1.0, -4.0}, Vec3{1e-7, 0, 0}}) {
    const Vec3 m = normalized(Vec3{0.3, 0.4, -0.8});
    Eigen::Matrix3d ax;
    ax << 0, -a.z, a.y, a.z, 0, -a.x, -a.y, a.x, 0;
    const Eigen::Vector3d mv(m.x, m.y, m.z);
    const Eigen::Vector3d direct =
        (Eigen::Matrix3d::Identity() - ax).partialPivLu().solve((Eigen::Matrix3d::Identity() + ax) * mv);
    const Vec3 closed = cayley_step(m, a);
    EXPECT_NEAR(closed.x, direct.x(), 1e-14);
    EXPECT_NEAR(closed.y, direct.y(), 1e-14);
    EXPECT_NEAR(closed.z, direct.z(), 1e-14);
    // And it satisfies the midpoint equation itself.
    const Vec3 residual = closed - m - cross(a, closed + m);
    EXPECT_LT(norm(residual), 1e-14);
  }
}

// Paper App. B: under a constant field the cell's free energy never rises.
TEST(LlgStep, FreeEnergyNeverRisesUnderConstantField) {
  struct Case {
    Vec3 H_A;
    double H_K;
  };
  for (const Case& k : {Case{{1e3, 0, 0}, 0.0}, Case{{2e5, 1e5, 0}, 0.0}, Case{{3e6, 0, 1e6}, 0.0},
                        Case{{1e5, 0, -2e5}, 8e5}, Case{{0, 0, 0}, 8e5}}) {
    SoftCellParams p = iron(1.7e6, 5000.0, k.H_K);
    std::vector<Vec3> m = {normalized(Vec3{0.2, 0.9, 0.1}), normalized(Vec3{-0.5, 0.1, 0.8})};
    Vec3 hc_prev[2];
    bool history = false;
    const double c = cayley_coefficient(p, k.H_A, LocalRelaxOptions{}.time_step_factor);
    const double scale = llg_field_scale(p, k.H_A);
    double g = cell_free_energy(p, k.H_A, m.data());
    for (int i = 0; i < 3000; ++i) {
      llg_step(p, k.H_A, m.data(), hc_prev, history, c, 0.0, 0);
      const double g_next = cell_free_energy(p, k.H_A, m.data());
      ASSERT_LE(g_next, g + 1e-13 * scale) << "step " << i;
      g = g_next;
    }
  }
}

// Paper App. C: with H_A = 0 and no anisotropy the net moment decays to zero,
// monotonically (Eq. 27).
TEST(LlgStep, NetMomentDecaysWithoutAppliedField) {
  for (int n : {2, 4}) {
    SoftCellParams p = iron(1.7e6, 5000.0, 0.0, n);
    std::vector<Vec3> m;
    for (int k = 0; k < n; ++k) m.push_back(normalized(Vec3{1.0, 0.3 * k, 0.5 - 0.2 * k}));
    std::vector<Vec3> hc_prev(n);
    bool history = false;
    const double c = cayley_coefficient(p, {}, LocalRelaxOptions{}.time_step_factor);
    double previous = norm(mean_moment(m.data(), n));
    ASSERT_GT(previous, 0.5);
    for (int i = 0; i < 2000; ++i) {
      llg_step(p, {}, m.data(), hc_prev.data(), history, c, 1e-6, static_cast<uint64_t>(i));
      const double now = norm(mean_moment(m.data(), n));
      ASSERT_LE(now, previous + 1e-12) << "n=" << n << " step " << i;
      previous = now;
    }
    EXPECT_LT(previous, 1e-6) << "n=" << n;
  }
}

// Relax a single soft cell (one-cell sphere) in a uniform external field.
struct SingleCell {
  MagneticModel model;
  MagneticState state;
  std::unique_ptr<MagneticBackend> backend = make_cpu_backend(1);
  explicit SingleCell(const SoftMaterial& mat, uint64_t seed = 7) {
    model.add_body("cell", Sphere{0.01}, mat, 0.0);
    state = make_state(model, seed);
  }
  Vec3 relax_in(const Vec3& H) {
    state.external_field = H;
    RelaxOptions o;
    o.tolerance = 1e-10;
    const RelaxReport r = relax(model, state, o, *backend);
    EXPECT_TRUE(r.converged);
    return state.magnetization[0];
  }
};

SoftMaterial soft(double Ms, double gamma_D, double H_K = 0.0) {
  SoftMaterial m;
  m.saturation = Ms;
  m.susceptibility = 1.0 / (gamma_D - 1.0 / 3.0);
  m.anisotropy_field = H_K;
  return m;
}

// Paper Fig. 11 and Eq. 21: M = H / gamma_D below saturation, Ms above, on the
// way up and on the way down.
void check_curve(double Ms, double gamma_D) {
  SingleCell cell(soft(Ms, gamma_D));
  const double Hs = gamma_D * Ms;
  std::vector<double> sweep;
  for (int i = 1; i <= 40; ++i) sweep.push_back(2.0 * Hs * i / 40.0);
  for (int i = 39; i >= 1; --i) sweep.push_back(2.0 * Hs * i / 40.0);
  const Vec3 dir = normalized(Vec3{1.0, 0.5, -0.3});
  for (double H : sweep) {
    const Vec3 M = cell.relax_in(H * dir);
    const double expected = std::min(H / gamma_D, Ms);
    EXPECT_NEAR(dot(M, dir), expected, 5e-3 * expected) << "Ms=" << Ms << " gamma_D=" << gamma_D << " H=" << H;
    EXPECT_LT(norm(M - dot(M, dir) * dir), 5e-3 * expected);
  }
}

TEST(MagnetizationCurve, ThreeSaturationsAtOneDemagFactor) {
  for (double Ms : {0.5e6, 1.0e6, 1.7e6}) check_curve(Ms, 0.5);
}

TEST(MagnetizationCurve, FourDemagFactorsAtOneSaturation) {
  for (double gamma_D : {1.0 / 3.0 + 1e-4, 0.5, 1.0, 2.0}) check_curve(1.0e6, gamma_D);
}

// Paper Fig. 10 / Sec. 4.6: remanence. An anisotropic cell (H_K > gamma_D Ms)
// keeps its magnetization when the field is removed; an isotropic one does not.
TEST(Remanence, AnisotropicCellKeepsMagnetizationIsotropicDoesNot) {
  const double Ms = 1.0e6, gamma_D = 1.0 / 3.0 + 1e-4;
  SingleCell aniso(soft(Ms, gamma_D, 6e5));
  SingleCell iso(soft(Ms, gamma_D, 0.0));
  const Vec3 easy{0, 0, 1};
  for (double H : {1e5, 5e5, 1e6, 2e6}) {
    aniso.relax_in(H * easy);
    iso.relax_in(H * easy);
  }
  EXPECT_GT(norm(aniso.state.magnetization[0]), 0.99 * Ms);
  EXPECT_GT(norm(iso.state.magnetization[0]), 0.99 * Ms);
  for (double H : {5e5, 1e5, 1e4, 0.0}) {
    aniso.relax_in(H * easy);
    iso.relax_in(H * easy);
  }
  EXPECT_GE(norm(aniso.state.magnetization[0]), 0.5 * Ms);
  EXPECT_LT(norm(iso.state.magnetization[0]), 0.01 * Ms);
}

// The O(n) Woodbury step of newton_polish equals the Newton step from the
// dense Riemannian Hessian (built here entry by entry from the free energy
// G = -H_A . mean(m) + gamma_D Ms |mean(m)|^2 / 2 + H_K / (2n) sum_k
// |m_k x e|^2) solved with Eigen, to 1e-9 relative, for 2, 4 and 8 moments near
// their easy axis (where every diagonal block is positive definite).
TEST(NewtonPolish, StructuredStepEqualsDenseNewtonStep) {
  uint64_t key = 7;
  int checked = 0;
  for (int n : {2, 4, 8}) {
    for (int trial = 0; trial < 20; ++trial) {
      SoftCellParams p = iron(8e5, 1000.0, 3.2e5, n);
      p.easy_axis = normalized(Vec3{0.3, -0.2, 1.0});
      Vec3 m[kMaxMomentsPerCell], heff[kMaxMomentsPerCell], basis[2 * kMaxMomentsPerCell];
      for (int k = 0; k < n; ++k) {
        const double sign = (k % 3 == 0) ? -1.0 : 1.0;  // some moments against the axis
        m[k] = normalized(sign * p.easy_axis + 0.3 * random_unit_vector(++key));
      }
      const Vec3 H_A = 2e5 * random_unit_vector(++key);
      const Vec3 mean_m = mean_moment(m, n);
      const int dim = 2 * n;
      Eigen::VectorXd grad(dim);
      for (int k = 0; k < n; ++k) {
        heff[k] = effective_field(p, H_A, mean_m, m[k]);
        tangent_basis(m[k], basis[2 * k], basis[2 * k + 1]);
      }
      for (int a = 0; a < dim; ++a) grad[a] = -dot(basis[a], heff[a / 2]) / n;
      Eigen::MatrixXd hess(dim, dim);
      for (int a = 0; a < dim; ++a)
        for (int b = 0; b < dim; ++b) {
          const int k = a / 2, l = b / 2;
          double h = p.gamma_D * p.Ms / (n * n) * dot(basis[a], basis[b]);
          if (k == l) {
            h += p.H_K / n * (dot(basis[a], basis[b]) - dot(basis[a], p.easy_axis) * dot(basis[b], p.easy_axis));
            if (a == b) h += dot(m[k], heff[k]) / n;
          }
          hess(a, b) = h;
        }
      const double curvature = (p.gamma_D * p.Ms + p.H_K + norm(H_A)) / n;
      double step[2 * kMaxMomentsPerCell];
      if (!structured_newton_step(p, m, heff, basis, grad.data(), curvature, step)) continue;
      hess.diagonal().array() += 1e-12 * curvature;
      const Eigen::VectorXd dense = hess.llt().solve(-grad);
      const Eigen::VectorXd structured = Eigen::Map<Eigen::VectorXd>(step, dim);
      EXPECT_LT((structured - dense).norm(), 1e-9 * dense.norm()) << "n " << n << " trial " << trial;
      ++checked;
    }
  }
  EXPECT_GE(checked, 30);  // most configurations take the structured path
}

// A nearly demagnetized 8-moment steel cell (moments near +-e,
// mean(m) ~ 1e-3) in a weak field. Its energy is a sum of terms up to H_K / 2
// = 1.6e5 A/m whose changes near convergence are 1e-13 and less, so the
// Newton polish's line search must see them: with the anisotropy term
// evaluated as 1 - (m.e)^2 (absolute error 1e-16 per moment) it rejected
// good steps and ran to its 40-step cap with the residual above the
// tolerance. Quadratic convergence: at most 6 steps, to the tolerance, with
// the energy not risen.
TEST(NewtonPolish, ConvergesInWeakFieldsNearTheEasyAxis) {
  uint64_t key = 31;
  int max_steps = 0;
  for (double H : {1.0, 50.0, 2e3}) {
    for (int trial = 0; trial < 40; ++trial) {
      const SoftCellParams p = iron(8e5, 1000.0, 3.2e5, 8);
      Vec3 m[kMaxMomentsPerCell];
      const int up = 4 + trial % 4;  // 4 of 8 moments up (M ~ 0) to 7 (remanent)
      const double spread = trial % 8 < 4 ? 1e-3 : 0.2;
      for (int k = 0; k < p.n; ++k)
        m[k] = normalized((k < up ? 1.0 : -1.0) * p.easy_axis + spread * random_unit_vector(++key));
      const Vec3 H_A = H * random_unit_vector(++key);
      const double e0 = cell_free_energy(p, H_A, m);
      double residual = 0.0;
      const int steps = newton_polish(p, H_A, m, 40, 1e-9, residual);
      max_steps = std::max(max_steps, steps);  // 40 (the cap) with 1 - (m.e)^2
      EXPECT_LE(residual, 1e-9) << "H " << H << " trial " << trial;
      EXPECT_LE(steps, 6) << "H " << H << " trial " << trial;
      EXPECT_LE(cell_free_energy(p, H_A, m), e0) << "H " << H << " trial " << trial;
    }
  }
  EXPECT_LE(max_steps, 6);
}

// An isotropic cell of opposite pairs ends on its exact minimum
// mean(m) = min(|H_A| / (gamma_D Ms), 1) H_A / |H_A| (docs/model.md), in
// closed form: no Newton step.
TEST(RelaxSoftCell, IsotropicPairsReachTheExactMinimumWithoutPolish) {
  uint64_t key = 5;
  for (int n : {2, 4}) {
    for (double H : {1e-3, 1.0, 1e3, 1e5, 1e6, 1e7}) {
      const SoftCellParams p = iron(1.7e6, 1000.0, 0.0, n);
      const Vec3 H_A = H * random_unit_vector(++key);
      const Vec3 exact = std::min(H / (p.gamma_D * p.Ms), 1.0) * normalized(H_A);
      Vec3 m[kMaxMomentsPerCell], hc[kMaxMomentsPerCell];
      for (int k = 0; k + 1 < n; k += 2) {
        m[k] = random_unit_vector(key + 100 + static_cast<uint64_t>(k));
        m[k + 1] = -1.0 * m[k];
      }
      const LocalRelaxOptions o;
      bool history = false;
      uint64_t counter = 0;
      const LocalRelaxResult r = relax_soft_cell(p, H_A, m, hc, history, counter, 3, o);
      EXPECT_LT(norm(mean_moment(m, n) - exact), 1e-12) << "n " << n << " H " << H;
      // Below 1 A/m the torque measure is at its round-off floor.
      if (H >= 1.0) {
        EXPECT_LE(r.residual, 1e-9) << "n " << n << " H " << H;
      }
      EXPECT_EQ(r.newton_steps, 0);
    }
  }
}

}  // namespace
}  // namespace odemag
