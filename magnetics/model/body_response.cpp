#include "magnetics/model/body_response.h"

#include <Eigen/Dense>
#include <cmath>

#include "magnetics/kernels/eigen_tensors.h"
#include "magnetics/model/model.h"

namespace odemag {

// I - J = W^-1/2 S W^1/2 with W = diag(V) (per component) and S = I - W^1/2
// K W^1/2 / gamma_D symmetric positive definite (K is symmetric, and I - J
// is (gamma_D I + N') / gamma_D with N' the body's demagnetising operator
// beyond I/3, positive semi-definite with the boundary correction too):
// S is factored by Cholesky, half the work of an LU.
struct BodyResponseFactor {
  Eigen::LLT<Eigen::MatrixXd> llt;
  Eigen::VectorXd sqrt_volume;  // W^1/2, per component
};

bool takes_body_response(const MagneticBody& body) {
  const int n = body.cell_count();
  return body.kind == CellKind::soft && body.bh_curve.empty() && body.soft.H_K == 0.0 && !body.cells.graded &&
         (!body.offset_tensors.empty() || body.cells.refined) && n >= kMinResponseCells &&
         n <= kMaxResponseCells &&
         body.soft.gamma_D <= 1.0 / 3.0 + 1e-2;
}

namespace {

// S = I - W^1/2 K W^1/2 / gamma (gamma_D for the factor), K_ij the field at cell i per unit moment
// at cell j inside the body: the offset tensors T(l_i - l_j) (i != j; a body
// of refined zones: its pair tensors T_ij), the
// boundary correction's self tensors S_i (i = j) and its uniform-mode terms
// Pi_i G_Pi Pi_j - beta_i G_beta beta_j (magnetics/model/model.cpp
// build_boundary_correction). So J_ij = K_ij V_j / gamma_D.
Eigen::MatrixXd body_response_matrix(const MagneticBody& body, double gamma) {
  const int n = body.cell_count();
  const CellSet& cells = body.cells;
  const bool boundary = !body.self_tensors.empty();
  const Eigen::Matrix3d G_pi = boundary ? eigen_matrix(body.uniform_inverse[0]) : Eigen::Matrix3d::Zero();
  const Eigen::Matrix3d G_beta = boundary ? eigen_matrix(body.uniform_inverse[1]) : Eigen::Matrix3d::Zero();
  Eigen::MatrixXd S = Eigen::MatrixXd::Identity(3 * n, 3 * n);
  for (int j = 0; j < n; ++j) {
    for (int i = j; i < n; ++i) {  // the lower triangle: all LLT reads
      Eigen::Matrix3d K = Eigen::Matrix3d::Zero();
      if (i != j)
        K = symmetric_matrix(
            cells.refined
                ? &body.pair_tensors[6u * (static_cast<size_t>(i) * n + j)]
                : &body.offset_tensors[6u * body.offset_index(cells.lattice_index[i], cells.lattice_index[j])]);
      if (boundary) {
        if (i == j) K += symmetric_matrix(&body.self_tensors[6u * i]);
        K += symmetric_matrix(&body.uniform_tensors[12u * i]) * G_pi * symmetric_matrix(&body.uniform_tensors[12u * j]) -
             symmetric_matrix(&body.uniform_tensors[12u * i + 6]) * G_beta * symmetric_matrix(&body.uniform_tensors[12u * j + 6]);
      }
      const double scale = std::sqrt(cells.volumes[i] * cells.volumes[j]) / gamma;
      S.block<3, 3>(3 * i, 3 * j) -= scale * K;
    }
  }
  return S;
}

}  // namespace

bool body_operator_positive_definite(const MagneticBody& body, double gamma) {
  const Eigen::LLT<Eigen::MatrixXd> llt(body_response_matrix(body, gamma));
  return llt.info() == Eigen::Success;
}

std::shared_ptr<const BodyResponseFactor> build_body_response(const MagneticBody& body) {
  if (!takes_body_response(body)) return nullptr;
  const int n = body.cell_count();
  auto factor = std::make_shared<BodyResponseFactor>();
  factor->sqrt_volume.resize(3 * n);
  for (int i = 0; i < n; ++i) factor->sqrt_volume.segment<3>(3 * i).setConstant(std::sqrt(body.cells.volumes[i]));
  factor->llt.compute(body_response_matrix(body, body.soft.gamma_D));
  // Not positive definite (it should be; a guard): no preconditioner.
  if (factor->llt.info() != Eigen::Success) return nullptr;
  return factor;
}

// (I - J)^-1 r = W^-1/2 S^-1 W^1/2 r.
void solve_body_response(const BodyResponseFactor& factor, double* r) {
  Eigen::Map<Eigen::VectorXd> v(r, factor.sqrt_volume.size());
  v = factor.llt.solve(v.cwiseProduct(factor.sqrt_volume)).cwiseQuotient(factor.sqrt_volume);
}

}  // namespace odemag
