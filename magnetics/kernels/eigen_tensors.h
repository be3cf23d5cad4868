// The model's small tensors as Eigen matrices, for host code that solves with
// them (the boundary correction, the body response's factor).
#pragma once

#include <Eigen/Dense>

#include <algorithm>

#include "odemag/vec3.h"

namespace odemag {

// A symmetric tensor stored as six components (xx, xy, xz, yy, yz, zz).
inline Eigen::Matrix3d symmetric_matrix(const double* t) {
  Eigen::Matrix3d m;
  m << t[0], t[1], t[2], t[1], t[3], t[4], t[2], t[4], t[5];
  return m;
}

// The boundary correction's local part (magnetics/model/model.cpp, part 1): the
// eigenvalues of a cell's K above cap = (1 - w) / 3 (w = V / h^3, its
// cube's share inside the body) cut to cap, and what was cut added to its
// other eigenvalues, the largest first, up to the same bound.
inline Eigen::Matrix3d capped_boundary_correction(const Eigen::Matrix3d& K, double cap) {
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(K);
  Eigen::Vector3d e = eig.eigenvalues();  // ascending
  double cut = 0.0;
  for (int q = 0; q < 3; ++q)
    if (e(q) > cap) cut += e(q) - cap, e(q) = cap;
  for (int q = 2; q >= 0 && cut > 0.0; --q) {
    const double add = std::min(cap - e(q), cut);
    e(q) += add, cut -= add;
  }
  return eig.eigenvectors() * e.asDiagonal() * eig.eigenvectors().transpose();
}

inline Eigen::Matrix3d eigen_matrix(const Mat3& a) {
  Eigen::Matrix3d m;
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) m(r, c) = a.m[r][c];
  return m;
}

}  // namespace odemag
