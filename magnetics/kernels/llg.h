// Per-cell magnetization dynamics (docs/model.md "Effective field", "LLG integration";
// paper Sections 3.4, 4.4, 4.6).
//
// A soft cell holds n unit moments m_k (stored in the body frame); its
// magnetization is M = Ms * mean(m_k). Under a frozen applied field H_A (the
// external field plus the field of every other cell) each moment feels
//   H_eff,k = H_A + H_endo + H_K,k + H_noise,k.
// Everything here is local to one cell and written once for host and device.
#pragma once

#include <cstdint>

#include "odemag/constants.h"
#include "magnetics/kernels/hd.h"
#include "magnetics/kernels/rng.h"
#include "magnetics/kernels/small_eigen.h"
#include "odemag/material.h"
#include "odemag/settings.h"
#include "odemag/vec3.h"

namespace odemag {

struct SoftCellParams {
  double Ms = 0.0;       // saturation magnetization, A/m
  double gamma_D = 0.0;  // demagnetising factor of the cell, 1/3 + 1/chi
  double H_K = 0.0;      // anisotropy field, A/m (the paper's 2 K_u)
  Vec3 easy_axis;        // unit vector in the moments' frame
  double alpha = 1.0;    // Gilbert damping
  int n = 2;             // moments per cell
};

struct LocalRelaxResult {
  int llg_steps = 0;
  int newton_steps = 0;
  double residual = 0.0;  // relative torque after relaxation
};

// ---- field terms --------------------------------------------------------------

ODEMAG_HD Vec3 mean_moment(const Vec3* m, int n) {
  Vec3 s;
  for (int k = 0; k < n; ++k) s += m[k];
  return (1.0 / n) * s;
}

// H_endo = -gamma_D M, M = Ms * mean(m)  (paper Eq. 16, 23).
ODEMAG_HD Vec3 endo_field(const SoftCellParams& p, const Vec3& mean_m) {
  return (-p.gamma_D * p.Ms) * mean_m;
}

// H_K,k = -H_K (m_k - (m_k . e) e): zero on the easy axis (paper Eq. 24).
ODEMAG_HD Vec3 anisotropy_field(const SoftCellParams& p, const Vec3& m) {
  if (p.H_K == 0.0) return {};
  return (-p.H_K) * (m - dot(m, p.easy_axis) * p.easy_axis);
}

// H_noise,k: ratio * |H_eff| in a direction drawn from key (paper Sec. 4.6).
ODEMAG_HD Vec3 noise_field(double ratio, const Vec3& heff, uint64_t key) {
  if (ratio == 0.0) return {};
  return (ratio * norm(heff)) * random_unit_vector(key);
}

// H_eff,k without the noise term.
ODEMAG_HD Vec3 effective_field(const SoftCellParams& p, const Vec3& H_A, const Vec3& mean_m,
                               const Vec3& m) {
  return H_A + endo_field(p, mean_m) + anisotropy_field(p, m);
}

// ---- LLG integration ----------------------------------------------------------

// Hc = H_eff + alpha m x H_eff  (paper Eq. 9).
ODEMAG_HD Vec3 gilbert_field(const Vec3& m, const Vec3& heff, double alpha) {
  return heff + alpha * cross(m, heff);
}

// Closed form of the implicit midpoint equation m' - m = a x (m' + m)
// (paper Eq. 12 with a = gamma0 dt / (2 (1 + alpha^2)) Hc): a Cayley rotation,
// so |m'| = |m| exactly.
ODEMAG_HD Vec3 cayley_step(const Vec3& m, const Vec3& a) {
  const Vec3 am = cross(a, m);
  return m + (2.0 / (1.0 + squared_norm(a))) * (am + cross(a, am));
}

// Field scale S bounding the stiffness of the cell's dynamics; sets dt.
ODEMAG_HD double llg_field_scale(const SoftCellParams& p, const Vec3& H_A) {
  return p.gamma_D * p.Ms + p.H_K + norm(H_A);
}

// Coefficient c with a = c Hc:  c = gamma0 dt / (2 (1 + alpha^2)) = tau / (2 S).
ODEMAG_HD double cayley_coefficient(const SoftCellParams& p, const Vec3& H_A, double tau) {
  return tau / (2.0 * llg_field_scale(p, H_A));
}

// One LLG step of every moment of the cell under the frozen field H_A:
// implicit midpoint with Hc extrapolated to the half step,
// Hc_half = 3/2 Hc^i - 1/2 Hc^(i-1) (paper Eq. 13); without history the step
// is second-order Runge-Kutta (midpoint). hc_prev holds Hc^(i-1).
ODEMAG_HD void llg_step(const SoftCellParams& p, const Vec3& H_A, Vec3* m, Vec3* hc_prev,
                        bool& has_history, double c, double noise_ratio, uint64_t noise_key) {
  const int n = p.n;
  Vec3 hc[kMaxMomentsPerCell], noise[kMaxMomentsPerCell];
  const Vec3 mean_m = mean_moment(m, n);
  for (int k = 0; k < n; ++k) {
    const Vec3 heff = effective_field(p, H_A, mean_m, m[k]);
    noise[k] = noise_field(noise_ratio, heff, mix64(noise_key + static_cast<uint64_t>(k)));
    hc[k] = gilbert_field(m[k], heff + noise[k], p.alpha);
  }
  if (!has_history) {
    Vec3 mh[kMaxMomentsPerCell];
    for (int k = 0; k < n; ++k) mh[k] = cayley_step(m[k], (0.5 * c) * hc[k]);
    const Vec3 mean_h = mean_moment(mh, n);
    for (int k = 0; k < n; ++k) {
      const Vec3 heff_h = effective_field(p, H_A, mean_h, mh[k]) + noise[k];
      m[k] = cayley_step(m[k], c * gilbert_field(mh[k], heff_h, p.alpha));
    }
  } else {
    for (int k = 0; k < n; ++k) m[k] = cayley_step(m[k], c * (1.5 * hc[k] - 0.5 * hc_prev[k]));
  }
  for (int k = 0; k < n; ++k) hc_prev[k] = hc[k];
  has_history = true;
}

// ---- energy and convergence ---------------------------------------------------

// Free energy density of the cell divided by mu0 Ms (A/m):
//   G / (mu0 Ms) = -H_A . mean(m) + gamma_D Ms |mean(m)|^2 / 2
//                  + H_K / (2n) sum_k |m_k - (m_k . e) e|^2.
// Its gradient with respect to m_k is -H_eff,k / n (paper App. B, Eq. 32).
ODEMAG_HD double cell_free_energy(const SoftCellParams& p, const Vec3& H_A, const Vec3* m) {
  const Vec3 mean_m = mean_moment(m, p.n);
  double e = -dot(H_A, mean_m) + 0.5 * p.gamma_D * p.Ms * squared_norm(mean_m);
  if (p.H_K != 0.0) {
    double s = 0.0;
    // |m_k x e|^2 = 1 - (m_k . e)^2 on the unit sphere, evaluated as the
    // cross product: near the easy axis 1 - c^2 cancels to an absolute error
    // of 1e-16 per moment, which times H_K / (2n) drowned the energy changes
    // that the Newton polish's line search compares in weak fields (6% of
    // the 8-moment cells' polishes ran to the 40-step cap with 1 - c^2, 69%
    // of the Newton steps of the crane's remanence phase).
    for (int k = 0; k < p.n; ++k) s += squared_norm(cross(m[k], p.easy_axis));
    e += 0.5 * p.H_K * s / p.n;
  }
  return e;
}

// Field scale for the convergence measure: the sizes of the terms of H_eff
// that do not vanish at equilibrium, with a floor so 0/0 cannot occur.
ODEMAG_HD double torque_scale(const SoftCellParams& p, const Vec3& H_A, const Vec3& mean_m) {
  return norm(H_A) + p.gamma_D * p.Ms * norm(mean_m) + 1e-9 * (p.gamma_D * p.Ms + p.H_K);
}

// max_k |m_k x H_eff,k| / scale: zero both where H_eff = 0 (below saturation)
// and where H_eff is parallel to every m_k (saturation, easy axis).
ODEMAG_HD double cell_torque_residual(const SoftCellParams& p, const Vec3& H_A, const Vec3* m) {
  const Vec3 mean_m = mean_moment(m, p.n);
  double worst = 0.0;
  for (int k = 0; k < p.n; ++k)
    worst = larger(worst, norm(cross(m[k], effective_field(p, H_A, mean_m, m[k]))));
  return worst / torque_scale(p, H_A, mean_m);
}

// ---- Newton polish ------------------------------------------------------------

// Move m by the tangent vector d and back onto the unit sphere (the
// projection retraction: first order like the exponential map, without sin
// and cos; Newton converges quadratically with either).
ODEMAG_HD Vec3 rotate_on_sphere(const Vec3& m, const Vec3& d) { return normalized(m + d); }

// Two unit vectors spanning the tangent plane at m.
ODEMAG_HD void tangent_basis(const Vec3& m, Vec3& u, Vec3& v) {
  const double ax = fabs(m.x), ay = fabs(m.y), az = fabs(m.z);
  const Vec3 axis = (ax <= ay && ax <= az) ? Vec3{1, 0, 0} : (ay <= az ? Vec3{0, 1, 0} : Vec3{0, 0, 1});
  u = normalized(cross(m, axis));
  v = cross(m, u);
}

// The Newton step of newton_polish without forming the Hessian. In the
// tangent bases the Hessian is D + c B B^T: D block diagonal, one 2 x 2 block
// per moment (anisotropy and the diagonal (m_k . H_eff,k) / n), c = gamma_D Ms
// / n^2 the endo coupling of every pair of moments, B the 2n x 3 matrix of the
// basis vectors. Where every block of D is positive definite (so is the
// Hessian), the Woodbury identity solves (D + c B B^T) step = -grad with 2 x 2
// and 3 x 3 solves: O(n) instead of the O(n^3) Cholesky of the 2n x 2n Hessian
// (n = 8: most of a crane step). Returns false, with step untouched, where a
// block is not safely positive definite (smallest eigenvalue below 1e-6 of
// the curvature scale): the caller then takes the dense path.
ODEMAG_HD bool structured_newton_step(const SoftCellParams& p, const Vec3* m, const Vec3* heff,
                                      const Vec3* basis, const double* grad, double curvature_scale,
                                      double* step) {
  const int n = p.n;
  const double inv_n = 1.0 / n, c = p.gamma_D * p.Ms * inv_n * inv_n;
  const double floor = 1e-6 * curvature_scale, shift = 1e-12 * curvature_scale;
  double dinv[kMaxMomentsPerCell][3];  // inverse blocks: (uu, uv, vv)
  for (int k = 0; k < n; ++k) {
    const Vec3 &u = basis[2 * k], &v = basis[2 * k + 1];
    const double q = inv_n * dot(m[k], heff[k]) + shift, ue = dot(u, p.easy_axis),
                 ve = dot(v, p.easy_axis), hk = p.H_K * inv_n;
    const double duu = hk * (1.0 - ue * ue) + q, duv = -hk * ue * ve, dvv = hk * (1.0 - ve * ve) + q;
    const double half_trace = 0.5 * (duu + dvv), det = duu * dvv - duv * duv;
    const double lowest = half_trace - sqrt(larger(0.0, half_trace * half_trace - det));
    if (!(lowest > floor)) return false;
    dinv[k][0] = dvv / det;
    dinv[k][1] = -duv / det;
    dinv[k][2] = duu / det;
  }
  // y = D^-1 (-grad); S = I / c + B^T D^-1 B; r = B^T y.
  double y[2 * kMaxMomentsPerCell], S[9] = {1.0 / c, 0, 0, 0, 1.0 / c, 0, 0, 0, 1.0 / c};
  Vec3 r;
  for (int k = 0; k < n; ++k) {
    const Vec3 &u = basis[2 * k], &v = basis[2 * k + 1];
    const double gu = -grad[2 * k], gv = -grad[2 * k + 1];
    y[2 * k] = dinv[k][0] * gu + dinv[k][1] * gv;
    y[2 * k + 1] = dinv[k][1] * gu + dinv[k][2] * gv;
    r += y[2 * k] * u + y[2 * k + 1] * v;
    const double uc[3] = {u.x, u.y, u.z}, vc[3] = {v.x, v.y, v.z};
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j)
        S[3 * i + j] += dinv[k][0] * uc[i] * uc[j] + dinv[k][1] * (uc[i] * vc[j] + vc[i] * uc[j]) +
                        dinv[k][2] * vc[i] * vc[j];
  }
  double z[3] = {r.x, r.y, r.z};
  if (!cholesky(S, 3, 0.0)) return false;
  cholesky_solve(S, 3, z);
  // step = y - D^-1 B z.
  const Vec3 zv{z[0], z[1], z[2]};
  for (int k = 0; k < n; ++k) {
    const double bu = dot(basis[2 * k], zv), bv = dot(basis[2 * k + 1], zv);
    step[2 * k] = y[2 * k] - (dinv[k][0] * bu + dinv[k][1] * bv);
    step[2 * k + 1] = y[2 * k + 1] - (dinv[k][1] * bu + dinv[k][2] * bv);
  }
  return true;
}

// Newton's method on the product of unit spheres for the cell free energy,
// with the Riemannian Hessian Hess[xi]_k = P_k (d2G xi)_k - (m_k . grad_k G) xi_k.
// Each step is Newton's where the Hessian is positive definite (by the O(n)
// structured_newton_step where its diagonal blocks are, else by Cholesky);
// elsewhere it uses |eigenvalue| (n = 2) or a Levenberg-Marquardt shift
// (more moments, where a 16 x 16 eigen-decomposition per step was 98% of
// the run time). A 0.5 rad trust radius and an
// energy line search keep the energy from rising. At a converged point that
// is a saddle (a Cholesky test fails) it steps along the negative curvature
// found by an eigen-decomposition, the role the noise field plays for LLG. Converges quadratically in the basin the LLG
// steps chose; it removes the slow "pair axis" mode that makes n = 2 LLG
// crawl in weak fields (docs/model.md). Returns the steps taken.
ODEMAG_HD int newton_polish(const SoftCellParams& p, const Vec3& H_A, Vec3* m, int max_steps,
                            double tolerance, double& residual) {
  const int n = p.n, dim = 2 * n;
  constexpr int kMaxDim = 2 * kMaxMomentsPerCell;
  Vec3 basis[kMaxDim], heff[kMaxMomentsPerCell], trial[kMaxMomentsPerCell];
  double hess[kMaxDim * kMaxDim], work[kMaxDim * kMaxDim], eval[kMaxDim], evec[kMaxDim * kMaxDim],
      grad[kMaxDim], step[kMaxDim];
  const double inv_n = 1.0 / n;
  int steps = 0;
  residual = cell_torque_residual(p, H_A, m);
  if (residual <= tolerance) {
    // Converged already. A saddle needs a negative diagonal (m_k . H_eff,k)
    // in the Hessian (its other parts are positive semi-definite), so only
    // then is the Hessian worth building.
    const Vec3 mean_m = mean_moment(m, n);
    bool saddle_possible = false;
    for (int k = 0; k < n; ++k)
      saddle_possible = saddle_possible || dot(m[k], effective_field(p, H_A, mean_m, m[k])) < 0.0;
    if (!saddle_possible) return 0;
  }
  for (; steps < max_steps; ++steps) {
    const Vec3 mean_m = mean_moment(m, n);
    const double scale = torque_scale(p, H_A, mean_m);
    for (int k = 0; k < n; ++k) {
      heff[k] = effective_field(p, H_A, mean_m, m[k]);
      tangent_basis(m[k], basis[2 * k], basis[2 * k + 1]);
    }
    for (int a = 0; a < dim; ++a) grad[a] = -inv_n * dot(basis[a], heff[a / 2]);
    const double curvature_scale = inv_n * (p.gamma_D * p.Ms + p.H_K + norm(H_A));
    if (structured_newton_step(p, m, heff, basis, grad, curvature_scale, step)) {
      if (residual <= tolerance) break;  // converged at a minimum (the Hessian is positive definite)
    } else {
      for (int a = 0; a < dim; ++a) {
        const int k = a / 2;
        for (int b = 0; b < dim; ++b) {
          const int l = b / 2;
          double h = p.gamma_D * p.Ms * inv_n * inv_n * dot(basis[a], basis[b]);
          if (k == l) {
            h += p.H_K * inv_n *
                 (dot(basis[a], basis[b]) - dot(basis[a], p.easy_axis) * dot(basis[b], p.easy_axis));
            if (a == b) h += inv_n * dot(m[k], heff[k]);
          }
          hess[a * dim + b] = h;
        }
      }
      if (residual <= tolerance) {
        // Converged: a minimum (positive semi-definite Hessian, up to 1e-8 of
        // the curvature scale), or a saddle to leave along its negative curvature.
        for (int i = 0; i < dim * dim; ++i) work[i] = hess[i];
        for (int a = 0; a < dim; ++a) work[a * dim + a] += 1e-8 * curvature_scale;
        if (cholesky(work, dim, 0.0)) break;
        for (int i = 0; i < dim * dim; ++i) work[i] = hess[i];
        symmetric_eigen(work, dim, eval, evec);
        int lowest = 0;
        for (int i = 1; i < dim; ++i)
          if (eval[i] < eval[lowest]) lowest = i;
        double sign = 0.0;
        for (int a = 0; a < dim; ++a)
          if (fabs(evec[a * dim + lowest]) > fabs(sign)) sign = evec[a * dim + lowest];
        for (int a = 0; a < dim; ++a) step[a] = (sign >= 0 ? 0.1 : -0.1) * evec[a * dim + lowest];
      } else {
        // Newton (shift 1e-12 of the curvature scale for the zero modes) where
        // the Hessian is positive definite. Otherwise: for n = 2 (4 x 4, cheap)
        // the eigen-decomposition with |eigenvalue|, which keeps the full
        // Newton step along the slow pair-axis mode of weak fields; for more
        // moments a Levenberg-Marquardt step: the Hessian is the positive
        // semi-definite endo and anisotropy parts plus the diagonal
        // (m_k . H_eff,k) / n, so shifting by the most negative of those makes
        // it positive definite without an eigen-decomposition of up to 16 x 16.
        for (int i = 0; i < dim * dim; ++i) work[i] = hess[i];
        for (int a = 0; a < dim; ++a) work[a * dim + a] += 1e-12 * curvature_scale;
        bool factored = cholesky(work, dim, 0.0);
        if (!factored && dim <= 4) {
          for (int i = 0; i < dim * dim; ++i) work[i] = hess[i];
          symmetric_eigen(work, dim, eval, evec);
          for (int a = 0; a < dim; ++a) step[a] = 0.0;
          for (int i = 0; i < dim; ++i) {
            double vg = 0.0;
            for (int a = 0; a < dim; ++a) vg += evec[a * dim + i] * grad[a];
            const double lam = larger(fabs(eval[i]), 1e-14 * curvature_scale);
            for (int a = 0; a < dim; ++a) step[a] -= (vg / lam) * evec[a * dim + i];
          }
        } else {
          if (!factored) {
            double mu = 1e-12 * curvature_scale;
            for (int k = 0; k < n; ++k) mu = larger(mu, -inv_n * dot(m[k], heff[k]) + 1e-12 * curvature_scale);
            for (int i = 0; i < dim * dim; ++i) work[i] = hess[i];
            for (int a = 0; a < dim; ++a) work[a * dim + a] += mu;
            factored = cholesky(work, dim, 0.0);
          }
          for (int a = 0; a < dim; ++a) step[a] = factored ? -grad[a] : -grad[a] / curvature_scale;
          if (factored) cholesky_solve(work, dim, step);  // else round-off: a gradient step
        }
      }
    }
    double longest = 0.0;
    for (int k = 0; k < n; ++k) longest = larger(longest, hypot(step[2 * k], step[2 * k + 1]));
    double t = longest > 0.5 ? 0.5 / longest : 1.0;
    const double e0 = cell_free_energy(p, H_A, m);
    bool accepted = false;
    for (int ls = 0; ls < 40 && !accepted; ++ls, t *= 0.5) {
      for (int k = 0; k < n; ++k)
        trial[k] = rotate_on_sphere(m[k], (t * step[2 * k]) * basis[2 * k] +
                                              (t * step[2 * k + 1]) * basis[2 * k + 1]);
      const double e1 = cell_free_energy(p, H_A, trial);
      if (e1 <= e0 + 1e-15 * (fabs(e0) + scale)) accepted = true;
    }
    if (!accepted) break;
    for (int k = 0; k < n; ++k) m[k] = trial[k];
    residual = cell_torque_residual(p, H_A, m);
  }
  return steps;
}

// The exact minimum of an isotropic cell's free energy (H_K = 0): mean(m) =
// t H_A/|H_A|, t = min(|H_A| / (gamma_D Ms), 1), with each opposite pair
// (m_2j, m_2j+1) placed symmetrically about H_A and its axis turned as little
// as possible. Applied instead of the Newton polish where every moment has
// its pair (n even), after it otherwise. The polish cannot resolve weak
// fields: the curvature of the pair-axis mode, |H_A|^2 / (gamma_D Ms), is
// lost to round-off next to gamma_D Ms, so for iron the polish stopped with M
// 13-32% off at 1e-4..1e-2 A/m and 2e-7 off at 1 A/m, where its torque
// residual (2.8e-13) looked converged (docs/hard-cases.md). Where the polish
// converges this moves M by round-off only.
ODEMAG_HD void isotropic_minimum(const SoftCellParams& p, const Vec3& H_A, Vec3* m) {
  const double h = norm(H_A);
  const double t = fmin(h / (p.gamma_D * p.Ms), 1.0), s = sqrt(larger(0.0, 1.0 - t * t));
  const Vec3 dir = h > 0.0 ? (1.0 / h) * H_A : Vec3{};
  for (int j = 0; j + 1 < p.n; j += 2) {
    Vec3 axis = m[j] - m[j + 1];
    axis = axis - dot(axis, dir) * dir;
    if (squared_norm(axis) < 1e-24) {
      Vec3 v;
      tangent_basis(h > 0.0 ? dir : Vec3{0, 0, 1}, axis, v);
    }
    axis = normalized(axis);
    m[j] = t * dir + s * axis;
    m[j + 1] = t * dir - s * axis;
  }
}

// ---- the inner relaxation of one cell -----------------------------------------

// The noise stream of a cell: its draws are hash(stream ^ counter), so they
// depend on the seed, the cell and how many steps it took, nothing else.
ODEMAG_HD uint64_t noise_stream(uint64_t seed, uint64_t cell) {
  return hash_key(seed, 0x4e4f495345ULL, cell, 0);
}

// Relax the moments of one soft cell under the frozen applied field H_A.
// single_step: one LLG step with history (paper Algorithm 1, one iteration).
// Otherwise: LLG steps until the relative torque falls below llg_switch (these
// choose the basin, so remanence stays path-dependent), then Newton polish to
// the tolerance. counter numbers the noise draws of this cell.
ODEMAG_HD LocalRelaxResult relax_soft_cell(const SoftCellParams& p, const Vec3& H_A, Vec3* m,
                                           Vec3* hc_prev, bool& has_history, uint64_t& counter,
                                           uint64_t noise_stream, const LocalRelaxOptions& o) {
  LocalRelaxResult r;
  const double c = cayley_coefficient(p, H_A, o.time_step_factor);
  r.residual = cell_torque_residual(p, H_A, m);
  if (o.single_step) {
    if (r.residual > o.tolerance) {
      llg_step(p, H_A, m, hc_prev, has_history, c, o.noise_ratio, mix64(noise_stream ^ counter++));
      r.llg_steps = 1;
    }
    return r;
  }
  bool history = false;
  while (r.residual > o.llg_switch && r.llg_steps < o.max_llg_steps) {
    llg_step(p, H_A, m, hc_prev, history, c, o.noise_ratio, mix64(noise_stream ^ counter++));
    ++r.llg_steps;
    r.residual = cell_torque_residual(p, H_A, m);
  }
  // An isotropic cell of opposite pairs has one minimum, put in closed form
  // below: mean(m) = min(|H_A| / (gamma_D Ms), 1) H_A / |H_A| whatever the
  // pair axes, so a polish would turn only the axes.
  const bool closed_form = o.newton && p.H_K == 0.0 && p.n % 2 == 0;
  if (o.newton && !closed_form)
    r.newton_steps = newton_polish(p, H_A, m, o.max_newton_steps, o.tolerance, r.residual);
  if (o.newton && p.H_K == 0.0) {
    isotropic_minimum(p, H_A, m);
    r.residual = cell_torque_residual(p, H_A, m);
  }
  has_history = false;
  return r;
}

// Magnetization of a permanent cell with recoil: M = M_r + chi_r H_inside with
// H_inside = H_A - M/3 (spherical cell), so M = (M_r + chi_r H_A) / (1 + chi_r/3).
ODEMAG_HD Vec3 recoil_magnetization(const Vec3& remanent, double chi_r, const Vec3& H_A) {
  return (1.0 / (1.0 + chi_r / 3.0)) * (remanent + chi_r * H_A);
}

}  // namespace odemag
