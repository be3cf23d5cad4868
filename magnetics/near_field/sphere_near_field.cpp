// Close pairs of one-cell spheres: their induced higher multipoles
// (magnetics/near_field/near_field.h; docs/model.md "The near field").
//
// A linear sphere (radius R, mu = 1 + chi) in an applied potential
//   phi_A = sum_lm I_lm r^l P_l^m(cos theta) e^{i m phi}        (about its centre)
// answers each order with the exterior potential
//   phi_ind = sum_lm E_lm r^-(l+1) P_l^m e^{i m phi},   E_lm = -gamma_l R^(2l+1) I_lm,
//   gamma_l = l (mu - 1) / (l mu + l + 1).
// The cell's dipole (l = 1) is what the relaxation solves, with saturation;
// l = 1 of the applied potential is the field at the centre, so the dipole is
// right. Missing are the orders l >= 2. For a pair of cells a, b (b at
// distance d along +z from a) with dipoles p_a, p_b these are linear in the
// dipoles; in the pair's frame they split into the axial sector m = 0 and the
// transverse sector m = 1 (a dipole's potential has no other m). Exterior
// harmonics about a become interior ones about b by the addition theorem
// (Ferrers functions without the Condon-Shortley phase):
//   r_a^-(l+1) P_l^m = sum_l' (-1)^(l'+m) (l+l')! / ((l-m)! (l'+m)!) r_b^l' P_l'^m / d^(l+l'+1),
// and from b to a the sign is (-1)^(l+m). With the scaled coefficients
// e = E / R^(l+1) and i = I R^l (d = 1) the two-centre problem is
//   e_b[l] = -gamma_b,l sum_k A_ab[k][l] e_a[k],  A_ab = (-1)^(l+m) C(k, l) r_a^(k+1) r_b^l,
// (likewise e_a), for l = 2..L, with e[1] = p / (4 pi R^2) given. Its
// solution gives the extra field at each centre, H = -I_1 (the l = 1 interior
// coefficient of the partner's higher orders), linear in the dipoles:
//   H_a = K_aa p_a + K_ab p_b,   H_b = K_ab p_a + K_bb p_b,
//   K_xy = k_par,xy(d) u u^T + k_perp,xy(d) (I - u u^T)   (u = (x_b - x_a) / d),
// symmetric by reciprocity. Eliminating the higher orders (linear, so exactly)
// leaves the pair energy W = -mu0/2 sum_xy p_x . K_xy p_y: its derivative in
// the dipoles is the extra field the relaxation adds to H_A, its gradient in
// the positions (dipoles fixed; they are stationary) the extra force, and
// mu0 p x H the extra torque. For a rigid partner (a permanent magnet or any
// non-spherical cell, which the dense sums treat as a point dipole) gamma = 0
// and W is the exact energy of a sphere next to a point dipole.
//
// The six k(d) d^3, functions of x = d / (R_a + R_b) only for a given pair
// type (radius ratio, susceptibilities), are tabulated once per pair type on
// knots clustered at contact and interpolated by natural cubic splines, so
// forces are the exact derivative of the interpolated energy.
//
// Range: full correction up to x = 3 (a gap of 4 R between equal spheres),
// smoothly tapered to 0 at x = 4; below contact (overlapping cells) each
// coefficient fades to 0 within 0.1 (R_a + R_b) by a cubic matching its value
// and slope at contact, so forces stay finite and continuous through contact
// and deeply overlapping high-chi balls stay stable.
//
// Saturation: a saturated sphere is uniformly magnetized, exactly a dipole,
// and real iron saturates first at the contact point. The table also holds
// the higher orders' magnetization at each contact point; where it would take
// the contact point past Ms the pair's correction is scaled down so that it
// stays at Ms (saturation_factor): the linear value while the contact is
// unsaturated, nothing once the sphere is. A heuristic between two exact
// limits (docs/model.md); forces take it as fixed (no gradient of the factor).
//
// Carried-over pairs: a pair's K with its first two derivatives in d, and
// the contact coefficients with their slope, are kept from build to build;
// while its centre distance stays within kReuseTolerance min(d0 - (R_a +
// R_b), R_a + R_b) of the distance d0 where they were evaluated, K is carried
// to second order, K(d) = K(d0) + K'(d0) (d - d0) + K''(d0) (d - d0)^2 / 2,
// dK/dd to first, the contact coefficients to first, and the direction u is
// the new one. The functions vary on the scale of the gap d - (R_a + R_b)
// near contact (they grow like its logarithm for high chi) and of R_a + R_b
// beyond, so the fields are off by O(kReuseTolerance^3) and the forces by
// O(kReuseTolerance^2) of the correction (docs/model.md "Carried-over
// pairs"); overlapping pairs are evaluated every time. Balls resting in a
// heap, hanging together, or pushed about by a moving body mostly change
// their distances by less than that between substeps.
//
// The pair list: the pairs within (kCutoff + kListMargin) (R_a + R_b) are
// found by testing every pair of spheres, and kept until a sphere has moved
// kListMargin R_min from where it was then (no pair outside the list can
// have come within the cutoff before); meanwhile each build updates the
// listed pairs in place, those in the margin with no correction.
//
// Pairs, not clusters: the higher orders of a sphere excited by two
// neighbours are the sum of the two pairs' (linear), but the cross terms
// between neighbours through a third sphere's higher orders are neglected.
#include <Eigen/Dense>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <map>
#include <memory>
#include <mutex>
#include <tuple>
#include <variant>

#include "odemag/constants.h"
#include "magnetics/near_field/near_field.h"

namespace odemag {

namespace {

constexpr int kOrders = 48;             // L, highest multipole order of the two-centre solve
constexpr double kTaperStart = 3.0;     // x = d / (R_a + R_b) where the taper begins
constexpr double kCutoff = 4.0;         // x beyond which a pair has no correction
constexpr double kInsideFade = 0.1;     // overlap (of R_a + R_b) over which K fades to 0
constexpr int kKnots = 160;             // spline knots on [1, kCutoff]
// A pair's coefficients are carried over from its last evaluation at d0
// while |d - d0| <= kReuseTolerance min(d0 - (R_a + R_b), R_a + R_b) (SphereNearField::build).
constexpr double kReuseTolerance = 1e-2;
// The pair list holds the pairs within (kCutoff + kListMargin) (R_a + R_b)
// and is made anew once a sphere has moved kListMargin R_min.
constexpr double kListMargin = 0.2;

// The susceptibility of a sphere without induced higher orders (a rigid
// magnet, a one-cell box or cylinder); linear spheres have chi >= -1 (below 0:
// diamagnets, whose gamma_l are negative).
constexpr double kRigid = -std::numeric_limits<double>::infinity();
bool rigid(double chi) { return chi == kRigid; }

// gamma_l of a linear sphere; chi = infinity gives 1.
double multipole_factor(int l, double chi) {
  if (std::isinf(chi)) return 1.0;
  return l * chi / (l * chi + 2.0 * l + 1.0);
}

// The reaction coefficients k d^3 of one pair at one distance:
// [sector][aa, ab, bb], sector 0 axial, 1 transverse, and the axial
// magnetization of the higher orders at each sphere's contact point (the
// point of its surface on the line of centres, facing the partner) per unit
// axial dipole, times d^3: [a from p_a, a from p_b, b from p_a, b from p_b].
struct Reaction {
  std::array<std::array<double, 3>, 2> k{};
  std::array<double, 4> contact{};
};

// What the table of a pair type depends on: R_a / (R_a + R_b) and the two
// susceptibilities (negative: rigid, no higher orders).
struct PairType {
  double radius_share;
  double chi_a, chi_b;
  bool operator<(const PairType& o) const {
    return std::tie(radius_share, chi_a, chi_b) < std::tie(o.radius_share, o.chi_a, o.chi_b);
  }
};

// The two-centre solve at x = d / (R_a + R_b) (d = 1 units: r_a, r_b < 1).
Reaction solve_pair(const PairType& type, double x) {
  const double ra = type.radius_share / x, rb = (1.0 - type.radius_share) / x;
  const int L = kOrders, n = L - 1;  // unknown orders 2..L per sphere
  std::vector<double> log_factorial(2 * L + 2);
  for (int i = 0; i < 2 * L + 2; ++i) log_factorial[i] = std::lgamma(i + 1.0);
  const double log_ra = std::log(ra), log_rb = std::log(rb);
  Reaction out{};
  for (int m = 0; m < 2; ++m) {
    // A_ab(k, l): e_a[k] -> i_b[l] = (-1)^(l+m) (k+l)! / ((k-m)! (l+m)!) r_a^(k+1) r_b^l;
    // A_ba(k, l) likewise with the radii swapped and the sign (-1)^(k+m).
    Eigen::MatrixXd A_ab_table(L + 1, L + 1), A_ba_table(L + 1, L + 1);
    for (int k = 1; k <= L; ++k)
      for (int l = 1; l <= L; ++l) {
        const double c = log_factorial[k + l] - log_factorial[k - m] - log_factorial[l + m];
        A_ab_table(k, l) = ((l + m) % 2 ? -1.0 : 1.0) * std::exp(c + (k + 1) * log_ra + l * log_rb);
        A_ba_table(k, l) = ((k + m) % 2 ? -1.0 : 1.0) * std::exp(c + (k + 1) * log_rb + l * log_ra);
      }
    auto A_ab = [&](int k, int l) { return A_ab_table(k, l); };
    auto A_ba = [&](int k, int l) { return A_ba_table(k, l); };
    std::vector<double> ga(L + 1, 0.0), gb(L + 1, 0.0);
    for (int l = 2; l <= L; ++l) {
      ga[l] = rigid(type.chi_a) ? 0.0 : multipole_factor(l, type.chi_a);
      gb[l] = rigid(type.chi_b) ? 0.0 : multipole_factor(l, type.chi_b);
    }
    // Unknowns [e_a[2..L], e_b[2..L]]; rows: e + gamma sum A e_partner = -gamma A e_partner[1].
    Eigen::MatrixXd S = Eigen::MatrixXd::Identity(2 * n, 2 * n);
    Eigen::MatrixXd rhs = Eigen::MatrixXd::Zero(2 * n, 2);  // columns: p_a = 1, p_b = 1
    const double ea1 = 1.0 / (4.0 * kPi * ra * ra), eb1 = 1.0 / (4.0 * kPi * rb * rb);
    for (int l = 2; l <= L; ++l) {
      for (int k = 2; k <= L; ++k) {
        S(n + l - 2, k - 2) += gb[l] * A_ab(k, l);
        S(l - 2, n + k - 2) += ga[l] * A_ba(k, l);
      }
      rhs(n + l - 2, 0) = -gb[l] * A_ab(1, l) * ea1;
      rhs(l - 2, 1) = -ga[l] * A_ba(1, l) * eb1;
    }
    const Eigen::MatrixXd e = S.partialPivLu().solve(rhs);
    if (m == 0) {
      // Inside a linear sphere c_l = I_l (1 - gamma_l); on the axis at the
      // contact point z = +-R, H_z = -sum_l l c_l (+-R)^(l-1), M = chi H.
      // chi (1 - gamma_l) = chi (2l + 1) / (l chi + 2l + 1), finite for chi = inf.
      auto chi_rest = [](int l, double chi) {
        if (rigid(chi)) return 0.0;
        return std::isinf(chi) ? (2.0 * l + 1.0) / l : chi * (2.0 * l + 1.0) / (l * chi + 2.0 * l + 1.0);
      };
      for (int col = 0; col < 2; ++col) {
        // Scaled interior coefficients i[l] at each centre from the partner's
        // dipole and higher orders (i = I R^l, d = 1).
        double Ma = 0.0, Mb = 0.0;
        for (int l = 2; l <= L; ++l) {
          double ia = A_ba(1, l) * (col == 1 ? eb1 : 0.0), ib = A_ab(1, l) * (col == 0 ? ea1 : 0.0);
          for (int k = 2; k <= L; ++k) ia += A_ba(k, l) * e(n + k - 2, col), ib += A_ab(k, l) * e(k - 2, col);
          // a's contact point at z = +R_a, b's at z = -R_b (sign (-1)^(l-1)).
          Ma -= chi_rest(l, type.chi_a) * l * ia / ra;
          Mb -= chi_rest(l, type.chi_b) * l * ib * ((l - 1) % 2 ? -1.0 : 1.0) / rb;
        }
        out.contact[col] = Ma;
        out.contact[2 + col] = Mb;
      }
    }
    // H at b from a's higher orders: -i_b[1] / r_b; at a from b's: -i_a[1] / r_a.
    for (int col = 0; col < 2; ++col) {
      double Hb = 0.0, Ha = 0.0;
      for (int k = 2; k <= L; ++k) {
        Hb -= A_ab(k, 1) * e(k - 2, col) / rb;
        Ha -= A_ba(k, 1) * e(n + k - 2, col) / ra;
      }
      if (col == 0) {
        out.k[m][0] = Ha;  // aa
        out.k[m][1] = Hb;  // ab (= ba)
      } else {
        out.k[m][2] = Hb;  // bb
      }
    }
  }
  return out;
}

// Natural cubic spline through (x_i, y_i) on a non-uniform grid: its second
// derivatives y2 at the knots.
std::vector<double> spline_second_derivatives(const std::vector<double>& x, const std::vector<double>& y) {
  const int n = static_cast<int>(x.size());
  std::vector<double> y2(n, 0.0), u(n, 0.0);
  for (int i = 1; i < n - 1; ++i) {
    const double sig = (x[i] - x[i - 1]) / (x[i + 1] - x[i - 1]);
    const double p = sig * y2[i - 1] + 2.0;
    y2[i] = (sig - 1.0) / p;
    const double slope = (y[i + 1] - y[i]) / (x[i + 1] - x[i]) - (y[i] - y[i - 1]) / (x[i] - x[i - 1]);
    u[i] = (6.0 * slope / (x[i + 1] - x[i - 1]) - sig * u[i - 1]) / p;
  }
  for (int i = n - 2; i >= 0; --i) y2[i] = y2[i] * y2[i + 1] + u[i];
  return y2;
}

class PairTable {
 public:
  // The tabulated series: the six k d^3 ([sector][aa, ab, bb]), then the four
  // contact coefficients (Reaction), all on the same knots.
  static constexpr int kSeries = 10;

  explicit PairTable(const PairType& type) : x_(kKnots), y_(kKnots * kSeries), y2_(kKnots * kSeries) {
    std::vector<std::vector<double>> series(kSeries, std::vector<double>(kKnots));
    for (int i = 0; i < kKnots; ++i) {
      x_[i] = knot(i);
      const Reaction r = solve_pair(type, x_[i]);
      for (int s = 0; s < 6; ++s) series[s][i] = r.k[s / 3][s % 3];
      for (int s = 0; s < 4; ++s) series[6 + s][i] = r.contact[s];
    }
    for (int s = 0; s < kSeries; ++s) {
      const std::vector<double> y2 = spline_second_derivatives(x_, series[s]);
      for (int i = 0; i < kKnots; ++i) {
        y_[i * kSeries + s] = series[s][i];
        y2_[i * kSeries + s] = y2[i];
      }
    }
  }

  // Contact-point magnetization coefficients (1/m^3) at centre distance d:
  // M_hi along u at a = c[0] (u.p_a) + c[1] (u.p_b), at b = c[2] (u.p_a) +
  // c[3] (u.p_b); dc their slope in d (1/m^4, 0 where d / reach is clamped).
  void contact(double d, double reach, double c[4], double dc[4]) const {
    const double x = std::clamp(d / reach, 1.0, kCutoff), xr = x * reach, inv_d3 = 1.0 / (xr * xr * xr);
    const bool clamped = x != d / reach;
    const Weights w = weights(x);
    for (int s = 0; s < 4; ++s) {
      double v, slope, curvature;
      series_at(w, 6 + s, v, slope, curvature);
      c[s] = v * inv_d3;
      dc[s] = clamped ? 0.0 : slope * inv_d3 / reach - 3.0 * c[s] / xr;
    }
  }
  // K (1/m^3), dK/dd (1/m^4) and d2K/dd2 (1/m^5) at centre distance d of a
  // pair with reach = R_a + R_b: k d^3 from the splines with the taper; zero
  // beyond the cutoff and deep inside contact (the fade below contact has
  // d2K = 0: overlapping pairs are not carried over).
  void eval(double d, double reach, double K[6], double dK[6], double d2K[6]) const {
    const double x = d / reach;
    std::fill(d2K, d2K + 6, 0.0);
    if (x >= kCutoff) {
      std::fill(K, K + 6, 0.0), std::fill(dK, dK + 6, 0.0);
      return;
    }
    if (x < 1.0) {
      // Overlapping cells: each K fades to 0 by a cubic Hermite that matches
      // K and dK/dd at contact (forces continuous) over kInsideFade reach:
      // bounded, with a repulsive core, and nothing for deeper overlaps (a
      // constant continuation made overlapping chi = 100 balls unstable).
      double K1[6], dK1[6], unused[6];
      eval(reach, reach, K1, dK1, unused);
      const double h = kInsideFade * reach, t = (d - (reach - h)) / h;
      for (int s = 0; s < 6; ++s) {
        if (t <= 0.0) {
          K[s] = dK[s] = 0.0;
          continue;
        }
        K[s] = K1[s] * t * t * (3.0 - 2.0 * t) + dK1[s] * h * t * t * (t - 1.0);
        dK[s] = (K1[s] * 6.0 * t * (1.0 - t)) / h + dK1[s] * t * (3.0 * t - 2.0);
      }
      return;
    }
    // Taper w(x) = 1 - S(u): 1 below kTaperStart, 0 at kCutoff, C^2
    // (smootherstep S = u^3 (10 - 15 u + 6 u^2), S' = 30 u^2 (1 - u)^2,
    // S'' = 60 u (1 - u) (1 - 2 u)); dw, d2w in x.
    double w = 1.0, dw = 0.0, d2w = 0.0;
    if (x > kTaperStart) {
      const double span = kCutoff - kTaperStart, u = (x - kTaperStart) / span;
      w = 1.0 - u * u * u * (10.0 - 15.0 * u + 6.0 * u * u);
      dw = -30.0 * u * u * (1.0 - u) * (1.0 - u) / span;
      d2w = -60.0 * u * (1.0 - u) * (1.0 - 2.0 * u) / (span * span);
    }
    const double inv_d = 1.0 / d, inv_d3 = inv_d * inv_d * inv_d, inv_reach_d3 = inv_d3 / reach;
    const Weights at = weights(x);
    for (int s = 0; s < 6; ++s) {
      double k, dk, d2k;
      series_at(at, s, k, dk, d2k);
      // K = f / d^3 with f = w k in x = d / reach:
      // K' = f' / (reach d^3) - 3 K / d, K'' = f'' / (reach^2 d^3) - 6 f' / (reach d^4) + 12 K /
      // d^2.
      const double f1 = w * dk + dw * k, f2 = d2w * k + 2.0 * dw * dk + w * d2k;
      K[s] = w * k * inv_d3;
      dK[s] = f1 * inv_reach_d3 - 3.0 * K[s] * inv_d;
      d2K[s] = (f2 * inv_reach_d3 / reach - 6.0 * f1 * inv_reach_d3 * inv_d) +
               12.0 * K[s] * inv_d * inv_d;
    }
  }

 private:
  // Knot i: x = 1 + (kCutoff - 1) t^2, t = i / (kKnots - 1), clustered at contact.
  static double knot(int i) {
    const double t = static_cast<double>(i) / (kKnots - 1);
    return 1.0 + (kCutoff - 1.0) * t * t;
  }
  // Where x in [1, kCutoff] lies among the knots, and the cubic spline's
  // weights there: one search for all the series (they share the knots).
  struct Weights {
    int i = 0;
    double h = 0.0, a = 0.0, b = 0.0;
  };
  Weights weights(double x) const {
    // The knot formula inverted, then a step either way for rounding.
    int i = static_cast<int>(std::sqrt(std::max(0.0, (x - 1.0) / (kCutoff - 1.0))) * (kKnots - 1));
    i = std::clamp(i, 0, kKnots - 2);
    while (i > 0 && x < x_[i]) --i;
    while (i < kKnots - 2 && x >= x_[i + 1]) ++i;
    Weights w;
    w.i = i;
    w.h = x_[i + 1] - x_[i];
    w.a = (x_[i + 1] - x) / w.h;
    w.b = (x - x_[i]) / w.h;
    return w;
  }
  // Series s's value and first two derivatives at the point of w.
  void series_at(const Weights& w, int s, double& value, double& slope, double& curvature) const {
    const double y0 = y_[w.i * kSeries + s], y1 = y_[(w.i + 1) * kSeries + s];
    const double c0 = y2_[w.i * kSeries + s], c1 = y2_[(w.i + 1) * kSeries + s];
    const double a = w.a, b = w.b, h = w.h;
    value = a * y0 + b * y1 + ((a * a * a - a) * c0 + (b * b * b - b) * c1) * h * h / 6.0;
    slope = (y1 - y0) / h + (-(3 * a * a - 1) * c0 + (3 * b * b - 1) * c1) * h / 6.0;
    curvature = a * c0 + b * c1;
  }

  std::vector<double> x_;        // knots
  std::vector<double> y_, y2_;   // per knot, per series: values and second derivatives
};

// One table per pair type, shared by every model of the process.
std::shared_ptr<const PairTable> pair_table(const PairType& type) {
  static std::mutex mutex;
  static std::map<PairType, std::shared_ptr<const PairTable>> tables;
  std::lock_guard<std::mutex> lock(mutex);
  auto& t = tables[type];
  if (!t) t = std::make_shared<const PairTable>(type);
  return t;
}

// How a one-cell body takes part: radius and susceptibility of its higher
// orders (kRigid: none), and what the per-iteration sums read of its body.
struct SphereCell {
  int cell = -1;
  double radius = 0.0;
  double chi = kRigid;
  double volume = 0.0;       // of the cell: the dipole is volume * M
  bool responsive = false;
  bool saturates = false;    // a soft sphere: saturation_factor limits it at Ms
  double Ms = 0.0;
  int type = 0;              // index of its (radius, chi) among the spheres'
  bool multipoles() const { return !rigid(chi); }
};

// A pair's data in three parts, side by side in three arrays, index for
// index: what every field sum reads (add_field runs at every outer iteration
// over tens of thousands of pairs, and reading only this part halves the
// bytes it streams); what the forces read besides; and the last evaluation,
// the only part a new pair list carries over (align_last_build copies it
// alone; the other two are set anew by every build).
struct SpherePair {
  int sa = -1, sb = -1;              // the SphereCells
  Vec3 u;                            // (x_b - x_a) / d
  double k[6] = {};                  // K entries, 1/m^3: [par aa, ab, bb, perp aa, ab, bb]
  double contact[4] = {};            // PairTable::contact
};
struct SpherePairSlope {
  double d = 0.0;
  double dk[6] = {};  // dK/dd at d, 1/m^4
};
// The last evaluation, at d0 (SphereNearField::build carries from it).
struct SpherePairEvaluation {
  int a = -1, b = -1;  // cells (the key: stable from build to build)
  bool evaluated = false;
  double d0 = 0.0;
  double k0[6] = {}, dk0[6] = {}, d2k0[6] = {};  // K, dK/dd, d2K/dd2 at d0
  double contact0[4] = {}, dcontact0[4] = {};    // PairTable::contact at d0
};

// A close pair found by the scan: the two SphereCells (cells_ indices).
struct ClosePair {
  int sa, sb;
};

// Each sphere's dipole p = V M and room below saturation max(0, Ms - |M|) at
// the current magnetizations: computed once per sum, read by every pair.
struct SphereMoments {
  std::vector<Vec3> dipole;
  std::vector<double> room;
};

class SphereNearField final : public NearFieldTerm {
 public:
  void build(const MagneticModel& model, const MagneticState& state) override {
    cells_.clear();
    std::map<std::pair<double, double>, int> types;  // (radius, chi) -> type
    for (int bi = 0; bi < model.body_count(); ++bi) {
      const MagneticBody& body = model.body(bi);
      if (body.inert() || !state.active[bi] || body.cell_count() != 1 || body.cells.spacing > 0.0) continue;
      SphereCell s;
      s.cell = body.first_cell;
      s.radius = body.cells.contact_radius;
      const bool sphere = std::holds_alternative<Sphere>(body.shape);
      if (sphere) {
        // A B-H curve: its initial susceptibility (docs/model.md "B-H curves").
        if (body.kind == CellKind::soft)
          s.chi = body.bh_curve.empty() ? std::get<SoftMaterial>(body.material).susceptibility
                                        : body.bh_curve.initial_susceptibility();
        if (body.kind == CellKind::recoil_permanent) s.chi = body.recoil;
      }
      s.volume = body.cells.cell_volume;
      s.responsive = body.responsive();
      s.saturates = sphere && body.kind == CellKind::soft;
      s.Ms = body.soft.Ms;
      s.type = types.emplace(std::make_pair(s.radius, s.chi), static_cast<int>(types.size())).first->second;
      cells_.push_back(s);
    }
    if (model.generation() != generation_) {  // another model: nothing to carry over
      pairs_.clear();
      slopes_.clear();
      evaluations_.clear();
    }
    generation_ = model.generation();
    const int n = static_cast<int>(cells_.size());
    centre_.resize(n);
    for (int i = 0; i < n; ++i) centre_[i] = state.cell_position[cells_[i].cell];
    if (!pair_list_holds()) {
      make_pair_list();
      align_last_build();
    }
    update_pairs();
  }

  void add_field(const MagneticModel& model, const MagneticState& state, NearFieldSources sources,
                 std::vector<Vec3>& H) const override {
    (void)model;
    const SphereMoments& m = moments(state);
    const bool responsive_sources = sources == NearFieldSources::responsive;
    // The pairs of two held cells, whose fields nothing reads, were left out
    // of field_pairs_ at the build; once the held cells are cleared
    // (NearFieldTerm::set_held_cells) every corrected pair counts.
    const bool any_held = held_cells_ && !held_cells_->empty();
    for (const int q : any_held ? field_pairs_ : corrected_) {
      const SpherePair& p = pairs_[q];
      const SphereCell &ca = cells_[p.sa], &cb = cells_[p.sb];
      const double sigma = saturation_factor(m, p);
      const Vec3 za = ca.responsive == responsive_sources ? m.dipole[p.sa] : Vec3{};
      const Vec3 zb = cb.responsive == responsive_sources ? m.dipole[p.sb] : Vec3{};
      Vec3 Ha, Hb;
      apply(p, za, zb, Ha, Hb);
      if (ca.responsive) H[ca.cell] += sigma * Ha;
      if (cb.responsive) H[cb.cell] += sigma * Hb;
    }
  }

  void add_forces(const MagneticModel& model, const MagneticState& state, std::vector<Vec3>& force,
                  std::vector<Vec3>& field) const override {
    (void)model;
    const SphereMoments& m = moments(state);
    for (const int q : corrected_) {
      const SpherePair& p = pairs_[q];
      const SpherePairSlope& ps = slopes_[q];
      const int a = cells_[p.sa].cell, b = cells_[p.sb].cell;
      const double sigma = saturation_factor(m, p);
      const Vec3 &pa = m.dipole[p.sa], &pb = m.dipole[p.sb];
      // F_b = +mu0/2 sigma grad_r (sum_xy p_x . K_xy p_y), F_a = -F_b.
      const Vec3 g = gradient(p, ps, 0, pa, pa) + 2.0 * gradient(p, ps, 1, pa, pb) + gradient(p, ps, 2, pb, pb);
      const Vec3 Fb = 0.5 * kMu0 * sigma * g;
      force[b] += Fb;
      force[a] -= Fb;
      Vec3 Ha, Hb;
      apply(p, pa, pb, Ha, Hb);
      field[a] += sigma * Ha;
      field[b] += sigma * Hb;
    }
  }

  double energy(const MagneticModel& model, const MagneticState& state) const override {
    (void)model;
    const SphereMoments& m = moments(state);
    double e = 0.0;
    for (const int q : corrected_) {
      const SpherePair& p = pairs_[q];
      const double sigma = saturation_factor(m, p);
      const Vec3 &pa = m.dipole[p.sa], &pb = m.dipole[p.sb];
      Vec3 Ha, Hb;
      apply(p, pa, pb, Ha, Hb);
      e -= 0.5 * kMu0 * sigma * (dot(pa, Ha) + dot(pb, Hb));
    }
    return e;
  }

  int pair_count() const override { return static_cast<int>(pairs_.size()); }

 private:
  // Every listed pair at the current centres: carried over from its last
  // evaluation, or evaluated afresh (header comment); corrected_ and
  // field_pairs_ made.
  void update_pairs() {
    corrected_.clear();
    field_pairs_.clear();
    std::map<std::pair<int, int>, std::shared_ptr<const PairTable>> tables;  // by (type a, type b)
    std::pair<int, int> last_types{-1, -1};
    const PairTable* table = nullptr;
    for (std::size_t q = 0; q < pairs_.size(); ++q) {
      SpherePair& p = pairs_[q];
      SpherePairSlope& ps = slopes_[q];
      SpherePairEvaluation& e = evaluations_[q];
      const SphereCell &ca = cells_[p.sa], &cb = cells_[p.sb];
      const Vec3 r = centre_[p.sb] - centre_[p.sa];
      const double d2 = dot(r, r), reach = ca.radius + cb.radius;
      if (d2 >= kCutoff * kCutoff * reach * reach) {  // in the list's margin: no correction
        e.evaluated = false;
        continue;
      }
      const double d = std::sqrt(d2);
      // Carried over from the last evaluation, if close enough (header comment).
      const double delta = d - e.d0;
      const bool carried = e.evaluated && e.d0 > reach &&
                           std::fabs(delta) <= kReuseTolerance * std::min(e.d0 - reach, reach);
      corrected_.push_back(static_cast<int>(q));
      if (!both_held(ca.cell, cb.cell)) field_pairs_.push_back(static_cast<int>(q));
      // Coincident centres: any axis (the functions are constant there).
      p.u = d > 0.0 ? r / d : Vec3{0.0, 0.0, 1.0};
      ps.d = d;
      if (carried) {
        for (int s = 0; s < 6; ++s) {
          p.k[s] = e.k0[s] + delta * (e.dk0[s] + 0.5 * delta * e.d2k0[s]);
          ps.dk[s] = e.dk0[s] + delta * e.d2k0[s];
        }
        for (int s = 0; s < 4; ++s) p.contact[s] = e.contact0[s] + delta * e.dcontact0[s];
        continue;
      }
      if (ca.type != last_types.first ||
          cb.type != last_types.second) {  // most pairs repeat the last type
        last_types = {ca.type, cb.type};
        auto& t = tables[last_types];
        if (!t) t = pair_table({ca.radius / reach, ca.chi, cb.chi});
        table = t.get();
      }
      e.evaluated = true;
      e.d0 = d;
      table->eval(d, reach, e.k0, e.dk0, e.d2k0);
      table->contact(d, reach, e.contact0, e.dcontact0);
      std::copy(e.k0, e.k0 + 6, p.k);
      std::copy(e.dk0, e.dk0 + 6, ps.dk);
      std::copy(e.contact0, e.contact0 + 4, p.contact);
    }
  }

  // Whether the pair list still holds every pair within the cutoff: the same
  // spheres, and none has moved more than kListMargin R_min from where it
  // was at the list's making (a pair's distance then changed by at most
  // kListMargin (R_a + R_b)). The list then stays, its pairs updated in place.
  bool pair_list_holds() const {
    if (list_generation_ != generation_ || list_mutual_induction_ != mutual_induction_ ||
        list_cells_.size() != cells_.size())
      return false;
    double smallest_radius = std::numeric_limits<double>::infinity(), largest_move2 = 0.0;
    for (std::size_t i = 0; i < cells_.size(); ++i) {
      const SphereCell &c = cells_[i], &l = list_cells_[i];
      if (c.cell != l.cell || c.radius != l.radius || c.chi != l.chi ||
          c.responsive != l.responsive)
        return false;
      smallest_radius = std::min(smallest_radius, c.radius);
      const Vec3 move = centre_[i] - list_centre_[i];
      largest_move2 = std::max(largest_move2, dot(move, move));
    }
    return largest_move2 <= kListMargin * kListMargin * smallest_radius * smallest_radius;
  }
  // close_: every pair within (kCutoff + kListMargin) (R_a + R_b) that can
  // carry a correction, in (a, b) order; every pair of spheres tested (a
  // heap is compact: buckets of the cutoff's width would hold most of it,
  // so they would prune little; and the list is made only every few steps).
  void make_pair_list() {
    list_generation_ = generation_;
    list_mutual_induction_ = mutual_induction_;
    list_cells_ = cells_;
    list_centre_ = centre_;
    const int n = static_cast<int>(cells_.size());
    const double range = kCutoff + kListMargin;
    close_.clear();
    for (int i = 0; i < n; ++i) {
      const Vec3 xa = centre_[i];
      const SphereCell& ca = cells_[i];
      for (int j = i + 1; j < n; ++j) {
        const Vec3 r = centre_[j] - xa;
        const SphereCell& cb = cells_[j];
        const double reach = ca.radius + cb.radius;
        if (dot(r, r) >= range * range * reach * reach) continue;
        if (!ca.multipoles() && !cb.multipoles()) continue;
        // Without mutual induction only fixed magnets induce (one partner fixed).
        if (!mutual_induction_ && ca.responsive && cb.responsive) continue;
        close_.push_back({i, j});
      }
    }
  }
  // pairs_, slopes_ and evaluations_ sized to close_, the list's sphere
  // indices set (they stay while the list does), each evaluation the last
  // build's of the same two cells (keys in the same order: one merge pass),
  // or none. Only the evaluations are copied, each entry written once (a
  // 1000-ball heap lists about 100,000 pairs and makes its list anew every
  // few builds); the other two parts are set by the build.
  void align_last_build() {
    const std::size_t n = close_.size();
    previous_evaluations_.swap(evaluations_);
    reserve_with_headroom(evaluations_, n);
    reserve_with_headroom(pairs_, n);
    reserve_with_headroom(slopes_, n);
    evaluations_.resize(n);
    pairs_.resize(n);
    slopes_.resize(n);
    std::size_t next = 0;
    for (std::size_t q = 0; q < n; ++q) {
      const std::pair<int, int> key{cells_[close_[q].sa].cell, cells_[close_[q].sb].cell};
      while (next < previous_evaluations_.size() &&
             std::make_pair(previous_evaluations_[next].a, previous_evaluations_[next].b) < key)
        ++next;
      if (next < previous_evaluations_.size() &&
          std::make_pair(previous_evaluations_[next].a, previous_evaluations_[next].b) == key)
        evaluations_[q] = previous_evaluations_[next];
      else
        evaluations_[q] = SpherePairEvaluation{key.first, key.second};
      pairs_[q].sa = close_[q].sa, pairs_[q].sb = close_[q].sb;
    }
  }
  // A list that grows by a few pairs should not reallocate (and fault in its
  // pages anew) at every making.
  template <typename T>
  static void reserve_with_headroom(std::vector<T>& v, std::size_t n) {
    if (v.capacity() < n) v.reserve(n + n / 4);
  }

  const SphereMoments& moments(const MagneticState& state) const {
    const size_t n = cells_.size();
    moments_.dipole.resize(n);
    moments_.room.resize(n);
    for (size_t i = 0; i < n; ++i) {
      const SphereCell& c = cells_[i];
      const Vec3& M = state.magnetization[c.cell];
      moments_.dipole[i] = c.volume * M;
      moments_.room[i] = c.saturates ? std::max(0.0, c.Ms - norm(M)) : 0.0;
    }
    return moments_;
  }
  // The pair's fields from dipoles pa, pb: H_a = K_aa pa + K_ab pb and
  // H_b = K_ab pa + K_bb pb, each K_xy v = perp v + (par - perp)(u . v) u.
  static void apply(const SpherePair& p, const Vec3& pa, const Vec3& pb, Vec3& Ha, Vec3& Hb) {
    const double ua = dot(p.u, pa), ub = dot(p.u, pb);
    const double d_aa = p.k[0] - p.k[3], d_ab = p.k[1] - p.k[4], d_bb = p.k[2] - p.k[5];
    Ha = p.k[3] * pa + p.k[4] * pb + (d_aa * ua + d_ab * ub) * p.u;
    Hb = p.k[4] * pa + p.k[5] * pb + (d_ab * ua + d_bb * ub) * p.u;
  }
  // grad_r of s . K_xy(r) t, r = x_b - x_a.
  static Vec3 gradient(const SpherePair& p, const SpherePairSlope& ps, int xy, const Vec3& s, const Vec3& t) {
    const double dpar = ps.dk[xy], dperp = ps.dk[3 + xy], delta = p.k[xy] - p.k[3 + xy];
    const double us = dot(p.u, s), ut = dot(p.u, t);
    Vec3 g = (dperp * dot(s, t) + (dpar - dperp) * us * ut) * p.u;
    if (ps.d > 0.0) g += (delta / ps.d) * ((s - us * p.u) * ut + us * (t - ut * p.u));
    return g;
  }
  // Local saturation at the contact points: the linear higher orders would
  // add M_hi (along u) to a soft sphere's magnetization M at its contact
  // point; where |M| + |M_hi| would pass Ms they are scaled by
  // sigma = (Ms - |M|) / |M_hi|, the smallest over the pair's soft spheres.
  double saturation_factor(const SphereMoments& m, const SpherePair& p) const {
    const double ua = dot(p.u, m.dipole[p.sa]), ub = dot(p.u, m.dipole[p.sb]);
    double sigma = 1.0;
    for (int side = 0; side < 2; ++side) {
      const int s = side == 0 ? p.sa : p.sb;
      if (!cells_[s].saturates) continue;
      const double M_hi = std::fabs(p.contact[2 * side] * ua + p.contact[2 * side + 1] * ub);
      const double room = m.room[s];
      if (M_hi > room) sigma = std::min(sigma, room / M_hi);
    }
    return sigma;
  }

  std::vector<SphereCell> cells_;
  std::vector<SpherePair> pairs_;
  std::vector<SpherePairSlope> slopes_;            // beside pairs_, index for index
  std::vector<SpherePairEvaluation> evaluations_;  // likewise
  // The pairs that carry a correction at this build, in list order (not in
  // the margin, nor two spheres whose forces are kept): what the sums walk.
  std::vector<int> corrected_;
  // Those of them that add_field walks while cells are held: not two held cells.
  std::vector<int> field_pairs_;
  // The pair list (make_pair_list) and what it was made from.
  std::vector<ClosePair> close_;
  std::vector<SphereCell> list_cells_;
  std::vector<Vec3> list_centre_;
  uint64_t list_generation_ = 0;
  bool list_mutual_induction_ = true;
  std::vector<SpherePairEvaluation> previous_evaluations_;  // scratch of align_last_build
  std::vector<Vec3> centre_;          // scratch of build: the spheres' centres
  uint64_t generation_ = 0;           // the model whose pairs pairs_ holds
  mutable SphereMoments moments_;  // scratch of the sums (the backends call them from one thread)
};

}  // namespace

std::unique_ptr<NearFieldTerm> make_sphere_near_field() { return std::make_unique<SphereNearField>(); }

}  // namespace odemag
