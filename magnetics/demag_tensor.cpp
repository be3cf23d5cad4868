#include "magnetics/demag_tensor.h"

#include <cmath>

#include "magnetics/constants.h"
#include "magnetics/kernels.h"

namespace odemag {

namespace {

// Newell's f(x, y, z): the sixfold antiderivative behind N_xx (even in each argument).
double newell_f(double x, double y, double z) {
  x = std::fabs(x), y = std::fabs(y), z = std::fabs(z);
  const double x2 = x * x, y2 = y * y, z2 = z * z;
  const double R = std::sqrt(x2 + y2 + z2);
  double f = (2.0 * x2 - y2 - z2) * R / 6.0;
  if (x2 + z2 > 0.0) f += 0.5 * y * (z2 - x2) * std::asinh(y / std::sqrt(x2 + z2));
  if (x2 + y2 > 0.0) f += 0.5 * z * (y2 - x2) * std::asinh(z / std::sqrt(x2 + y2));
  if (x > 0.0) f -= x * y * z * std::atan(y * z / (x * R));
  return f;
}

// Newell's g(x, y, z): the antiderivative behind N_xy (odd in x and y, even in z).
double newell_g(double x, double y, double z) {
  const double sign = (x < 0.0 ? -1.0 : 1.0) * (y < 0.0 ? -1.0 : 1.0);
  x = std::fabs(x), y = std::fabs(y), z = std::fabs(z);
  const double x2 = x * x, y2 = y * y, z2 = z * z;
  const double R = std::sqrt(x2 + y2 + z2);
  double g = -x * y * R / 3.0;
  if (x2 + y2 > 0.0) g += x * y * z * std::asinh(z / std::sqrt(x2 + y2));
  if (y2 + z2 > 0.0) g += y / 6.0 * (3.0 * z2 - y2) * std::asinh(x / std::sqrt(y2 + z2));
  if (x2 + z2 > 0.0) g += x / 6.0 * (3.0 * z2 - x2) * std::asinh(y / std::sqrt(x2 + z2));
  if (z > 0.0) g -= z2 * z / 6.0 * std::atan(x * y / (z * R));
  if (y > 0.0) g -= 0.5 * z * y2 * std::atan(x * z / (y * R));
  if (x > 0.0) g -= 0.5 * z * x2 * std::atan(y * z / (x * R));
  return sign * g;
}

// Second difference in each axis with weights (-1, 2, -1): the 27-point
// combination 8 f(X) - 4 (faces) + 2 (edges) - (corners).
template <class F>
double second_differences(F fn, double X, double Y, double Z, double h) {
  static constexpr double w[3] = {-1.0, 2.0, -1.0};
  double s = 0.0;
  for (int a = 0; a < 3; ++a)
    for (int b = 0; b < 3; ++b)
      for (int c = 0; c < 3; ++c)
        s += w[a] * w[b] * w[c] * fn(X + (a - 1) * h, Y + (b - 1) * h, Z + (c - 1) * h);
  return s;
}

}  // namespace

void cube_demag_tensor(int i, int j, int k, double h, double n[6]) {
  // Evaluate at |offset| and restore the signs of the odd components, so that
  // N(-d) = N(d) holds exactly (the 27-term sums cancel to ~1e-12 relative);
  // components odd in an axis along which the offset is zero vanish exactly.
  const double sx = i < 0 ? -1.0 : (i > 0 ? 1.0 : 0.0);
  const double sy = j < 0 ? -1.0 : (j > 0 ? 1.0 : 0.0);
  const double sz = k < 0 ? -1.0 : (k > 0 ? 1.0 : 0.0);
  const double X = std::abs(i) * h, Y = std::abs(j) * h, Z = std::abs(k) * h;
  if (i * i + j * j + k * k > kNewellRange * kNewellRange) {
    double t[6];
    dipole_tensor({X, Y, Z}, 0.0, t);  // H = T mu with mu = M h^3, and H = -N M
    for (int a = 0; a < 6; ++a) n[a] = -t[a] * h * h * h;
  } else {
    const double c = 1.0 / (4.0 * kPi * h * h * h);
    auto fxx = [](double x, double y, double z) { return newell_f(x, y, z); };
    auto fyy = [](double x, double y, double z) { return newell_f(y, x, z); };
    auto fzz = [](double x, double y, double z) { return newell_f(z, y, x); };
    auto gxy = [](double x, double y, double z) { return newell_g(x, y, z); };
    auto gxz = [](double x, double y, double z) { return newell_g(x, z, y); };
    auto gyz = [](double x, double y, double z) { return newell_g(y, z, x); };
    n[0] = c * second_differences(fxx, X, Y, Z, h);
    n[1] = c * second_differences(gxy, X, Y, Z, h);
    n[2] = c * second_differences(gxz, X, Y, Z, h);
    n[3] = c * second_differences(fyy, X, Y, Z, h);
    n[4] = c * second_differences(gyz, X, Y, Z, h);
    n[5] = c * second_differences(fzz, X, Y, Z, h);
  }
  n[1] *= sx * sy;
  n[2] *= sx * sz;
  n[4] *= sy * sz;
}

}  // namespace odemag
