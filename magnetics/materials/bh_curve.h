// Anhysteretic B-H curves of soft materials (docs/model.md "B-H curves").
//
// A table of points (H_i, B_i), H in A/m, B in T, from (0, 0) up, gives the
// magnetization M(H) = B / mu0 - H of the material in its own internal field
// H. Between points M(H) is the monotone cubic Hermite interpolant
// (Fritsch-Carlson slopes: no overshoot, so M stays monotone where the table
// is); past the last point M stays at its last value, dB/dH = mu0 (the
// material is saturated). The last M is the material's saturation Ms; the
// slope at 0 its initial susceptibility chi_0.
//
// A cell of the curve's material answers an applied field H_A (that of the
// other cells and sources, the cell's own excluded) with the M that solves
// M = M(|H_A| - M / 3) (the cell's self field -M/3), along H_A. The LLG cell
// relaxes to M = H_A / gamma_D (below saturation); with a curve, gamma_D is
// the secant |H_A| / M of that solution, set per cell and outer iteration
// (secant_demag_factor), so that the relaxed cell sits on the curve.
#pragma once

#include <array>
#include <string>
#include <vector>

namespace odemag {

class BhCurve {
 public:
  BhCurve() = default;
  // Points (H, B): H strictly increasing from 0 (a first point (0, 0) is
  // implied when H_0 > 0), B strictly increasing, B_0 = 0 at H = 0, and M = B /
  // mu0 - H non-decreasing and positive at the end. Throws std::invalid_argument
  // naming the first bad point (bh_curve_error gives the message).
  explicit BhCurve(const std::vector<std::array<double, 2>>& points);

  bool empty() const { return H_.empty(); }
  double magnetization(double H) const;        // M(H), A/m, H >= 0
  double slope(double H) const;                // dM/dH
  double saturation() const { return M_.empty() ? 0.0 : M_.back(); }  // Ms, A/m
  double initial_susceptibility() const { return slope(0.0); }

  // The cell's M (A/m, >= 0) in applied field magnitude h: M = M(h - M / 3).
  double cell_magnetization(double h) const;
  // gamma_D = h / M of that solution; 1/3 + 1/chi_0 at h = 0.
  double secant_demag_factor(double h) const;

 private:
  // The knot interval [H_i, H_i+1] holding 0 < H < H_back: i, its width w and
  // the position t in it (0..1).
  size_t segment(double H, double& w, double& t) const;

  std::vector<double> H_, M_, d_;              // knots from H = 0, values, Hermite slopes
};

// Why the points are not a valid curve ("" when they are).
std::string bh_curve_error(const std::vector<std::array<double, 2>>& points);

}  // namespace odemag
