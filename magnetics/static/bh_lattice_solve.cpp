// Newton-Krylov for soft lattice bodies with a B-H curve (magnetics/static/bh_lattice_solve.h).
#include "magnetics/static/bh_lattice_solve.h"

#include <Eigen/Dense>

#include <cmath>
#include <functional>

#include "magnetics/kernels/eigen_tensors.h"
#include "magnetics/kernels/kernels.h"

namespace odemag {

namespace {

using Eigen::VectorXd;

Eigen::Map<VectorXd> flat(std::vector<Vec3>& v) { return {&v[0].x, static_cast<Eigen::Index>(3 * v.size())}; }

// Restarted GMRES with right preconditioning: solves A x = b from x = 0 to
// |b - A x| <= tol |b|; returns the iterations (matvecs).
int gmres(const std::function<void(const VectorXd&, VectorXd&)>& A,
          const std::function<void(const VectorXd&, VectorXd&)>& precondition, const VectorXd& b, VectorXd& x,
          double tol, int restart, int max_iterations) {
  const Eigen::Index n = b.size();
  x.setZero(n);
  const double target = tol * b.norm();
  if (b.norm() == 0.0) return 0;
  int iterations = 0;
  VectorXd r = b, w(n), z(n);
  while (iterations < max_iterations) {
    const double beta = r.norm();
    if (beta <= target) break;
    Eigen::MatrixXd V(n, restart + 1), H = Eigen::MatrixXd::Zero(restart + 1, restart);
    VectorXd cs = VectorXd::Zero(restart), sn = VectorXd::Zero(restart), g = VectorXd::Zero(restart + 1);
    V.col(0) = r / beta;
    g(0) = beta;
    int k = 0;  // Arnoldi vectors of this cycle
    while (k < restart && iterations < max_iterations) {
      precondition(V.col(k), z);
      A(z, w);
      for (int i = 0; i <= k; ++i) {  // modified Gram-Schmidt
        H(i, k) = w.dot(V.col(i));
        w -= H(i, k) * V.col(i);
      }
      H(k + 1, k) = w.norm();
      if (H(k + 1, k) > 0.0) V.col(k + 1) = w / H(k + 1, k);
      for (int i = 0; i < k; ++i) {  // the earlier Givens rotations
        const double t = cs(i) * H(i, k) + sn(i) * H(i + 1, k);
        H(i + 1, k) = -sn(i) * H(i, k) + cs(i) * H(i + 1, k);
        H(i, k) = t;
      }
      const double d = std::hypot(H(k, k), H(k + 1, k));
      cs(k) = H(k, k) / d;
      sn(k) = H(k + 1, k) / d;
      H(k, k) = d;
      H(k + 1, k) = 0.0;
      g(k + 1) = -sn(k) * g(k);
      g(k) = cs(k) * g(k);
      ++k;
      ++iterations;
      if (std::abs(g(k)) <= target) break;  // |g(k)| is the residual of the least-squares solution
    }
    const VectorXd y = H.topLeftCorner(k, k).triangularView<Eigen::Upper>().solve(g.head(k));
    precondition(V.leftCols(k) * y, z);
    x += z;
    A(x, w);
    r = b - w;
  }
  return iterations;
}

}  // namespace

Vec3 bh_cell_law(const BhCurve& curve, double w, const Vec3& H, double jacobian[6]) {
  const double h = norm(H);
  const double chi_d = w * curve.slope(h);
  if (h == 0.0) {
    for (int c = 0; c < 6; ++c) jacobian[c] = (c == 0 || c == 3 || c == 5) ? chi_d : 0.0;
    return {};
  }
  const double m = w * curve.magnetization(h), chi_s = m / h;
  const Vec3 u = H / h;
  const double uu[6] = {u.x * u.x, u.x * u.y, u.x * u.z, u.y * u.y, u.y * u.z, u.z * u.z};
  for (int c = 0; c < 6; ++c) jacobian[c] = (chi_d - chi_s) * uu[c] + ((c == 0 || c == 3 || c == 5) ? chi_s : 0.0);
  return m * u;
}

Vec3 bh_flux_cell_law(const BhCurve& curve, double w, const Vec3& b, Vec3& H, double jacobian[6]) {
  // b = H + w f(H) along one direction: |b| = h + w M(h), dM/db = chi_d / (1 +
  // chi_d) along b, M / |b| across (chi_d = w dM/dh).
  const double beta = norm(b);
  const double chi0 = w * curve.slope(0.0);
  if (beta == 0.0) {
    H = {};
    const double d = chi0 / (1.0 + chi0);
    for (int c = 0; c < 6; ++c) jacobian[c] = (c == 0 || c == 3 || c == 5) ? d : 0.0;
    return {};
  }
  // |H| = h solves h + w M(h) = beta (monotone, slope >= 1): safeguarded Newton in [lo, hi].
  double lo = std::max(0.0, beta - w * curve.saturation()), hi = beta;
  double h = std::min(hi, std::max(lo, beta / (1.0 + chi0)));
  for (int it = 0; it < 60; ++it) {
    const double phi = h + w * curve.magnetization(h) - beta;
    if (phi > 0.0) hi = h; else lo = h;
    const double next = h - phi / (1.0 + w * curve.slope(h));
    const double previous = h;
    h = (next > lo && next < hi) ? next : 0.5 * (lo + hi);
    if (std::abs(h - previous) <= 1e-14 * beta || hi - lo <= 1e-14 * beta) break;
  }
  const Vec3 u = b / beta;
  const double m = beta - h;
  H = h * u;
  const double along = w * curve.slope(h) / (1.0 + w * curve.slope(h)), across = m / beta;
  const double uu[6] = {u.x * u.x, u.x * u.y, u.x * u.z, u.y * u.y, u.y * u.z, u.z * u.z};
  for (int c = 0; c < 6; ++c) jacobian[c] = (along - across) * uu[c] + ((c == 0 || c == 3 || c == 5) ? across : 0.0);
  return m * u;
}

BhSolveReport solve_bh_lattice(const DemagOperator& demag, const BhCurve& curve, const std::vector<double>& fill,
                               const std::vector<Vec3>& H_source, std::vector<Vec3>& M,
                               const BhSolveOptions& options) {
  const int N = demag.cells();
  M.resize(N);
  std::vector<Vec3> x(N), R(N), trial(N), Hd, m(N);  // x: the Newton variable per cell
  std::vector<std::array<double, 6>> J(N);
  std::vector<Eigen::Matrix3d> block(N);
  double source = 0.0;
  for (const Vec3& h : H_source) source += squared_norm(h);
  source = std::sqrt(source);
  // x per cell: b = H + M for (5), H for (4). R(x) = H(x) - H_source -
  // H_d(M(x)), |R| / |H_source|; sets m = M(x), H = H(x), J = dM/dx, and g =
  // |G| / |M(x)|, the residual of (3) at M = m.
  const bool flux = options.variable == BhNewtonVariable::flux_density;
  std::vector<Vec3> H(N);
  double g = 0.0;
  BhSolveReport report;
  auto residual = [&](const std::vector<Vec3>& at, std::vector<Vec3>& r) {
    for (int i = 0; i < N; ++i) {
      if (flux) {
        m[i] = bh_flux_cell_law(curve, fill[i], at[i], H[i], J[i].data());
      } else {
        m[i] = bh_cell_law(curve, fill[i], at[i], J[i].data());
        H[i] = at[i];
      }
    }
    demag.field(m, Hd);
    ++report.matvecs;
    double rr = 0.0, gg = 0.0, mm = 0.0;
    for (int i = 0; i < N; ++i) {
      r[i] = H[i] - H_source[i] - Hd[i];
      rr += squared_norm(r[i]);
      double unused[6];
      gg += squared_norm(m[i] - bh_cell_law(curve, fill[i], H[i] - r[i], unused));
      mm += squared_norm(m[i]);
    }
    g = mm > 0.0 ? std::sqrt(gg / mm) : std::sqrt(gg);
    return source > 0.0 ? std::sqrt(rr) / source : std::sqrt(rr);
  };
  // The start: from the initial M (H = H_source + H_d(M), b = H + M); for M =
  // 0, x = 0, so that the first Newton step is the linear solve with the
  // initial susceptibility.
  bool zero = true;
  for (const Vec3& v : M) zero = zero && squared_norm(v) == 0.0;
  if (!zero) {
    demag.field(M, Hd);
    ++report.matvecs;
    for (int i = 0; i < N; ++i) x[i] = H_source[i] + Hd[i] + (flux ? M[i] : Vec3{});
  }
  double r = residual(x, R);
  report.residuals.push_back(g);
  std::vector<Vec3> x3(N), y3(N);
  // dR/dx v: (I + N J) v for (4), (I + (N - I) J) v for (5) (dH/db = I - J); N v = -H_d(v).
  auto apply = [&](const VectorXd& v, VectorXd& y) {
    for (int i = 0; i < N; ++i) x3[i] = symmetric_times(J[i].data(), Vec3{v(3 * i), v(3 * i + 1), v(3 * i + 2)});
    demag.field(x3, y3);
    ++report.matvecs;
    y = v;
    for (int i = 0; i < N; ++i) {
      y.segment<3>(3 * i) -= Eigen::Vector3d(y3[i].x, y3[i].y, y3[i].z);
      if (flux) y.segment<3>(3 * i) -= Eigen::Vector3d(x3[i].x, x3[i].y, x3[i].z);
    }
  };
  auto precondition = [&](const VectorXd& v, VectorXd& y) {
    y.resize(3 * N);
    for (int i = 0; i < N; ++i) y.segment<3>(3 * i) = block[i] * v.segment<3>(3 * i);
  };
  double eta = options.forcing;
  while (g > options.tolerance && report.newton_iterations < options.max_newton) {
    for (int i = 0; i < N; ++i) {  // the cell's own block: N(0) of its lattice, less I for (5)
      double n0[6];
      demag.self_block(i, n0);
      Eigen::Matrix3d Ni = symmetric_matrix(n0);
      const Eigen::Matrix3d Ji = symmetric_matrix(J[i].data());
      if (flux) Ni -= Eigen::Matrix3d::Identity();
      block[i] = (Eigen::Matrix3d::Identity() + Ni * Ji).inverse();
    }
    VectorXd dx;
    const VectorXd minus_R = -flat(R);
    report.krylov_iterations += gmres(apply, precondition, minus_R, dx, eta, options.restart, options.max_krylov);
    // Backtracking on |R|: full step first, halved until |R| decreases.
    double step = 1.0, r_trial = 0.0;
    for (int halvings = 0;; ++halvings, step *= 0.5) {
      for (int i = 0; i < N; ++i) trial[i] = x[i] + step * Vec3{dx(3 * i), dx(3 * i + 1), dx(3 * i + 2)};
      r_trial = residual(trial, R);
      if (r_trial < (1.0 - 1e-4 * step) * r || halvings == 10) break;
    }
    x.swap(trial);
    // Eisenstat-Walker forcing (choice 2): loose while |R| falls slowly, tight near the solution.
    const double previous = eta;
    eta = std::min(options.forcing, 0.9 * (r_trial / r) * (r_trial / r));
    if (0.9 * previous * previous > 0.1) eta = std::max(eta, 0.9 * previous * previous);
    eta = std::max(eta, options.min_forcing);
    r = r_trial;
    ++report.newton_iterations;
    report.residuals.push_back(g);
  }
  M = m;
  report.residual = g;
  report.converged = g <= options.tolerance;
  return report;
}

}  // namespace odemag
