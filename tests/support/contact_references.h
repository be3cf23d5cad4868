// Independent references for magnetic contact forces: linear (soft) spheres
// near a point dipole and near each other, coaxial cylinder magnets, and the
// magnetometric demagnetizing factor of a soft cube. Written from the physics
// only: nothing here uses odemag's engine code; only the plain value type Vec3
// (include/odemag/vec3.h) and the constants kPi, kMu0 (include/odemag/constants.h) are
// shared. SI units throughout (H, M in A/m, moments in A m^2, forces in N,
// energies in J). Magnetic scalar potential phi with H = -grad phi; the
// potential of a magnetic charge density rho (A/m^2 per m) is
// phi = 1/(4 pi) int rho / |r - r'| dV', the force on charge in a field
// mu0 rho H, and a linear material has M = chi H, mu = 1 + chi.
//
// Notation used in the derivations below (non-Condon-Shortley Legendre
// functions, P_l^m(x) = (1 - x^2)^(m/2) d^m P_l / dx^m, so P_1^1 = sin(theta)):
//   interior (regular) solid harmonics  I_l^m(r) = r^l P_l^m(cos theta) cos(m phi),
//   exterior (decaying) solid harmonics E_l^m(r) = r^-(l+1) P_l^m(cos theta) cos(m phi).
//
// ===========================================================================
// (A) Linear sphere in the field of a point dipole
// ===========================================================================
// Sphere of radius R, permeability mu, at the origin. An applied potential
// r^l Y_lm (any spherical harmonic Y of degree l) is answered by
//   inside  phi = c r^l Y,   outside phi = (r^l + beta R^(2l+1) r^-(l+1)) Y;
// continuity of phi and of mu d(phi)/dr at r = R gives c = 1 + beta and
// mu l c = l - (l + 1) beta, so beta = -gamma_l with
//   gamma_l = l (mu - 1) / (l mu + l + 1)        (gamma_l -> 1 for mu -> inf,
//                                                  gamma_1 = (mu-1)/(mu+2)).
// The Green's function 1/|r - r0| = sum_l r^l / r0^(l+1) P_l(u.u0) (r < r0) is
// therefore answered by the reaction Green's function
//   G_r(r, r0) = -sum_l gamma_l R^(2l+1) (r r0)^-(l+1) P_l(u . u0),
// symmetric in r and r0. A dipole m at r0 has phi0 = (1/4 pi) m . grad_r0
// 1/|r - r0|, so its reaction field at its own position is
//   H_r(r0) = -(1/4 pi) [grad_r grad_r0 G_r](r = r0) m.
// Put r0 = D z^. Along z, (r r0)^-(l+1) differentiates to (l+1)^2 D^-(2l+4).
// Across (r = (x1, 0, D), r0 = (x2, 0, D)), u.u0 = 1 - (x1 - x2)^2 / (2 D^2)
// + ..., r r0 has no x1 x2 term, so d2/dx1 dx2 of P_l(u.u0) at 0 is
// P_l'(1) / D^2 = l (l + 1) / (2 D^2); mixed x z terms vanish by symmetry:
//   H_r = sum_l gamma_l R^(2l+1) / (4 pi D^(2l+4)) [(l+1)^2 m_par + l(l+1)/2 m_perp].
// (l = 1 check: the sphere's induced moment 4 pi R^3 gamma_1 * 2m/(4 pi D^3)
// acts back with 2 p / (4 pi D^3) = 4 gamma_1 R^3 m / (4 pi D^6).)
// The energy of a linear body in the field of fixed sources is
// U = -(mu0/2) int M . H0 dV = -(mu0/2) m . H_r (reciprocity), and the force
// on the body is -grad of U with the sources held fixed. With r = dipole
// position - sphere centre, D = |r|, (l+1)^2 (m.u)^2 + l(l+1)/2 (m^2 - (m.u)^2)
// = A_l (m.u)^2 + B_l m^2, A_l = (l+1)(l+2)/2, B_l = l(l+1)/2:
//   U(r) = -(mu0 / 8 pi) sum_l gamma_l R^(2l+1) [A_l (m.r)^2 r^-(2l+6) + B_l m^2 r^-(2l+4)]
//   F_sphere = -dU/d(centre) = +dU/dr
//     = -(mu0/8 pi) sum_l gamma_l R^(2l+1) [ A_l (2 (m.r) m r^-(2l+6)
//          - (2l+6) (m.r)^2 r^-(2l+8) r) - B_l (2l+4) m^2 r^-(2l+6) r ].
// For m along r this reduces to the known attractive axial force
//   F = mu0 m^2 / (4 pi D^4) sum_l gamma_l (l+1)^2 (l+2) (R/D)^(2l+1)  (towards m).
// The series converge like (R/D)^(2l); they are summed until a term is below
// 1e-17 of the sum.
//
// ===========================================================================
// (B) Two linear spheres in a uniform field: two-centre multipole solution
// ===========================================================================
// Sphere 1 (R1, chi1) at the origin, sphere 2 (R2, chi2) at d z^ (local frame:
// z along the line of centres, x along the transverse part of H0). The
// applied potential -H0 . r splits into the sectors m = 0 (-H_z z = -H_z I_1^0)
// and m = 1 (-H_x x = -H_x I_1^1); each sector is solved alone (the geometry
// is axisymmetric, so m is conserved). In sector m the field of sphere i
// outside itself is sum_{l>=1} A_l^(i) E_l^m(r - centre_i), and the regular
// part of the potential around centre i (applied field plus the other
// sphere) is sum_l c_l^(i) I_l^m(r - centre_i). Each sphere answers its
// regular field as in (A): A_l^(i) = -gamma_l^(i) R_i^(2l+1) c_l^(i).
//
// Addition theorem (coaxial translation). From E_n^0 = (-1)^n/n! d^n/dz^n (1/r)
// and 1/|r - d z^| = sum_l I_l^0(r) / d^(l+1) (r < d, d > 0), using
// d/dz f(r - d z^) = -d/dd f:
//   E_n^0(r - d z^) = (-1)^n sum_{l>=0} (l+n)!/(l! n!) I_l^0(r) / d^(l+n+1).
// With d/dx E_n^0 = -E_{n+1}^1 and d/dx I_l^0 = -I_{l-1}^1 (both checked on
// explicit polynomials, e.g. d/dx (1/r) = -x/r^3 = -E_1^1, d/dx (r^2 P_2) = -x
// = -I_1^1), the general coaxial result for m = 0, 1 is
//   E_n^m(r - d z^) = (-1)^(n+m) sum_{l>=m} (l+n)! / ((l+m)! (n-m)!) I_l^m(r) / d^(l+n+1),
// and, by the reflection z -> -z (E_n^m, I_l^m pick up (-1)^(n+m), (-1)^(l+m)),
//   E_n^m(r + d z^) = sum_{l>=m} (-1)^(l+m) (l+n)! / ((l+m)! (n-m)!) I_l^m(r) / d^(l+n+1).
// (The test file checks both by evaluating the two sides at sample points.)
// So, with C(l, n) = (l+n)! / ((l+m)! (n-m)!),
//   c_l^(1) = c0_l + sum_n (-1)^(n+m) C(l,n) d^-(l+n+1) A_n^(2),
//   c_l^(2) = c0_l + sum_n (-1)^(l+m) C(l,n) d^-(l+n+1) A_n^(1),
// c0_l = -delta_l1 (unit applied field in the sector; the constant -H_z d in
// the expansion about centre 2 is an l = 0 term and has no effect, gamma_0 = 0).
// Scaled unknowns make every coefficient O(1) and prevent overflow:
//   b_l^(i) = c_l^(i) R_i^l,  a_l^(i) = A_l^(i) / R_i^(l+1) = -gamma_l^(i) b_l^(i),
//   b^(1) + M12 G2 b^(2) = b0^(1),   b^(2) + M21 G1 b^(1) = b0^(2),
//   M12(l,n) = (-1)^(n+m) C(l,n) R1^l R2^(n+1) / d^(l+n+1),
//   M21(l,n) = (-1)^(l+m) C(l,n) R2^l R1^(n+1) / d^(l+n+1),
// with C(l,n) (R1/d)^l (R2/d)^n <= ((R1+R2)/d)^(l+n) < 1; the elements are
// formed as exp of lgamma sums in long double. The 2L x 2L system (orders
// l = 1..L in each sphere) is solved by LU in double: a long double solve was
// measured to agree to 12 significant digits at gaps down to 0.01 min(R),
// chi = 1e4 and inf, radius ratios 1/3..3 (and costs 8 times more).
//
// Moments: the l = 1 exterior term is exactly the dipole field of the total
// moment int M dV, phi = m . r / (4 pi r^3), so m_z = 4 pi A_1 (sector 0) and
// m_x = 4 pi A_1 (sector 1, P_1^1 = sin theta).
//
// Force on sphere 2: the Maxwell stress over a surface enclosing sphere 2
// alone equals the force of the regular (external) field on any charge
// distribution rho_2 that reproduces sphere 2's field outside it (the self
// term integrates to zero), F = -mu0 int rho_2 grad(phi_ext) dV, and for point
// multipoles at centre 2: from 1/|r - r'| = sum_l r'^l/r^(l+1) sum_m
// (2 - delta_m0) (l-m)!/(l+m)! P_l^m P_l^m cos(m (phi - phi')),
//   int rho I_l^0 dV = 4 pi A_l (m = 0),  int rho I_l^1 dV = 4 pi A_l l(l+1)/2 (m = 1).
// The derivatives d/dz I_l^m = (l+m) I_{l-1}^m, and for the x-force the m = 0
// part of d/dx I_l^1 = l(l+1)/2 I_{l-1}^0 together with d/dx I_l^0 = -I_{l-1}^1,
// give (c = c^(2), A = A^(2), superscript = sector, unit sector fields)
//   F_z = -4 pi mu0 sum_{l>=2} [ H_z^2 l c_l^0 A_{l-1}^0
//                                 + H_x^2 (l+1) l (l-1)/2 c_l^1 A_{l-1}^1 ]
//   F_x = -4 pi mu0 H_z H_x sum_{l>=2} [ l(l+1)/2 c_l^1 A_{l-1}^0 - l(l-1)/2 c_l^0 A_{l-1}^1 ]
// and c_l A_{l-1} = b_l a_{l-1} in the scaled variables. (Checks: a dipole m_z
// in phi = c_2 (z^2 - rho^2/2) feels mu0 m_z dH_z/dz = -2 mu0 c_2 m_z, the l = 2
// term; the tests also compare with -dW/dd, W = -(mu0/2) H0 . (m1 + m2), the
// energy of linear bodies in the field of fixed sources, and with Newton's
// third law.)
//
// Truncation: the exterior field of sphere i, continued into sphere i, is
// singular only at the limit point of its Kelvin images (for equal spheres the
// bispherical focus, e^-mu0 R from the surface with cosh mu0 = d / (2R)), so
// the scaled coefficients fall like e^(-mu0 l): at a gap of 0.05 R, e^-mu0 =
// 0.80. L is doubled from 20 until the force and the moments change by less
// than 1e-7 (relative), up to L = 640; otherwise NaN is returned.
//
// Second opinion for mu = inf, equal spheres (bispherical coordinates):
//   z = a sinh(mu) / (cosh mu - cos eta), rho = a sin(eta) / (cosh mu - cos eta),
// spheres mu = +-mu0, cosh mu0 = d / (2R), a = R sinh mu0; midplane mu = 0.
// Generating function: 1/sqrt(cosh mu - cos eta) = sqrt2 sum_n e^-(n+1/2)|mu| P_n(cos eta)
// (from sum t^n P_n(x) = (1 - 2xt + t^2)^-1/2, t = e^-|mu|). Differentiating,
//   z / sqrt(C) = 2 sqrt2 a sum_n (n+1/2) sgn(mu) e^-(n+1/2)|mu| P_n(cos eta),
//   x / sqrt(C) = 2 sqrt2 a cos(phi) sum_n e^-(n+1/2)|mu| P_n^1(cos eta),   C = cosh mu - cos eta.
// Axial field (phi odd in z, spheres at potentials +-V, zero net charge):
//   phi = -H z + sqrt(C) sum_n B_n sinh((n+1/2) mu) P_n(cos eta),
//   B_n = sqrt2 e^-(n+1/2)mu0 (V + 2 a H (n+1/2)) / sinh((n+1/2) mu0);
// the charge of sphere 2 is the flux through the midplane, 2 pi sqrt2 a sum B_n
// (int_-1^1 P_n (1-x)^-1/2 dx = 2 sqrt2 / (2n+1)), so sum B_n = 0 fixes V. On
// the midplane H is normal, H_z = H - (1 - x)^(3/2)/a S(x), S = sum (n+1/2) B_n P_n(x),
// x = cos eta, and the stress on the upper half space (the uniform part
// integrates to zero over the closed surface) gives
//   F_z = -(mu0/2) int (H_z^2 - H^2) dA = -pi mu0 int_-1^1 (1 - x) S^2 dx
//       = -pi mu0 [ sum_n (n+1/2) B_n^2 - sum_n (n+1) B_n B_{n+1} ]
// (the term linear in S is the zero charge; the rest by Legendre orthogonality
// and x P_n = ((n+1) P_{n+1} + n P_{n-1}) / (2n+1)).
// Transverse field (phi even in z, spheres at potential 0 by x -> -x):
//   phi = -H x + sqrt(C) cos(phi) sum_{n>=1} B_n cosh((n+1/2) mu) P_n^1(cos eta),
//   B_n = 2 sqrt2 a H e^-(n+1/2)mu0 / cosh((n+1/2) mu0).
// On the midplane H_z = 0 and phi = g(rho) cos(phi), g = -H rho + f(rho),
// f = sqrt(1 - x) sum B_n P_n^1(x); F_z = (mu0/2) int (H_t^2 - H^2) dA
// = (pi mu0 / 2) int (f'^2 + f^2/rho^2) rho drho (the linear term is
// [rho f] = 0 at both ends), and with rho = a cot(eta/2) (a conformal map)
//   F_z = (pi mu0 / 2) int_0^pi [ sin(eta) (df/deta)^2 + f^2 / sin(eta) ] d eta,
// d/deta P_n^1(cos eta) = n(n+1) P_n - x P_n' (Legendre's equation), done by
// Gauss-Kronrod quadrature.
//
// ===========================================================================
// (C) Coaxial uniformly magnetized cylinders
// ===========================================================================
// Each cylinder (radius a, magnetization M along the axis) is equivalent to
// two uniformly charged discs, sigma = +M on the end face its M points to and
// -M on the other. A disc (radius a, charge sigma, at z = 0) has
//   phi = (sigma a / 2) int_0^inf J0(k rho) J1(k a) e^-k|z| dk / k
// (from 1/r = int J0(k rho) e^-k|z| dk and int_disc J0(k |rho - rho'|) dA' =
// 2 pi a J1(k a) J0(k rho) / k), so H_z = (sigma a/2) int J0 J1 e^-kz dk, and
// the force on a second coaxial disc (sigma') at height h > 0 is
//   F = mu0 sigma' int_disc H_z dA = pi mu0 sigma sigma' a^2 I(h),
//   I(h) = int_0^inf J1(k a)^2 e^-kh / k dk     (repulsive for like charges).
// Cylinder 1 on z in [-L1, 0], cylinder 2 on [g, g + L2], M1, M2 along +z:
// the four face pairs (+M1 at 0, -M1 at -L1; -M2 at g, +M2 at g + L2) give
//   F_2 = -pi mu0 M1 M2 a^2 int_0^inf J1(ka)^2 e^-kg (1 - e^-kL1)(1 - e^-kL2) dk / k
// (negative = attraction for parallel M). This combined integral has no
// cancellation; it is integrated (x = ka) between consecutive multiples of
// pi by adaptive Gauss-Kronrod until the tail bound is below 1e-14 of the
// sum: with x J1(x)^2 <= 0.645 < 1 for x >= pi (asymptotically 2/pi; checked
// numerically on [pi, 2000]) and a weight <= c e^-rate x, c <= 2, the tail
// beyond X is below c e^-rate X / (rate X^2). For small gaps (g < 0.1 a) the tail of the e^-kg term decays
// slowly; then I(g) (for which I(0) = int J1^2/k = 1/2) is taken from the
// second route below and only the fast-decaying rest is done as a Bessel
// integral.
// Second route (elliptic): dI/dh = -int J1(ka)^2 e^-kh dk = -Q_{1/2}(1 + h^2/(2a^2)) / (pi a)
// (int_0^inf e^-pt J_nu(at) J_nu(bt) dt = Q_{nu-1/2}((a^2+b^2+p^2)/(2ab)) / (pi sqrt(ab))),
// so I(h) = 1/2 - (1/pi) int_0^(h/a) Q_{1/2}(1 + t^2/2) dt and the cylinder force is
//   F_2 = -mu0 M1 M2 a^2 [ int_g^(g+L1) - int_(g+L2)^(g+L1+L2) ] Q_{1/2}(1 + t^2/(2a^2)) dt / a,
// Q_{1/2}(z) = z k K(k) - (2/k) E(k), k = sqrt(2/(z+1)) (complete elliptic
// integrals, modulus k, by the AGM from k' = t / sqrt(4 + t^2) so that k -> 1
// loses nothing; checked against Q_nu(z) = int_0^inf (z + sqrt(z^2-1)
// cosh u)^-(nu+1) du to 1e-15), and for z > 2, where that difference cancels, the
// hypergeometric series Q_{1/2}(z) = (pi/2) (2z)^-3/2 2F1(5/4, 3/4; 2; 1/z^2).
// The log singularity of Q at t = 0 (touching faces) is integrable and handled
// by the adaptive quadrature.
//
// ===========================================================================
// (D) Magnetometric demagnetizing factor of a linear cube
// ===========================================================================
// Cube [-1/2, 1/2]^3 (the factor is scale free), M = chi H inside, uniform
// applied field H0 z^. div M = 0 inside, so the body is the surface charge
// sigma = M . n. Just inside the surface H . n = H0 . n + K[sigma] - sigma/2,
// K[sigma](r) = p.v. int sigma(r') (r - r') . n(r) / (4 pi |r - r'|^3) dA', and
// sigma = chi H_in . n gives the second-kind equation
//   (1/chi + 1/2) sigma - K[sigma] = H0 . n.
// Piecewise constant sigma on rectangular panels, collocation at the panel
// centres; the normal field of a uniformly charged rectangle is closed form
// (a panel in the plane w = w0 spanning [u1,u2] x [v1,v2], X = u - u', Y = v - v',
// Z = w - w0, R = |(X, Y, Z)|):
//   H_w = (1/4 pi) sum_corners s atan(X Y / (Z R))   (solid angle),
//   H_u = (1/4 pi) [ L(X2) - L(X1) ],  L(X) = log((Y1 + R1)/(Y2 + R2)) = asinh(Y1/rho) - asinh(Y2/rho),
// rho = sqrt(X^2 + Z^2), X1 = u - u1 > X2 = u - u2, Y1 = v - v1 > Y2 = v - v2
// (coplanar panels give no normal field; the self panel's p.v. normal field is 0).
// Symmetry: sigma is even in x and y and odd in z on the top/bottom faces,
// even in the horizontal coordinate and odd in z on the four equal side faces,
// and symmetric under x <-> y on the top face; the reduced unknowns are one
// octant of the top face and one quarter of one side face (about 3 n^2 / 8
// for n panels per edge), which also removes the constant-potential null
// space of the chi = inf operator. The mesh is graded towards the edges,
// where sigma is singular (~ r^-1/3 for chi -> inf, stronger at the corners):
// nodes s_i = (1/2) g(-1 + 2 i / n), g(u) = sgn(u) (1 - (1 - |u|)^4); the
// corner functions (atan, asinh) are evaluated once per mesh node and
// differenced per panel. (Uniform panels converge only like h^0.7 at chi =
// 1000, h^1 at chi = 0; quadratic grading like h^1.2.) The error then follows
// A h^2 + B h^(8/3) closely and is extrapolated (see
// cube_magnetometric_demag_factor_estimates).
// Mean magnetization <M_z> = int sigma z dA / V (moment of the charge), and
// N_m = H0 / <M_z> - 1/chi, computed without cancellation (see code) so that
// chi = 0 (N_m -> 1/3) and chi = inf work.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <limits>
#include <utility>
#include <vector>

#include <Eigen/Dense>

#include "odemag/constants.h"
#include "odemag/vec3.h"

namespace odemag::reference {

// ---------------------------------------------------------------------------
// Numerical utilities
// ---------------------------------------------------------------------------
namespace detail {

// Gauss-Kronrod 7/15 rule on [-1, 1]: Kronrod abscissae (positive half; the
// Gauss nodes are the odd-indexed ones and 0) and weights.
inline constexpr double kGK15x[8] = {
    0.991455371120812639206854697526329, 0.949107912342758524526189684047851,
    0.864864423359769072789712788640926, 0.741531185599394439863864773280788,
    0.586087235467691130294144845693013, 0.405845151377397166906606412076961,
    0.207784955007898467600689403773245, 0.0};
inline constexpr double kGK15wk[8] = {
    0.022935322010529224963732008058970, 0.063092092629978553290700663189204,
    0.104790010322250183839876322541518, 0.140653259715525918745189590510238,
    0.169004726639267902826583426598550, 0.190350578064785409913256402421014,
    0.204432940075298892414161999234649, 0.209482141084727828012999174891714};
inline constexpr double kGK15wg[4] = {0.129484966168869693270611432679082,
                                      0.279705391489276667901467771423780,
                                      0.381830050505118944950369775488975,
                                      0.417959183673469387755102040816327};

// One GK15 panel: returns the Kronrod estimate, *err = |Kronrod - Gauss|.
template <class F>
double gk15(F& f, double a, double b, double* err) {
  const double c = 0.5 * (a + b), h = 0.5 * (b - a);
  const double fc = f(c);
  double rk = kGK15wk[7] * fc, rg = kGK15wg[3] * fc;
  for (int j = 0; j < 7; ++j) {
    const double dx = h * kGK15x[j];
    const double s = f(c - dx) + f(c + dx);
    rk += kGK15wk[j] * s;
    if (j % 2 == 1) rg += kGK15wg[j / 2] * s;
  }
  *err = std::abs((rk - rg) * h);
  return rk * h;
}

}  // namespace detail

// Globally adaptive Gauss-Kronrod quadrature of f on [a, b]: bisects the
// panel with the largest |K15 - G7| until the summed estimate is below
// max(abs_tol, rel_tol |integral|) or max_panels is reached. The G7/K15
// difference is used as is (pessimistic for smooth integrands).
template <class F>
double integrate(F&& f, double a, double b, double rel_tol, double abs_tol = 0.0,
                 int max_panels = 4000, double* err_out = nullptr) {
  struct Panel {
    double a, b, value, err;
  };
  std::vector<Panel> panels;
  double e0 = 0.0;
  const double v0 = detail::gk15(f, a, b, &e0);
  panels.push_back({a, b, v0, e0});
  double total = v0, total_err = e0;
  while (total_err > std::max(abs_tol, rel_tol * std::abs(total)) &&
         static_cast<int>(panels.size()) < max_panels) {
    std::size_t worst = 0;
    for (std::size_t i = 1; i < panels.size(); ++i)
      if (panels[i].err > panels[worst].err) worst = i;
    const Panel p = panels[worst];
    const double m = 0.5 * (p.a + p.b);
    double el = 0.0, er = 0.0;
    const double vl = detail::gk15(f, p.a, m, &el);
    const double vr = detail::gk15(f, m, p.b, &er);
    panels[worst] = {p.a, m, vl, el};
    panels.push_back({m, p.b, vr, er});
    total += vl + vr - p.value;
    total_err += el + er - p.err;
  }
  // Final re-sum, free of the running update's rounding.
  total = 0.0;
  total_err = 0.0;
  for (const Panel& q : panels) {
    total += q.value;
    total_err += q.err;
  }
  if (err_out) *err_out = total_err;
  return total;
}

// ---------------------------------------------------------------------------
// (A) Linear sphere next to a point dipole
// ---------------------------------------------------------------------------

// gamma_l = l (mu - 1) / (l mu + l + 1), mu = 1 + chi; chi = +inf gives 1.
inline long double sphere_response(int l, double chi) {
  if (std::isinf(chi)) return 1.0L;
  const long double c = chi;
  return l * c / (l * (c + 2.0L) + 1.0L);
}

namespace detail {

// Sums over l of gamma_l (R/D)^(2l+1) D^-(2l+4) times the three coefficient
// families needed by the energy and the force.
struct DipoleSphereSums {
  long double a = 0, b = 0;          // sum g_l R^(2l+1) D^-(2l+4) A_l, ... B_l
  long double fa = 0, fb = 0;        // ... times (2l+6) for A_l and (2l+4) for B_l
};

inline DipoleSphereSums dipole_sphere_sums(double R, double chi, double D) {
  DipoleSphereSums s;
  const long double q = static_cast<long double>(R) / D;
  long double p = q / (static_cast<long double>(D) * D * D);  // R^(2l+1) / D^(2l+4) at l = 0
  for (int l = 1; l < 1000000; ++l) {
    p *= q * q;
    const long double g = sphere_response(l, chi);
    const long double Al = 0.5L * (l + 1) * (l + 2), Bl = 0.5L * l * (l + 1);
    const long double ta = g * p * Al, tb = g * p * Bl;
    s.a += ta;
    s.b += tb;
    s.fa += ta * (2 * l + 6);
    s.fb += tb * (2 * l + 4);
    if (std::abs(ta * (2 * l + 6)) <= 1e-17L * std::abs(s.fa) && l > 2) break;
  }
  return s;
}

}  // namespace detail

// Energy (J) of the linear sphere (radius R, susceptibility chi, centre
// sphere_centre) in the field of the point dipole m at dipole_position,
// U = -(mu0/2) m . H_reaction. Requires |dipole_position - sphere_centre| > R.
inline double linear_sphere_reaction_energy(double R, double chi, const Vec3& sphere_centre,
                                            const Vec3& dipole_position, const Vec3& m) {
  const Vec3 r = dipole_position - sphere_centre;
  const double D = norm(r);
  const detail::DipoleSphereSums s = detail::dipole_sphere_sums(R, chi, D);
  const long double mu = dot(m, r) / D, m2 = dot(m, m);
  return static_cast<double>(-(kMu0 / (8.0 * kPi)) * (s.a * mu * mu + s.b * m2));
}

// Force (N) on that sphere (the force on the dipole is its negative).
inline Vec3 linear_sphere_force_from_dipole(double R, double chi, const Vec3& sphere_centre,
                                            const Vec3& dipole_position, const Vec3& m) {
  const Vec3 r = dipole_position - sphere_centre;
  const double D = norm(r);
  const detail::DipoleSphereSums s = detail::dipole_sphere_sums(R, chi, D);
  // Written with r = D u: the sums carry D^-(2l+4); (m.r) = D (m.u).
  const double mu = dot(m, r) / D, m2 = dot(m, m);
  const Vec3 u = r / D;
  const double k = kMu0 / (8.0 * kPi);
  const double cm = static_cast<double>(-k * 2.0L * s.a * mu / D);
  const double cu = static_cast<double>(-k * (-s.fa * mu * mu - s.fb * m2) / D);
  return cm * m + cu * u;
}

// ---------------------------------------------------------------------------
// (B) Two linear spheres in a uniform field
// ---------------------------------------------------------------------------

struct TwoSphereResult {
  Vec3 force_on_2;  // N; the force on sphere 1 is its negative
  Vec3 moment_1;    // A m^2
  Vec3 moment_2;
  int orders = 0;   // multipole order L of the returned (converged) solution
};

namespace detail {


// Scaled solution of one azimuthal sector for a unit applied field
// component; index l = 0..L (entry 0 unused).
struct SectorSolution {
  std::vector<long double> a1, b1, a2, b2;
};

inline SectorSolution solve_sector(int m, int L, double R1, double chi1, double R2,
                                   double chi2, double d) {
  const long double lr1 = std::log(static_cast<long double>(R1) / d);
  const long double lr2 = std::log(static_cast<long double>(R2) / d);
  std::vector<long double> g1(L + 1), g2(L + 1);
  for (int l = 1; l <= L; ++l) {
    g1[l] = sphere_response(l, chi1);
    g2[l] = sphere_response(l, chi2);
  }
  Eigen::MatrixXd A = Eigen::MatrixXd::Identity(2 * L, 2 * L);
  for (int l = 1; l <= L; ++l)
    for (int n = 1; n <= L; ++n) {
      // log C(l, n) with C = (l+n)! / ((l+m)! (n-m)!)
      const long double lc = std::lgamma(static_cast<long double>(l + n + 1)) -
                             std::lgamma(static_cast<long double>(l + m + 1)) -
                             std::lgamma(static_cast<long double>(n - m + 1));
      // M12(l,n) = (-1)^(n+m) C R1^l R2^(n+1) / d^(l+n+1)
      //          = (-1)^(n+m) C (R1/d)^l (R2/d)^(n+1)   (the powers of d cancel)
      const long double m12 = std::exp(lc + l * lr1 + (n + 1) * lr2) * (((n + m) % 2) ? -1 : 1);
      const long double m21 = std::exp(lc + l * lr2 + (n + 1) * lr1) * (((l + m) % 2) ? -1 : 1);
      A(l - 1, L + n - 1) = static_cast<double>(m12 * g2[n]);
      A(L + l - 1, n - 1) = static_cast<double>(m21 * g1[n]);
    }
  Eigen::VectorXd rhs = Eigen::VectorXd::Zero(2 * L);
  rhs(0) = -R1;  // b0_1 = c0_1 R^1 = -R
  rhs(L) = -R2;
  const Eigen::VectorXd x = A.partialPivLu().solve(rhs);
  SectorSolution s;
  s.a1.assign(L + 1, 0.0L);
  s.b1.assign(L + 1, 0.0L);
  s.a2.assign(L + 1, 0.0L);
  s.b2.assign(L + 1, 0.0L);
  for (int l = 1; l <= L; ++l) {
    s.b1[l] = x(l - 1);
    s.b2[l] = x(L + l - 1);
    s.a1[l] = -g1[l] * s.b1[l];
    s.a2[l] = -g2[l] * s.b2[l];
  }
  return s;
}

// Force and moments in the local frame (z along 1 -> 2, x along the
// transverse field) for field components hz, hx at truncation L.
struct LocalTwoSphere {
  double fz = 0, fx = 0, m1z = 0, m1x = 0, m2z = 0, m2x = 0;
};

inline LocalTwoSphere two_sphere_local(int L, double R1, double chi1, double R2, double chi2,
                                       double d, double hz, double hx) {
  LocalTwoSphere out;
  const long double fourpi = 4.0L * static_cast<long double>(kPi);
  long double fz = 0, fx = 0;
  SectorSolution s0, s1;
  if (hz != 0.0) {
    s0 = solve_sector(0, L, R1, chi1, R2, chi2, d);
    long double sum = 0;
    for (int l = 2; l <= L; ++l) sum += l * s0.b2[l] * s0.a2[l - 1];
    fz += sum * hz * hz;
    out.m1z = static_cast<double>(fourpi * s0.a1[1] * R1 * R1 * hz);
    out.m2z = static_cast<double>(fourpi * s0.a2[1] * R2 * R2 * hz);
  }
  if (hx != 0.0) {
    s1 = solve_sector(1, L, R1, chi1, R2, chi2, d);
    long double sum = 0;
    for (int l = 2; l <= L; ++l) sum += 0.5L * (l + 1) * l * (l - 1) * s1.b2[l] * s1.a2[l - 1];
    fz += sum * hx * hx;
    out.m1x = static_cast<double>(fourpi * s1.a1[1] * R1 * R1 * hx);
    out.m2x = static_cast<double>(fourpi * s1.a2[1] * R2 * R2 * hx);
  }
  if (hz != 0.0 && hx != 0.0) {
    long double sum = 0;
    for (int l = 2; l <= L; ++l)
      sum += 0.5L * l * (l + 1) * s1.b2[l] * s0.a2[l - 1] -
             0.5L * l * (l - 1) * s0.b2[l] * s1.a2[l - 1];
    fx = sum * hz * hx;
  }
  const long double k = -fourpi * static_cast<long double>(kMu0);
  out.fz = static_cast<double>(k * fz);
  out.fx = static_cast<double>(k * fx);
  return out;
}

}  // namespace detail

// Two linear spheres (radius R_i, susceptibility chi_i >= 0, +inf allowed) at
// centre_1, centre_2 (|centre_2 - centre_1| > R1 + R2) in the uniform applied
// field H0: force on sphere 2 and both moments. Converged to 1e-7 relative in
// the force and moments (see the header comment), else all NaN.
inline TwoSphereResult two_linear_spheres_in_uniform_field(double R1, double chi1, double R2,
                                                           double chi2, const Vec3& centre_1,
                                                           const Vec3& centre_2, const Vec3& H0) {
  const Vec3 axis = centre_2 - centre_1;
  const double d = norm(axis);
  const Vec3 ez = axis / d;
  const double hz = dot(H0, ez);
  Vec3 perp = H0 - hz * ez;
  const double hx = norm(perp);
  Vec3 ex;
  if (hx > 0.0) {
    ex = perp / hx;
  } else {
    perp = std::abs(ez.x) < 0.9 ? cross(ez, Vec3{1, 0, 0}) : cross(ez, Vec3{0, 1, 0});
    ex = normalized(perp);
  }
  auto to_world = [&](const detail::LocalTwoSphere& s) {
    TwoSphereResult r;
    r.force_on_2 = s.fz * ez + s.fx * ex;
    r.moment_1 = s.m1z * ez + s.m1x * ex;
    r.moment_2 = s.m2z * ez + s.m2x * ex;
    return r;
  };
  auto change = [](const TwoSphereResult& a, const TwoSphereResult& b) {
    auto rel = [](const Vec3& x, const Vec3& y) {
      const double n = std::max(norm(x), norm(y));
      return n > 0.0 ? norm(x - y) / n : 0.0;
    };
    return std::max({rel(a.force_on_2, b.force_on_2), rel(a.moment_1, b.moment_1),
                     rel(a.moment_2, b.moment_2)});
  };
  TwoSphereResult prev = to_world(detail::two_sphere_local(20, R1, chi1, R2, chi2, d, hz, hx));
  for (int L = 40; L <= 640; L *= 2) {
    TwoSphereResult cur = to_world(detail::two_sphere_local(L, R1, chi1, R2, chi2, d, hz, hx));
    cur.orders = L;
    if (change(prev, cur) < 1e-7) return cur;
    prev = cur;
  }
  const double nan = std::numeric_limits<double>::quiet_NaN();
  TwoSphereResult bad;
  bad.force_on_2 = bad.moment_1 = bad.moment_2 = Vec3{nan, nan, nan};
  bad.orders = -1;
  return bad;
}

// Two-dipole model of the same pair: Clausius-Mossotti moments
// m_i = 4 pi R_i^3 gamma_1,i H_local,i with the mutual dipole fields solved
// exactly (2 x 2 per direction), and the dipole-dipole force on sphere 2.
inline TwoSphereResult two_sphere_dipole_model(double R1, double chi1, double R2, double chi2,
                                               const Vec3& centre_1, const Vec3& centre_2,
                                               const Vec3& H0) {
  const Vec3 axis = centre_2 - centre_1;
  const double d = norm(axis);
  const Vec3 u = axis / d;
  const double a1 = 4.0 * kPi * R1 * R1 * R1 * static_cast<double>(sphere_response(1, chi1));
  const double a2 = 4.0 * kPi * R2 * R2 * R2 * static_cast<double>(sphere_response(1, chi2));
  const double k = 1.0 / (4.0 * kPi * d * d * d);
  // Along u the dipole field is 2 k m, across -k m:
  // m1 = a1 (h + c k m2), m2 = a2 (h + c k m1)  =>  m1 = a1 h (1 + c k a2) / (1 - c^2 k^2 a1 a2).
  auto solve = [&](double h, double c, double& m1, double& m2) {
    const double det = 1.0 - c * c * k * k * a1 * a2;
    m1 = a1 * h * (1.0 + c * k * a2) / det;
    m2 = a2 * h * (1.0 + c * k * a1) / det;
  };
  const double hz = dot(H0, u);
  const Vec3 hp = H0 - hz * u;
  double m1z, m2z, m1p, m2p;
  solve(hz, 2.0, m1z, m2z);
  solve(1.0, -1.0, m1p, m2p);
  TwoSphereResult r;
  r.moment_1 = m1z * u + m1p * hp;
  r.moment_2 = m2z * u + m2p * hp;
  const Vec3& m1 = r.moment_1;
  const Vec3& m2 = r.moment_2;
  // F on 2 = grad (mu0 m2 . H1) = 3 mu0 / (4 pi d^4) [(m1.u) m2 + (m2.u) m1 + (m1.m2) u - 5 (m1.u)(m2.u) u]
  const double c = 3.0 * kMu0 / (4.0 * kPi * d * d * d * d);
  r.force_on_2 = c * (dot(m1, u) * m2 + dot(m2, u) * m1 +
                      (dot(m1, m2) - 5.0 * dot(m1, u) * dot(m2, u)) * u);
  r.orders = 1;
  return r;
}

// Bispherical-coordinate second opinion: two equal spheres (radius R, centre
// distance d), mu = inf, field H along the line of centres: the (signed)
// force on sphere 2 along the axis (negative = attraction). See (B) above.
inline double equal_infinite_mu_spheres_axial_force(double R, double d, double H) {
  const double mu0c = std::acosh(d / (2.0 * R));
  const double a = R * std::sinh(mu0c);
  std::vector<double> w, nh;
  double sw = 0, snw = 0;
  for (int n = 0; n < 100000; ++n) {
    const double k = n + 0.5;
    const double wn = std::exp(-k * mu0c) / std::sinh(k * mu0c);
    w.push_back(wn);
    sw += wn;
    snw += k * wn;
    if (wn * (n + 1) < 1e-20 * w[0] && n > 4) break;
  }
  const double V = -2.0 * a * H * snw / sw;
  const int N = static_cast<int>(w.size());
  std::vector<double> B(N + 1, 0.0);
  for (int n = 0; n < N; ++n) {
    const double k = n + 0.5;
    B[n] = std::sqrt(2.0) * std::exp(-k * mu0c) * (V + 2.0 * a * H * k) / std::sinh(k * mu0c);
  }
  long double s = 0;
  for (int n = 0; n < N; ++n)
    s += (n + 0.5L) * B[n] * B[n] - (n + 1.0L) * B[n] * B[n + 1];
  return static_cast<double>(-kPi * kMu0 * s);
}

// Same, field H across the line of centres: the (signed) axial force on
// sphere 2 (positive = repulsion).
inline double equal_infinite_mu_spheres_transverse_force(double R, double d, double H) {
  const double mu0c = std::acosh(d / (2.0 * R));
  const double a = R * std::sinh(mu0c);
  std::vector<double> B(1, 0.0);  // B_0 unused (P_0^1 = 0)
  for (int n = 1; n < 100000; ++n) {
    const double k = n + 0.5;
    B.push_back(2.0 * std::sqrt(2.0) * a * H * std::exp(-k * mu0c) / std::cosh(k * mu0c));
    if (B.back() < 1e-19 * B[1] && n > 4) break;
  }
  const int N = static_cast<int>(B.size()) - 1;
  auto integrand = [&](double eta) {
    const double x = std::cos(eta), s = std::sin(eta);
    // P_n, P_n' by recurrence: P_{n+1} = ((2n+1) x P_n - n P_{n-1}) / (n+1),
    // P'_{n+1} = P'_{n-1} + (2n+1) P_n.
    double p0 = 1.0, p1 = x, dp0 = 0.0, dp1 = 1.0;
    double sum_f = 0.0, sum_df = 0.0;  // sum B_n P_n^1, sum B_n dP_n^1/deta
    for (int n = 1; n <= N; ++n) {
      sum_f += B[n] * s * dp1;
      sum_df += B[n] * (n * (n + 1.0) * p1 - x * dp1);
      const double p2 = ((2.0 * n + 1.0) * x * p1 - n * p0) / (n + 1.0);
      const double dp2 = dp0 + (2.0 * n + 1.0) * p1;
      p0 = p1;
      p1 = p2;
      dp0 = dp1;
      dp1 = dp2;
    }
    const double q = std::sqrt(2.0) * std::sin(0.5 * eta);       // sqrt(1 - cos eta)
    const double dq = std::sqrt(2.0) * 0.5 * std::cos(0.5 * eta);  // d/deta
    const double f = q * sum_f;
    const double df = dq * sum_f + q * sum_df;
    return s * df * df + (s > 0.0 ? f * f / s : 0.0);
  };
  const double I = integrate(integrand, 0.0, kPi, 1e-12, 0.0, 4000);
  return 0.5 * kPi * kMu0 * I;
}

// ---------------------------------------------------------------------------
// (C) Coaxial cylinder magnets
// ---------------------------------------------------------------------------
namespace detail {

// Complete elliptic integrals K(k), E(k) from the complementary modulus
// k' = sqrt(1 - k^2) (accurate for k -> 1) by the arithmetic-geometric mean:
// a0 = 1, b0 = k', c0 = k; a+ = (a+b)/2, b+ = sqrt(ab), c+ = (a-b)/2;
// K = pi / (2 a_inf), E = K (1 - sum_n 2^(n-1) c_n^2).
inline void elliptic_ke(double k, double kc, double& K, double& E) {
  double a = 1.0, b = kc, c = k, sum = 0.5 * c * c, pw = 0.5;
  for (int i = 0; i < 60 && std::abs(c) > 1e-17 * a; ++i) {
    const double an = 0.5 * (a + b), bn = std::sqrt(a * b);
    c = 0.5 * (a - b);
    a = an;
    b = bn;
    pw *= 2.0;
    sum += pw * c * c;
  }
  K = kPi / (2.0 * a);
  E = K * (1.0 - sum);
}

// Legendre function of the second kind Q_{1/2}(z) at z = 1 + t^2/2, t > 0.
inline double legendre_q_half_t(double t) {
  const double z = 1.0 + 0.5 * t * t;
  if (z > 2.0) {
    // (pi/2) (2z)^-3/2 2F1(5/4, 3/4; 2; 1/z^2)
    const double y = 1.0 / (z * z);
    double term = 1.0, sum = 1.0;
    for (int k = 0; k < 200; ++k) {
      term *= (1.25 + k) * (0.75 + k) / ((2.0 + k) * (1.0 + k)) * y;
      sum += term;
      if (term < 1e-17 * sum) break;
    }
    return 0.5 * kPi * std::pow(2.0 * z, -1.5) * sum;
  }
  // k^2 = 2/(z+1) = 4/(4+t^2), k'^2 = t^2/(4+t^2); Q = z k K - (2/k) E.
  const double r = std::sqrt(4.0 + t * t);
  const double k = 2.0 / r, kc = t / r;
  double K, E;
  elliptic_ke(k, kc, K, E);
  return z * k * K - (2.0 / k) * E;
}

// int_0^inf J1(x)^2 w(x) / x dx for a weight |w(x)| <= 2 e^-rate x,
// integrated between multiples of pi.
template <class W>
double bessel_j1_squared_integral(W&& weight, double rate) {
  auto f = [&](double x) {
    if (x == 0.0) return 0.0;
    const double j = std::cyl_bessel_j(1.0, x);
    return j * j / x * weight(x);
  };
  double sum = 0.0;
  for (int i = 0;; ++i) {
    const double x0 = i * kPi, x1 = (i + 1) * kPi;
    sum += integrate(f, x0, x1, 1e-14, 1e-17 * std::abs(sum), 200);
    // Tail beyond x1 (header comment): <= 2 e^-rate x1 / (rate x1^2).
    const double tail = 2.0 * std::exp(-rate * x1) / (rate * x1 * x1);
    if (tail < 1e-14 * std::abs(sum) || i > 2000000) break;
  }
  return sum;
}

// I(h) = int_0^inf J1(x)^2 e^-x h / x dx (radius 1), elliptic route.
inline double disc_pair_integral_elliptic(double h) {
  if (h == 0.0) return 0.5;
  auto q = [](double t) { return detail::legendre_q_half_t(t); };
  return 0.5 - integrate(q, 0.0, h, 1e-13, 0.0, 4000) / kPi;
}

}  // namespace detail

// Force (N) on cylinder 2 along the common axis, pointing away from cylinder
// 1 (negative = attraction). Radius a, lengths L1, L2, axial magnetizations
// M1, M2 (signed, along the same axis; parallel M attract), gap g >= 0 between
// the facing end faces. Bessel-integral route (small gaps: I(g) by the
// elliptic route, see the header comment).
inline double coaxial_cylinder_force(double a, double L1, double L2, double M1, double M2,
                                     double g) {
  const double t1 = L1 / a, t2 = L2 / a, tg = g / a;
  const double pref = -kPi * kMu0 * M1 * M2 * a * a;
  if (tg >= 0.1) {
    auto w = [&](double x) {
      return std::exp(-x * tg) * std::expm1(-x * t1) * std::expm1(-x * t2);
    };
    return pref * detail::bessel_j1_squared_integral(w, tg);
  }
  // e^-xg (1 - e^-xL1)(1 - e^-xL2) = e^-xg + e^-xg (e^-x(L1+L2) - e^-xL1 - e^-xL2)
  auto w = [&](double x) {
    return std::exp(-x * tg) * (std::exp(-x * (t1 + t2)) - std::exp(-x * t1) - std::exp(-x * t2));
  };
  const double rest = detail::bessel_j1_squared_integral(w, tg + std::min(t1, t2));
  return pref * (detail::disc_pair_integral_elliptic(tg) + rest);
}

// The same force by the elliptic route alone (second opinion).
inline double coaxial_cylinder_force_elliptic(double a, double L1, double L2, double M1,
                                              double M2, double g) {
  const double t1 = L1 / a, t2 = L2 / a, tg = g / a;
  auto q = [](double t) { return detail::legendre_q_half_t(t); };
  const double i1 = integrate(q, tg, tg + t1, 1e-13, 0.0, 4000);
  const double i2 = integrate(q, tg + t2, tg + t1 + t2, 1e-13, 0.0, 4000);
  return -kMu0 * M1 * M2 * a * a * (i1 - i2);
}

// Coulomb force (N, along the axis, positive = repulsion) between two coaxial
// uniformly charged discs (radius a, charges sigma1, sigma2 in A/m, axial
// separation h > 0) by direct quadrature of
//   F = mu0 sigma1 sigma2 h / (4 pi) int dA1 int dA2 |r1 - r2|^-3,
// the angle done in closed form: int_0^2pi (A - B cos phi)^-3/2 dphi =
// 4 E(k) / ((A - B) sqrt(A + B)), k^2 = 2B / (A + B), A = rho1^2 + rho2^2 + h^2,
// B = 2 rho1 rho2; the two radii by nested adaptive Gauss-Kronrod. Slow; for tests.
inline double coaxial_disc_force_direct(double a, double sigma1, double sigma2, double h,
                                        double rel_tol = 1e-11) {
  auto inner = [&](double r1) {
    auto f = [&](double r2) {
      const double A = r1 * r1 + r2 * r2 + h * h, B = 2.0 * r1 * r2;
      const double k = std::sqrt(2.0 * B / (A + B));
      return r2 * 4.0 * std::comp_ellint_2(k) / ((A - B) * std::sqrt(A + B));
    };
    // The integrand peaks at r2 = r1 (width ~ h): split there.
    return 2.0 * kPi * r1 *
           (integrate(f, 0.0, r1, rel_tol, 0.0, 4000) + integrate(f, r1, a, rel_tol, 0.0, 4000));
  };
  const double I = integrate(inner, 0.0, a, rel_tol, 0.0, 4000);
  return kMu0 * sigma1 * sigma2 * h / (4.0 * kPi) * I;
}

// ---------------------------------------------------------------------------
// (D) Magnetometric demagnetizing factor of a linear cube
// ---------------------------------------------------------------------------
namespace detail {

// Normal-field kernels of a unit-charge rectangle [u1,u2] x [v1,v2] in the
// plane w = w0, at the point (u, v, w) (local coordinates).
inline double rect_field_normal(double u1, double u2, double v1, double v2, double Z, double u,
                                double v) {
  const double X[2] = {u - u1, u - u2}, Y[2] = {v - v1, v - v2};
  double s = 0.0;
  for (int i = 0; i < 2; ++i)
    for (int j = 0; j < 2; ++j) {
      const double R = std::sqrt(X[i] * X[i] + Y[j] * Y[j] + Z * Z);
      s += ((i + j) % 2 ? -1.0 : 1.0) * std::atan(X[i] * Y[j] / (Z * R));
    }
  return s / (4.0 * kPi);
}

// asinh(Y1/rho) - asinh(Y2/rho) for Y1 > Y2, rho > 0, without cancellation:
// for 0 <= b < a, asinh a - asinh b = log1p((a - b) (1 + (a + b)/(sa + sb)) / (b + sb)),
// sa = sqrt(1 + a^2) (the ratio (a + sa)/(b + sb) written as 1 + exact difference);
// both negative by oddness; opposite signs add two positive terms.
inline double asinh_diff(double Y1, double Y2, double rho) {
  double a = Y1 / rho, b = Y2 / rho;
  if (b < 0.0 && a > 0.0) return std::asinh(a) + std::asinh(-b);
  if (a <= 0.0) {
    const double t = -b;
    b = -a;
    a = t;
  }
  const double sa = std::sqrt(1.0 + a * a), sb = std::sqrt(1.0 + b * b);
  return std::log1p((a - b) * (1.0 + (a + b) / (sa + sb)) / (b + sb));
}

// In-plane component along u of the same rectangle's field.
inline double rect_field_tangential(double u1, double u2, double v1, double v2, double Z,
                                    double u, double v) {
  const double X1 = u - u1, X2 = u - u2, Y1 = v - v1, Y2 = v - v2;
  const double r1 = std::sqrt(X1 * X1 + Z * Z), r2 = std::sqrt(X2 * X2 + Z * Z);
  return (asinh_diff(Y1, Y2, r2) - asinh_diff(Y1, Y2, r1)) / (4.0 * kPi);
}

struct CubeSystem {
  Eigen::MatrixXd K;        // reduced K (normal field at rep r from its class-summed charges)
  Eigen::VectorXd nz;       // H0 . n at the reps (H0 = z^)
  Eigen::VectorXd moment;   // d m_z / d sigma_class (class-summed sigma z dA)
};

// Mesh grading exponent q: nodes s_i = (1/2) g(-1 + 2i/n), g(u) = sgn(u) (1 - (1 - |u|)^q).
inline constexpr double kCubeGrading = 4.0;

inline std::vector<double> cube_nodes(int n) {
  std::vector<double> s(n + 1);
  for (int i = 0; i <= n; ++i) {
    const double u = -1.0 + 2.0 * i / n;
    s[i] = 0.5 * (u < 0 ? -1.0 : 1.0) * (1.0 - std::pow(1.0 - std::abs(u), kCubeGrading));
  }
  s[0] = -0.5;
  s[n] = 0.5;
  s[n / 2] = 0.0;
  return s;
}

// Reduced collocation system for n (even) panels per edge.
inline CubeSystem cube_system(int n) {
  const std::vector<double> s = cube_nodes(n);
  const int h = n / 2;
  // Classes: top (i <= j < h, index j(j+1)/2 + i) first, then side (j < h, kk < h).
  const int T = h * (h + 1) / 2, S = h * h, U = T + S;
  auto top_index = [&](int i, int j) {
    i = std::min(i, n - 1 - i);
    j = std::min(j, n - 1 - j);
    if (i > j) std::swap(i, j);
    return j * (j + 1) / 2 + i;
  };
  auto side_index = [&](int j, int k, int& sign) {
    j = std::min(j, n - 1 - j);
    sign = k >= h ? 1 : -1;
    const int kk = k >= h ? k - h : n - 1 - k - h;
    return T + kk * h + j;
  };
  // Calls g(axis, side, ua, va, p, q, id) for every panel (p, q) of every face
  // f = 2 * axis + (side > 0), id = (f * n + p) * n + q; p runs along axis
  // ua = (axis+1)%3, q along va = (axis+2)%3.
  auto for_each_panel = [n](auto&& g) {
    for (int axis = 0; axis < 3; ++axis)
      for (int side = -1; side <= 1; side += 2) {
        const int f = 2 * axis + (side > 0);
        const int ua = (axis + 1) % 3, va = (axis + 2) % 3;
        for (int p = 0; p < n; ++p)
          for (int q = 0; q < n; ++q) g(axis, side, ua, va, p, q, (f * n + p) * n + q);
      }
  };
  // Class and sign of each panel.
  std::vector<int> cls(6 * n * n), sgn(6 * n * n);
  for_each_panel([&](int axis, int side, int ua, int va, int p, int q, int id) {
    int idx[3] = {0, 0, 0};
    idx[ua] = p;
    idx[va] = q;
    int c, sg = side;
    if (axis == 2) {
      c = top_index(idx[0], idx[1]);
    } else {
      c = side_index(axis == 0 ? idx[1] : idx[0], idx[2], sg);
    }
    cls[id] = c;
    sgn[id] = sg;
  });
  // Representatives: top (i <= j < h) on z = +1/2; side (j < h, k = h + kk) on x = +1/2.
  struct Rep {
    int axis;
    Vec3 r;
  };
  std::vector<Rep> reps(U);
  for (int j = 0; j < h; ++j)
    for (int i = 0; i <= j; ++i)
      reps[j * (j + 1) / 2 + i] = {2, Vec3{0.5 * (s[i] + s[i + 1]), 0.5 * (s[j] + s[j + 1]), 0.5}};
  for (int kk = 0; kk < h; ++kk)
    for (int j = 0; j < h; ++j)
      reps[T + kk * h + j] = {0, Vec3{0.5, 0.5 * (s[j] + s[j + 1]), 0.5 * (s[h + kk] + s[h + kk + 1])}};
  CubeSystem sys;
  sys.K = Eigen::MatrixXd::Zero(U, U);
  sys.nz = Eigen::VectorXd::Zero(U);
  sys.moment = Eigen::VectorXd::Zero(U);
  const double k4pi = 1.0 / (4.0 * kPi);
  std::vector<double> F((n + 1) * (n + 1)), X(n + 1), Y(n + 1), rho(n + 1);
  for (int r = 0; r < U; ++r) {
    const Rep& R = reps[r];  // outward normal +e_axis (side +1) for every rep
    sys.nz(r) = R.axis == 2 ? 1.0 : 0.0;
    for (int axis = 0; axis < 3; ++axis)
      for (int side = -1; side <= 1; side += 2) {
        if (axis == R.axis && side == 1) continue;  // coplanar: no normal field
        const int f = 2 * axis + (side > 0);
        const int ua = (axis + 1) % 3, va = (axis + 2) % 3;
        const double Z = R.r[axis] - 0.5 * side;
        for (int i = 0; i <= n; ++i) {
          X[i] = R.r[ua] - s[i];
          Y[i] = R.r[va] - s[i];
        }
        // Corner functions at the mesh nodes, combined per panel (p, q):
        //   normal (rep normal along axis): atan(X Y / (Z R)), + - - + over (p,q),(p+1,q),(p,q+1),(p+1,q+1);
        //   along ua: asinh(Y_j / rho(X_i)), H_u = G(p+1,q) - G(p+1,q+1) - G(p,q) + G(p,q+1);
        //   along va: asinh(X_i / rho(Y_j)), H_v = G(p,q+1) - G(p+1,q+1) - G(p,q) + G(p+1,q).
        int mode;
        if (axis == R.axis) {
          mode = 0;
          for (int i = 0; i <= n; ++i)
            for (int j = 0; j <= n; ++j) {
              const double Rn = std::sqrt(X[i] * X[i] + Y[j] * Y[j] + Z * Z);
              F[i * (n + 1) + j] = std::atan(X[i] * Y[j] / (Z * Rn));
            }
        } else if (R.axis == ua) {
          mode = 1;
          for (int i = 0; i <= n; ++i) rho[i] = std::sqrt(X[i] * X[i] + Z * Z);
          for (int i = 0; i <= n; ++i)
            for (int j = 0; j <= n; ++j) F[i * (n + 1) + j] = std::asinh(Y[j] / rho[i]);
        } else {
          mode = 2;
          for (int j = 0; j <= n; ++j) rho[j] = std::sqrt(Y[j] * Y[j] + Z * Z);
          for (int i = 0; i <= n; ++i)
            for (int j = 0; j <= n; ++j) F[i * (n + 1) + j] = std::asinh(X[i] / rho[j]);
        }
        for (int p = 0; p < n; ++p)
          for (int q = 0; q < n; ++q) {
            const double f00 = F[p * (n + 1) + q], f10 = F[(p + 1) * (n + 1) + q];
            const double f01 = F[p * (n + 1) + q + 1], f11 = F[(p + 1) * (n + 1) + q + 1];
            double k;
            if (mode == 0) k = f00 - f10 - f01 + f11;
            else if (mode == 1) k = f10 - f11 - f00 + f01;
            else k = f01 - f11 - f00 + f10;
            const int id = (f * n + p) * n + q;
            sys.K(r, cls[id]) += sgn[id] * k4pi * k;
          }
      }
  }
  for_each_panel([&](int axis, int side, int ua, int va, int p, int q, int id) {
    double zc = 0.0;
    if (axis == 2) zc = 0.5 * side;
    else if (ua == 2) zc = 0.5 * (s[p] + s[p + 1]);
    else if (va == 2) zc = 0.5 * (s[q] + s[q + 1]);
    sys.moment(cls[id]) += sgn[id] * zc * (s[p + 1] - s[p]) * (s[q + 1] - s[q]);
  });
  return sys;
}

// N_m(chi) from an assembled system.
inline double cube_demag_from_system(const CubeSystem& sys, double chi) {
  const int U = static_cast<int>(sys.nz.size());
  const Eigen::MatrixXd I = Eigen::MatrixXd::Identity(U, U);
  if (std::isinf(chi)) {
    const Eigen::VectorXd sigma = (0.5 * I - sys.K).partialPivLu().solve(sys.nz);
    return 1.0 / sys.moment.dot(sigma);
  }
  // sigma = chi tau, tau = n_z + chi delta (n_z as a class vector: 1 on the
  // top classes, 0 on the side classes), so
  //   ((1 + chi/2) I - chi K) delta = K n_z - n_z / 2,
  // <tau z> = 1 + chi p with p = <delta z> (int n_z z dA = V = 1 exactly), and
  // N = (1 - <tau z>) / (chi <tau z>) = -p / (1 + chi p), also at chi = 0.
  const Eigen::VectorXd rhs = sys.K * sys.nz - 0.5 * sys.nz;
  const Eigen::VectorXd delta = ((1.0 + 0.5 * chi) * I - chi * sys.K).partialPivLu().solve(rhs);
  const double p = sys.moment.dot(delta);
  return -p / (1.0 + chi * p);
}

}  // namespace detail

// N_m(chi) of the cube with n panels per edge (rounded up to even, >= 2);
// chi in [0, inf]. <M> = chi H0 / (1 + N_m chi) along the edge-parallel field.
inline double cube_magnetometric_demag_factor(double chi, int panels_per_edge) {
  const int n = std::max(2, panels_per_edge + (panels_per_edge % 2));
  return detail::cube_demag_from_system(detail::cube_system(n), chi);
}

// Extrapolated N_m. The error of the graded collocation behaves as
// A h^2 + B h^(8/3), h = 1/n (8/3 = q (1 - 1/3): the r^-1/3 edge singularity
// of sigma on the q = 4 graded mesh); found by fitting runs up to n = 128,
// whose three-level fits through (n, 2n, 4n) = (12..), (16..), (24..), (32..)
// gave, at chi = inf, 0.274465, 0.274422, 0.274405, 0.274402 (conducting-cube
// polarizability: 1/3.6442 = 0.274409) and at chi = 0 0.333307, 0.333323,
// 0.333331, 0.333332. The raw sequence is pre-asymptotic: observed local
// order log2((N_16 - N_32)/(N_32 - N_64)) = 1.66 at chi = 1000 and inf, 1.74
// at chi = 10, 1.92 at chi = 0.
// value: the three-level fit N + A h^2 + B h^(8/3) through n = 16, 32, 64
// (measured errors 1.0e-5 at chi = 0, 1.4e-5 at chi = inf, about 1e-5 at
// chi = 10 and 1000 judging by the finer fits).
// error: max(|value - same fit through 12, 24, 48|, |value - fit with
// exponents (2, 3)|), 1.6e-5 .. 4.6e-5 at these chi, 1.5-4 times the
// measured errors.
struct CubeDemagEstimate {
  double value = 0;
  double error = 0;           // estimate of |value - exact|
  double observed_order = 0;  // local order of the raw sequence 16, 32, 64
};

namespace detail {

// N through three levels n, 2n, 4n with error model A h^p1 + B h^p2.
inline double cube_three_level_fit(double n1, double v1, double v2, double v3, double p1 = 2.0,
                                   double p2 = 8.0 / 3.0) {
  double h[3] = {1.0 / n1, 0.5 / n1, 0.25 / n1}, v[3] = {v1, v2, v3};
  Eigen::Matrix3d A;
  Eigen::Vector3d b;
  for (int i = 0; i < 3; ++i) {
    A(i, 0) = 1.0;
    A(i, 1) = std::pow(h[i], p1);
    A(i, 2) = std::pow(h[i], p2);
    b(i) = v[i];
  }
  return A.colPivHouseholderQr().solve(b)(0);
}

}  // namespace detail

// Extrapolated estimates for several chi (the panel systems are shared). About
// 1 s for the assemblies plus 0.5 s per chi on one core.
inline std::vector<CubeDemagEstimate> cube_magnetometric_demag_factor_estimates(
    const std::vector<double>& chis) {
  const int levels[6] = {12, 16, 24, 32, 48, 64};
  std::vector<std::vector<double>> v(chis.size(), std::vector<double>(6));
  for (int k = 0; k < 6; ++k) {
    const detail::CubeSystem sys = detail::cube_system(levels[k]);
    for (std::size_t c = 0; c < chis.size(); ++c) v[c][k] = detail::cube_demag_from_system(sys, chis[c]);
  }
  std::vector<CubeDemagEstimate> out(chis.size());
  for (std::size_t c = 0; c < chis.size(); ++c) {
    const std::vector<double>& w = v[c];  // 12, 16, 24, 32, 48, 64
    const double fine = detail::cube_three_level_fit(16, w[1], w[3], w[5]);
    const double coarse = detail::cube_three_level_fit(12, w[0], w[2], w[4]);
    out[c].value = fine;
    const double other_model = detail::cube_three_level_fit(16, w[1], w[3], w[5], 2.0, 3.0);
    out[c].error = std::max(std::abs(fine - coarse), std::abs(fine - other_model));
    out[c].observed_order = std::log2((w[1] - w[3]) / (w[3] - w[5]));
  }
  return out;
}

inline CubeDemagEstimate cube_magnetometric_demag_factor_estimate(double chi) {
  return cube_magnetometric_demag_factor_estimates({chi})[0];
}

inline double cube_magnetometric_demag_factor_extrapolated(double chi) {
  return cube_magnetometric_demag_factor_estimate(chi).value;
}

}  // namespace odemag::reference
