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
// Discretization (the rule, docs/validation.md "TEAM 20"): cubic cells of
// edge h (25 / h and 2.5 / h integers) on four lattices with arbitrary
// offsets: the pole's from its corner (-12.5, -5, 26.5), exact in its
// cross-section and the 1.5 mm gap, its top cell cut at z = 125; each column
// with its top bar from the yoke's outer face (x = -63.5 and 13.5, z = 25):
// exact, the 1 mm between pole and top bars included; the bottom bar centred
// on x = 0, exact in y and z, its 127 mm length in ceil(127 / h) cells with
// the end cells cut. A cell's volume share of steel w (the overlap of the cell
// with the body's boxes over h^3) is its mean magnetization's weight
// (bh_lattice_solve.h (3)).
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <vector>

#include "magnetics/bh_curve.h"
#include "magnetics/bh_lattice_solve.h"
#include "magnetics/cell_field.h"
#include "magnetics/coil.h"
#include "magnetics/constants.h"
#include "magnetics/lattice_fft.h"

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

// Lattice of cubes of edge h with cell (0, 0, 0) spanning [corner, corner + h]
// and n cells per axis; each cell's volume share of the boxes.
inline LatticeGrid box_lattice(const Vec3& corner, double h, const std::array<int, 3>& n,
                               const std::vector<Box>& boxes, std::vector<double>& share) {
  LatticeGrid g;
  g.origin = corner + Vec3{0.5 * h, 0.5 * h, 0.5 * h};
  g.n = n;
  g.mask.assign(static_cast<size_t>(n[0]) * n[1] * n[2], 0);
  for (int k = 0; k < n[2]; ++k)
    for (int j = 0; j < n[1]; ++j)
      for (int i = 0; i < n[0]; ++i) {
        const Vec3 lo = corner + Vec3{i * h, j * h, k * h};
        double w = 0.0;
        for (const Box& b : boxes) {
          double v = 1.0;
          for (int a = 0; a < 3; ++a) v *= std::max(0.0, std::min(lo[a] + h, b.hi[a]) - std::max(lo[a], b.lo[a])) / h;
          w += v;
        }
        if (w > 1e-9) {  // slivers below 1e-9 of a cell (round-off at shared faces) are not cells
          g.mask[i + static_cast<size_t>(n[0]) * (j + static_cast<size_t>(n[1]) * k)] = 1;
          share.push_back(std::min(w, 1.0));
        }
      }
  return g;
}

// The discretized problem at cell edge h (mm; 25 / h and 2.5 / h integers).
struct Problem {
  double h = 0.0;  // m
  bool balance = false;
  std::vector<double> fill;          // volume share per cell (pole cells first)
  std::vector<Vec3> coil_H;          // coil field at 1 A-turn at the cell centres, A/m
  std::vector<std::array<Vec3, 3>> coil_gradient;  // pole cells: d(coil_H)/dx_a (row a), 1 A-turn
  LatticeDemag demag;
  BhCurve curve{bh_table()};

  // Lattices: 0 the pole, 1 the bottom bar, 2 and 3 the left and right
  // column with its top bar (x faces on the yoke's outer face).
  static LatticeDemag make(double h, std::vector<double>& fill, bool balance) {
    auto cells = [h](double length_mm) { return static_cast<int>(std::ceil(length_mm * kMm / h - 1e-9)); };
    const auto yoke = yoke_boxes();
    const std::vector<Box> bar{yoke[0]}, left{yoke[1], yoke[3]}, right{yoke[2], yoke[4]};
    const int bar_x = cells(127.0), side_x = cells(50.0), side_z = cells(125.0), y = cells(25.0);
    std::vector<LatticeGrid> g;
    g.push_back(box_lattice({-12.5 * kMm, -5 * kMm, 26.5 * kMm}, h, {cells(25.0), cells(10.0), cells(98.5)}, pole_boxes(), fill));
    g.push_back(box_lattice({-0.5 * bar_x * h, -12.5 * kMm, 0.0}, h, {bar_x, y, cells(25.0)}, bar, fill));
    g.push_back(box_lattice({-63.5 * kMm, -12.5 * kMm, 25 * kMm}, h, {side_x, y, side_z}, left, fill));
    g.push_back(box_lattice({13.5 * kMm, -12.5 * kMm, 25 * kMm}, h, {side_x, y, side_z}, right, fill));
    std::vector<std::array<int, 2>> pairs{{0, 1}, {0, 2}, {0, 3}};
    if (balance) pairs.insert(pairs.end(), {{1, 0}, {2, 0}, {3, 0}});
    return LatticeDemag({h, h, h}, g, pairs);
  }

  // balance: also the forces on the yoke from the pole (the momentum check).
  explicit Problem(double h_mm, bool with_balance = false)
      : h(h_mm * kMm), balance(with_balance), demag(make(h, fill, with_balance)) {
    const RoundedRectangleCoil unit = coil(1.0);
    const int N = demag.cells(), pole = demag.cells_of(0);
    coil_H.resize(N);
    coil_gradient.resize(pole);
    const double d = 1e-2 * h;  // central differences of the smooth coil field (the pole is 7 mm from the copper)
#pragma omp parallel for schedule(dynamic, 8)
    for (int i = 0; i < N; ++i) {
      const Vec3 c = demag.centre(i);
      coil_H[i] = coil_field_H(unit, c);
      if (i < pole)
        for (int a = 0; a < 3; ++a) {
          Vec3 e{};
          e[a] = d;
          coil_gradient[i][a] = (coil_field_H(unit, c + e) - coil_field_H(unit, c - e)) / (2.0 * d);
        }
    }
  }
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
  const Vec3 half{0.5 * p.h, 0.5 * p.h, 0.5 * p.h};
  for (int i = 0; i < p.demag.cells(); ++i) H += uniform_cuboid_field(point - p.demag.centre(i), half, M[i]);
  return kMu0 * H;
}

// Solves at `ampere_turns` from M (a previous solution or zeros).
inline Result solve(const Problem& p, double ampere_turns, std::vector<Vec3>& M, const BhSolveOptions& options = {}) {
  std::vector<Vec3> source(p.coil_H.size());
  for (size_t i = 0; i < source.size(); ++i) source[i] = ampere_turns * p.coil_H[i];
  Result r;
  r.report = solve_bh_lattice(p.demag, p.curve, p.fill, source, M, options);
  for (int s = 1; s < p.demag.lattice_count(); ++s) r.force_from_yoke += p.demag.force(0, s, M);
  if (p.balance)
    for (int s = 1; s < p.demag.lattice_count(); ++s) r.force_on_yoke += p.demag.force(s, 0, M);
  // The coil's part, mu0 V sum (M . grad) H_coil at the pole's cell centres.
  Vec3 coil_force{};
  for (int i = 0; i < p.demag.cells_of(0); ++i)
    for (int a = 0; a < 3; ++a) coil_force += (kMu0 * p.h * p.h * p.h * ampere_turns * M[i][a]) * p.coil_gradient[i][a];
  r.force_pole = r.force_from_yoke + coil_force;
  r.Bz_P1 = flux_density(p, M, ampere_turns, kP1).z;
  r.Bz_P2 = flux_density(p, M, ampere_turns, kP2).z;
  return r;
}

}  // namespace odemag::team20
