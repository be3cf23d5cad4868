// TEAM workshop problem 20 (3-D static force problem), shared by
// tests/magnetics/team20_test.cpp and benchmarks/team20.cpp (docs/validation.md
// "TEAM 20").
//
// Data from the public benchmark: the problem statement (Compumag TEAM
// problem 20: geometry, B-H curve of the steel, its Table 1) and the measured
// force and gap flux density of N. Takahashi, T. Nakata, H. Morishige,
// "Summary of results for problem 20 (3-D static force problem)", COMPEL
// 14(2/3), 57-75, 1995 (Tables 4 and 6).
//
// Geometry (mm, z up, symmetric about x = 0 and y = 0): yoke 25 deep (|y| <=
// 12.5) of a bottom bar |x| <= 63.5, 0 <= z <= 25, two columns 38.5 <= |x| <=
// 63.5, 25 <= z <= 125 and two top bars 13.5 <= |x| <= 63.5, 125 <= z <= 150;
// centre pole |x| <= 12.5, |y| <= 5, 26.5 <= z <= 125 (1.5 mm above the bar);
// coil: rounded-square annulus, outer 75 x 75 (corner radius 23), inner 39 x
// 39 (corner radius 5), 26.7 <= z <= 123.3, uniform current density. Gap
// probes P1 = (0, 0, 25.75), P2 = (12.5, 5, 25.75).
//
// Discretization (the rule, docs/validation.md "TEAM 20"): every cell is
// all steel (no cut cells: a cut cell is a full cuboid of weaker M whose
// charge sits in the air beside the steel, in series with the gaps' flux).
// Cubes of edge h (25 / h and 10 / h integers) on lattices with arbitrary
// offsets: the pole's from its corner (-12.5, -5, 26.5), exact in its
// cross-section and the 1.5 mm gap, up to the last whole cube below z = 125,
// and a layer of flat cells (h, h, t) up to z = 125 (t = 98.5 mm mod h);
// the bottom bar's centred on x = 0 (cell faces on the pole's faces x =
// +-12.5), exact in y and z, its whole cubes within |x| <= 63.5 and at each
// end a layer of thin cells (t, h, h) (t = 51 mm mod h); each column with its
// top bar from the yoke's outer face (x = -63.5 and 13.5, z = 25): exact, the
// 1 mm between pole and top bars included. The layers are lattices of their
// own whose cells are smaller than the spacing (LatticeGrid::extent).
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <vector>

#include "magnetics/materials/bh_curve.h"
#include "magnetics/static/bh_lattice_solve.h"
#include "magnetics/kernels/cell_field.h"
#include "magnetics/sources/coil.h"
#include "magnetics/static/cuboid_demag.h"
#include "odemag/constants.h"
#include "magnetics/static/lattice_fft.h"

namespace odemag::team20 {

// The steel's B-H curve, TEAM 20 Table 1: (H in A/m, B in T).
inline std::vector<std::array<double, 2>> bh_table() {
  return {{0.0, 0.0},      {27.0, 0.01},   {58.0, 0.025},   {100.0, 0.05},   {153.0, 0.1},   {185.0, 0.15},
          {205.0, 0.2},    {233.0, 0.3},   {255.0, 0.4},    {285.0, 0.5},    {320.0, 0.6},   {355.0, 0.7},
          {405.0, 0.8},    {470.0, 0.9},   {555.0, 1.0},    {673.0, 1.1},    {836.0, 1.2},   {1065.0, 1.3},
          {1220.0, 1.35},  {1420.0, 1.4},  {1720.0, 1.45},  {2130.0, 1.5},   {2670.0, 1.55}, {3480.0, 1.6},
          {4500.0, 1.65},  {5950.0, 1.7},  {7650.0, 1.75},  {10100.0, 1.8},  {13000.0, 1.85}, {15900.0, 1.9},
          {21100.0, 1.95}, {26300.0, 2.0}, {32900.0, 2.05}, {42700.0, 2.1},  {61700.0, 2.15}, {84300.0, 2.2},
          {110000.0, 2.25}, {135000.0, 2.3}};
}

// Measured (COMPEL 14, 1995, Tables 4 and 6): ampere-turns, force on the pole
// (N, toward the bar), Bz at P1 and P2 (T).
struct Measured {
  double ampere_turns, force, Bz_P1, Bz_P2;
};
inline constexpr Measured kMeasured[4] = {
    {1000.0, 8.1, 0.36, 0.24}, {3000.0, 54.4, 0.84, 0.63}, {4500.0, 75.0, 0.99, 0.72}, {5000.0, 80.1, 1.03, 0.74}};

inline constexpr double kMm = 1e-3;

struct Box {
  Vec3 lo, hi;  // m
};

inline std::vector<Box> pole_boxes() { return {{{-12.5 * kMm, -5 * kMm, 26.5 * kMm}, {12.5 * kMm, 5 * kMm, 125 * kMm}}}; }

inline std::vector<Box> yoke_boxes() {
  const double y = 12.5 * kMm;
  return {{{-63.5 * kMm, -y, 0.0}, {63.5 * kMm, y, 25 * kMm}},
          {{-63.5 * kMm, -y, 25 * kMm}, {-38.5 * kMm, y, 125 * kMm}},
          {{38.5 * kMm, -y, 25 * kMm}, {63.5 * kMm, y, 125 * kMm}},
          {{-63.5 * kMm, -y, 125 * kMm}, {-13.5 * kMm, y, 150 * kMm}},
          {{13.5 * kMm, -y, 125 * kMm}, {63.5 * kMm, y, 150 * kMm}}};
}

// The coil for `ampere_turns` (one turn carrying the whole current).
inline RoundedRectangleCoil coil(double ampere_turns) {
  RoundedRectangleCoil c;
  c.centre = {0.0, 0.0, 75 * kMm};
  c.core_half_width = c.core_half_depth = 14.5 * kMm;  // 75 / 2 - 23 = 39 / 2 - 5
  c.inner_corner_radius = 5 * kMm;
  c.outer_corner_radius = 23 * kMm;
  c.height = 96.6 * kMm;
  c.current = ampere_turns;
  return c;
}

inline const Vec3 kP1{0.0, 0.0, 25.75 * kMm}, kP2{12.5 * kMm, 5 * kMm, 25.75 * kMm};

// The coil's field at 1 A-turn at the cells' centres, and at the first
// `pole` of them its gradient (row a: d/dx_a) by central differences of step
// d (the coil field is smooth there: the pole is 7 mm from the copper).
inline void unit_coil_fields(const std::vector<Vec3>& centres, int pole, double d, std::vector<Vec3>& H,
                             std::vector<std::array<Vec3, 3>>& gradient) {
  const RoundedRectangleCoil unit = coil(1.0);
  const int N = static_cast<int>(centres.size());
  H.resize(N);
  gradient.resize(pole);
#pragma omp parallel for schedule(dynamic, 8)
  for (int i = 0; i < N; ++i) {
    H[i] = coil_field_H(unit, centres[i]);
    if (i < pole)
      for (int a = 0; a < 3; ++a) {
        Vec3 e{};
        e[a] = d;
        gradient[i][a] = (coil_field_H(unit, centres[i] + e) - coil_field_H(unit, centres[i] - e)) / (2.0 * d);
      }
  }
}

// Lattice of cells of edges e (spacing h per axis) with cell (0, 0, 0)
// spanning [corner, corner + e] and n cells per axis; a cell where it lies
// inside the boxes (every cell all steel or none, by the rule above).
inline LatticeGrid box_lattice(const Vec3& corner, const Vec3& h, const std::array<int, 3>& n,
                               const std::vector<Box>& boxes, const Vec3& e) {
  LatticeGrid g;
  g.origin = corner + 0.5 * e;
  g.n = n;
  g.extent = e;
  g.mask.assign(static_cast<size_t>(n[0]) * n[1] * n[2], 0);
  for (int k = 0; k < n[2]; ++k)
    for (int j = 0; j < n[1]; ++j)
      for (int i = 0; i < n[0]; ++i) {
        const Vec3 c = g.origin + Vec3{i * h.x, j * h.y, k * h.z};
        for (const Box& b : boxes)
          if (c.x > b.lo.x && c.x < b.hi.x && c.y > b.lo.y && c.y < b.hi.y && c.z > b.lo.z && c.z < b.hi.z)
            g.mask[i + static_cast<size_t>(n[0]) * (j + static_cast<size_t>(n[1]) * k)] = 1;
      }
  return g;
}

// The discretized problem at cell edges h = (hx, hy, hz) (mm; 25 / hx,
// 10 / hy, 25 / hy and 25 / hz integers): cubes, or cuboids coarser along z.
struct Problem {
  Vec3 h;  // m
  bool balance = false;
  std::vector<Vec3> coil_H;          // coil field at 1 A-turn at the cell centres, A/m
  std::vector<std::array<Vec3, 3>> coil_gradient;  // pole cells: d(coil_H)/dx_a (row a), 1 A-turn
  int pole_lattices = 0;  // set by make (declared before demag, which is built by it)
  LatticeDemag demag;
  BhCurve curve{bh_table()};

  // Lattices: the pole's (its cells, then its top layer when hz does not
  // divide 98.5 mm), then the yoke's: the bottom bar's cells, its end layers
  // (when hx does not divide 51 mm), the left and right column with its top bar.
  static LatticeDemag make(const Vec3& h, bool balance, int& pole_lattices) {
    auto whole = [](double length_mm, double edge) {
      return static_cast<int>(std::floor((length_mm * kMm + 1e-9 * edge) / edge));
    };
    const auto yoke = yoke_boxes();
    const std::vector<Box> pole = pole_boxes(), bar{yoke[0]}, left{yoke[1], yoke[3]}, right{yoke[2], yoke[4]};
    const int px = whole(25.0, h.x), py = whole(10.0, h.y), pz = whole(98.5, h.z), y = whole(25.0, h.y);
    const int bar_z = whole(25.0, h.z), side_x = whole(50.0, h.x), side_z = whole(125.0, h.z);
    std::vector<LatticeGrid> g;
    g.push_back(box_lattice({-12.5 * kMm, -5 * kMm, 26.5 * kMm}, h, {px, py, pz}, pole, h));
    const double top = 98.5 * kMm - pz * h.z;  // the pole's top layer
    if (top > 1e-9 * h.z)
      g.push_back(box_lattice({-12.5 * kMm, -5 * kMm, 125 * kMm - top}, h, {px, py, 1}, pole, {h.x, h.y, top}));
    pole_lattices = static_cast<int>(g.size());
    const int k = whole(51.0, h.x);
    const double reach = 12.5 * kMm + k * h.x, end = 63.5 * kMm - reach;  // the bar's cells reach |x| = reach
    g.push_back(box_lattice({-reach, -12.5 * kMm, 0.0}, h, {2 * k + px, y, bar_z}, bar, h));
    if (end > 1e-9 * h.x) {
      g.push_back(box_lattice({-63.5 * kMm, -12.5 * kMm, 0.0}, h, {1, y, bar_z}, bar, {end, h.y, h.z}));
      g.push_back(box_lattice({reach, -12.5 * kMm, 0.0}, h, {1, y, bar_z}, bar, {end, h.y, h.z}));
    }
    g.push_back(box_lattice({-63.5 * kMm, -12.5 * kMm, 25 * kMm}, h, {side_x, y, side_z}, left, h));
    g.push_back(box_lattice({13.5 * kMm, -12.5 * kMm, 25 * kMm}, h, {side_x, y, side_z}, right, h));
    std::vector<std::array<int, 2>> pairs;
    for (int t = 0; t < pole_lattices; ++t)
      for (int s = pole_lattices; s < static_cast<int>(g.size()); ++s) {
        pairs.push_back({t, s});
        if (balance) pairs.push_back({s, t});
      }
    return LatticeDemag(h, g, pairs);
  }

  int pole_cells() const { return demag.first_cell(pole_lattices); }

  // balance: also the forces on the yoke from the pole (the momentum check).
  explicit Problem(const Vec3& h_mm, bool with_balance = false)
      : h(kMm * h_mm), balance(with_balance), demag(make(h, with_balance, pole_lattices)) {
    std::vector<Vec3> centres(demag.cells());
    for (int i = 0; i < demag.cells(); ++i) centres[i] = demag.centre(i);
    unit_coil_fields(centres, pole_cells(), 1e-2 * std::min({h.x, h.y, h.z}), coil_H, coil_gradient);
  }
  explicit Problem(double h_mm, bool with_balance = false) : Problem(Vec3{h_mm, h_mm, h_mm}, with_balance) {}
};

struct Result {
  BhSolveReport report;
  Vec3 force_pole;         // N, on the pole from yoke and coil
  Vec3 force_from_yoke;    // the yoke's part of it
  Vec3 force_on_yoke;      // on the yoke from the pole (momentum balance: -force_from_yoke); with balance only
  double Bz_P1 = 0.0, Bz_P2 = 0.0;  // T
};

// B (T) at a point outside the steel: the coil's and every cell's field.
inline Vec3 flux_density(const Problem& p, const std::vector<Vec3>& M, double ampere_turns, const Vec3& point) {
  Vec3 H = coil_field_H(coil(ampere_turns), point);
  for (int i = 0; i < p.demag.cells(); ++i)
    H += uniform_cuboid_field(point - p.demag.centre(i), 0.5 * p.demag.extent(p.demag.lattice_of(i)), M[i]);
  return kMu0 * H;
}

// Solves at `ampere_turns` from M (a previous solution or zeros).
inline Result solve(const Problem& p, double ampere_turns, std::vector<Vec3>& M, const BhSolveOptions& options = {}) {
  std::vector<Vec3> source(p.coil_H.size());
  for (size_t i = 0; i < source.size(); ++i) source[i] = ampere_turns * p.coil_H[i];
  Result r;
  const std::vector<double> fill(p.coil_H.size(), 1.0);  // every cell all steel
  r.report = solve_bh_lattice(p.demag, p.curve, fill, source, M, options);
  for (int t = 0; t < p.pole_lattices; ++t)
    for (int s = p.pole_lattices; s < p.demag.lattice_count(); ++s) {
      r.force_from_yoke += p.demag.force(t, s, M);
      if (p.balance) r.force_on_yoke += p.demag.force(s, t, M);
    }
  // The coil's part, mu0 V sum (M . grad) H_coil at the pole's cell centres.
  Vec3 coil_force{};
  for (int i = 0; i < p.pole_cells(); ++i)
    for (int a = 0; a < 3; ++a)
      coil_force += (kMu0 * p.demag.volume(p.demag.lattice_of(i)) * ampere_turns * M[i][a]) * p.coil_gradient[i][a];
  r.force_pole = r.force_from_yoke + coil_force;
  r.Bz_P1 = flux_density(p, M, ampere_turns, kP1).z;
  r.Bz_P2 = flux_density(p, M, ampere_turns, kP2).z;
  return r;
}

// Graded cells with the mirror planes x = 0 and y = 0 (docs/validation.md
// "TEAM 20", docs/model.md "Graded cells with mirror planes"): the quarter
// x, y >= 0 of every box cut into a tensor-product grid whose cells are
// h_min at the refined faces (every face in the air, the faces where bars
// meet, and the lines where a facing body's edge lies: the pole's x = 12.5
// on the bar, its y = 5 on the bar, the columns and the top bars, the
// columns' x = 38.5 on the bar and the top bars)
// and grow by `growth` per cell away from them up to h_max; the symmetry
// planes are not refined. The dense sum of magnetics/static/cuboid_demag.h, with
// the images in both planes.
struct Grading {
  double h_min, growth, h_max;  // mm
};

// Faces of [lo, hi] (mm) graded toward the refine points (those within [lo,
// hi] are faces): the target edge s(x) = min(h_max, h_min + (growth - 1)
// dist(x, refine)) grows geometrically along a march; each stretch between
// faces is cut into ceil(integral dx / s) cells of equal share of that
// integral.
inline std::vector<double> graded_faces(double lo, double hi, const std::vector<double>& refine, const Grading& g) {
  std::vector<double> breaks = {lo, hi};
  for (double r : refine)
    if (r > lo && r < hi) breaks.push_back(r);
  std::sort(breaks.begin(), breaks.end());
  auto edge = [&](double x) {
    double d = 1e300;
    for (double r : refine) d = std::min(d, std::fabs(x - r));
    return std::min(g.h_max, g.h_min + (g.growth - 1.0) * d);
  };
  std::vector<double> faces = {lo};
  constexpr int kSamples = 4000;
  for (size_t b = 0; b + 1 < breaks.size(); ++b) {
    const double a = breaks[b], c = breaks[b + 1], dx = (c - a) / kSamples;
    std::vector<double> phi(kSamples + 1, 0.0);  // integral of dx / s from a
    for (int k = 0; k < kSamples; ++k) phi[k + 1] = phi[k] + dx / edge(a + (k + 0.5) * dx);
    const int n = std::max(1, static_cast<int>(std::ceil(phi[kSamples] - 1e-6)));
    int k = 0;
    for (int f = 1; f < n; ++f) {
      const double target = phi[kSamples] * f / n;
      while (phi[k + 1] < target) ++k;
      faces.push_back(a + dx * (k + (target - phi[k]) / (phi[k + 1] - phi[k])));
    }
    faces.push_back(c);
  }
  return faces;
}

struct GradedProblem {
  Grading grading;
  bool balance = false;
  int pole_cells = 0;  // the pole's cells come first
  CuboidDemag demag;
  CuboidDemag::ForceOperator force_from_yoke, force_on_yoke;  // (2) of magnetics/static/cuboid_demag.h
  std::vector<Vec3> coil_H;                        // at 1 A-turn, at the cell centres
  std::vector<std::array<Vec3, 3>> coil_gradient;  // pole cells: d(coil_H)/dx_a, 1 A-turn
  BhCurve curve{bh_table()};

  // The quarter boxes (mm) with their refine points per axis.
  struct QuarterBox {
    std::array<double, 2> x, y, z;
    std::vector<double> refine_x, refine_y, refine_z;
  };
  static std::vector<QuarterBox> boxes() {
    return {{{0, 12.5}, {0, 5}, {26.5, 125}, {12.5}, {5}, {26.5, 125}},                  // pole
            {{0, 63.5}, {0, 12.5}, {0, 25}, {12.5, 38.5, 63.5}, {5, 12.5}, {0, 25}},    // bottom bar
            {{38.5, 63.5}, {0, 12.5}, {25, 125}, {38.5, 63.5}, {5, 12.5}, {25, 125}},   // column
            {{13.5, 63.5}, {0, 12.5}, {125, 150}, {13.5, 38.5, 63.5}, {5, 12.5}, {125, 150}}};  // top bar
  }
  static std::vector<CuboidCell> make(const Grading& g, int& pole_cells) {
    std::vector<CuboidCell> cells;
    bool first = true;
    for (const QuarterBox& b : boxes()) {
      auto faces = [&](const std::array<double, 2>& range, const std::vector<double>& refine) {
        std::vector<double> f = graded_faces(range[0], range[1], refine, g);
        for (double& x : f) x *= kMm;
        return f;
      };
      const auto box = grid_cells(faces(b.x, b.refine_x), faces(b.y, b.refine_y), faces(b.z, b.refine_z));
      cells.insert(cells.end(), box.begin(), box.end());
      if (first) pole_cells = static_cast<int>(cells.size());
      first = false;
    }
    return cells;
  }

  // balance: also the forces on the yoke from the pole (the momentum check).
  // The operator dense, or as a hierarchical matrix (magnetics/static/hmatrix.h)
  // in double or single precision.
  enum class Storage { dense, compressed, compressed_single };
  explicit GradedProblem(const Grading& g, bool with_balance = false, Storage storage = Storage::compressed)
      : grading(g), balance(with_balance), demag(make(g, pole_cells), true, true) {
    std::vector<Vec3> centres(demag.cells());
    for (int i = 0; i < demag.cells(); ++i) centres[i] = demag.cell(i).centre;
    unit_coil_fields(centres, pole_cells, 1e-2 * kMm * g.h_min, coil_H, coil_gradient);
    const int N = demag.cells();
    force_from_yoke = demag.force_operator(0, pole_cells, pole_cells, N);
    if (balance) force_on_yoke = demag.force_operator(pole_cells, N, 0, pole_cells);
    HMatrixOptions options;
    options.single_precision = storage == Storage::compressed_single;
    if (storage != Storage::dense) demag.compress(options);
  }
  // All cells of the whole problem (the quarter's times four).
  int full_cells() const { return 4 * demag.cells(); }
};

inline Result solve(const GradedProblem& p, double ampere_turns, std::vector<Vec3>& M, const BhSolveOptions& options = {}) {
  const int N = p.demag.cells();
  std::vector<Vec3> source(N);
  for (int i = 0; i < N; ++i) source[i] = ampere_turns * p.coil_H[i];
  Result r;
  const std::vector<double> fill(N, 1.0);
  r.report = solve_bh_lattice(p.demag, p.curve, fill, source, M, options);
  r.force_from_yoke = p.force_from_yoke(M);
  if (p.balance) r.force_on_yoke = p.force_on_yoke(M);
  // The coil's part on the quarter's pole cells, then on all four images.
  Vec3 quarter{};
  for (int i = 0; i < p.pole_cells; ++i)
    for (int a = 0; a < 3; ++a) quarter += (kMu0 * p.demag.volume(i) * ampere_turns * M[i][a]) * p.coil_gradient[i][a];
  Vec3 coil_force{};
  for (const Vec3& s : p.demag.images()) coil_force += Vec3{s.x * quarter.x, s.y * quarter.y, s.z * quarter.z};
  r.force_pole = r.force_from_yoke + coil_force;
  r.Bz_P1 = kMu0 * (coil_field_H(coil(ampere_turns), kP1) + p.demag.field_at(kP1, M)).z;
  r.Bz_P2 = kMu0 * (coil_field_H(coil(ampere_turns), kP2) + p.demag.field_at(kP2, M)).z;
  return r;
}

}  // namespace odemag::team20
