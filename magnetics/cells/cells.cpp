#include "magnetics/cells/cells.h"

#include <algorithm>
#include <cmath>
#include <functional>
#include <stdexcept>
#include <string>

#include "magnetics/cells/compound.h"
#include "magnetics/cells/demag_tensor.h"
#include "magnetics/cells/mesh.h"
#include "magnetics/kernels/cell_field.h"
#include "odemag/constants.h"

namespace odemag {

namespace {

using Moments = VolumeMoments;

// Area and first moments (integrals of x and y) of the rectangle [x0, x1] x
// [y0, y1] inside the disc x^2 + y^2 <= r^2, in closed form: in x the chord
// limits are constants or +-s(x), s = sqrt(r^2 - x^2), piecewise between the
// points where s crosses y0 or y1.
Moments rect_in_disc(double r, double x0, double x1, double y0, double y1) {
  Moments m;
  if (r <= 0.0) return m;
  const double a = std::max(x0, -r), b = std::min(x1, r);
  if (b <= a) return m;
  // (r - x)(r + x), not r^2 - x^2: exactly 0 at x = +-r whether or not the
  // compiler fuses the multiply-add (fused, r^2 - x^2 left a rounding residue
  // whose root, ~1e-11 r, put 2e-9 into a ball's total volume).
  auto s = [r](double x) { return std::sqrt(std::max(0.0, (r - x) * (r + x))); };
  auto P = [&](double x) { return 0.5 * (x * s(x) + r * r * std::asin(std::clamp(x / r, -1.0, 1.0))); };  // int s
  auto Q = [&](double x) { const double t = s(x); return -t * t * t / 3.0; };                              // int x s
  auto S2 = [r](double x) { return r * r * x - x * x * x / 3.0; };                                          // int s^2
  double breaks[6] = {a, b, 0, 0, 0, 0};
  int nb = 2;
  for (double y : {y0, y1})
    if (std::fabs(y) < r) {
      const double c = std::sqrt((r - y) * (r + y));
      for (double p : {-c, c})
        if (p > a && p < b) breaks[nb++] = p;
    }
  for (int k = 1; k < nb; ++k)  // insertion sort of at most 6
    for (int j = k; j > 0 && breaks[j - 1] > breaks[j]; --j) std::swap(breaks[j - 1], breaks[j]);
  for (int k = 0; k + 1 < nb; ++k) {
    const double u = breaks[k], v = breaks[k + 1];
    if (v <= u) continue;
    const double sm = s(0.5 * (u + v));
    const bool hi_const = y1 < sm, lo_const = y0 > -sm;
    const double hi_m = hi_const ? y1 : sm, lo_m = lo_const ? y0 : -sm;
    if (hi_m <= lo_m) continue;
    // hi - lo, x (hi - lo), (hi^2 - lo^2) / 2 integrated over [u, v].
    const double len = v - u, xlen = 0.5 * (v * v - u * u);
    const double Ps = P(v) - P(u), Qs = Q(v) - Q(u), Ss = S2(v) - S2(u);
    m.v += (hi_const ? y1 * len : Ps) - (lo_const ? y0 * len : -Ps);
    m.x += (hi_const ? y1 * xlen : Qs) - (lo_const ? y0 * xlen : -Qs);
    m.y += 0.5 * ((hi_const ? y1 * y1 * len : Ss) - (lo_const ? y0 * y0 * len : Ss));
  }
  return m;
}

// Gauss-Legendre nodes and weights on [-1, 1] (Newton on P_n).
struct GaussLegendre {
  std::vector<double> x, w;
  explicit GaussLegendre(int n) : x(n), w(n) {
    for (int i = 0; i < n; ++i) {
      double t = std::cos(kPi * (i + 0.75) / (n + 0.5)), dp = 1.0;
      for (int it = 0; it < 100; ++it) {
        double p0 = 1.0, p1 = t;
        for (int k = 2; k <= n; ++k) {
          const double p2 = ((2 * k - 1) * t * p1 - (k - 1) * p0) / k;
          p0 = p1, p1 = p2;
        }
        dp = n * (t * p1 - p0) / (t * t - 1.0);
        const double dt = p1 / dp;
        t -= dt;
        if (std::fabs(dt) < 1e-16) break;
      }
      double p0 = 1.0, p1 = t;
      for (int k = 2; k <= n; ++k) {
        const double p2 = ((2 * k - 1) * t * p1 - (k - 1) * p0) / k;
        p0 = p1, p1 = p2;
      }
      dp = n * (t * p1 - p0) / (t * t - 1.0);
      x[i] = t;
      w[i] = 2.0 / ((1.0 - t * t) * dp * dp);
    }
  }
};

const GaussLegendre& gauss16() {
  static const GaussLegendre g(16);
  return g;
}

// Volume and first moments of the box [lo, hi] inside the ball of radius R:
// the disc sections (rect_in_disc) integrated along x by 16-point Gauss on
// each interval between the x where the section radius crosses a distance at
// which the section's shape changes, with the map x = m + w (3t - t^3) / 2
// flattening the (x - x_b)^(3/2) kinks at those points. Relative error of a
// ball's total volume below 1e-14 (R/h = 2 ... 8).
Moments box_in_ball(double R, const Vec3& lo, const Vec3& hi) {
  Moments m;
  const double x0 = std::max(lo.x, -R), x1 = std::min(hi.x, R);
  if (x1 <= x0) return m;
  double rho[9] = {std::fabs(lo.y), std::fabs(hi.y), std::fabs(lo.z), std::fabs(hi.z)};
  int nr = 4;
  for (double y : {lo.y, hi.y})
    for (double z : {lo.z, hi.z}) rho[nr++] = std::hypot(y, z);
  const double ny = lo.y > 0.0 ? lo.y : (hi.y < 0.0 ? hi.y : 0.0);
  const double nz = lo.z > 0.0 ? lo.z : (hi.z < 0.0 ? hi.z : 0.0);
  rho[nr++] = std::hypot(ny, nz);
  std::vector<double> xs = {x0, x1};
  for (int k = 0; k < nr; ++k)
    if (rho[k] < R) {
      const double x = std::sqrt((R - rho[k]) * (R + rho[k]));
      for (double p : {-x, x})
        if (p > x0 && p < x1) xs.push_back(p);
    }
  std::sort(xs.begin(), xs.end());
  const GaussLegendre& g = gauss16();
  for (size_t k = 0; k + 1 < xs.size(); ++k) {
    const double a = xs[k], b = xs[k + 1];
    if (b <= a) continue;
    const double mid = 0.5 * (a + b), half = 0.5 * (b - a);
    for (size_t i = 0; i < g.x.size(); ++i) {
      const double t = g.x[i];
      const double x = mid + half * 0.5 * (3.0 * t - t * t * t);
      const double wx = g.w[i] * half * 1.5 * (1.0 - t * t);
      const Moments s = rect_in_disc(std::sqrt(std::max(0.0, (R - x) * (R + x))), lo.y, hi.y, lo.z, hi.z);
      m.v += wx * s.v;
      m.x += wx * x * s.v;
      m.y += wx * s.x;
      m.z += wx * s.y;
    }
  }
  return m;
}

// Volume and first moments of the box [lo, hi] inside the shape.
Moments box_in_shape(const Shape& shape, const Vec3& lo, const Vec3& hi) {
  return std::visit(
      Overloaded{
          [&](const Sphere& s) { return box_in_ball(s.radius, lo, hi); },
          [&](const Box& b) {
            Moments m;
            double len[3], mid[3];
            const Vec3 e = 0.5 * b.size;
            for (int k = 0; k < 3; ++k) {
              const double u = std::max(lo[k], -e[k]), v = std::min(hi[k], e[k]);
              len[k] = std::max(0.0, v - u);
              mid[k] = 0.5 * (u + v);
            }
            m.v = len[0] * len[1] * len[2];
            m.x = m.v * mid[0], m.y = m.v * mid[1], m.z = m.v * mid[2];
            return m;
          },
          [&](const Cylinder& c) {
            Moments m;
            const double e = 0.5 * c.length;
            const double u = std::max(lo.z, -e), v = std::min(hi.z, e);
            if (v <= u) return m;
            const Moments d = rect_in_disc(c.radius, lo.x, hi.x, lo.y, hi.y);
            m.v = d.v * (v - u);
            m.x = d.x * (v - u), m.y = d.y * (v - u), m.z = m.v * 0.5 * (u + v);
            return m;
          },
          [&](const Mesh& m) { return mesh_box_moments(m, lo, hi); },
          [&](const Compound& c) { return compound_box_moments(c, lo, hi); },
      },
      shape);
}

// True when the whole box [lo, hi] lies inside the shape (to tol).
bool box_inside_shape(const Shape& shape, const Vec3& lo, const Vec3& hi, double tol) {
  if (const Mesh* m = std::get_if<Mesh>(&shape)) return mesh_box_inside(*m, lo, hi);
  if (const Compound* c = std::get_if<Compound>(&shape)) return compound_box_inside(*c, lo, hi);
  const Vec3 far{std::max(std::fabs(lo.x), std::fabs(hi.x)), std::max(std::fabs(lo.y), std::fabs(hi.y)),
                 std::max(std::fabs(lo.z), std::fabs(hi.z))};
  return shape_contains(shape, far, tol);
}

// Distance from an inside point to the shape's surface.
double depth_inside(const Shape& shape, const Vec3& p) {
  return std::visit(Overloaded{
                        [&](const Sphere& s) { return s.radius - norm(p); },
                        [&](const Box& b) {
                          return std::min({0.5 * b.size.x - std::fabs(p.x), 0.5 * b.size.y - std::fabs(p.y),
                                           0.5 * b.size.z - std::fabs(p.z)});
                        },
                        [&](const Cylinder& c) {
                          return std::min(c.radius - std::hypot(p.x, p.y), 0.5 * c.length - std::fabs(p.z));
                        },
                        [&](const Mesh& m) { return norm(mesh_closest_point(m, p) - p); },
                        [&](const Compound& c) { return compound_depth(c, p); },
                    },
                    shape);
}

// Adaptive Gauss-Kronrod (7/15) quadrature by bisection to a relative and an
// absolute tolerance.
double gk15(const std::function<double(double)>& f, double a, double b, double* err) {
  static constexpr double xk[8] = {0.991455371120812639206854697526329, 0.949107912342758524526189684047851,
                                   0.864864423359769072789712788640926, 0.741531185599394439863864773280788,
                                   0.586087235467691130294144845693013, 0.405845151377397166906606412076961,
                                   0.207784955007898467600689403773245, 0.0};
  static constexpr double wk[8] = {0.022935322010529224963732008058970, 0.063092092629978553290700663189204,
                                   0.104790010322250183839876322541518, 0.140653259715525918745189590510238,
                                   0.169004726639267902826583426598550, 0.190350578064785409913256402421014,
                                   0.204432940075298892414161999234649, 0.209482141084727828012999174891714};
  static constexpr double wg[4] = {0.129484966168869693270611432679082, 0.279705391489276667901467771423780,
                                   0.381830050505118944950369775488975, 0.417959183673469387755102040816327};
  const double c = 0.5 * (a + b), h = 0.5 * (b - a);
  const double fc = f(c);
  double rk = wk[7] * fc, rg = wg[3] * fc;
  for (int j = 0; j < 7; ++j) {
    const double s = f(c - h * xk[j]) + f(c + h * xk[j]);
    rk += wk[j] * s;
    if (j % 2 == 1) rg += wg[j / 2] * s;
  }
  *err = std::fabs((rk - rg) * h);
  return rk * h;
}

// Globally adaptive: bisects the panel with the largest error estimate until
// the total is below abs_tol or 2000 panels are used (round-off then limits).
double integrate(const std::function<double(double)>& f, double a, double b, double abs_tol) {
  struct Panel {
    double a, b, v, e;
  };
  std::vector<Panel> panels;
  double e0 = 0.0;
  const double v0 = gk15(f, a, b, &e0);
  panels.push_back({a, b, v0, e0});
  double err = e0;
  while (err > abs_tol && panels.size() < 2000) {
    size_t w = 0;
    for (size_t i = 1; i < panels.size(); ++i)
      if (panels[i].e > panels[w].e) w = i;
    const Panel p = panels[w];
    const double m = 0.5 * (p.a + p.b);
    double el = 0.0, er = 0.0;
    const double vl = gk15(f, p.a, m, &el), vr = gk15(f, m, p.b, &er);
    panels[w] = {p.a, m, vl, el};
    panels.push_back({m, p.b, vr, er});
    err += el + er - p.e;
  }
  double v = 0.0;
  for (const Panel& p : panels) v += p.v;
  return v;
}

// Demagnetising tensor N(p) of a uniformly magnetized cylinder (radius a, axis
// z, half length c) at an inside point p, from its surface charges (potential
// phi = (1/4pi) int sigma / |x - x'| dA', N = -grad grad psi with psi the
// Newtonian potential of the solid, of unit density, divided by 4 pi):
//   N_zz = (Omega_top + Omega_bottom) / 4pi, Omega the solid angle of an end disc,
//          Omega = int_0^2pi (1 - |zeta| / sqrt(zeta^2 + l(t)^2)) dt with l(t) =
//          -rho cos t + sqrt(a^2 - rho^2 sin^2 t) the distance to the rim along t;
//   N_rho z = d/drho (phi_top - phi_bottom), the in-plane gradient of a disc's
//          potential being the rim integral -(1/4pi) int a cos t dt / |x - x'|;
//   N_phiphi = -(1/rho) d psi / d rho = (1/4pi rho) int_0^2pi a cos t
//          [asinh((c - z)/sqrt(A)) + asinh((c + z)/sqrt(A))] dt, A = rho^2 + a^2 - 2 a rho cos t
//          (the side's share of grad psi = -(1/4pi) int n' / |x - x'| dA', along z in closed form);
//   N_rhorho = 1 - N_zz - N_phiphi (trace 1 inside).
// The integrands are even in t, so each is twice the integral over [0, pi].
void cylinder_demag_tensor(double a, double c, const Vec3& p, double n[6]) {
  const double rho = std::min(std::hypot(p.x, p.y), a * (1.0 - 1e-12)), z = p.z;
  const double tol = 1e-11;
  auto solid_angle = [&](double zeta) {
    zeta = std::fabs(zeta);
    auto f = [&](double t) {
      const double st = std::sin(t);
      const double l = -rho * std::cos(t) + std::sqrt(std::max(0.0, a * a - rho * rho * st * st));
      return 1.0 - zeta / std::sqrt(zeta * zeta + l * l);
    };
    return 2.0 * integrate(f, 0.0, kPi, tol);
  };
  const double nzz = (solid_angle(c - z) + solid_angle(c + z)) / (4.0 * kPi);
  double nrz = 0.0, npp = 0.5 * (1.0 - nzz);
  if (rho > 1e-9 * a) {
    auto rim = [&](double zeta) {
      auto f = [&](double t) {
        return a * std::cos(t) / std::sqrt(rho * rho + a * a - 2.0 * a * rho * std::cos(t) + zeta * zeta);
      };
      return -2.0 * integrate(f, 0.0, kPi, tol) / (4.0 * kPi);
    };
    nrz = rim(z - c) - rim(z + c);
    auto side = [&](double t) {
      const double A = std::max(rho * rho + a * a - 2.0 * a * rho * std::cos(t), 1e-300);
      const double s = std::sqrt(A);
      return a * std::cos(t) * (std::asinh((c - z) / s) + std::asinh((c + z) / s));
    };
    npp = 2.0 * integrate(side, 0.0, kPi, tol * rho) / (4.0 * kPi * rho);
  }
  const double nrr = 1.0 - nzz - npp;
  const double r = std::hypot(p.x, p.y);
  const double cs = r > 0.0 ? p.x / r : 1.0, sn = r > 0.0 ? p.y / r : 0.0;
  n[0] = nrr * cs * cs + npp * sn * sn;
  n[1] = (nrr - npp) * cs * sn;
  n[2] = nrz * cs;
  n[3] = nrr * sn * sn + npp * cs * cs;
  n[4] = nrz * sn;
  n[5] = nzz;
}

}  // namespace

VolumeMoments shape_box_moments(const Shape& shape, const Vec3& lo, const Vec3& hi) {
  return box_in_shape(shape, lo, hi);
}

double shape_depth(const Shape& shape, const Vec3& p) { return depth_inside(shape, p); }

namespace {

// Centre-inside cells (the paper's lattice): per axis max(1, floor(extent / h))
// points, so that no cell's cube reaches beyond the body; every point inside
// the shape is a cell standing for volume / N (h^3 for boxes whose edges are
// multiples of h). A lattice coarser than the body, or cell_size <= 0, gives
// one cell at the centre.
CellSet centre_inside_cells(const Shape& shape, double cell_size) {
  CellSet cells;
  const double volume = shape_volume(shape);
  const Vec3 half = shape_half_extents(shape);
  if (cell_size > 0.0) {
    std::array<int, 3> n{};
    for (int a = 0; a < 3; ++a)
      n[a] = std::max(1, static_cast<int>(std::floor(2.0 * half[a] / cell_size + 1e-9)));
    const double tol = 1e-9 * cell_size;
    for (int k = 0; k < n[2]; ++k)
      for (int j = 0; j < n[1]; ++j)
        for (int i = 0; i < n[0]; ++i) {
          const Vec3 p{(i - 0.5 * (n[0] - 1)) * cell_size, (j - 0.5 * (n[1] - 1)) * cell_size,
                       (k - 0.5 * (n[2] - 1)) * cell_size};
          if (!shape_contains(shape, p, tol)) continue;
          cells.local_positions.push_back(p);
          cells.lattice_index.push_back({i, j, k});
        }
    cells.lattice_extent = n;
    cells.spacing = cell_size;
  }
  if (cells.local_positions.empty()) {
    cells.local_positions.push_back({0.0, 0.0, 0.0});
    cells.lattice_index.push_back({0, 0, 0});
    cells.lattice_extent = {1, 1, 1};
    cells.spacing = 0.0;
  }
  cells.cell_volume = volume / static_cast<double>(cells.size());
  cells.volumes.assign(cells.size(), cells.cell_volume);
  // A box's cells: the part of the box each stands for, where the cells tile
  // it (a thin box's one layer: the layer, not the cube of edge h): extents
  // e_k = min(h, 2 (L_k/2 - |c_k|)), kept where they account for the cell's
  // volume; elsewhere the cube.
  if (const Box* box = std::get_if<Box>(&shape); box && cells.spacing > 0.0) {
    const double h = cells.spacing;
    for (int i = 0; i < cells.size(); ++i) {
      const Vec3& c = cells.local_positions[i];
      Vec3 e;
      for (int k = 0; k < 3; ++k) e[k] = std::min(h, 2.0 * (0.5 * box->size[k] - std::fabs(c[k])));
      const bool tiles = e.x > 0.0 && e.y > 0.0 && e.z > 0.0 &&
                         std::fabs(e.x * e.y * e.z - cells.cell_volume) <= 1e-6 * cells.cell_volume;
      cells.part_halves.push_back(tiles ? 0.5 * e : Vec3{0.5 * h, 0.5 * h, 0.5 * h});
    }
  }
  cells.contact_radius = cells.spacing > 0.0 ? 0.5 * cells.spacing : std::min({half.x, half.y, half.z});
  cells.contact_radii.assign(cells.size(), cells.contact_radius);
  cells.cell_radius = std::cbrt(3.0 * cells.cell_volume / (4.0 * kPi));
  return cells;
}

// The part of the cube of edge a centred on site inside the shape, as a
// volume-share cell: its volume, centroid and contact radius (the inscribed
// radius about the centroid, clamped to [a/4, a/2]); volume 0 for a cube
// with no more than kMinCellShare of its volume inside. whole: the cube lies
// inside (volume a^3, at the site).
struct ShareCell {
  double volume = 0.0;
  Vec3 centroid;
  double contact = 0.0;
  bool whole = true;
};

ShareCell share_cell(const Shape& shape, const Vec3& site, double a) {
  const double a3 = a * a * a;
  const Vec3 lo = site - Vec3{0.5 * a, 0.5 * a, 0.5 * a}, hi = site + Vec3{0.5 * a, 0.5 * a, 0.5 * a};
  if (box_inside_shape(shape, lo, hi, 1e-9 * a)) return {a3, site, 0.5 * a, true};
  const Moments m = box_in_shape(shape, lo, hi);
  if (!(m.v > kMinCellShare * a3)) return {};
  const Vec3 p = Vec3{m.x, m.y, m.z} / m.v;
  double in_region = 0.5 * a;
  for (int k = 0; k < 3; ++k) in_region = std::min({in_region, p[k] - lo[k], hi[k] - p[k]});
  return {m.v, p, std::clamp(std::min(in_region, depth_inside(shape, p)), 0.25 * a, 0.5 * a), false};
}

// Lattice points per axis of the volume-share cells at h: ceil(extent / h),
// so that the cubes cover the body.
std::array<int, 3> volume_share_extent(const Shape& shape, double h) {
  const Vec3 half = shape_half_extents(shape);
  std::array<int, 3> n{};
  for (int a = 0; a < 3; ++a) n[a] = static_cast<int>(std::ceil(2.0 * half[a] / h - 1e-9));
  return n;
}

// Volume-share cells: per axis ceil(extent / h) points, so that the cubes
// cover the body; every cube with more than kMinCellShare of its volume inside
// is a cell standing for its part of the body, at that part's centroid.
CellSet volume_share_cells(const Shape& shape, double h) {
  CellSet cells;
  const std::array<int, 3> n = volume_share_extent(shape, h);
  const Box* box = std::get_if<Box>(&shape);
  for (int k = 0; k < n[2]; ++k)
    for (int j = 0; j < n[1]; ++j)
      for (int i = 0; i < n[0]; ++i) {
        const Vec3 site = lattice_site(n, h, {i, j, k});
        const ShareCell c = share_cell(shape, site, h);
        if (c.volume == 0.0) continue;
        if (!c.whole) cells.whole_cells = false;
        cells.local_positions.push_back(c.centroid);
        cells.lattice_index.push_back({i, j, k});
        cells.volumes.push_back(c.volume);
        cells.contact_radii.push_back(c.contact);
        if (box) {  // the part cube ∩ box, a cuboid about the centroid
          Vec3 half;
          for (int a = 0; a < 3; ++a)
            half[a] = 0.5 * (std::min(site[a] + 0.5 * h, 0.5 * box->size[a]) -
                             std::max(site[a] - 0.5 * h, -0.5 * box->size[a]));
          cells.part_halves.push_back(c.whole ? Vec3{0.5 * h, 0.5 * h, 0.5 * h} : half);
        }
      }
  cells.lattice_extent = n;
  cells.spacing = h;
  cells.cell_volume = h * h * h;
  cells.contact_radius = 0.5 * h;
  cells.cell_radius = std::cbrt(3.0 * cells.cell_volume / (4.0 * kPi));
  return cells;
}

}  // namespace

bool uses_volume_shares(const Shape& shape, double cell_size, bool responsive) {
  if (!(cell_size > 0.0)) return false;
  if (!responsive) return true;
  const Vec3 half = shape_half_extents(shape);
  for (int a = 0; a < 3; ++a)
    if (2.0 * half[a] < kMinVolumeShareExtent * cell_size) return false;
  return true;
}

namespace {

// Cells per axis of a box at cell_size, as centre_inside_cells.
std::array<int, 3> box_cell_counts(const Shape& shape, double cell_size) {
  const Vec3 half = shape_half_extents(shape);
  std::array<int, 3> n{};
  for (int a = 0; a < 3; ++a)
    n[a] = std::max(1, static_cast<int>(std::floor(2.0 * half[a] / cell_size + 1e-9)));
  return n;
}

}  // namespace

bool uses_graded_cells(const Shape& shape, double cell_size) {
  if (!(cell_size > 0.0) || !std::holds_alternative<Box>(shape)) return false;
  const std::array<int, 3> n = box_cell_counts(shape, cell_size);
  for (int a = 0; a < 3; ++a)
    if (n[a] < kMinGradedExtent) return false;
  return static_cast<long>(n[0]) * n[1] * n[2] <= kMaxGradedCells;
}

CellSet make_graded_box_cells(const Shape& shape, double cell_size) {
  if (!uses_graded_cells(shape, cell_size))
    throw std::invalid_argument("make_graded_box_cells: not a box of graded cells at this cell size");
  const Vec3 half = shape_half_extents(shape);
  const std::array<int, 3> n = box_cell_counts(shape, cell_size);
  // Faces per axis at the Chebyshev-Lobatto points x_k = -half cos(pi k / n).
  std::array<std::vector<double>, 3> faces;
  for (int a = 0; a < 3; ++a) {
    faces[a].resize(n[a] + 1);
    for (int k = 0; 2 * k <= n[a]; ++k) {  // mirror-symmetric to the bit
      faces[a][k] = -half[a] * std::cos(kPi * k / n[a]);
      faces[a][n[a] - k] = -faces[a][k];
    }
    if (n[a] % 2 == 0) faces[a][n[a] / 2] = 0.0;
  }
  CellSet cells;
  for (int k = 0; k < n[2]; ++k)
    for (int j = 0; j < n[1]; ++j)
      for (int i = 0; i < n[0]; ++i) {
        const int l[3] = {i, j, k};
        Vec3 p, w;
        for (int a = 0; a < 3; ++a) {
          p[a] = 0.5 * (faces[a][l[a]] + faces[a][l[a] + 1]);
          w[a] = 0.5 * (faces[a][l[a] + 1] - faces[a][l[a]]);
        }
        cells.local_positions.push_back(p);
        cells.lattice_index.push_back({i, j, k});
        cells.half_extents.push_back(w);
        cells.volumes.push_back(8.0 * w.x * w.y * w.z);
        cells.contact_radii.push_back(std::min({w.x, w.y, w.z}));
      }
  cells.faces = faces;
  cells.lattice_extent = n;
  cells.spacing = 2.0 * half.x / n[0];
  cells.cell_volume = shape_volume(shape) / static_cast<double>(cells.size());
  cells.cell_radius = std::cbrt(3.0 * cells.cell_volume / (4.0 * kPi));
  cells.contact_radius = *std::max_element(cells.contact_radii.begin(), cells.contact_radii.end());
  cells.whole_cells = false;
  cells.graded = true;
  return cells;
}

CellSet make_cells(const Shape& shape, double cell_size, bool responsive) {
  return uses_volume_shares(shape, cell_size, responsive) ? volume_share_cells(shape, cell_size)
                                                          : centre_inside_cells(shape, cell_size);
}

std::vector<double> default_refinement_radii(double cell_size) {
  return {1.25 * cell_size, 0.75 * cell_size, 0.25 * cell_size};
}

CellSet make_refined_cells(const Shape& shape, double cell_size, const std::vector<RefinedZone>& zones) {
  if (!uses_volume_shares(shape, cell_size))
    throw std::invalid_argument("refined zones need a body at least 2 cells across along every axis "
                                "(volume-share cells)");
  for (const RefinedZone& z : zones) {
    if (!is_finite(z.point)) throw std::invalid_argument("refined zone: the point must be finite");
    if (z.radii.size() > kMaxRefinementLevels)
      throw std::invalid_argument("refined zone: at most " + std::to_string(kMaxRefinementLevels) +
                                  " levels");
    for (double r : z.radii)
      if (!(r >= 0.0) || !std::isfinite(r))
        throw std::invalid_argument("refined zone: the radii must be finite and not negative");
  }
  const double h = cell_size;
  const std::array<int, 3> n = volume_share_extent(shape, h);
  const Box* box = std::get_if<Box>(&shape);
  CellSet cells;
  // A cube of edge a at level l is split when it comes within radii[l] of a zone's point.
  auto split = [&](const Vec3& site, double a, size_t level) {
    for (const RefinedZone& z : zones) {
      if (level >= z.radii.size()) continue;
      double d2 = 0.0;
      for (int k = 0; k < 3; ++k) {
        const double e = std::max(0.0, std::fabs(z.point[k] - site[k]) - 0.5 * a);
        d2 += e * e;
      }
      // Ties (a cube exactly D_l away: symmetric scenes) are not refined.
      if (d2 < z.radii[level] * z.radii[level] * (1.0 - 1e-9)) return true;
    }
    return false;
  };
  // Depth first, the 8 sub-cubes of a split cube in x-fastest order in its
  // place: the order depends only on the geometry.
  auto emit = [&](auto&& self, const Vec3& site, double a, size_t level,
                  const std::array<int, 3>& index) -> void {
    if (split(site, a, level)) {
      for (int dz = 0; dz < 2; ++dz)
        for (int dy = 0; dy < 2; ++dy)
          for (int dx = 0; dx < 2; ++dx)
            self(self, site + 0.25 * a * Vec3{2.0 * dx - 1.0, 2.0 * dy - 1.0, 2.0 * dz - 1.0}, 0.5 * a,
                 level + 1, {2 * index[0] + dx, 2 * index[1] + dy, 2 * index[2] + dz});
      return;
    }
    const ShareCell c = share_cell(shape, site, a);
    if (c.volume == 0.0) return;
    if (box) {  // the part sub-cube ∩ box, a cuboid about the centroid
      Vec3 half;
      for (int k = 0; k < 3; ++k)
        half[k] = 0.5 * (std::min(site[k] + 0.5 * a, 0.5 * box->size[k]) -
                         std::max(site[k] - 0.5 * a, -0.5 * box->size[k]));
      cells.part_halves.push_back(half);
    }
    if (cells.size() >= kMaxRefinedCells)
      throw std::invalid_argument("refined zones give more than " + std::to_string(kMaxRefinedCells) +
                                  " cells (their intra-body tensors take 48 bytes per pair of cells)");
    cells.local_positions.push_back(c.centroid);
    cells.lattice_index.push_back(index);
    cells.volumes.push_back(c.volume);
    cells.contact_radii.push_back(c.contact);
    cells.cube_centres.push_back(site);
    cells.half_extents.push_back({0.5 * a, 0.5 * a, 0.5 * a});
  };
  for (int k = 0; k < n[2]; ++k)
    for (int j = 0; j < n[1]; ++j)
      for (int i = 0; i < n[0]; ++i) emit(emit, lattice_site(n, h, {i, j, k}), h, 0, {i, j, k});
  cells.lattice_extent = n;
  cells.spacing = h;
  cells.cell_volume = h * h * h;
  cells.contact_radius = 0.5 * h;
  cells.cell_radius = std::cbrt(3.0 * cells.cell_volume / (4.0 * kPi));
  cells.whole_cells = false;
  cells.refined = true;
  return cells;
}

void uniform_demag_over_cell(const Shape& shape, const CellSet& cells, int i, double n[6]) {
  for (int a = 0; a < 6; ++a) n[a] = 0.0;
  static const double g3x[3] = {-0.774596669241483377035853079956, 0.0, 0.774596669241483377035853079956};
  static const double g3w[3] = {5.0 / 18.0, 8.0 / 18.0, 5.0 / 18.0};  // weights / 2 (mean over [-1, 1])
  // The cell's region, as make_cells: its cube (clipped to the body below).
  const Vec3 site = cells.cube_centre(i), half = cells.cube_half(i);
  const Vec3 rlo = site - half, rhi = site + half;
  std::visit(Overloaded{
                 [&](const Sphere&) { n[0] = n[3] = n[5] = 1.0 / 3.0; },
                 [&](const Box& b) {
                   // The mean over the cell's part (a cuboid) of the box's own
                   // field: the mutual tensor of the two cuboids.
                   const Vec3 e = 0.5 * b.size;
                   double lo[3], hi[3], part[3], whole[3], d[3];
                   for (int k = 0; k < 3; ++k) {
                     lo[k] = std::max(rlo[k], -e[k]);
                     hi[k] = std::min(rhi[k], e[k]);
                     part[k] = 0.5 * (hi[k] - lo[k]);
                     whole[k] = e[k];
                     d[k] = 0.5 * (lo[k] + hi[k]);
                   }
                   cuboid_demag_tensor(part, whole, d, n);
                 },
                 [&](const Cylinder& c) {
                   const Vec3& p = cells.local_positions[i];
                   const double e = 0.5 * c.length;
                   const double lo = std::max(rlo.z, -e), hi = std::min(rhi.z, e);
                   for (int w = 0; w < 3; ++w) {
                     double t[6];
                     cylinder_demag_tensor(c.radius, e, {p.x, p.y, 0.5 * (lo + hi) + 0.5 * (hi - lo) * g3x[w]}, t);
                     for (int a = 0; a < 6; ++a) n[a] += g3w[w] * t[a];
                   }
                 },
                 [&](const Mesh& m) { mesh_demag_tensor(m, cells.local_positions[i], n); },
                 [&](const Compound& c) { compound_demag_tensor(c, cells.local_positions[i], n); },
             },
             shape);
}

}  // namespace odemag
