// Checks on the magnetics shared by the tests and the benchmarks
// (tests/support/): F = -grad U and tau = -dU/dtheta by central differences,
// the balance of a closed system, and the largest eigenvalue of a soft body's
// linear response map.
#pragma once

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>

#include "magnetics/model/model.h"
#include "magnetics/model/state.h"
#include "tests/support/test_math.h"

namespace odemag::test_support {

// -dU/dq_a (a = x, y, z) of a body by central differences of step h:
// move(pose, saved, e_a, +-h) displaces the body from its pose `saved` along
// the world axis e_a; `energy()` returns U with the body at `pose`, which is
// restored after.
template <class Energy, class Move>
Vec3 minus_gradient(BodyPose& pose, Energy&& energy, double h, Move&& move) {
  const BodyPose saved = pose;
  Vec3 g;
  for (int a = 0; a < 3; ++a) {
    Vec3 e;
    e[a] = 1.0;
    move(pose, saved, e, h);
    const double up = energy();
    move(pose, saved, e, -h);
    const double down = energy();
    pose = saved;
    g[a] = -(up - down) / (2 * h);
  }
  return g;
}

// -dU/dx_a (the force) by shifts of +-dx (m).
template <class Energy>
Vec3 minus_position_gradient(BodyPose& pose, Energy&& energy, double dx) {
  return minus_gradient(pose, energy, dx, [](BodyPose& p, const BodyPose& saved, const Vec3& e, double d) {
    p.position = saved.position + d * e;
  });
}

// -dU/dtheta_a (the torque) by turns of +-dtheta (rad) about the world axes.
template <class Energy>
Vec3 minus_rotation_gradient(BodyPose& pose, Energy&& energy, double dtheta) {
  return minus_gradient(pose, energy, dtheta, [](BodyPose& p, const BodyPose& saved, const Vec3& e, double d) {
    p.rotation = axis_rotation(e, d) * saved.rotation;
  });
}

// The net force and the net torque about the origin (sum of x_b x F_b +
// tau_b) of all bodies, with the scales to compare them to: the largest |F_b|
// and the largest |tau_b| + |x_b| |F_b|.
struct NetForceAndTorque {
  Vec3 force, torque;
  double force_scale = 0.0, torque_scale = 0.0;
};

inline NetForceAndTorque net_force_and_torque(const MagneticModel& model, const MagneticState& state) {
  NetForceAndTorque net;
  for (int b = 0; b < model.body_count(); ++b) {
    net.force += state.force[b];
    net.torque += cross(state.pose[b].position, state.force[b]) + state.torque[b];
    net.force_scale = std::max(net.force_scale, norm(state.force[b]));
    net.torque_scale =
        std::max(net.torque_scale, norm(state.torque[b]) + norm(state.pose[b].position) * norm(state.force[b]));
  }
  return net;
}

// A model of one soft iron body (M_s = 1.7e6 A/m, susceptibility chi) on a
// lattice of spacing h.
inline MagneticModel soft_body_model(IntraBodyTensor kind, const Shape& shape, double h, double chi) {
  MagneticModel model(kind);
  SoftMaterial iron;
  iron.saturation = 1.7e6;
  iron.susceptibility = chi;
  model.add_body("body", shape, iron, h);
  return model;
}

// Largest eigenvalue of the linear response map M -> H_intra(M) / gamma_D of
// a soft body: above 1 the body magnetizes itself without any applied field.
// H_i = sum_j F_ij V_j M_j with F symmetric: the lattice tensors, and for
// bodies with boundary cells the boundary correction (self and uniform-mode
// tensors, magnetics/model/model.cpp). The map is similar to W^1/2 F W^1/2 / gamma_D
// (W = diag V), which is symmetric.
inline double largest_response_eigenvalue(const MagneticBody& b) {
  const int n = b.cell_count();
  const bool corrected = !b.self_tensors.empty();
  const Eigen::Matrix3d Gpi = eigen_matrix(b.uniform_inverse[0]), Gbeta = eigen_matrix(b.uniform_inverse[1]);
  auto mat = symmetric_matrix;
  Eigen::MatrixXd G = Eigen::MatrixXd::Zero(3 * n, 3 * n);
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) {
      Eigen::Matrix3d F = Eigen::Matrix3d::Zero();
      if (i != j) F = mat(&b.offset_tensors[6u * b.offset_index(b.cells.lattice_index[i], b.cells.lattice_index[j])]);
      if (corrected) {
        if (i == j) F += mat(&b.self_tensors[6u * i]);
        F += mat(&b.uniform_tensors[12u * i]) * Gpi * mat(&b.uniform_tensors[12u * j]) -
             mat(&b.uniform_tensors[12u * i + 6]) * Gbeta * mat(&b.uniform_tensors[12u * j + 6]);
      }
      G.block<3, 3>(3 * i, 3 * j) = std::sqrt(b.cells.volumes[i] * b.cells.volumes[j]) / b.soft.gamma_D * F;
    }
  G = 0.5 * (G + G.transpose());  // symmetric to rounding
  return Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(G, Eigen::EigenvaluesOnly).eigenvalues().maxCoeff();
}

}  // namespace odemag::test_support
