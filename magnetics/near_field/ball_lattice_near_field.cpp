// Close pairs of a one-cell ball and a cell of a lattice body: the exact
// field of the cell's cube instead of the point dipole (magnetics/near_field/near_field.h;
// docs/model.md "The near field").
//
// The dense sums couple a one-cell ball (radius R, dipole mu_b = V_b M_b) and a
// lattice cell c (spacing h, mu_c = V_c M_c) as two point dipoles, H = T(r; s)
// mu (magnetics/kernels/kernels.h). Inside its body the cell is a cube of edge h
// centred on its cell point, magnetization mu_c / V (V = the body's
// CellSet::cell_volume, h^3 for volume-share cells: the convention of the
// intra-body tensors and of lattice_near_field.cpp). In a box body every
// cell's part of the body is itself a cuboid, centred on the cell point (its
// centroid), with extents e_k = min(h, 2 (L_k/2 - |x_k|)) and volume V_i: there
// the cell is that cuboid with magnetization mu_c / V_i, so that the cells'
// fields add up to the box's exactly, also for a plate thinner than h (whose
// cubes would stand out of its faces, into a touching ball). A ball touching the
// body's face sits R from the cube's face, r = h/2 + R from its centre, where
// the point dipole is far from the cube's field (the ball chain's magnet, h =
// 20 mm, R = 5 mm: r = 0.75 h). Two exact statements give the pair tensor:
// the mean of a harmonic field over a ball is its value at the centre, so the
// ball's dipole answers the cube's field at its centre; and a uniformly
// magnetized ball's external field is exactly a point dipole, whose mean
// over the cube is, by reciprocity, the same tensor acting on mu_b. So
//
//   T_c(r) = -R_X N(R_X^T r; e/2) R_X^T / V,   r = x_b - x_c,
//
// N the point demagnetising tensor of the cuboid (cuboid_demag_tensor,
// magnetics/kernels/cell_field.h), R_X the lattice body's rotation, and this term adds
//
//   H_b += K mu_c,  H_c += K mu_b,  U = -mu0 mu_b . K mu_c,
//   K = w(r) [T_c(r) - T(r; s)],    s = the pair's contact distance.
//
// Window w = w_out(|r|) w_in(delta), both C2 quintic steps:
// - w_out: 1 up to kCutoffStart h, 0 beyond kCutoffEnd h (centre distance),
//   as lattice_near_field.cpp; for a cube |T_c - T| / |T| ~ (h / r)^4 there
//   (no quadrupole): a fixed dipole next to the ball chain's magnet (3 x 3 x 2
//   cubes of 20 mm, R = 5 mm, gaps 0.05 .. 4 R) gets the box's force to 1.1e-3
//   (point dipoles: up to 3.9 times off). A flat partial cuboid has a
//   quadrupole: a 5 mm plate of 20 mm cells is off by up to 1.4e-2 at 4 R
//   (point dipoles: up to 31 times).
// - w_in: in delta = the distance from the ball's centre to the cube (0 when
//   inside), 1 above kFadeStart R, 0 below kFadeEnd R. A ball that touches a
//   box body has delta >= R for every cell's cuboid; the fade only
//   acts where the ball's centre comes within 0.75 R of a cube (overlapping
//   bodies), before the cube's field jumps at its face or diverges (logarithmically)
//   at its edges: fields and forces stay bounded and continuous through
//   overlap down to coincident centres, where only the dense sums' bounded
//   core is left. Where several cubes meet on the body's surface their
//   edge terms cancel exactly (equal weights: all have delta >= R at contact).
//
// Forces: F_b = mu0 grad_r (w phi0) = -F_c, phi0 = mu_b . (T_c - T) mu_c, with
// the cube tensor's analytic gradient (cuboid_demag_gradient) and the dense
// kernel's (dipole_force). Torques: mu0 mu x (K mu) at both cells (the
// backends' field output), and, since T_c and w_in turn with the lattice body,
// the pure torque -dU/dtheta of turning its frame alone,
//
//   tau_X = -mu0 [ r x (phi0 w_out grad w_in + w g_c) + w (mu_b x T_c mu_c + mu_c x T_c mu_b) ],
//
// g_c = grad_r (mu_b . T_c mu_c) (rotating r, mu_b, mu_c and the frame together
// leaves U unchanged). It is applied as the rigid force couple F_i = (J^-1 tau)
// x (x_i - x_bar) over the body's cells (as lattice_near_field.cpp); bodies with
// fewer than three or collinear cells take no correction, nor do models with
// point-dipole intra-body tensors (a lattice body's cells are point dipoles
// there).
//
// Balls: one-cell bodies of shape Sphere (permanent, soft or recoil). One-cell
// boxes and cylinders are point dipoles in the model with a field that is not
// one outside them; they are left as they are. Without mutual induction the
// backends evaluate no responsive sources, so the pairs between a soft ball
// and a soft core then act in the forces only, like the dense sums.
//
// Pair search: every ball against every lattice body's bounding sphere (cell
// points), then the cells of the face-plane slots within 3 h of the ball
// (SharedCorners): O(balls x lattice bodies + their close cells). Each cell's
// cube tensor is assembled from corner and edge terms that the cells meeting
// there share, computed once per ball (CuboidCornerTerms); build evaluates
// every pair with its gradient, and add_forces reuses that at unchanged poses.
// Pairs in a fixed order, summed on one thread.
//
// Carried-over pairs: a ball's pairs with a lattice body (PairGroup) are kept
// from build to build. While the ball's centre stays within kReuseTolerance R
// of the point q0 where they were evaluated (in the body's frame, the frame
// not turned; kReuseToleranceInFade R where a pair is in the inner fade
// w_in < 1, an overlapping ball), each pair is carried to its new offset r = r0 + dr to first
// order, w = w0 + grad w . dr and T_c = T_c0 + (dT_c/dr) dr, with the point
// dipole's T(r; s) exact, and the gradients as at r0. Since T_c varies on the
// scale of delta >= kFadeEnd R, the fields (and the energy) are off by
// O((dr / delta)^2) <= ~1e-6 and the forces by O(dr / delta) <= ~1e-3 of the
// correction (measured at 0.9 tolerance: 1.0e-8 and 1.2e-4 of a touching
// ball's field and force): below the near field's own error (~1e-3). A
// ball that hangs or rests against a magnet moves nanometres per substep in its
// frame, so most of its pairs skip the corner terms (ball chain: T_m median
// 0.050 ms with a window of 1e-5 R, 0.040 ms with 1e-4 R); the balls that
// hang from the lifted crane, jostled by their neighbours, move 1e-4 to
// 1e-3 R per substep (a window of 1e-3 R evaluates 2.5 times fewer of the
// crane's ball-lattice pairs than one of 1e-4 R).
#include <Eigen/Dense>
#include <algorithm>
#include <array>
#include <cmath>
#include <variant>

#include "magnetics/kernels/cell_field.h"
#include "odemag/constants.h"
#include "magnetics/kernels/kernels.h"
#include "magnetics/near_field/near_field.h"

namespace odemag {

namespace {

// Outer window in the centre distance, units of h.
constexpr double kCutoffStart = 2.0;
constexpr double kCutoffEnd = 3.0;
// Inner window in the distance from the ball's centre to the cube, units of R.
constexpr double kFadeEnd = 0.5;    // below: no correction
constexpr double kFadeStart = 0.75;  // above: full correction
// Lattice bodies need cells spread in 3 dimensions to take a pure torque:
// smallest eigenvalue of J above this times h^2.
constexpr double kMinCoupleInertia = 0.1;
// A ball's pairs are carried over from the last evaluation while its centre
// stays within this many R of where they were evaluated (lattice body frame).
constexpr double kReuseTolerance = 1e-3;
// The same where a pair is in the inner fade (an overlapping ball), where w_in
// and T_c vary on the scale of 0.25 R: the carry's force error O(dr / 0.25 R).
constexpr double kReuseToleranceInFade = 1e-4;

// C2 step S(t) = t^3 (10 - 15 t + 6 t^2) on [0, 1], clamped; slope dS/dt.
double quintic_step(double t, double& slope) {
  if (t <= 0.0 || t >= 1.0) {
    slope = 0.0;
    return t <= 0.0 ? 0.0 : 1.0;
  }
  slope = 30.0 * t * t * (1.0 - t) * (1.0 - t);
  return t * t * t * (10.0 + t * (6.0 * t - 15.0));
}

// The pair's geometry: windows and the cube tensor, with gradients (world).
struct PairGeometry {
  double w = 0.0, w_out = 0.0, w_in = 0.0;
  Vec3 grad_w, grad_w_in;  // grad_r
  double Tc[6];            // T_c(r), world, 1/m^3
  double dTc[3][6];        // dT_c / dr_k, world, 1/m^4 (only with gradients)
};

bool is_identity(const Mat3& R) {
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j)
      if (R.m[i][j] != (i == j ? 1.0 : 0.0)) return false;
  return true;
}

// Rotated symmetric tensor R S R^T (six components xx, xy, xz, yy, yz, zz);
// S itself where R is the identity (a lattice body that has not turned, as
// the fixed magnets of most scenes: four of these per pair are a third of
// the pairs' arithmetic).
void rotate_symmetric(const Mat3& R, const double s[6], double out[6]) {
  if (is_identity(R)) {
    std::copy(s, s + 6, out);
    return;
  }
  constexpr int row[6] = {0, 0, 0, 1, 1, 2}, col[6] = {0, 1, 2, 1, 2, 2};
  const double S[3][3] = {{s[0], s[1], s[2]}, {s[1], s[3], s[4]}, {s[2], s[4], s[5]}};
  double RS[3][3];
  for (int a = 0; a < 3; ++a)
    for (int b = 0; b < 3; ++b) RS[a][b] = R.m[a][0] * S[0][b] + R.m[a][1] * S[1][b] + R.m[a][2] * S[2][b];
  for (int m = 0; m < 6; ++m) {
    const int a = row[m], b = col[m];
    out[m] = RS[a][0] * R.m[b][0] + RS[a][1] * R.m[b][1] + RS[a][2] * R.m[b][2];
  }
}

// The windows at offset r = x_b - x_c (world) of a ball of radius R from a
// cuboid of half extents `half`, frame R_X, cell spacing h; l = R_X^T r.
// false: the pair has no weight (the tensor is then not needed).
bool pair_windows(const Vec3& r, const Mat3& R_X, double h, const Vec3& half, double R, bool with_gradient,
                  PairGeometry& g, Vec3& l) {
  const double d = norm(r);
  double s_out;
  g.w_out = 1.0 - quintic_step((d / h - kCutoffStart) / (kCutoffEnd - kCutoffStart), s_out);
  if (g.w_out == 0.0) return false;
  l = R_X.transpose_times(r);
  // delta = |max(|l_k| - half_k, 0)|, C1 off the cuboid.
  Vec3 outside;
  for (int k = 0; k < 3; ++k) outside[k] = std::max(std::fabs(l[k]) - half[k], 0.0) * (l[k] < 0.0 ? -1.0 : 1.0);
  const double delta = norm(outside);
  double s_in;
  g.w_in = quintic_step((delta / R - kFadeEnd) / (kFadeStart - kFadeEnd), s_in);
  g.w = g.w_out * g.w_in;
  if (g.w == 0.0) return false;
  if (!with_gradient) return true;
  // grad_r delta = R_X (outside / delta) (delta > 0 where w_in > 0).
  g.grad_w_in = (s_in / ((kFadeStart - kFadeEnd) * R * delta)) * (R_X * outside);
  const Vec3 grad_w_out = (-s_out / ((kCutoffEnd - kCutoffStart) * h * d)) * r;
  g.grad_w = g.w_in * grad_w_out + g.w_out * g.grad_w_in;
  return true;
}

// T_c (world) and, with_gradient, dT_c/dr from the cuboid's corner terms in
// its frame R_X, volume V.
void pair_tensor(const CuboidCornerTerms& t, const Mat3& R_X, double V, bool with_gradient, PairGeometry& g) {
  double n[6];
  cuboid_demag_tensor(t, n);
  for (double& v : n) v /= -V;
  rotate_symmetric(R_X, n, g.Tc);
  if (!with_gradient) return;
  // dT_c/dr_k = -R_X (sum_j R_jk dN/dl_j) R_X^T / V.
  double dn[6][3];
  cuboid_demag_gradient(t, dn);
  for (int k = 0; k < 3; ++k) {
    double local[6];
    for (int m = 0; m < 6; ++m)
      local[m] = -(dn[m][0] * R_X.m[k][0] + dn[m][1] * R_X.m[k][1] + dn[m][2] * R_X.m[k][2]) / V;
    rotate_symmetric(R_X, local, g.dTc[k]);
  }
}

// Windows and T_c at offset r = x_b - x_c (world) of a ball of radius R from a
// cube of edge h, volume V, frame R_X; with_gradient: also the gradients.
PairGeometry pair_geometry(const Vec3& r, const Mat3& R_X, double h, const Vec3& half, double V, double R,
                           bool with_gradient) {
  PairGeometry g;
  Vec3 l;
  if (!pair_windows(r, R_X, h, half, R, with_gradient, g, l)) return g;
  CuboidCornerTerms t;
  cuboid_corner_terms(l, half, with_gradient, t);
  pair_tensor(t, R_X, V, with_gradient, g);
  return g;
}

// A lattice body's cells as solids between face planes: per axis the sorted
// distinct planes (body frame) and each cell's lower plane, its upper being the
// next (lattices whose solids tile the body: box parts and cubes on a grid).
// For one ball at a time (begin) the corner terms of every corner and edge its
// pairs need are computed once and shared by the cells that meet there
// (CuboidCornerTerms): a cell's eight corners are shared by up to eight cells.
class SharedCorners {
 public:
  // false: the solids do not tile planes; the pairs then take per-cell terms.
  bool build(const std::vector<Vec3>& lower, const std::vector<Vec3>& upper, double h) {
    const int n = static_cast<int>(lower.size());
    const double tol = 1e-9 * h;
    lower_plane_.assign(n, {});
    for (int k = 0; k < 3; ++k) {
      std::vector<double> v;
      for (int i = 0; i < n; ++i) {
        v.push_back(lower[i][k]);
        v.push_back(upper[i][k]);
      }
      std::sort(v.begin(), v.end());
      planes_[k].clear();
      for (double x : v)
        if (planes_[k].empty() || x - planes_[k].back() > tol) planes_[k].push_back(x);
      for (int i = 0; i < n; ++i) {
        const auto lo = std::lower_bound(planes_[k].begin(), planes_[k].end(), lower[i][k] - tol);
        const int j = static_cast<int>(lo - planes_[k].begin());
        if (j + 1 >= static_cast<int>(planes_[k].size()) || std::fabs(planes_[k][j + 1] - upper[i][k]) > tol)
          return false;
        lower_plane_[i][k] = j;
      }
    }
    for (int k = 0; k < 3; ++k) count_[k] = static_cast<int>(planes_[k].size());
    cell_at_.assign(static_cast<std::size_t>(count_[0] - 1) * (count_[1] - 1) * (count_[2] - 1), -1);
    for (int i = 0; i < n; ++i) {
      int& slot = cell_at_[slab(lower_plane_[i][0], lower_plane_[i][1], lower_plane_[i][2])];
      if (slot >= 0) return false;  // two solids in one slot: not a tiling
      slot = i;
    }
    corners_.assign(static_cast<std::size_t>(count_[0]) * count_[1] * count_[2], {});
    for (int e = 0; e < 3; ++e)
      edges_[e].assign(static_cast<std::size_t>(count_[kU[e]]) * count_[kW[e]] * (count_[kAlong[e]] - 1), {});
    eps_ = cuboid_snap_distance({0.5 * h, 0.5 * h, 0.5 * h});
    return true;
  }

  // The cells whose solids reach within `reach` of q (body frame) along every
  // axis, in a fixed order: a superset of the cells whose centres lie within
  // `reach` of q.
  void cells_near(const Vec3& q, double reach, std::vector<int>& cells) const {
    cells.clear();
    int first[3], last[3];
    for (int k = 0; k < 3; ++k) {
      const std::vector<double>& v = planes_[k];
      // slots j with v[j + 1] >= q - reach and v[j] <= q + reach
      first[k] = std::max(0, static_cast<int>(std::lower_bound(v.begin(), v.end(), q[k] - reach) - v.begin()) - 1);
      last[k] = std::min(count_[k] - 2,
                         static_cast<int>(std::upper_bound(v.begin(), v.end(), q[k] + reach) - v.begin()) - 1);
      if (first[k] > last[k]) return;
    }
    for (int i = first[0]; i <= last[0]; ++i)
      for (int j = first[1]; j <= last[1]; ++j)
        for (int l = first[2]; l <= last[2]; ++l) {
          const int c = cell_at_[slab(i, j, l)];
          if (c >= 0) cells.push_back(c);
        }
  }

  // The next ball, at q in the body frame.
  void begin(const Vec3& q) {
    q_ = q;
    ++generation_;
  }

  // Cell i's corner terms at the current ball (with the gradient's terms).
  void terms(int i, CuboidCornerTerms& t) {
    const int lo[3] = {lower_plane_[i][0], lower_plane_[i][1], lower_plane_[i][2]};
    for (int k = 0; k < 3; ++k)
      for (int a = 0; a < 2; ++a) t.offset[k][a] = q_[k] - planes_[k][lo[k] + a];
    for (int a = 0; a < 2; ++a)
      for (int b = 0; b < 2; ++b)
        for (int c = 0; c < 2; ++c) {
          Corner& x = corners_[(static_cast<std::size_t>(lo[0] + a) * count_[1] + lo[1] + b) * count_[2] + lo[2] + c];
          if (x.generation != generation_) {
            cuboid_corner(t.offset[0][a], t.offset[1][b], t.offset[2][c], eps_, true, x.angle, x.inverse_distance);
            x.generation = generation_;
          }
          for (int m = 0; m < 3; ++m) t.angle[a][b][c][m] = x.angle[m];
          t.inverse_distance[a][b][c] = x.inverse_distance;
        }
    for (int e = 0; e < 3; ++e)
      for (int a = 0; a < 2; ++a)
        for (int b = 0; b < 2; ++b) {
          const int u = kU[e], w = kW[e], along = kAlong[e];
          Edge& x = edges_[e][(static_cast<std::size_t>(lo[u] + a) * count_[w] + lo[w] + b) * (count_[along] - 1) +
                              lo[along]];
          if (x.generation != generation_) {
            cuboid_edge(t.offset[u][a], t.offset[w][b], t.offset[along][0], t.offset[along][1], eps_, true, x.log_term,
                        x.ratio);
            x.generation = generation_;
          }
          t.log_pair[e][a][b] = x.log_term;
          t.edge_ratio[e][a][b] = x.ratio;
        }
  }

 private:
  // Edge e runs along axis kAlong[e] between planes of axes kU[e], kW[e] (CuboidCornerTerms).
  static constexpr int kU[3] = {0, 0, 1}, kW[3] = {1, 2, 2}, kAlong[3] = {2, 1, 0};
  struct Corner {
    double angle[3];
    double inverse_distance;
    long generation = 0;
  };
  struct Edge {
    double log_term, ratio;
    long generation = 0;
  };
  std::vector<double> planes_[3];
  int count_[3] = {};
  std::size_t slab(int i, int j, int l) const {
    return (static_cast<std::size_t>(i) * (count_[1] - 1) + j) * (count_[2] - 1) + l;
  }
  std::vector<std::array<int, 3>> lower_plane_;
  std::vector<int> cell_at_;  // per slot between consecutive planes: the cell there, or -1
  std::vector<Corner> corners_;
  std::vector<Edge> edges_[3];
  double eps_ = 0.0;
  long generation_ = 0;
  Vec3 q_;
};

struct Ball {
  int cell = -1;
  int body = -1;
  double radius = 0.0;
};

// A lattice body's data that depend on the model only (rebuilt when its
// generation changes), and its pose-dependent part (every build).
struct LatticeBody {
  int body = -1;
  double h = 0.0;
  double volume = 0.0;  // V of T_c for a cube cell (CellSet::cell_volume)
  Vec3 local_centroid;  // of the cell points, body frame
  double radius = 0.0;  // bounding sphere about it
  Eigen::Matrix3d local_J_inverse = Eigen::Matrix3d::Zero();  // body frame
  std::vector<Vec3> half;         // per cell: half extents of its solid (CellSet::solid_half)
  std::vector<double> solid_volume;  // per cell: V of T_c
  bool shared = false;            // corners shares the cells' corner terms
  SharedCorners corners;
  // At build:
  Mat3 rotation;  // R_X
  Vec3 centroid;  // world
  Eigen::Matrix3d J_inverse = Eigen::Matrix3d::Zero();  // world: R_X J^-1 R_X^T
};

struct BallCellPair {
  int ball = -1, lattice = -1;  // indices into balls_, cached_
  int b = -1, c = -1;           // cells
  bool responsive_b = false, responsive_c = false;  // their bodies respond to fields
  double volume_b = 0.0, volume_c = 0.0;            // their cell volumes (moments V M)
  Vec3 half;                    // half extents of the cell's cuboid (body frame)
  double volume = 0.0;          // V of T_c
  double K[6];                  // world, 1/m^3
  Vec3 r;                       // x_b - x_c at build
  double w = 0.0, Tc[6];        // the window and T_c at r (carried from base: carry_to)
  Vec3 r0;                      // x_b - x_c where `base` was evaluated
  PairGeometry base;  // evaluated at r0 with the gradients (PairGroup), which add_forces reuses
};

// What the field sums (add_field at every outer iteration, energy) read of a
// pair, copied from the pairs at the end of every build in for_each_pair's
// order: 80 bytes a pair streamed instead of a whole BallCellPair (over 600
// bytes with its two geometries).
struct PairCoupling {
  int b = -1, c = -1;
  bool responsive_b = false, responsive_c = false;
  double volume_b = 0.0, volume_c = 0.0;
  double K[6];
};

// A ball's pairs with one lattice body, kept from build to build: while the
// ball's centre stays within kReuseTolerance R (kReuseToleranceInFade R with
// a pair in the inner fade) of q0 in the body's frame and the frame has not
// turned, the pairs are those evaluated at q0, carried to the new offset to
// first order (header comment).
struct PairGroup {
  bool valid = false;
  // A pair in the inner fade (an overlapping ball): kReuseToleranceInFade.
  bool in_fade = false;
  Vec3 q0;  // ball centre in the lattice body's frame at the evaluation
  Mat3 R0;  // the lattice body's rotation then
  std::vector<BallCellPair> pairs;
};

bool same(const Vec3& a, const Vec3& b) { return a.x == b.x && a.y == b.y && a.z == b.z; }
bool same(const Mat3& a, const Mat3& b) {
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j)
      if (a.m[i][j] != b.m[i][j]) return false;
  return true;
}

class BallLatticeNearField final : public NearFieldTerm {
 public:
  void build(const MagneticModel& model, const MagneticState& state) override {
    balls_.clear();
    lattices_.clear();
    active_groups_.clear();
    couplings_.clear();
    if (model.intra_body_tensor() != IntraBodyTensor::cell_average) return;
    if (model.generation() != cached_generation_ || cached_bodies_ != model.body_count()) cache_lattices(model);
    for (int bi = 0; bi < model.body_count(); ++bi) {
      const MagneticBody& body = model.body(bi);
      if (body.inert() || !state.active[bi]) continue;
      if (body.cells.spacing <= 0.0 && body.cell_count() == 1 && std::holds_alternative<Sphere>(body.shape))
        balls_.push_back({body.first_cell, bi, body.cells.contact_radius});
    }
    for (int li = 0; li < static_cast<int>(cached_.size()); ++li) {
      const LatticeBody& lb = cached_[li];
      if (!state.active[lb.body]) continue;
      lattices_.push_back(li);
      LatticeBody& l = cached_[li];
      const BodyPose& pose = state.pose[lb.body];
      l.rotation = pose.rotation;
      l.centroid = pose.position + pose.rotation * lb.local_centroid;
      Eigen::Matrix3d R;
      for (int a = 0; a < 3; ++a)
        for (int b = 0; b < 3; ++b) R(a, b) = pose.rotation.m[a][b];
      l.J_inverse = R * lb.local_J_inverse * R.transpose();
    }
    std::vector<int> near;
    for (int bi = 0; bi < static_cast<int>(balls_.size()); ++bi) {
      const Ball& ball = balls_[bi];
      const Vec3& xb = state.cell_position[ball.cell];
      for (int li : lattices_) {
        LatticeBody& lb = cached_[li];
        if (norm(xb - lb.centroid) >= lb.radius + kCutoffEnd * lb.h) continue;
        const Mat3& R_X = lb.rotation;
        const Vec3 q = R_X.transpose_times(xb - state.pose[lb.body].position);
        const std::size_t gi = static_cast<std::size_t>(ball.body) * cached_.size() + li;
        PairGroup& group = groups_[gi];
        active_groups_.push_back(gi);
        const double tolerance = group.in_fade ? kReuseToleranceInFade : kReuseTolerance;
        if (group.valid && same(R_X, group.R0) && norm(q - group.q0) <= tolerance * ball.radius) {
          for (BallCellPair& p : group.pairs) {
            p.ball = bi;
            p.r = xb - state.cell_position[p.c];
            carry_to(p.r - p.r0, p);
            set_K(model, p);
          }
          continue;
        }
        group.valid = true;
        group.in_fade = false;
        group.q0 = q;
        group.R0 = R_X;
        group.pairs.clear();
        const MagneticBody& body = model.body(lb.body);
        if (lb.shared) {
          lb.corners.begin(q);
          lb.corners.cells_near(q, kCutoffEnd * lb.h, near);
        } else {
          near.resize(body.cell_count());
          for (int i = 0; i < body.cell_count(); ++i) near[i] = i;
        }
        for (int i : near) {
          const int c = body.first_cell + i;
          BallCellPair p;
          p.r = xb - state.cell_position[c];
          p.half = lb.half[i];
          p.volume = lb.solid_volume[i];
          Vec3 l;
          if (!pair_windows(p.r, R_X, lb.h, p.half, ball.radius, true, p.base, l)) continue;
          CuboidCornerTerms t;
          if (lb.shared)
            lb.corners.terms(i, t);
          else
            cuboid_corner_terms(l, p.half, true, t);
          pair_tensor(t, R_X, p.volume, true, p.base);
          p.ball = bi, p.lattice = li, p.b = ball.cell, p.c = c;
          p.responsive_b = model.body(ball.body).responsive();
          p.responsive_c = model.body(lb.body).responsive();
          p.volume_b = model.cell_volume(p.b);
          p.volume_c = model.cell_volume(p.c);
          p.r0 = p.r;
          p.w = p.base.w;
          std::copy(p.base.Tc, p.base.Tc + 6, p.Tc);
          if (p.base.w_in < 1.0) group.in_fade = true;
          set_K(model, p);
          group.pairs.push_back(p);
        }
      }
    }
    for_each_pair([&](const BallCellPair& p) {
      PairCoupling k{p.b, p.c, p.responsive_b, p.responsive_c, p.volume_b, p.volume_c, {}};
      std::copy(p.K, p.K + 6, k.K);
      couplings_.push_back(k);
    });
  }

  void add_field(const MagneticModel& /*model*/, const MagneticState& state, NearFieldSources sources,
                 std::vector<Vec3>& H) const override {
    const bool responsive_sources = sources == NearFieldSources::responsive;
    for (const PairCoupling& p : couplings_) {
      if (both_held(p.b, p.c)) continue;
      if (p.responsive_b && p.responsive_c == responsive_sources)
        H[p.b] += symmetric_times(p.K, p.volume_c * state.magnetization[p.c]);
      if (p.responsive_c && p.responsive_b == responsive_sources)
        H[p.c] += symmetric_times(p.K, p.volume_b * state.magnetization[p.b]);
    }
  }

  void add_forces(const MagneticModel& model, const MagneticState& state, std::vector<Vec3>& force,
                  std::vector<Vec3>& field) const override {
    std::vector<Vec3> torque(cached_.size());
    for_each_pair([&](const BallCellPair& p) {
      const LatticeBody& lb = cached_[p.lattice];
      const Vec3 mu_b = p.volume_b * state.magnetization[p.b], mu_c = p.volume_c * state.magnetization[p.c];
      const Vec3 r = state.cell_position[p.b] - state.cell_position[p.c];
      const Mat3& R_X = state.pose[lb.body].rotation;
      // The geometry of build where nothing has moved since (the usual case:
      // the backends build at begin_step and take forces at the same poses):
      // w and T_c at r, the gradients of the evaluation at r0.
      PairGeometry moved;
      const bool unmoved = same(r, p.r) && same(R_X, lb.rotation);
      if (!unmoved) moved = pair_geometry(r, R_X, lb.h, p.half, p.volume, balls_[p.ball].radius, true);
      const PairGeometry& g = unmoved ? p.base : moved;
      const double w = unmoved ? p.w : moved.w;
      const double* Tc = unmoved ? p.Tc : moved.Tc;
      if (w == 0.0) return;
      const double s = model.cell_contact_radius(p.b) + model.cell_contact_radius(p.c);
      const DipoleCoefficients dc = dipole_coefficients(dot(r, r), s * s);
      const Vec3 Tc_mu_c = symmetric_times(Tc, mu_c), Tc_mu_b = symmetric_times(Tc, mu_b);
      const Vec3 T_mu_c = dipole_field(dc, r, mu_c), T_mu_b = dipole_field(dc, r, mu_b);
      const double phi0 = dot(mu_b, Tc_mu_c - T_mu_c);
      Vec3 g_c;  // grad_r (mu_b . T_c mu_c)
      for (int k = 0; k < 3; ++k) g_c[k] = dot(mu_b, symmetric_times(g.dTc[k], mu_c));
      // F_b = mu0 grad_r (w phi0); dipole_force is mu0 grad_r (mu_b . T mu_c).
      const Vec3 F_b = kMu0 * (phi0 * g.grad_w + w * g_c) - w * dipole_force(dc, r, mu_c, mu_b);
      force[p.b] += F_b;
      force[p.c] -= F_b;
      field[p.b] += w * (Tc_mu_c - T_mu_c);
      field[p.c] += w * (Tc_mu_b - T_mu_b);
      // The lattice frame's pure torque (header comment).
      torque[p.lattice] -= kMu0 * (cross(r, (phi0 * g.w_out) * g.grad_w_in + w * g_c) +
                                   w * (cross(mu_b, Tc_mu_c) + cross(mu_c, Tc_mu_b)));
    });
    for (int li : lattices_) {
      const Vec3& tau = torque[li];
      if (tau.x == 0.0 && tau.y == 0.0 && tau.z == 0.0) continue;
      const LatticeBody& lb = cached_[li];
      const Eigen::Vector3d omega = lb.J_inverse * Eigen::Vector3d(tau.x, tau.y, tau.z);
      const MagneticBody& body = model.body(lb.body);
      for (int i = 0; i < body.cell_count(); ++i) {
        const int c = body.first_cell + i;
        force[c] += cross(Vec3{omega(0), omega(1), omega(2)}, state.cell_position[c] - lb.centroid);
      }
    }
  }

  double energy(const MagneticModel& /*model*/, const MagneticState& state) const override {
    double e = 0.0;
    for (const PairCoupling& p : couplings_)
      e -= kMu0 * dot(p.volume_b * state.magnetization[p.b], symmetric_times(p.K, p.volume_c * state.magnetization[p.c]));
    return e;
  }

  int pair_count() const override {
    return static_cast<int>(couplings_.size());
  }

 private:
  // Every pair of the current build: groups in ball order, then lattice body
  // order, each group's pairs in cell order.
  template <class F>
  void for_each_pair(F&& f) const {
    for (std::size_t gi : active_groups_)
      for (const BallCellPair& p : groups_[gi].pairs) f(p);
  }

  // K = w (T_c - T(r; s)) at the pair's r.
  static void set_K(const MagneticModel& model, BallCellPair& p) {
    const double s = model.cell_contact_radius(p.b) + model.cell_contact_radius(p.c);
    double dipole[6];
    dipole_tensor(p.r, s * s, dipole);
    for (int m = 0; m < 6; ++m) p.K[m] = p.w * (p.Tc[m] - dipole[m]);
  }

  // w and T_c at r0 + dr from the evaluation at r0, to first order in dr
  // (its gradients stay those at r0).
  static void carry_to(const Vec3& dr, BallCellPair& p) {
    const PairGeometry& base = p.base;
    p.w = base.w + dot(base.grad_w, dr);
    for (int m = 0; m < 6; ++m)
      p.Tc[m] = base.Tc[m] + base.dTc[0][m] * dr.x + base.dTc[1][m] * dr.y + base.dTc[2][m] * dr.z;
  }

  // The model-only data of every lattice body with at least three cells spread
  // in three dimensions (the frame couple needs them), not graded (graded
  // cells stay point dipoles: lattice_near_field.cpp) and not inert.
  void cache_lattices(const MagneticModel& model) {
    cached_.clear();
    groups_.clear();
    cached_generation_ = model.generation();
    cached_bodies_ = model.body_count();
    for (int bi = 0; bi < model.body_count(); ++bi) {
      const MagneticBody& body = model.body(bi);
      if (body.inert() || body.cells.spacing <= 0.0 || body.cell_count() < 3 || body.cells.mixed_sizes())
        continue;
      LatticeBody lb;
      lb.body = bi;
      lb.h = body.cells.spacing;
      lb.volume = body.cells.cell_volume;
      const std::vector<Vec3>& x = body.cells.local_positions;
      for (const Vec3& xi : x) lb.local_centroid += xi;
      lb.local_centroid = lb.local_centroid / body.cell_count();
      Eigen::Matrix3d J = Eigen::Matrix3d::Zero();
      for (const Vec3& xi : x) {
        const Vec3 d = xi - lb.local_centroid;
        lb.radius = std::max(lb.radius, norm(d));
        const Eigen::Vector3d e(d.x, d.y, d.z);
        J += e.squaredNorm() * Eigen::Matrix3d::Identity() - e * e.transpose();
      }
      const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(J);
      if (eig.eigenvalues()(0) < kMinCoupleInertia * lb.h * lb.h) continue;  // collinear cells
      lb.local_J_inverse = J.inverse();
      std::vector<Vec3> lower, upper;
      for (int i = 0; i < body.cell_count(); ++i) {
        const Vec3 half = body.cells.solid_half(i);
        lb.half.push_back(half);
        lb.solid_volume.push_back(body.cells.solid_volume(i));
        lower.push_back(x[i] - half);
        upper.push_back(x[i] + half);
      }
      lb.shared = lb.corners.build(lower, upper, lb.h);
      cached_.push_back(std::move(lb));
    }
    groups_.assign(static_cast<std::size_t>(model.body_count()) * cached_.size(), {});
  }

  std::vector<Ball> balls_;
  std::vector<LatticeBody> cached_;  // every lattice body that can take a pair (cache_lattices)
  uint64_t cached_generation_ = 0;
  int cached_bodies_ = -1;
  std::vector<int> lattices_;  // the active ones at build, indices into cached_
  // Per (ball body, cached lattice body): groups_[ball * cached_.size() + li],
  // kept across builds; those of the current build in active_groups_.
  std::vector<PairGroup> groups_;
  std::vector<std::size_t> active_groups_;
  std::vector<PairCoupling> couplings_;  // every pair of the current build (for_each_pair's order)
};

}  // namespace

std::unique_ptr<NearFieldTerm> make_ball_lattice_near_field() { return std::make_unique<BallLatticeNearField>(); }

}  // namespace odemag
