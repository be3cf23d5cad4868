// The static magnetization of fixed soft lattice bodies with a B-H curve in
// an applied (coil) field, by Newton-Krylov on FFT matvecs (docs/model.md
// "Nonlinear static solve").
//
// Unknowns: the mean magnetization M_i of every cell. Equations
//   G_i(M) = M_i - w_i f(H_i) = 0,   H = H_source + H_d(M)               (3)
// with H_d the cell-averaged demagnetizing field (magnetics/static/lattice_fft.h),
// f(H) = M(|H|) H / |H| the anhysteretic curve (magnetics/materials/bh_curve.h,
// extrapolated with dB/dH = mu0) and w_i the cell's volume share of steel
// (1 inside, less for a cell the body's surface cuts: the cell's mean M).
// Solved for the cells' field H instead (docs/model.md "Nonlinear static solve"):
//   R(H) = H - H_source - H_d(w f(H)) = 0                                 (4)
// by Newton, (I + N J) dH = -R, J_i = w_i (chi_d u u^T + chi_s (I - u u^T))
// the cell law's Jacobian dM/dH, chi_d = dM/dH the differential (chord along
// H) and chi_s = M/|H| the secant susceptibility (across H), u = H / |H|, and
// N v = -H_d(v); the Newton system by GMRES (FFT matvecs), right-
// preconditioned with the cells' own blocks (I + N(0) J_i)^-1, to the
// Eisenstat-Walker forcing, and a backtracking line search on |R|. In H the
// cell law is bounded (|M| <= Ms), so a step cannot overshoot saturation as
// a step in M does; from M = 0 the solve starts at H = 0, whose first step is
// the linear problem with the initial susceptibility. Converged when (3)'s
// residual at M = w f(H) is below the tolerance.
//
// By default the Newton variable is the cells' b = H + M (B / mu0) instead
// (docs/model.md "Nonlinear static solve"):
//   R(b) = H(b) - H_source - H_d(M(b)) = 0,   M(b) = b - H(b)            (5)
// with H(b) the inverse of b = H + w f(H) along b: both H(b) and M(b) have
// slopes between 0 and 1 (dM/db = chi_d / (1 + chi_d) along b), so the cell
// law is as mild at the knee of the curve as in saturation, where in H its
// slope runs from the initial susceptibility through the largest to 0.
// Newton matrix I + (N - I) J with J = dM/db, blocks (I + (N(0) - I) J_i)^-1.
// Measured on TEAM 20: 3-7 Newton steps instead of 10-23, 1.8 times fewer
// field evaluations, the same solution.
#pragma once

#include <vector>

#include "magnetics/materials/bh_curve.h"
#include "magnetics/static/demag_operator.h"
#include "odemag/vec3.h"

namespace odemag {

// The Newton variable of solve_bh_lattice: the cells' H (4) or b = H + M (5).
enum class BhNewtonVariable { field, flux_density };

struct BhSolveOptions {
  double tolerance = 1e-7;   // on |G| / |w f(H)| (2-norms over all cells)
  BhNewtonVariable variable = BhNewtonVariable::flux_density;
  int max_newton = 60;
  // GMRES stops at the relative residual eta of the Newton system, eta by
  // Eisenstat and Walker's choice 2 between min_forcing and forcing.
  double forcing = 0.1;
  double min_forcing = 1e-6;
  int restart = 80;
  int max_krylov = 3000;     // per Newton step
};

struct BhSolveReport {
  bool converged = false;
  int newton_iterations = 0;
  int krylov_iterations = 0;     // all GMRES iterations (one FFT matvec each)
  int matvecs = 0;               // all demagnetizing-field evaluations (GMRES, restarts, residuals)
  double residual = 0.0;         // final |G| / |w f(H)| of (3)
  std::vector<double> residuals; // the same, before the first and after each Newton step
};

// Solves (3) from the initial M (size demag.cells(); a previous solution, or
// zeros). fill and H_source per cell.
BhSolveReport solve_bh_lattice(const DemagOperator& demag, const BhCurve& curve, const std::vector<double>& fill,
                               const std::vector<Vec3>& H_source, std::vector<Vec3>& M,
                               const BhSolveOptions& options = {});

// f(H) of (3) for one cell, and its Jacobian dM/dH (six components), times w.
Vec3 bh_cell_law(const BhCurve& curve, double w, const Vec3& H, double jacobian[6]);

// The same law in b = H + M (5): M and H (A/m) of the cell whose b is given,
// and dM/db (six components).
Vec3 bh_flux_cell_law(const BhCurve& curve, double w, const Vec3& b, Vec3& H, double jacobian[6]);

}  // namespace odemag
