// Two lattice balls near contact in a field along their
// line of centres. Does refining only the cells of the contact zone recover
// the force, and how many cells does it take? (docs/validation.md section 5,
// "Local refinement of the contact zone".)
//
// A standalone Galerkin solve of two linear balls (chi, radius R, gap g R, the
// field H0 along the line or across it), independent of the engine's relaxation: every cell
// is a cube of edge a (h / 2^l) standing for its part of the ball
// (volume V = w a^3, the volume-share cells of magnetics/cells/cells.h), coupled to
// every other cell by the cuboid-cuboid tensor N_ij (cuboid_demag_tensor):
//   H_i = H0 - sum_j N_ij w_j M_j + K_i M_i,   M_i = chi H_i,
// cubes centred on their lattice sites within a body and on their centroids
// between bodies (as the engine), and K_i = sum_{j in body} N_ij w_j - I/3 the
// boundary correction that gives a uniformly magnetized ball its exact field
// -M/3 in every cell (exact; --cap gives the engine's). Force on ball 2 at
// fixed M (the linear bodies' force):
//   F_2 = mu0 sum_{i in 1, j in 2} V_i M_i . dN_ij/dd w_j M_j,   d = c_i - c_j.
// Refinement: a cell whose cube comes within D_0 of the contact point (the
// ball's point nearest the other ball) is replaced by its 8 sub-cubes of the
// lattice at h/2 (the volume-share cells of make_cells at h/2, whose lattice
// nests in the one at h); a sub-cube within D_1 again by its 8 at h/4, and so
// on (ball_cells).
// Against the two-centre series of tests/support/contact_references.h.
//
// Usage: contact_refinement [R/h] [--chi X] [--across] [--sites] [--cap] [--cap-coarse]
//                           [--stability] [--gap g] [--dipoles] [--zone D0,D1,...]... [--line x,y,z]
//   R/h: with 2R/h an integer (4, 5.5, 6.5), so that the lattices nest;
//   --chi: the balls' susceptibility (1000); --across: the field across the
//   line of centres;
//   --sites: between bodies too, the cubes on their lattice sites (a
//   diagnostic: the engine puts them on the centroids);
//   --cap: the boundary correction as the engine's: its local part capped,
//   and the uniform-mode update;
//   --cap-coarse: as --cap, but the local part capped on the cells of edge h
//   only (the refined sub-cubes take the exact one);
//   --gap g: one gap, g R (default 0.05, 0.1, 0.5);
//   --stability: print the smallest eigenvalue of ball 1's operator in
//   moments, W^-1/2 S W^-1/2 (with --chi 1e12: the chi -> infinity margin);
//   --dipoles: between bodies, point dipoles at the centroids (the engine's
//   dense sums, which is what bodies of refined zones get) instead of cubes;
//   --zone: a row of zone radii / h (repeatable; "0" for none) instead of
//   the default list;
//   --line: the line of centres (default z; the force is its component
//   along the line).
// The refined cells here are this program's own: a cube exactly D_l from
// the point is refined or not as rounding decides, where the engine's
// make_refined_cells leaves such ties unrefined (the same radii give it
// fewer cells in these symmetric set-ups: 852 against 992 at R/h 4 with
// 1.5, 1, 0.25).
#include <Eigen/Dense>

#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <map>
#include <string>
#include <vector>

#include "magnetics/cells/cells.h"
#include "odemag/constants.h"
#include "magnetics/cells/demag_tensor.h"
#include "magnetics/kernels/eigen_tensors.h"
#include "magnetics/kernels/kernels.h"
#include "tests/support/contact_references.h"

using namespace odemag;

namespace {

struct Cell {
  Vec3 site;      // body frame, m: centre of the cube within the body
  Vec3 centroid;  // body frame, m: centre of the cube between bodies
  double edge;    // a, m
  double volume;  // V = w a^3, m^3
  int body;
  double share() const { return volume / (edge * edge * edge); }  // w: the cube's share inside the ball
};

using Index = std::array<int, 3>;

// The cells of a ball of radius R on the lattice h with the contact zone
// (around the body-frame point P) refined: a cell of the lattice at h / 2^l
// whose cube comes within D[l] of P is replaced by its 8 sub-cubes at h /
// 2^(l+1), for l < D.size().
std::vector<Cell> ball_cells(double R, double h, const Vec3& P, const std::vector<double>& D) {
  const int levels = static_cast<int>(D.size()) + 1;
  std::vector<CellSet> level(levels);
  std::vector<std::map<Index, int>> at(levels);
  for (int l = 0; l < levels; ++l) {
    level[l] = make_cells(Sphere{R}, h / std::pow(2.0, l));
    for (int i = 0; i < level[l].size(); ++i) at[l][level[l].lattice_index[i]] = i;
    // The nesting: the sub-cubes' sites are the parent's +- a/4.
    if (l > 0 && level[l].lattice_extent[0] != 2 * level[l - 1].lattice_extent[0]) {
      std::fprintf(stderr, "contact_refinement: the lattices at h and h/2 do not nest"
                           " (2R/h not an integer)\n");
      std::exit(2);
    }
  }
  auto site = [&](int l, const Index& q) {
    const CellSet& c = level[l];
    Vec3 s;
    for (int a = 0; a < 3; ++a) s[a] = (q[a] - 0.5 * (c.lattice_extent[a] - 1)) * c.spacing;
    return s;
  };
  auto near = [&](int l, const Index& q) {  // the cube within D[l] of P
    if (l + 1 >= levels) return false;
    const Vec3 s = site(l, q);
    const double half = 0.5 * level[l].spacing;
    double d2 = 0.0;
    for (int a = 0; a < 3; ++a) {
      const double e = std::max(0.0, std::abs(P[a] - s[a]) - half);
      d2 += e * e;
    }
    return d2 <= D[l] * D[l];
  };
  std::vector<Cell> out;
  auto emit = [&](auto&& self, int l, const Index& q) -> void {
    if (near(l, q)) {
      for (int dz = 0; dz < 2; ++dz)
        for (int dy = 0; dy < 2; ++dy)
          for (int dx = 0; dx < 2; ++dx)
            self(self, l + 1, Index{2 * q[0] + dx, 2 * q[1] + dy, 2 * q[2] + dz});
      return;
    }
    const auto it = at[l].find(q);
    if (it == at[l].end()) return;  // no share of the ball
    const CellSet& c = level[l];
    out.push_back({site(l, q), c.local_positions[it->second], c.spacing, c.volumes[it->second], 0});
  };
  for (const Index& q : level[0].lattice_index) emit(emit, 0, q);
  return out;
}

struct Result {
  double force_along;  // F_2 . line, N
  int cells_per_ball;
  double seconds;
};

struct Options {
  double chi = 1000;      // susceptibility of both balls
  bool across = false;    // the field across the line of centres (else along it)
  bool at_sites = false;  // cubes on their sites between bodies too (else on their centroids)
  bool cap = false;       // the engine's boundary correction (capped, uniform-mode update)
  bool dipoles = false;   // point dipoles at the centroids between bodies (the engine's dense sums)
  bool cap_coarse = false;  // with cap: the local part capped on the cells of edge h only
  bool stability = false;   // print the smallest eigenvalue of ball 1's operator
  std::vector<double> gaps{0.05, 0.1, 0.5};  // / R
  std::vector<std::vector<double>> zones;  // per row the zone radii / h (empty: the default list)
  Vec3 line{0, 0, 1};  // unit vector from ball 1 to ball 2
};

Result solve(double R, double h, double gap_over_R, const std::vector<double>& D, const Vec3& H0,
             const Options& options) {
  const auto t0 = std::chrono::steady_clock::now();
  const double chi = options.chi;
  const Vec3& u = options.line;
  const bool along_z = u.x == 0.0 && u.y == 0.0;
  std::vector<Cell> cells = ball_cells(R, h, R * u, D);
  const int per_ball = static_cast<int>(cells.size());
  const Vec3 c2 = (2.0 + gap_over_R) * R * u;
  if (along_z) {
    for (int i = 0; i < per_ball; ++i) {  // ball 2: the mirror image in z, moved up
      Cell c = cells[i];
      c.site.z = -c.site.z;
      c.centroid.z = -c.centroid.z;
      c.body = 1;
      cells.push_back(c);
    }
  } else {  // ball 2 refined towards ball 1
    for (Cell c : ball_cells(R, h, -R * u, D)) {
      c.body = 1;
      cells.push_back(c);
    }
  }
  const int n = static_cast<int>(cells.size());
  auto world = [&](const Cell& c) {
    return (options.at_sites ? c.site : c.centroid) + (c.body == 1 ? c2 : Vec3{});
  };
  Eigen::MatrixXd A = Eigen::MatrixXd::Zero(3 * n, 3 * n);
#pragma omp parallel for schedule(dynamic, 8)
  for (int i = 0; i < n; ++i) {
    const Cell& a = cells[i];
    const double ha[3] = {0.5 * a.edge, 0.5 * a.edge, 0.5 * a.edge};
    Eigen::Matrix3d sum = Eigen::Matrix3d::Zero();
    for (int j = 0; j < n; ++j) {
      if (j == i) continue;
      const Cell& b = cells[j];
      const double hb[3] = {0.5 * b.edge, 0.5 * b.edge, 0.5 * b.edge};
      const Vec3 d = a.body == b.body ? a.site - b.site : world(a) - world(b);
      const double dd[3] = {d.x, d.y, d.z};
      double t[6];
      if (a.body != b.body && options.dipoles) {
        dipole_tensor(d, 0.0, t);  // H = T mu: N = -a_j^3 T
        for (double& x : t) x *= -b.edge * b.edge * b.edge;
      } else {
        cuboid_demag_tensor(ha, hb, dd, t);
      }
      const Eigen::Matrix3d N = symmetric_matrix(t);
      const double w = b.share();
      A.block<3, 3>(3 * i, 3 * j) = w * N;
      if (a.body == b.body) sum += w * N;
    }
    // The engine's split (magnetics/model/model.cpp build_boundary_correction): the
    // cell's own I/3 (gamma_D = 1/3 + 1/chi) and K_i = I/3 + sum_{j != i} w_j
    // N_ij - Nbar_i, Nbar_i = I/3 for a ball, its eigenvalues capped at (1 -
    // w_i)/3 with --cap.
    const double wi = a.share();
    Eigen::Matrix3d K = sum;
    if (options.cap && (!options.cap_coarse || a.edge > 0.75 * h))
      K = capped_boundary_correction(K, (1.0 - wi) / 3.0);  // the engine's local part
    A.block<3, 3>(3 * i, 3 * i) = Eigen::Matrix3d::Identity() / 3.0 - K;
    A.block<3, 3>(3 * i, 3 * i) += Eigen::Matrix3d::Identity() / chi;
  }
  // In moments: S = W A (W = diag(V), symmetric), S M = W H0.
  for (int i = 0; i < n; ++i) A.middleRows(3 * i, 3) *= cells[i].volume;
  Eigen::VectorXd rhs = Eigen::VectorXd::Zero(3 * n);
  for (int i = 0; i < n; ++i)
    for (int a = 0; a < 3; ++a) rhs(3 * i + a) = cells[i].volume * H0[a];
  if (options.cap) {
    // The engine's uniform-mode update of each body's own operator S_b
    // (magnetics/model/model.cpp): S_b' = S_b - (S_b U)(U^T S_b U)^-1 (S_b U)^T + B (U^T B)^-1 B^T,
    // U the body's uniform fields, B = W beta, beta = (1/chi + 1/3) I for a ball.
    for (int body = 0; body < 2; ++body) {
      const int first = body * per_ball;
      const Eigen::Index rows = 3 * per_ball;
      Eigen::MatrixXd SU = Eigen::MatrixXd::Zero(rows, 3), B = Eigen::MatrixXd::Zero(rows, 3);
      for (int i = 0; i < per_ball; ++i) {
        for (int j = 0; j < per_ball; ++j)
          SU.middleRows(3 * i, 3) += A.block<3, 3>(3 * (first + i), 3 * (first + j));
        const double beta = 1.0 / chi + 1.0 / 3.0;
        B.middleRows(3 * i, 3) = cells[first + i].volume * beta * Eigen::Matrix3d::Identity();
      }
      Eigen::Matrix3d uSu = Eigen::Matrix3d::Zero(), uB = Eigen::Matrix3d::Zero();
      for (int i = 0; i < per_ball; ++i) uSu += SU.middleRows(3 * i, 3), uB += B.middleRows(3 * i, 3);
      A.block(3 * first, 3 * first, rows, rows) +=
          -SU * uSu.inverse() * SU.transpose() + B * uB.inverse() * B.transpose();
    }
  }
  if (options.stability) {
    // Ball 1's operator in moments, W^-1/2 S_1 W^-1/2 (symmetric): positive
    // definite or not (at chi -> infinity the relaxation's stability margin).
    const Eigen::Index rows = 3 * per_ball;
    Eigen::MatrixXd S1 = A.topLeftCorner(rows, rows);
    for (int i = 0; i < per_ball; ++i) {
      const double s = 1.0 / std::sqrt(cells[i].volume);
      S1.middleRows(3 * i, 3) *= s;
      S1.middleCols(3 * i, 3) *= s;
    }
    S1 = 0.5 * (S1 + S1.transpose()).eval();
    const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(S1, Eigen::EigenvaluesOnly);
    std::printf("ball 1: smallest eigenvalue of W^-1/2 S W^-1/2 %.4g (1/chi = %.3g)\n", eig.eigenvalues()(0),
                1.0 / chi);
  }
  const Eigen::VectorXd M = A.partialPivLu().solve(rhs);
  double fz = 0.0;
#pragma omp parallel for reduction(+ : fz) schedule(dynamic, 8)
  for (int i = 0; i < per_ball; ++i) {
    const Cell& a = cells[i];
    const double ha[3] = {0.5 * a.edge, 0.5 * a.edge, 0.5 * a.edge};
    const Eigen::Vector3d Mi = M.segment<3>(3 * i);
    for (int j = per_ball; j < static_cast<int>(cells.size()); ++j) {
      const Cell& b = cells[j];
      const double hb[3] = {0.5 * b.edge, 0.5 * b.edge, 0.5 * b.edge};
      const Vec3 d = world(a) - world(b);
      if (options.dipoles) {  // the force on b from a, r = x_b - x_a
        const Eigen::Vector3d Mj = M.segment<3>(3 * j);
        const Vec3 mu_a = a.volume * Vec3{Mi(0), Mi(1), Mi(2)}, mu_b = b.volume * Vec3{Mj(0), Mj(1), Mj(2)};
        fz += dot(dipole_force(-d, mu_a, mu_b, 0.0), u);
        continue;
      }
      const double dd[3] = {d.x, d.y, d.z};
      double t[6], dt[3][6];
      cuboid_demag_tensor(ha, hb, dd, t, dt);
      double du[6];  // dN/dd . u
      for (int c = 0; c < 6; ++c) du[c] = u.x * dt[0][c] + u.y * dt[1][c] + u.z * dt[2][c];
      const Eigen::Matrix3d G = symmetric_matrix(du);
      const double w = b.share();
      fz += kMu0 * a.volume * Mi.dot(G * (w * M.segment<3>(3 * j)));
    }
  }
  const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return {fz, per_ball, s};
}

// "D0,D1,..." (radii / h, each >= 0; "0": no refinement) appended to zones;
// false when malformed.
bool parse_zone(const char* text, std::vector<std::vector<double>>& zones) {
  std::vector<double> zone;
  const char* p = text;
  while (true) {
    char* end = nullptr;
    const double d = std::strtod(p, &end);
    if (end == p || !(d >= 0.0)) return false;
    zone.push_back(d);
    if (*end == '\0') break;
    if (*end != ',') return false;
    p = end + 1;
  }
  if (zone.size() == 1 && zone[0] == 0.0) zone.clear();
  zones.push_back(zone);
  return true;
}

// "x,y,z", normalized into line; false when malformed or zero.
bool parse_line(const char* text, Vec3& line) {
  Vec3 v;
  const char* p = text;
  for (int k = 0; k < 3; ++k) {
    char* end = nullptr;
    v[k] = std::strtod(p, &end);
    if (end == p || !std::isfinite(v[k]) || *end != (k < 2 ? ',' : '\0')) return false;
    p = end + 1;
  }
  if (!(norm(v) > 0.0)) return false;
  line = v / norm(v);
  return true;
}

}  // namespace

int main(int argc, char** argv) {
  const double R = 0.005;
  double k = 5.5;
  Options options;
  for (int a = 1; a < argc; ++a) {
    const std::string arg = argv[a];
    if (arg == "--sites")
      options.at_sites = true;
    else if (arg == "--cap")
      options.cap = true;
    else if (arg == "--cap-coarse")
      options.cap = options.cap_coarse = true;
    else if (arg == "--stability")
      options.stability = true;
    else if (arg == "--gap" && a + 1 < argc)
      options.gaps = {std::atof(argv[++a])};
    else if (arg == "--line" && a + 1 < argc && parse_line(argv[a + 1], options.line))
      ++a;
    else if (arg == "--dipoles")
      options.dipoles = true;
    else if (arg == "--zone" && a + 1 < argc && parse_zone(argv[a + 1], options.zones))
      ++a;
    else if (arg == "--across")
      options.across = true;
    else if (arg == "--chi" && a + 1 < argc && std::atof(argv[a + 1]) > 0.0)
      options.chi = std::atof(argv[++a]);
    else if (!arg.empty() && arg[0] != '-' && std::atof(arg.c_str()) >= 2.0)
      k = std::atof(arg.c_str());
    else {
      std::fprintf(stderr,
                   "contact_refinement: unknown argument '%s' (usage: contact_refinement [R/h] [--chi X]"
                   " [--across] [--sites] [--cap] [--cap-coarse] [--stability] [--gap g] [--dipoles] [--zone D0,D1,...]... [--line x,y,z])\n",
                   arg.c_str());
      return 2;
    }
  }
  const double h = R / k, chi = options.chi;
  const Vec3& u = options.line;
  Vec3 across = cross(u, Vec3{0, 0, 1});
  if (norm(across) < 0.1) across = {1, 0, 0};
  const Vec3 H0 = options.across ? 1e3 / norm(across) * across : 1e3 * u;
  if (u.x != 0.0 || u.y != 0.0) std::printf("The line of centres along (%g, %g, %g).\n", u.x, u.y, u.z);
  std::printf("R/h %g, chi %g, the field %s the line of centres, %s between bodies on their %s,"
              " %s boundary correction\n\n",
              k, chi, options.across ? "across" : "along", options.dipoles ? "point dipoles" : "cubes",
              options.at_sites ? "sites" : "centroids", options.cap_coarse ? "the engine's on the cells of edge h, the exact on sub-cubes,"
              : options.cap      ? "the engine's"
                                 : "the exact");
  std::printf("| gap | zone radii D_l / h (to h/2, h/4, h/8) | cells per ball | force against exact |"
              " solve (s) |\n");
  std::printf("|---|---|---|---|---|\n");
  // Per row the zone radius of each refinement level, in units of h.
  const std::vector<std::vector<double>> default_zones = {{},         {0.5},      {1.0},      {1.5},
                                                          {1.0, 0.5}, {1.5, 0.5}, {1.5, 1.0}, {2.0, 1.0},
                                                          {1.5, 1.0, 0.25}, {1.5, 1.0, 0.5}};
  const auto& zones = options.zones.empty() ? default_zones : options.zones;
  for (double g : options.gaps) {
    const auto ref = reference::two_linear_spheres_in_uniform_field(R, chi, R, chi, {0, 0, 0},
                                                                    (2.0 + g) * R * u, H0);
    const double exact = dot(ref.force_on_2, u);
    for (const std::vector<double>& zone : zones) {
      std::vector<double> D;
      std::string radii = zone.empty() ? "none" : "";
      for (double d : zone) {
        D.push_back(d * h);
        char b[32];
        std::snprintf(b, sizeof b, "%s%g", radii.empty() ? "" : ", ", d);
        radii += b;
      }
      const Result r = solve(R, h, g, D, H0, options);
      std::printf("| %g R | %s | %d | %+.2f%% | %.1f |\n", g, radii.c_str(), r.cells_per_ball,
                  100.0 * (std::abs(r.force_along) - std::abs(exact)) / std::abs(exact),
                  r.seconds);
      std::fflush(stdout);
    }
  }
  return 0;
}
