// Small math helpers of the tests and the benchmarks (tests/support/).
#pragma once

#include <Eigen/Dense>
#include <cmath>

#include "magnetics/vec3.h"

namespace odemag::test_support {

// The rotation by `angle` (rad) about `axis` (any length).
inline Mat3 axis_rotation(const Vec3& axis, double angle) {
  const Vec3 a = normalized(axis);
  const double s = std::sin(angle / 2);
  return rotation_from_quaternion(std::cos(angle / 2), s * a.x, s * a.y, s * a.z);
}

// A symmetric 3x3 tensor stored as its 6 upper components (xx, xy, xz, yy,
// yz, zz; magnetics/model.h) as an Eigen matrix.
inline Eigen::Matrix3d symmetric_matrix(const double* t) {
  Eigen::Matrix3d m;
  m << t[0], t[1], t[2], t[1], t[3], t[4], t[2], t[4], t[5];
  return m;
}

// A Mat3 as an Eigen matrix.
inline Eigen::Matrix3d eigen_matrix(const Mat3& a) {
  Eigen::Matrix3d m;
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) m(r, c) = a.m[r][c];
  return m;
}

}  // namespace odemag::test_support
