// Small fixed-size vector and matrix types usable on host and device.
#pragma once

#include <cmath>

// Functions marked ODEMAG_HD are compiled for the host and, under nvcc, for the
// device as well, so the CPU and CUDA backends share one copy of each formula.
#ifndef ODEMAG_HD
#if defined(__CUDACC__)
#define ODEMAG_HD __host__ __device__ inline
#else
#define ODEMAG_HD inline
#endif
#endif

namespace odemag {

struct Vec3 {
  double x = 0.0, y = 0.0, z = 0.0;

  ODEMAG_HD double& operator[](int i) { return i == 0 ? x : (i == 1 ? y : z); }
  ODEMAG_HD double operator[](int i) const { return i == 0 ? x : (i == 1 ? y : z); }
  ODEMAG_HD Vec3& operator+=(const Vec3& b) { x += b.x; y += b.y; z += b.z; return *this; }
  ODEMAG_HD Vec3& operator-=(const Vec3& b) { x -= b.x; y -= b.y; z -= b.z; return *this; }
  ODEMAG_HD Vec3& operator*=(double s) { x *= s; y *= s; z *= s; return *this; }
};

ODEMAG_HD Vec3 operator+(const Vec3& a, const Vec3& b) { return {a.x + b.x, a.y + b.y, a.z + b.z}; }
ODEMAG_HD Vec3 operator-(const Vec3& a, const Vec3& b) { return {a.x - b.x, a.y - b.y, a.z - b.z}; }
ODEMAG_HD Vec3 operator-(const Vec3& a) { return {-a.x, -a.y, -a.z}; }
ODEMAG_HD Vec3 operator*(double s, const Vec3& a) { return {s * a.x, s * a.y, s * a.z}; }
ODEMAG_HD Vec3 operator*(const Vec3& a, double s) { return {s * a.x, s * a.y, s * a.z}; }
ODEMAG_HD Vec3 operator/(const Vec3& a, double s) { return {a.x / s, a.y / s, a.z / s}; }
ODEMAG_HD double dot(const Vec3& a, const Vec3& b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
ODEMAG_HD Vec3 cross(const Vec3& a, const Vec3& b) {
  return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}
ODEMAG_HD double squared_norm(const Vec3& a) { return dot(a, a); }
ODEMAG_HD double norm(const Vec3& a) { return sqrt(dot(a, a)); }
ODEMAG_HD Vec3 normalized(const Vec3& a) {
  const double n = norm(a);
  return n > 0.0 ? a / n : Vec3{0.0, 0.0, 0.0};
}
ODEMAG_HD bool is_finite(const Vec3& a) {
  return std::isfinite(a.x) && std::isfinite(a.y) && std::isfinite(a.z);
}

// Row-major 3x3 matrix; used for body rotations (body frame -> world frame).
struct Mat3 {
  double m[3][3] = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}};

  ODEMAG_HD Vec3 operator*(const Vec3& v) const {
    return {m[0][0] * v.x + m[0][1] * v.y + m[0][2] * v.z,
            m[1][0] * v.x + m[1][1] * v.y + m[1][2] * v.z,
            m[2][0] * v.x + m[2][1] * v.y + m[2][2] * v.z};
  }
  // Transpose times vector: world -> body for a rotation.
  ODEMAG_HD Vec3 transpose_times(const Vec3& v) const {
    return {m[0][0] * v.x + m[1][0] * v.y + m[2][0] * v.z,
            m[0][1] * v.x + m[1][1] * v.y + m[2][1] * v.z,
            m[0][2] * v.x + m[1][2] * v.y + m[2][2] * v.z};
  }
  ODEMAG_HD Mat3 operator*(const Mat3& b) const {
    Mat3 r;
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j)
        r.m[i][j] = m[i][0] * b.m[0][j] + m[i][1] * b.m[1][j] + m[i][2] * b.m[2][j];
    return r;
  }
  ODEMAG_HD Mat3 transposed() const {
    Mat3 r;
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) r.m[i][j] = m[j][i];
    return r;
  }
};

// Rotation matrix of the unit quaternion (w, x, y, z); the quaternion is normalised first.
ODEMAG_HD Mat3 rotation_from_quaternion(double w, double x, double y, double z) {
  const double n = sqrt(w * w + x * x + y * y + z * z);
  w /= n; x /= n; y /= n; z /= n;
  Mat3 r;
  r.m[0][0] = 1 - 2 * (y * y + z * z); r.m[0][1] = 2 * (x * y - w * z);     r.m[0][2] = 2 * (x * z + w * y);
  r.m[1][0] = 2 * (x * y + w * z);     r.m[1][1] = 1 - 2 * (x * x + z * z); r.m[1][2] = 2 * (y * z - w * x);
  r.m[2][0] = 2 * (x * z - w * y);     r.m[2][1] = 2 * (y * z + w * x);     r.m[2][2] = 1 - 2 * (x * x + y * y);
  return r;
}

// A rigid body's pose: the rotation that takes body-frame vectors to the
// world frame, and the position of its centre of mass.
struct BodyPose {
  Mat3 rotation;  // body frame -> world frame
  Vec3 position;  // centre of mass, world, m
};

}  // namespace odemag
