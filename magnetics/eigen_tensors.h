// The model's small tensors as Eigen matrices, for host code that solves with
// them (the boundary correction, the body response's factor).
#pragma once

#include <Eigen/Dense>

#include "magnetics/vec3.h"

namespace odemag {

// A symmetric tensor stored as six components (xx, xy, xz, yy, yz, zz).
inline Eigen::Matrix3d symmetric_matrix(const double* t) {
  Eigen::Matrix3d m;
  m << t[0], t[1], t[2], t[1], t[3], t[4], t[2], t[4], t[5];
  return m;
}

inline Eigen::Matrix3d eigen_matrix(const Mat3& a) {
  Eigen::Matrix3d m;
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) m(r, c) = a.m[r][c];
  return m;
}

}  // namespace odemag
