#include "magnetics/cells/demag_tensor.h"

#include <algorithm>
#include <array>
#include <cmath>

#include "odemag/constants.h"
#include "magnetics/kernels/kernels.h"

namespace odemag {

namespace {

// Far away a cell-averaged tensor is the point dipole's: N = -V T(d) with V
// the source cell's volume (H = T mu, mu = M V, H = -N M), and its gradient
// from T = A I + B d d^T, dT_ab/dd_k = B (d_k delta_ab + delta_ak d_b +
// delta_bk d_a) + C d_k d_a d_b (magnetics/kernels/kernels.h); r2 = |d|^2.
void point_dipole_demag(const Vec3& d, double r2, double volume, double n[6], double (*dn)[6]) {
  double t[6];
  dipole_tensor(d, 0.0, t);
  for (int a = 0; a < 6; ++a) n[a] = -t[a] * volume;
  if (!dn) return;
  const DipoleCoefficients c = dipole_coefficients(r2, 0.0);
  static constexpr int row[6] = {0, 0, 0, 1, 1, 2}, col[6] = {0, 1, 2, 1, 2, 2};
  for (int k = 0; k < 3; ++k)
    for (int m = 0; m < 6; ++m) {
      const int a = row[m], b = col[m];
      double v = c.C * d[k] * d[a] * d[b];
      if (a == b) v += c.B * d[k];
      if (a == k) v += c.B * d[b];
      if (b == k) v += c.B * d[a];
      dn[k][m] = -volume * v;
    }
}

// Which components of N are odd in each axis (xx, xy, xz, yy, yz, zz).
constexpr int kOddIn[6][3] = {{0, 0, 0}, {1, 1, 0}, {1, 0, 1}, {0, 0, 0}, {0, 1, 1}, {0, 0, 0}};

// The sign of each component of d (0 for a zero component).
std::array<double, 3> axis_signs(const double d[3]) {
  std::array<double, 3> s{};
  for (int k = 0; k < 3; ++k) s[k] = d[k] < 0.0 ? -1.0 : (d[k] > 0.0 ? 1.0 : 0.0);
  return s;
}

// dN/dd at the signed d from c du, the gradient computed at |d|: axis k's
// sign moves from the components odd in it to the even ones.
void signed_gradient(double c, const double du[3][6], const std::array<double, 3>& sign, double (*dn)[6]) {
  for (int k = 0; k < 3; ++k)
    for (int m = 0; m < 6; ++m) {
      double v = c * du[k][m];
      for (int j = 0; j < 3; ++j)
        if ((j == k) != (kOddIn[m][j] != 0)) v *= sign[j];
      dn[k][m] = v;
    }
}

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

// f and g with their first derivatives at one point, sharing the
// transcendental terms. With v = (|x|, |y|, |z|), R = |v| and, per axis k
// with the other two axes i, j: L_k = asinh(v_k / sqrt(v_i^2 + v_j^2)) and
// A_k = atan(v_i v_j / (v_k R)) (each 0 where its denominator vanishes, as
// the guards in newell_f and newell_g drop those terms). Then f(p_i, p_j, p_k)
// and g(p_i, p_j, p_k) for any order
// (i, j, k) of the axes, and their derivatives (derived symbolically from f
// and g above; the test checks them against central differences).
struct NewellPoint {
  double v[3], s[3], R, L[3], A[3];

  NewellPoint(double x, double y, double z) {
    const double p[3] = {x, y, z};
    for (int k = 0; k < 3; ++k) v[k] = std::fabs(p[k]), s[k] = p[k] < 0.0 ? -1.0 : (p[k] > 0.0 ? 1.0 : 0.0);
    R = std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
    for (int k = 0; k < 3; ++k) {
      const double a = v[(k + 1) % 3], b = v[(k + 2) % 3];
      const double rho2 = a * a + b * b;
      L[k] = rho2 > 0.0 ? std::asinh(v[k] / std::sqrt(rho2)) : 0.0;
      A[k] = v[k] > 0.0 ? std::atan(a * b / (v[k] * R)) : 0.0;
    }
  }
  // Newell's f and g of the positive octant, arguments (v_i, v_j, v_k).
  double F(int i, int j, int k) const {
    const double a = v[i], b = v[j], c = v[k];
    return (2.0 * a * a - b * b - c * c) * R / 6.0 + 0.5 * b * (c * c - a * a) * L[j] +
           0.5 * c * (b * b - a * a) * L[k] - a * b * c * A[i];
  }
  double G(int i, int j, int k) const {
    const double a = v[i], b = v[j], c = v[k];
    return -a * b * R / 3.0 + a * b * c * L[k] + b / 6.0 * (3.0 * c * c - b * b) * L[i] +
           a / 6.0 * (3.0 * c * c - a * a) * L[j] - c * c * c / 6.0 * A[k] - 0.5 * c * b * b * A[j] -
           0.5 * c * a * a * A[i];
  }
  // dF/dv_i, dF/dv_j (= dG/dv_i) and dG/dv_k.
  double Fi(int i, int j, int k) const {
    const double a = v[i], b = v[j], c = v[k];
    return a * R - a * b * L[j] - a * c * L[k] - b * c * A[i];
  }
  double Fj(int i, int j, int k) const {
    const double a = v[i], b = v[j], c = v[k];
    return -0.5 * b * R + 0.5 * (c * c - a * a) * L[j] + b * c * L[k] - a * c * A[i];
  }
  double Gk(int i, int j, int k) const {
    const double a = v[i], b = v[j], c = v[k];
    return a * b * L[k] + a * c * L[j] + b * c * L[i] - 0.5 * (a * a * A[i] + b * b * A[j] + c * c * A[k]);
  }
  // The signed functions: f (even in each argument) and g (odd in the first
  // two) of (p_i, p_j, p_k), and their gradients along (p_i, p_j, p_k); at a
  // kink (an argument exactly 0) the mean of the two sides (s = 0 there).
  double f(int i, int j, int k, double grad[3]) const {
    grad[0] = s[i] * Fi(i, j, k);
    grad[1] = s[j] * Fj(i, j, k);
    grad[2] = s[k] * Fj(i, k, j);  // f is symmetric in its last two arguments
    return F(i, j, k);
  }
  double g(int i, int j, int k, double grad[3]) const {
    grad[0] = s[j] * Fj(i, j, k);  // dg/dx = df/dy
    grad[1] = s[i] * Fj(j, i, k);  // g is symmetric in its first two arguments
    grad[2] = s[i] * s[j] * s[k] * Gk(i, j, k);
    return s[i] * s[j] * G(i, j, k);
  }
};

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

void cube_demag_tensor_at(const double d[3], double h, double n[6], double (*dn)[6]) {
  const double r2 = d[0] * d[0] + d[1] * d[1] + d[2] * d[2];
  const double range = kNewellRange * h;
  if (r2 > range * range) {
    point_dipole_demag(Vec3{d[0], d[1], d[2]}, r2, h * h * h, n, dn);
    return;
  }
  // As cube_demag_tensor: the 27-point second differences at |d|, then the
  // signs of the components odd in an axis restored. Component m is f (xx,
  // yy, zz) or g (xy, xz, yz) with its arguments in the order order[m].
  static constexpr int order[6][3] = {{0, 1, 2}, {0, 1, 2}, {0, 2, 1}, {1, 0, 2}, {1, 2, 0}, {2, 1, 0}};
  static constexpr bool is_f[6] = {true, false, false, true, false, true};
  static constexpr double w[3] = {-1.0, 2.0, -1.0};
  const std::array<double, 3> sign = axis_signs(d);
  const double X = std::fabs(d[0]), Y = std::fabs(d[1]), Z = std::fabs(d[2]);
  double u[6] = {}, du[3][6] = {};  // the tensor at |d| and its gradient
  for (int a = 0; a < 3; ++a)
    for (int b = 0; b < 3; ++b)
      for (int e = 0; e < 3; ++e) {
        const double wt = w[a] * w[b] * w[e];
        const NewellPoint pt(X + (a - 1) * h, Y + (b - 1) * h, Z + (e - 1) * h);
        for (int m = 0; m < 6; ++m) {
          const int* o = order[m];
          double g[3];
          u[m] += wt * (is_f[m] ? pt.f(o[0], o[1], o[2], g) : pt.g(o[0], o[1], o[2], g));
          if (dn)
            for (int q = 0; q < 3; ++q) du[o[q]][m] += wt * g[q];
        }
      }
  const double c = 1.0 / (4.0 * kPi * h * h * h);
  for (int m = 0; m < 6; ++m) {
    n[m] = c * u[m];
    for (int k = 0; k < 3; ++k)
      if (kOddIn[m][k]) n[m] *= sign[k];
  }
  if (dn) signed_gradient(c, du, sign, dn);
}

void cuboid_demag_tensor(const double half_a[3], const double half_b[3], const double d[3], double n[6],
                         double (*dn)[6]) {
  const std::array<double, 3> sign = axis_signs(d);
  const double X[3] = {std::fabs(d[0]), std::fabs(d[1]), std::fabs(d[2])};
  double edge = 0.0;
  for (int k = 0; k < 3; ++k) edge = std::max({edge, 2.0 * half_a[k], 2.0 * half_b[k]});
  const double range = kNewellRange * edge;
  const double r2 = X[0] * X[0] + X[1] * X[1] + X[2] * X[2];
  if (r2 > range * range) {
    // At the signed d: the signs restored below are already in it.
    point_dipole_demag(Vec3{d[0], d[1], d[2]}, r2, 8.0 * half_b[0] * half_b[1] * half_b[2], n, dn);
    return;
  }
  // Per axis: the four corner differences of the two intervals and their
  // weights (the double integral of a function of x - x' over both
  // intervals is this combination of its second antiderivative).
  double u[3][4];
  for (int k = 0; k < 3; ++k) {
    const double s = half_a[k] + half_b[k], t = half_a[k] - half_b[k];
    u[k][0] = X[k] - s, u[k][1] = X[k] - t, u[k][2] = X[k] + t, u[k][3] = X[k] + s;
  }
  static constexpr double w[4] = {-1.0, 1.0, 1.0, -1.0};
  static constexpr int order[6][3] = {{0, 1, 2}, {0, 1, 2}, {0, 2, 1}, {1, 0, 2}, {1, 2, 0}, {2, 1, 0}};
  static constexpr bool is_f[6] = {true, false, false, true, false, true};
  double sum[6] = {0, 0, 0, 0, 0, 0}, du[3][6] = {};  // the tensor at |d| and its gradient
  for (int a = 0; a < 4; ++a)
    for (int b = 0; b < 4; ++b)
      for (int e = 0; e < 4; ++e) {
        const double wt = w[a] * w[b] * w[e];
        const NewellPoint pt(u[0][a], u[1][b], u[2][e]);
        for (int m = 0; m < 6; ++m) {
          const int* o = order[m];
          double g[3];
          sum[m] += wt * (is_f[m] ? pt.f(o[0], o[1], o[2], g) : pt.g(o[0], o[1], o[2], g));
          if (dn)  // every corner difference moves with X_k: d/dX_k is the antiderivative's derivative
            for (int q = 0; q < 3; ++q) du[o[q]][m] += wt * g[q];
        }
      }
  const double c = 1.0 / (4.0 * kPi * 8.0 * half_a[0] * half_a[1] * half_a[2]);
  for (int m = 0; m < 6; ++m) n[m] = c * sum[m];
  if (dn) signed_gradient(c, du, sign, dn);
  // Components odd in an axis take its sign (zero offset: they vanish).
  n[1] *= sign[0] * sign[1];
  n[2] *= sign[0] * sign[2];
  n[4] *= sign[1] * sign[2];
}

GridDemagTable::GridDemagTable(const std::array<std::vector<double>, 3>& faces) : faces_(faces) {
  std::array<std::vector<double>, 3> values;
  for (int k = 0; k < 3; ++k) {
    const std::vector<double>& F = faces_[k];
    const int m = static_cast<int>(F.size());
    std::vector<double>& v = values[k];
    for (int p = 0; p < m; ++p)
      for (int q = 0; q < m; ++q) v.push_back(std::fabs(F[p] - F[q]));
    std::sort(v.begin(), v.end());
    v.erase(std::unique(v.begin(), v.end()), v.end());
    count_[k] = static_cast<int>(v.size());
    index_[k].resize(static_cast<size_t>(m) * m);
    for (int p = 0; p < m; ++p)
      for (int q = 0; q < m; ++q)
        index_[k][p * m + q] = static_cast<int>(
            std::lower_bound(v.begin(), v.end(), std::fabs(F[p] - F[q])) - v.begin());
  }
  // Component m is f (xx, yy, zz) or g (xy, xz, yz) with its arguments in the
  // order order[m], as cube_demag_tensor_at; at non-negative arguments.
  static constexpr int order[6][3] = {{0, 1, 2}, {0, 1, 2}, {0, 2, 1}, {1, 0, 2}, {1, 2, 0}, {2, 1, 0}};
  static constexpr bool is_f[6] = {true, false, false, true, false, true};
  table_.resize(6u * count_[0] * count_[1] * count_[2]);
  for (int z = 0; z < count_[2]; ++z)
    for (int y = 0; y < count_[1]; ++y)
      for (int x = 0; x < count_[0]; ++x) {
        const NewellPoint pt(values[0][x], values[1][y], values[2][z]);
        double* t = &table_[6u * (x + static_cast<size_t>(count_[0]) * (y + static_cast<size_t>(count_[1]) * z))];
        for (int c = 0; c < 6; ++c) {
          const int* o = order[c];
          double g[3];
          t[c] = is_f[c] ? pt.f(o[0], o[1], o[2], g) : pt.g(o[0], o[1], o[2], g);
        }
      }
}

void GridDemagTable::tensor(const std::array<int, 3>& a, const std::array<int, 3>& b, double n[6]) const {
  double half_a[3], half_b[3], d[3], edge = 0.0;
  for (int k = 0; k < 3; ++k) {
    const std::vector<double>& F = faces_[k];
    half_a[k] = 0.5 * (F[a[k] + 1] - F[a[k]]), half_b[k] = 0.5 * (F[b[k] + 1] - F[b[k]]);
    d[k] = 0.5 * (F[a[k]] + F[a[k] + 1]) - 0.5 * (F[b[k]] + F[b[k] + 1]);
    edge = std::max({edge, 2.0 * half_a[k], 2.0 * half_b[k]});
  }
  const double range = kNewellRange * edge;
  if (d[0] * d[0] + d[1] * d[1] + d[2] * d[2] > range * range) {
    cuboid_demag_tensor(half_a, half_b, d, n);  // the point dipole
    return;
  }
  // Per axis the corner differences u = F_p - F_q of cuboid_demag_tensor:
  // (a, b + 1), (a, b), (a + 1, b + 1), (a + 1, b) with weights -1, 1, 1, -1.
  int idx[3][4];
  double sgn[3][4];
  static constexpr double w[4] = {-1.0, 1.0, 1.0, -1.0};
  for (int k = 0; k < 3; ++k) {
    const std::vector<double>& F = faces_[k];
    const int m = static_cast<int>(F.size());
    const int p[4] = {a[k], a[k], a[k] + 1, a[k] + 1}, q[4] = {b[k] + 1, b[k], b[k] + 1, b[k]};
    for (int e = 0; e < 4; ++e) {
      const double u = F[p[e]] - F[q[e]];
      idx[k][e] = index_[k][p[e] * m + q[e]];
      sgn[k][e] = u < 0.0 ? -1.0 : (u > 0.0 ? 1.0 : 0.0);
    }
  }
  double sum[6] = {0, 0, 0, 0, 0, 0};
  for (int z = 0; z < 4; ++z)
    for (int y = 0; y < 4; ++y)
      for (int x = 0; x < 4; ++x) {
        const double wt = w[x] * w[y] * w[z];
        const double* t =
            &table_[6u * (idx[0][x] + static_cast<size_t>(count_[0]) * (idx[1][y] + static_cast<size_t>(count_[1]) * idx[2][z]))];
        // f even in every argument; g odd in its first two.
        sum[0] += wt * t[0], sum[3] += wt * t[3], sum[5] += wt * t[5];
        sum[1] += wt * sgn[0][x] * sgn[1][y] * t[1];
        sum[2] += wt * sgn[0][x] * sgn[2][z] * t[2];
        sum[4] += wt * sgn[1][y] * sgn[2][z] * t[4];
      }
  const double c = 1.0 / (4.0 * kPi * 8.0 * half_a[0] * half_a[1] * half_a[2]);
  for (int m = 0; m < 6; ++m) n[m] = c * sum[m];
}

}  // namespace odemag
