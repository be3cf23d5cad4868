// Close pairs of lattice cells of different, aligned bodies: the cell-averaged
// (Newell) tensor instead of the point dipole (magnetics/near_field/near_field.h).
//
// Inside a body two lattice cells couple through the mean over cube a of the
// field of cube b, H_a = -N(d) mu_b / V (magnetics/model/model.cpp; N the Newell
// tensor, magnetics/cells/demag_tensor.h, d the offset of the cubes' centres); between
// bodies the dense sums couple them as point dipoles, H_a = T(r) mu_b
// (magnetics/kernels/kernels.h, r the offset of the cell points), 18% too strongly for
// face neighbours: a chi = 1000 cube cut in two touching halves had a moment
// percents above the uncut cube (3.2% for 8^3 cells in
// tests/magnetics/lattice_near_field_test.cpp), and the halves did not converge
// in 200 iterations. For cells i, j of two bodies A, B with parallel lattices (the
// same spacing h, R_A^T R_B a signed permutation within the window w_a) this term
// adds the difference for every pair whose points are closer than kCutoffEnd h:
//
//   H_i += K mu_j,  H_j += K mu_i,   U = -mu0 mu_i . K mu_j,   mu = M V (cell volume),
//   K = w_a(c) w_r(|d|) [ (T_A(d) + T_B(d)) / 2 - T(r; s_ij) ],
//   T_X(d) = -R_X N_s(R_X^T d) R_X^T / V,   V = sqrt(V_i V_j) (pair_volume),
//
// d = r = x_i - x_j, the cell points (each cell's cube is centred on its point:
// the lattice site of a whole cube, the centroid of its part of the body for a
// boundary cell, which puts an end face's charge where the material is; coaxial
// cylinders, docs/model.md), T(r; s_ij) the dense kernel
// with the pair's contact distance, R_X the rotation of body X. So a pair couples
// exactly as two cells of one body do, and cutting a box of whole cells into
// touching pieces changes nothing but the pairs beyond the cutoff (for other
// shapes each piece also has its own boundary correction, MagneticBody::
// self_tensors, computed for its own shape). The two frames agree for
// aligned lattices (N has the cube's symmetry); averaging them keeps K symmetric
// in A and B while they differ by the small angle w_a allows.
//
// Cutoff (w_r, C2 quintic steps): full correction from 0.75 h to 2 h, none beyond
// 3 h. |K| relative to the face neighbours' coupling 1 / (2 pi h^3), largest over
// directions: 2.9e-3 at 2 h, 1.9e-4 at 3 h, 2.6e-5 at 4 h (~ (h/r)^7). The cut
// cube's moment error (2 / 8 pieces) with the window at 1.5-2.5 h: 4.6e-4 /
// 2.7e-4 (1980 / 5236 pairs); 2-3 h: 4.7e-5 / 4.2e-5 (2364 / 6196 pairs); 3-4 h:
// 1.2e-5 / 8.1e-6 (8064 / 19536); 4-5 h: 1.5e-6 / 4.0e-6 (17572 / 39612).
//
// Overlap. The exact N has a kink where two cubes start to overlap along an
// axis k: the facing faces' charges pass through each other and their
// attraction reverses at once (N_kk gains exactly p_k p_i p_j / h^3 at an
// overlap p_k = h - |d_k|, with p_i, p_j the overlaps of the other two axes). In
// ODE's soft contacts, where touching bodies overlap a little, the force on two
// touching permanent cubes then jumped by 2.4 times itself. N_s replaces that
// onset by a C2 one over the first kOnsetWidth h of overlap:
//   N_s,kk = N_kk - D(p_k) q(p_i) q(p_j) / h^3,   D(p) = p (1 - (p / delta)^2)^3,
// (q: p smoothed where it vanishes, over kEdgeWidth h, so that the term adds no
// kink where edges pass), equal to N wherever the cubes do not overlap or
// overlap by more than delta. The smoothing lowers the positive overlap energy
// that keeps soft bodies stable; with delta = 0.15 h two halves of a chi = 1000
// cube pressed 0 .. 0.3 h into each other converge in 53-78 iterations (with
// 0.25 h they did not at 0.05-0.1 h). Two permanent cubes' attraction turns into
// repulsion at an overlap of 0.035 h (the dense core's at about 0.09 h). Deeper
// than a quarter cell the term fades out (w_r), leaving the dense sums' bounded core.
//
// Alignment (w_a, quintic step in c = 3 - tr(R_A^T R_B P^T) = 2 (1 - cos phi), phi
// the angle between the lattices, P the nearest signed permutation): 1 below
// 0.5 degrees, 0 beyond 1 degree, so that jitter of resting bodies does not
// switch the term. Misaligned lattices keep the point dipoles (a general
// relative rotation would need the tensor of two rotated cubes, not
// implemented). Cost, the 8 h cube cut in halves with one half turned about
// an axis in the contact plane (its ends then overlap and part a little):
// moment error against the uncut cube 1.0e-3 / 2.3e-3 /
// 1.5e-2 at 0.25 / 0.5 / 0.75 degrees (55 / 62 / 174 iterations), 2.2e-2 at 1
// degree and no convergence in 400 iterations (as without the term: 3.6e-2 ..
// 5.9e-2, not converged, at every angle).
//
// Forces and torques. F_i = -dU/dx_i = -F_j from the analytic gradient of N
// (cube_demag_tensor_at) and of the windows; the field K mu goes to the
// backends' field output (torque mu0 mu x H). Three torques remain, each a
// pure torque on a body: K is not isotropic, so mu0 mu x H and r x F leave the
// torque on the cubes' frames, -dU/dtheta of turning R_X alone,
//   tau_X = -mu0 w_a w_r / 2 [ d x g_X + mu_i x T_X mu_j + mu_j x T_X mu_i ],
// g_X = grad_d (mu_i . T_X mu_j); the alignment window gives body B
// mu0 w_r w_a'(c) (dc/dtheta_B) (mu_i . K mu_j) / w_a and A the opposite. (The
// cubes are centred on the cell points, where the backends apply the forces,
// so the forces themselves add no torque about the points.) The interface passes forces and fields
// per cell, so each body's sum tau is applied as the rigid distribution
// F_c = (J^-1 tau) x (x_c - x_bar) over its cells (J = sum |x_c - x_bar|^2 I -
// (x_c - x_bar)(x_c - x_bar)^T about their centroid x_bar): no net force,
// torque tau. Bodies with fewer than three cells or collinear cells (J singular)
// take no correction, nor do models with point-dipole intra-body tensors
// (IntraBodyTensor::point_dipole: there a body's own cells are point dipoles too).
//
// Cost: the halves of an 8^3 cube have 2364 pairs (8 pieces: 6196); build
// about 10 us per pair (the cube tensor and its gradient in each frame, once
// when the two bodies' rotations are equal bit for bit), kept for the forces
// at the same pose, which then cost a few 3 x 3 products per pair; each field
// evaluation two 3 x 3 products per pair. (Computing the tensors again in the
// forces, and in both frames, was 83% of the thin-plate scene's time.)
//
// Pair search (build): bodies first, by the bounding spheres of their cell
// points; then the cells of each body within reach of the other's sphere; then
// those cell pairs: O(bodies^2 + cells of close bodies + their cell pairs), not
// O(N^2) over a scene of separate bodies. Pairs are kept in a fixed order and
// summed on one thread. The dense sums' responsive-responsive pairs are left
// out of the relaxation with mutual induction off, and so are these (the
// backends then evaluate no responsive field).
#include <Eigen/Dense>
#include <algorithm>
#include <cmath>

#include "odemag/constants.h"
#include "magnetics/cells/demag_tensor.h"
#include "magnetics/kernels/kernels.h"
#include "magnetics/near_field/near_field.h"

namespace odemag {

namespace {

// Radial window, in units of h (measurements in the header comment).
constexpr double kCutoffStart = 2.0;
constexpr double kCutoffEnd = 3.0;
constexpr double kCoreEnd = 0.5;     // below: no correction (deep overlap)
constexpr double kCoreStart = 0.75;  // above: full correction
// Alignment window (radians).
constexpr double kAlignStart = 0.5 * kPi / 180.0;
constexpr double kAlignEnd = 1.0 * kPi / 180.0;
// Smoothed onset of overlap and of edges passing, in units of h.
constexpr double kOnsetWidth = 0.15;
constexpr double kEdgeWidth = 0.05;
// Bodies need cells spread in 3 dimensions to take a pure torque: smallest
// eigenvalue of J above this times h^2.
constexpr double kMinCoupleInertia = 0.1;
// Spacings of two lattices equal to this relative tolerance.
constexpr double kSpacingTolerance = 1e-9;

// Quintic smoothstep S(t): 0 below 0, 1 above 1, C2; ds = dS/dt.
double smoothstep(double t, double& ds) {
  if (t <= 0.0) return ds = 0.0, 0.0;
  if (t >= 1.0) return ds = 0.0, 1.0;
  ds = 30.0 * t * t * (t - 1.0) * (t - 1.0);
  return t * t * t * (10.0 + t * (6.0 * t - 15.0));
}

struct Window {
  double w = 1.0;   // value
  double dw = 0.0;  // derivative with respect to the argument
};

Window radial_window(double r, double h) {
  double d_in, d_out;
  const double in = smoothstep((r / h - kCoreEnd) / (kCoreStart - kCoreEnd), d_in);
  const double out = 1.0 - smoothstep((r / h - kCutoffStart) / (kCutoffEnd - kCutoffStart), d_out);
  return {in * out, (d_in / (kCoreStart - kCoreEnd) * out - in * d_out / (kCutoffEnd - kCutoffStart)) / h};
}

Window alignment_window(double c) {
  const double c0 = 2.0 * (1.0 - std::cos(kAlignStart)), c1 = 2.0 * (1.0 - std::cos(kAlignEnd));
  double ds;
  const double s = smoothstep((c - c0) / (c1 - c0), ds);
  return {1.0 - s, -ds / (c1 - c0)};
}

// D(p) = p (1 - (p / delta)^2)^3 for 0 <= p < delta, else 0, and dD/dp: D = p +
// O(p^3), so it cancels N's kink at the onset of overlap to second order, and
// D, D', D'' vanish at delta, where N is restored.
double onset(double p, double delta, double& dp) {
  if (p < 0.0 || p >= delta) return dp = 0.0, 0.0;
  const double u2 = (p / delta) * (p / delta), v = 1.0 - u2;
  dp = v * v * (1.0 - 7.0 * u2);
  return p * v * v * v;
}

// q(p) = w (3 u^2 - 3 u^3 + u^4), u = p / w, for 0 <= p < w, else p: C2, with
// q(0) = q'(0) = 0; and dq/dp.
double edge_ramp(double p, double w, double& dq) {
  if (p >= w) return dq = 1.0, p;
  const double u = p / w;
  dq = u * (6.0 + u * (4.0 * u - 9.0));
  return w * u * u * (3.0 + u * (u - 3.0));
}

// Symmetric tensors as six components (xx, xy, xz, yy, yz, zz).
constexpr int kRow[6] = {0, 0, 0, 1, 1, 2}, kCol[6] = {0, 1, 2, 1, 2, 2};
constexpr int kDiagonal[3] = {0, 3, 5};

// R S R^T for a symmetric S.
void rotate_symmetric(const Mat3& R, const double s[6], double out[6]) {
  const double S[3][3] = {{s[0], s[1], s[2]}, {s[1], s[3], s[4]}, {s[2], s[4], s[5]}};
  double RS[3][3];
  for (int a = 0; a < 3; ++a)
    for (int b = 0; b < 3; ++b) RS[a][b] = R.m[a][0] * S[0][b] + R.m[a][1] * S[1][b] + R.m[a][2] * S[2][b];
  for (int m = 0; m < 6; ++m) {
    const int a = kRow[m], b = kCol[m];
    out[m] = RS[a][0] * R.m[b][0] + RS[a][1] * R.m[b][1] + RS[a][2] * R.m[b][2];
  }
}

// The smoothed onset of overlap of two aligned solids with overlaps p_k
// (dp_k = dp_k / dd_k) along each axis: s_k = D(p_k) q_i q_j, subtracted from
// N_kk, q the edge ramps of the overlaps, and ds[k][m] = ds_k / dd_m.
void overlap_onset(const double p[3], const double dp[3], double h, double s[3], double ds[3][3]) {
  double q[3], dq[3];
  for (int k = 0; k < 3; ++k) q[k] = edge_ramp(p[k], kEdgeWidth * h, dq[k]), dq[k] *= dp[k];
  for (int k = 0; k < 3; ++k) {
    s[k] = 0.0, ds[k][0] = ds[k][1] = ds[k][2] = 0.0;
    const int i = (k + 1) % 3, j = (k + 2) % 3;
    double dD_dp;
    const double o = onset(p[k], kOnsetWidth * h, dD_dp);
    if (o == 0.0 && dD_dp == 0.0) continue;
    s[k] = o * q[i] * q[j];
    ds[k][k] = dD_dp * dp[k] * q[i] * q[j];
    ds[k][i] = o * dq[i] * q[j];
    ds[k][j] = o * q[i] * dq[j];
  }
}

// The tensor of two aligned cubes of edge h acting on moments, H = D mu, at the
// offset d of their centres in their frame: D = -N_s(d) / h^3 (header comment), and, when
// dD is not null, its gradient dD[k] = dD / dd_k.
void cube_pair_tensor(const double d[3], double h, double volume, double D[6], double (*dD)[6]) {
  double n[6], dn[3][6];
  cube_demag_tensor_at(d, h, n, dD ? dn : nullptr);
  // Overlaps p_k = max(h - |d_k|, 0) and dp_k/dd_k; at a kink (|d_k| = 0 or h)
  // the mean of the two sides, as for N.
  double p[3], dp[3];
  for (int k = 0; k < 3; ++k) {
    const double a = std::fabs(d[k]);
    const double sign = d[k] > 0.0 ? 1.0 : (d[k] < 0.0 ? -1.0 : 0.0);
    p[k] = std::max(h - a, 0.0);
    dp[k] = a < h ? -sign : (a == h ? -0.5 * sign : 0.0);
  }
  // s_k / h^3 subtracted from N_kk (overlap_onset).
  double s[3], ds[3][3];
  overlap_onset(p, dp, h, s, ds);
  const double h3 = h * h * h;
  for (int m = 0; m < 6; ++m) D[m] = -n[m] / volume;
  for (int k = 0; k < 3; ++k) D[kDiagonal[k]] += s[k] / (h3 * volume);
  if (!dD) return;
  for (int m = 0; m < 3; ++m) {
    for (int c = 0; c < 6; ++c) dD[m][c] = -dn[m][c] / volume;
    for (int k = 0; k < 3; ++k) dD[m][kDiagonal[k]] += ds[k][m] / (h3 * volume);
  }
}

// The tensor of two aligned cuboid solids (half extents a of the target, b
// of the source, CellSet::solid_half) acting on moments, H = D mu, at the
// offset d of their centres: D = -(N_ab - S / V_a) / V_b with N_ab the
// cuboid-cuboid tensor (cuboid_demag_tensor), V the solids' volumes and S the
// smoothed onset of overlap of cube_pair_tensor with the overlaps p_k = a_k +
// b_k - |d_k| (at most 2 min(a_k, b_k)), so that V_a V_b D is symmetric in
// the two cells; and, when dD is not null, dD[k] = dD / dd_k. A box's
// boundary cells are such cuboids: its face's charge sits on the face.
void solid_pair_tensor(const double d[3], const double a[3], const double b[3], double h, double D[6],
                       double (*dD)[6]) {
  double n[6], dn[3][6];
  cuboid_demag_tensor(a, b, d, n, dD ? dn : nullptr);
  const double Va = 8.0 * a[0] * a[1] * a[2], Vb = 8.0 * b[0] * b[1] * b[2];
  double p[3], dp[3];
  for (int k = 0; k < 3; ++k) {
    const double s = std::fabs(d[k]), reach = a[k] + b[k], full = 2.0 * std::min(a[k], b[k]);
    const double sign = d[k] > 0.0 ? 1.0 : (d[k] < 0.0 ? -1.0 : 0.0);
    p[k] = std::clamp(reach - s, 0.0, full);
    dp[k] = (s < reach && reach - s < full) ? -sign : 0.0;
  }
  double s[3], ds[3][3];
  overlap_onset(p, dp, h, s, ds);
  for (int m = 0; m < 6; ++m) D[m] = -n[m] / Vb;
  for (int k = 0; k < 3; ++k) D[kDiagonal[k]] += s[k] / (Va * Vb);
  if (!dD) return;
  for (int m = 0; m < 3; ++m) {
    for (int c = 0; c < 6; ++c) dD[m][c] = -dn[m][c] / Vb;
    for (int k = 0; k < 3; ++k) dD[m][kDiagonal[k]] += ds[k][m] / (Va * Vb);
  }
}

// The volume that turns the cube tensor into one on moments, H = -N mu / V:
// the one the body's own tensors use, as inside a body (CellSet::cell_volume:
// h^3 for volume-share cells and boxes of whole cells, where a boundary cell
// acts as its cube with the reduced magnetization V_i M / h^3); the geometric
// mean when two bodies' cells stand for different volumes, so that K stays
// symmetric.
double pair_volume(const MagneticModel& model, int i, int j) {
  return std::sqrt(model.body(model.cell_body(i)).cells.cell_volume * model.body(model.cell_body(j)).cells.cell_volume);
}

// A pair's tensor in one body frame X, at the local offset R_X^T d: D and its
// gradient dD[k] = dD / d(local offset)_k (cube_pair_tensor).
struct LocalTensor {
  double D[6];
  double dD[3][6];
};

// The cells' solids in one body frame: both the cube of edge h (cubes), or
// their half extents in that frame.
struct PairSolids {
  bool cubes = true;
  Vec3 half_i, half_j;
};

LocalTensor local_tensor(const Mat3& R, const Vec3& d, double h, double volume, const PairSolids& solids) {
  LocalTensor t;
  const Vec3 dl = R.transpose_times(d);
  const double local[3] = {dl.x, dl.y, dl.z};
  if (solids.cubes) {
    cube_pair_tensor(local, h, volume, t.D, t.dD);
  } else {
    const double a[3] = {solids.half_i.x, solids.half_i.y, solids.half_i.z};
    const double b[3] = {solids.half_j.x, solids.half_j.y, solids.half_j.z};
    solid_pair_tensor(local, a, b, h, t.D, t.dD);
  }
  return t;
}

// Half extents given in one lattice's frame, in the other's: components
// permuted as the signed permutation P (x_A = P x_B) maps the axes.
Vec3 permuted_half(const Mat3& P, const Vec3& half) {
  Vec3 out;
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c)
      if (P.m[r][c] != 0.0) out[r] = half[c];
  return out;
}

// One body frame's share of a pair, given the moments: phi = mu_i . T_X mu_j
// (T_X = R D R^T, world), the fields T_X mu_j, T_X mu_i at i and j, and
// grad = grad_d phi.
struct FrameShare {
  double phi = 0.0;
  Vec3 H_i, H_j, grad;
};

FrameShare frame_share(const Mat3& R, const LocalTensor& t, const Vec3& mu_i, const Vec3& mu_j) {
  FrameShare f;
  const Vec3 mi = R.transpose_times(mu_i), mj = R.transpose_times(mu_j);
  const Vec3 Dmj = symmetric_times(t.D, mj), Dmi = symmetric_times(t.D, mi);
  f.phi = dot(mi, Dmj);
  f.H_i = R * Dmj;
  f.H_j = R * Dmi;
  Vec3 g;
  for (int k = 0; k < 3; ++k) g[k] = dot(mi, symmetric_times(t.dD[k], mj));
  f.grad = R * g;
  return f;
}

bool same_rotation(const Mat3& a, const Mat3& b) {
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c)
      if (a.m[r][c] != b.m[r][c]) return false;
  return true;
}

// Two bodies whose lattices are aligned closely enough to be corrected.
struct BodyLink {
  int a = 0, b = 0;  // body indices, a < b
  double h = 0.0;
  Window align;      // w_a(c)
  Vec3 dc_dtheta_b;  // dc / dtheta of turning body b (world); body a: the opposite
  Mat3 rotation_a, rotation_b;  // the poses the pairs' tensors were built at
  bool same_frames = false;     // rotation_a == rotation_b bit for bit: T_B = T_A
};

struct CellPair {
  int i = 0, j = 0;  // cells of link.a and link.b
  int link = 0;
  double K[6];       // world
  // The build's frame tensors with their gradients, kept for the forces at the
  // same pose (cube_demag_tensor_at is most of this term's cost), and the
  // offset d they were computed at.
  Vec3 d;
  double volume = 0.0;
  PairSolids solids_a, solids_b;  // in body a's and body b's frames
  LocalTensor frame_a, frame_b;
};

// A body's bounding sphere about its cells' centroid and the rigid
// distribution of a pure torque over its cells: forces (J^-1 tau) x (x_c - centroid).
struct LatticeBody {
  bool eligible = false;
  Vec3 centroid;  // of the cell points
  double radius = 0.0;
  Eigen::Matrix3d J_inverse = Eigen::Matrix3d::Zero();
};

class LatticeNearField final : public NearFieldTerm {
 public:
  void build(const MagneticModel& model, const MagneticState& state) override {
    // The last build's pairs: their frame tensors are taken again where every
    // input is the same (reused_frames).
    std::swap(links_, previous_links_);
    std::swap(pairs_, previous_pairs_);
    links_.clear();
    pairs_.clear();
    bodies_.assign(model.body_count(), {});
    // With point-dipole intra-body tensors (the paper's model) a body's own
    // cells couple as point dipoles too: nothing to correct.
    if (model.intra_body_tensor() != IntraBodyTensor::cell_average) return;
    std::vector<int> eligible;
    for (int b = 0; b < model.body_count(); ++b) {
      const MagneticBody& body = model.body(b);
      // Graded bodies and a curved body's refined zones (CellSet::mixed_sizes)
      // are not solids on one lattice: they keep the point dipoles between
      // bodies (docs/model.md "Graded cells", "Refined contact zones"). A
      // box's refined cells are exact cuboid parts of it (exact_solids).
      if (body.inert() || !state.active[b] || body.cells.spacing <= 0.0 || body.cell_count() < 3 ||
          (body.cells.mixed_sizes() && !(body.cells.refined && body.cells.exact_solids())))
        continue;
      LatticeBody& lb = bodies_[b];
      const double h = body.cells.spacing;
      for (int i = 0; i < body.cell_count(); ++i) lb.centroid += state.cell_position[body.first_cell + i];
      lb.centroid = lb.centroid / body.cell_count();
      Eigen::Matrix3d J = Eigen::Matrix3d::Zero();
      for (int i = 0; i < body.cell_count(); ++i) {
        const int c = body.first_cell + i;
        const Vec3 d = state.cell_position[c] - lb.centroid;
        lb.radius = std::max(lb.radius, norm(d));
        const Eigen::Vector3d e(d.x, d.y, d.z);
        J += e.squaredNorm() * Eigen::Matrix3d::Identity() - e * e.transpose();
      }
      const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(J);
      if (eig.eigenvalues()(0) < kMinCoupleInertia * h * h) continue;  // collinear cells
      lb.J_inverse = J.inverse();
      lb.eligible = true;
      eligible.push_back(b);
    }
    for (std::size_t p = 0; p < eligible.size(); ++p)
      for (std::size_t q = p + 1; q < eligible.size(); ++q) link_bodies(model, state, eligible[p], eligible[q]);
  }

  void add_field(const MagneticModel& model, const MagneticState& state, NearFieldSources sources,
                 std::vector<Vec3>& H) const override {
    for (const CellPair& p : pairs_) {
      if (both_held(p.i, p.j)) continue;
      const BodyLink& l = links_[p.link];
      const bool resp_a = model.body(l.a).responsive(), resp_b = model.body(l.b).responsive();
      // Targets: responsive cells; sources: as the dense sums split them.
      const bool to_i = resp_a && (sources == NearFieldSources::responsive ? resp_b : !resp_b);
      const bool to_j = resp_b && (sources == NearFieldSources::responsive ? resp_a : !resp_a);
      if (to_i) H[p.i] += symmetric_times(p.K, moment(model, state, p.j));
      if (to_j) H[p.j] += symmetric_times(p.K, moment(model, state, p.i));
    }
  }

  void add_forces(const MagneticModel& model, const MagneticState& state, std::vector<Vec3>& force,
                  std::vector<Vec3>& field) const override {
    std::vector<Vec3> body_torque(model.body_count());
    for (const CellPair& p : pairs_) {
      const BodyLink& l = links_[p.link];
      const Vec3 mu_i = moment(model, state, p.i), mu_j = moment(model, state, p.j);
      const Vec3 r = state.cell_position[p.i] - state.cell_position[p.j], &d = r;
      const double dn = norm(d);
      const Window wr = radial_window(dn, l.h);
      const double w = l.align.w * wr.w;
      // The build's tensors where the pose is the build's (the backends build
      // and then take forces at one pose); else computed here.
      const Mat3 &Ra = state.pose[l.a].rotation, &Rb = state.pose[l.b].rotation;
      const bool built_here = same_rotation(Ra, l.rotation_a) && same_rotation(Rb, l.rotation_b) &&
                              d.x == p.d.x && d.y == p.d.y && d.z == p.d.z;
      LocalTensor ta, tb;
      if (!built_here) {
        ta = local_tensor(Ra, d, l.h, p.volume, p.solids_a);
        tb = same_rotation(Ra, Rb) ? ta : local_tensor(Rb, d, l.h, p.volume, p.solids_b);
      }
      const FrameShare A = frame_share(Ra, built_here ? p.frame_a : ta, mu_i, mu_j);
      const FrameShare B = frame_share(Rb, built_here ? p.frame_b : tb, mu_i, mu_j);
      // The dense kernel's share, at the cell points with the pair's contact distance.
      const double s = model.cell_contact_radius(p.i) + model.cell_contact_radius(p.j);
      const Vec3 Tk_mu_j = dipole_field(r, mu_j, s * s), Tk_mu_i = dipole_field(r, mu_i, s * s);
      const double phi0 = 0.5 * (A.phi + B.phi) - dot(mu_i, Tk_mu_j);
      // F_i = mu0 grad (w phi0): the part through the cubes' tensor (offset d) and
      // through the dense kernel's (r).
      const Vec3 F_cubes = (kMu0 * l.align.w) * ((wr.dw * phi0 / dn) * d + (0.5 * wr.w) * (A.grad + B.grad));
      const Vec3 F_points = -w * dipole_force(r, mu_j, mu_i, s * s);
      force[p.i] += F_cubes + F_points;
      force[p.j] -= F_cubes + F_points;
      field[p.i] += w * (0.5 * (A.H_i + B.H_i) - Tk_mu_j);
      field[p.j] += w * (0.5 * (A.H_j + B.H_j) - Tk_mu_i);
      // Pure torques (header comment): the frames' and the alignment window's.
      body_torque[l.a] -= (0.5 * kMu0 * w) * (cross(d, A.grad) + cross(mu_i, A.H_i) + cross(mu_j, A.H_j));
      body_torque[l.b] -= (0.5 * kMu0 * w) * (cross(d, B.grad) + cross(mu_i, B.H_i) + cross(mu_j, B.H_j));
      const Vec3 tau_align = (kMu0 * wr.w * l.align.dw * phi0) * l.dc_dtheta_b;
      body_torque[l.b] += tau_align;
      body_torque[l.a] -= tau_align;
    }
    for (int b = 0; b < model.body_count(); ++b) {
      const Vec3& tau = body_torque[b];
      if (tau.x == 0.0 && tau.y == 0.0 && tau.z == 0.0) continue;
      const LatticeBody& lb = bodies_[b];
      const Eigen::Vector3d omega = lb.J_inverse * Eigen::Vector3d(tau.x, tau.y, tau.z);
      const MagneticBody& body = model.body(b);
      for (int i = 0; i < body.cell_count(); ++i) {
        const int c = body.first_cell + i;
        force[c] += cross(Vec3{omega(0), omega(1), omega(2)}, state.cell_position[c] - lb.centroid);
      }
    }
  }

  double energy(const MagneticModel& model, const MagneticState& state) const override {
    double e = 0.0;
    for (const CellPair& p : pairs_)
      e -= kMu0 * dot(moment(model, state, p.i), symmetric_times(p.K, moment(model, state, p.j)));
    return e;
  }

  int pair_count() const override { return static_cast<int>(pairs_.size()); }

 private:
  static Vec3 moment(const MagneticModel& model, const MagneticState& state, int cell) {
    return model.cell_volume(cell) * state.magnetization[cell];
  }

  void link_bodies(const MagneticModel& model, const MagneticState& state, int a, int b) {
    const MagneticBody& A = model.body(a);
    const MagneticBody& B = model.body(b);
    const double ha = A.cells.spacing, hb = B.cells.spacing;
    if (std::fabs(ha - hb) > kSpacingTolerance * std::max(ha, hb)) return;
    const double h = 0.5 * (ha + hb), cutoff = kCutoffEnd * h;
    const LatticeBody &la = bodies_[a], &lb = bodies_[b];
    if (norm(la.centroid - lb.centroid) >= la.radius + lb.radius + cutoff) return;
    // Alignment: Q = R_A^T R_B, P its nearest signed permutation, E = Q P^T.
    const Mat3& Ra = state.pose[a].rotation;
    const Mat3 Q = Ra.transposed() * state.pose[b].rotation;
    Mat3 P;
    bool used[3] = {false, false, false};
    for (int i = 0; i < 3; ++i) {
      int best = 0;
      for (int j = 1; j < 3; ++j)
        if (std::fabs(Q.m[i][j]) > std::fabs(Q.m[i][best])) best = j;
      if (used[best]) return;  // not near any signed permutation
      used[best] = true;
      for (int j = 0; j < 3; ++j) P.m[i][j] = j == best ? (Q.m[i][j] < 0.0 ? -1.0 : 1.0) : 0.0;
    }
    const Mat3 E = Q * P.transposed();
    BodyLink link;
    link.a = a, link.b = b, link.h = h;
    link.align = alignment_window(3.0 - (E.m[0][0] + E.m[1][1] + E.m[2][2]));
    if (link.align.w == 0.0) return;
    // Turning body b by dtheta: E -> E + [R_A^T dtheta]x E, so dtr(E)/dtheta_b = R_A v.
    const Vec3 v{E.m[1][2] - E.m[2][1], E.m[2][0] - E.m[0][2], E.m[0][1] - E.m[1][0]};
    link.dc_dtheta_b = -(Ra * v);
    const Mat3& Rb = state.pose[b].rotation;
    link.rotation_a = Ra, link.rotation_b = Rb;
    link.same_frames = same_rotation(Ra, Rb);
    // The cells of each body within reach of the other's sphere, then their pairs.
    auto near_cells = [&](const MagneticBody& body, const LatticeBody& other) {
      std::vector<int> cells;
      for (int i = 0; i < body.cell_count(); ++i) {
        const int c = body.first_cell + i;
        if (norm(state.cell_position[c] - other.centroid) < other.radius + cutoff) cells.push_back(c);
      }
      return cells;
    };
    const std::vector<int> cells_a = near_cells(A, lb), cells_b = near_cells(B, la);
    const int link_index = static_cast<int>(links_.size());
    const std::size_t first_pair = pairs_.size();
    // The last build's pairs of the same two bodies at the same rotations, in
    // the same (i, j) order as the loop below.
    int previous_link = -1;
    for (std::size_t k = 0; k < previous_links_.size(); ++k) {
      const BodyLink& o = previous_links_[k];
      if (o.a == a && o.b == b && o.h == h && same_rotation(o.rotation_a, Ra) && same_rotation(o.rotation_b, Rb))
        previous_link = static_cast<int>(k);
    }
    std::size_t previous = 0;
    for (int i : cells_a)
      for (int j : cells_b) {
        const Vec3 d = state.cell_position[i] - state.cell_position[j];
        const Window wr = radial_window(norm(d), h);
        if (wr.w == 0.0) continue;
        CellPair p;
        p.i = i, p.j = j, p.link = link_index;
        p.d = d;
        p.volume = pair_volume(model, i, j);
        const CellSet &ca = A.cells, &cb = B.cells;
        const int ia = i - A.first_cell, jb = j - B.first_cell;
        const bool cubes = ca.solid_is_cube(ia) && cb.solid_is_cube(jb);
        p.solids_a = {cubes, ca.solid_half(ia), permuted_half(P, cb.solid_half(jb))};
        p.solids_b = {cubes, permuted_half(P.transposed(), ca.solid_half(ia)), cb.solid_half(jb)};
        if (!reused_frames(previous_link, previous, p)) {
          p.frame_a = local_tensor(Ra, d, h, p.volume, p.solids_a);
          p.frame_b = link.same_frames ? p.frame_a : local_tensor(Rb, d, h, p.volume, p.solids_b);
        }
        double ta[6], tb[6];
        rotate_symmetric(Ra, p.frame_a.D, ta);
        rotate_symmetric(Rb, p.frame_b.D, tb);
        const double s = model.cell_contact_radius(i) + model.cell_contact_radius(j);
        double t[6];
        dipole_tensor(d, s * s, t);
        for (int m = 0; m < 6; ++m) p.K[m] = link.align.w * wr.w * (0.5 * (ta[m] + tb[m]) - t[m]);
        pairs_.push_back(p);
      }
    if (pairs_.size() > first_pair) links_.push_back(link);
  }

  // Whether the last build's pair of link previous_link with p's cells had
  // every input of its frame tensors equal to p's, bit for bit (offset,
  // volume, solids; the link's rotations are equal): then p takes its frame
  // tensors, which local_tensor would compute anew to the same bits. Pairs
  // come in (i, j) order in both builds; `cursor` walks the last one's.
  bool reused_frames(int previous_link, std::size_t& cursor, CellPair& p) const {
    if (previous_link < 0) return false;
    while (cursor < previous_pairs_.size() &&
           (previous_pairs_[cursor].link < previous_link ||
            (previous_pairs_[cursor].link == previous_link &&
             (previous_pairs_[cursor].i < p.i || (previous_pairs_[cursor].i == p.i && previous_pairs_[cursor].j < p.j)))))
      ++cursor;
    if (cursor >= previous_pairs_.size()) return false;
    const CellPair& o = previous_pairs_[cursor];
    if (o.link != previous_link || o.i != p.i || o.j != p.j || !same_vector(o.d, p.d) || o.volume != p.volume ||
        !same_solids(o.solids_a, p.solids_a) || !same_solids(o.solids_b, p.solids_b))
      return false;
    p.frame_a = o.frame_a;
    p.frame_b = o.frame_b;
    return true;
  }

  static bool same_vector(const Vec3& u, const Vec3& v) { return u.x == v.x && u.y == v.y && u.z == v.z; }
  static bool same_solids(const PairSolids& u, const PairSolids& v) {
    return u.cubes == v.cubes && same_vector(u.half_i, v.half_i) && same_vector(u.half_j, v.half_j);
  }

  std::vector<BodyLink> links_, previous_links_;
  std::vector<CellPair> pairs_, previous_pairs_;
  std::vector<LatticeBody> bodies_;
};

}  // namespace

std::unique_ptr<NearFieldTerm> make_lattice_near_field() { return std::make_unique<LatticeNearField>(); }

}  // namespace odemag
