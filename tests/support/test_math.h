// Small math helpers of the tests and the benchmarks (tests/support/).
#pragma once

#include <Eigen/Dense>
#include <cmath>

#include "magnetics/kernels/eigen_tensors.h"
#include "odemag/vec3.h"

namespace odemag::test_support {

// The rotation by `angle` (rad) about `axis` (any length).
inline Mat3 axis_rotation(const Vec3& axis, double angle) {
  const Vec3 a = normalized(axis);
  const double s = std::sin(angle / 2);
  return rotation_from_quaternion(std::cos(angle / 2), s * a.x, s * a.y, s * a.z);
}

// Tensors as Eigen matrices: the library's (magnetics/kernels/eigen_tensors.h).
using odemag::eigen_matrix;
using odemag::symmetric_matrix;

}  // namespace odemag::test_support
