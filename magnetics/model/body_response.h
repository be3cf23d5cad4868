// The linear response of a high-susceptibility lattice body to its own
// intra-body field, factorized once per body: the block preconditioner of
// the outer relaxation loop (docs/model.md "Block preconditioner").
//
// The outer loop iterates the cells' applied fields x -> G(x) = H_fixed +
// H_resp(M(x)). For an isotropic soft body below saturation each cell takes
// M_i = H_A,i / gamma_D, so the body's own part of G is linear with Jacobian
// J_ij = T_ij V_j / gamma_D (T the intra-body tensors and boundary terms,
// H_i += T_ij mu_j). Its eigenvalues reach (1 - 1/3) / gamma_D ~ 2 for chi
// >> 1: the body's slow modes, which plain mixing cannot converge and
// Anderson converges only slowly (the crane core, docs/benchmarks.md
// section 4). A Newton step for the block, (I - J) dx = f, removes them:
// (I - J) = (gamma_D I + N) / gamma_D with N the body's positive
// semi-definite demagnetising operator, so it is well conditioned.
#pragma once

#include <memory>

namespace odemag {

struct MagneticBody;
struct BodyResponseFactor;  // the factorization (body_response.cpp)

// Bodies that get it: soft, isotropic (H_K = 0, no B-H curve), on a uniform
// lattice of kMinResponseCells .. kMaxResponseCells cells, chi >= 100
// (gamma_D <= 1/3 + 1e-2): below it the plain loop converges in a few
// iterations and the solve would cost more than it saves; above the cell
// cap the dense factor (9 n^2 doubles) and its build (9 n^3 flops) grow
// past what a scene load should take (400 cells: 11 MB, 0.05 s measured).
inline constexpr int kMinResponseCells = 8;
inline constexpr int kMaxResponseCells = 400;
bool takes_body_response(const MagneticBody& body);

// The factor of I - J for the body (body frame, 3 n unknowns, cell-major).
std::shared_ptr<const BodyResponseFactor> build_body_response(const MagneticBody& body);

// Whether S = I - W^1/2 K W^1/2 / gamma (the matrix the factor is of, K the
// body's own field per unit moment with its boundary correction) is
// positive definite: Cholesky of 3 n unknowns (9 n^3 / 3 flops), for any
// responsive body with cells. The relaxation of a linear body whose cells
// take M = H / gamma needs it.
bool body_operator_positive_definite(const MagneticBody& body, double gamma);
// Replaces r (3 n doubles, body frame) by (I - J)^-1 r.
void solve_body_response(const BodyResponseFactor& factor, double* r);

}  // namespace odemag
