#include "magnetics/materials/bh_curve.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "odemag/constants.h"

namespace odemag {

std::string bh_curve_error(const std::vector<std::array<double, 2>>& points) {
  if (points.size() < 2) return "a B-H curve needs at least two points";
  for (size_t i = 0; i < points.size(); ++i) {
    const double H = points[i][0], B = points[i][1];
    const std::string at = "point " + std::to_string(i) + ": ";
    if (!std::isfinite(H) || !std::isfinite(B)) return at + "H and B must be finite";
    if (H < 0.0 || B < 0.0) return at + "H and B must be >= 0";
    if (H == 0.0 && B != 0.0) return at + "B must be 0 at H = 0 (an anhysteretic curve has no remanence)";
    if (i > 0) {
      const double H0 = points[i - 1][0], B0 = points[i - 1][1];
      if (!(H > H0)) return at + "H must increase";
      if (!(B > B0)) return at + "B must increase";
      if (B / kMu0 - H < B0 / kMu0 - H0 - 1e-9 * (B / kMu0))
        return at + "M = B/mu0 - H must not decrease (dB/dH >= mu0)";
    }
  }
  const double M_last = points.back()[1] / kMu0 - points.back()[0];
  if (!(M_last > 0.0)) return "the last point's M = B/mu0 - H must be > 0";
  return {};
}

BhCurve::BhCurve(const std::vector<std::array<double, 2>>& points) {
  if (const std::string e = bh_curve_error(points); !e.empty()) throw std::invalid_argument("B-H curve: " + e);
  if (points.front()[0] > 0.0) {
    H_.push_back(0.0);
    M_.push_back(0.0);
  }
  for (const auto& p : points) {
    H_.push_back(p[0]);
    M_.push_back(std::max(p[1] / kMu0 - p[0], M_.empty() ? 0.0 : M_.back()));
  }
  // Fritsch-Carlson slopes: secants, harmonic-type limiting, zero at flat parts.
  const size_t n = H_.size();
  std::vector<double> s(n - 1);
  for (size_t i = 0; i + 1 < n; ++i) s[i] = (M_[i + 1] - M_[i]) / (H_[i + 1] - H_[i]);
  d_.assign(n, 0.0);
  d_[0] = s[0];
  d_[n - 1] = 0.0;  // joins M = const beyond the table smoothly
  for (size_t i = 1; i + 1 < n; ++i) d_[i] = s[i - 1] * s[i] > 0.0 ? 0.5 * (s[i - 1] + s[i]) : 0.0;
  for (size_t i = 0; i + 1 < n; ++i) {
    if (s[i] == 0.0) {
      d_[i] = d_[i + 1] = 0.0;
      continue;
    }
    const double a = d_[i] / s[i], b = d_[i + 1] / s[i], r = a * a + b * b;
    if (r > 9.0) {
      const double t = 3.0 / std::sqrt(r);
      d_[i] = t * a * s[i];
      d_[i + 1] = t * b * s[i];
    }
  }
}

namespace {
// Cubic Hermite basis on [0, 1]: value and derivative (per unit t).
void hermite(double t, double& h00, double& h10, double& h01, double& h11) {
  const double t2 = t * t, t3 = t2 * t;
  h00 = 2 * t3 - 3 * t2 + 1;
  h10 = t3 - 2 * t2 + t;
  h01 = -2 * t3 + 3 * t2;
  h11 = t3 - t2;
}
}  // namespace

size_t BhCurve::segment(double H, double& w, double& t) const {
  const size_t i = static_cast<size_t>(std::upper_bound(H_.begin(), H_.end(), H) - H_.begin()) - 1;
  w = H_[i + 1] - H_[i];
  t = (H - H_[i]) / w;
  return i;
}

double BhCurve::magnetization(double H) const {
  if (H_.empty() || H <= 0.0) return 0.0;
  if (H >= H_.back()) return M_.back();
  double w, t;
  const size_t i = segment(H, w, t);
  double h00, h10, h01, h11;
  hermite(t, h00, h10, h01, h11);
  return h00 * M_[i] + h10 * w * d_[i] + h01 * M_[i + 1] + h11 * w * d_[i + 1];
}

double BhCurve::slope(double H) const {
  if (H_.empty()) return 0.0;
  if (H <= 0.0) return d_[0];
  if (H >= H_.back()) return 0.0;
  double w, t;
  const size_t i = segment(H, w, t);
  const double t2 = t * t;
  const double g00 = 6 * t2 - 6 * t, g10 = 3 * t2 - 4 * t + 1, g01 = -6 * t2 + 6 * t, g11 = 3 * t2 - 2 * t;
  // >= 0 for a monotone interpolant; the max removes round-off.
  return std::max(0.0, (g00 * M_[i] + g01 * M_[i + 1]) / w + g10 * d_[i] + g11 * d_[i + 1]);
}

double BhCurve::cell_magnetization(double h) const {
  if (H_.empty() || !(h > 0.0)) return 0.0;
  // f(M) = M - M(h - M/3) rises strictly (dM/dH >= 0), f(0) <= 0 <= f(3h):
  // bisection, then Newton steps kept inside the bracket.
  double lo = 0.0, hi = std::min(3.0 * h, M_.back());
  auto f = [&](double M) { return M - magnetization(h - M / 3.0); };
  if (f(hi) <= 0.0) return hi;
  double M = 0.5 * (lo + hi);
  for (int it = 0; it < 200; ++it) {
    const double v = f(M);
    if (v == 0.0) return M;
    (v < 0.0 ? lo : hi) = M;
    const double dv = 1.0 + slope(h - M / 3.0) / 3.0;
    double next = M - v / dv;
    if (!(next > lo && next < hi)) next = 0.5 * (lo + hi);
    if (std::fabs(next - M) <= 1e-15 * std::max(M, 1e-300) || hi - lo <= 1e-15 * hi) return next;
    M = next;
  }
  return M;
}

double BhCurve::secant_demag_factor(double h) const {
  const double M = cell_magnetization(h);
  if (!(M > 0.0)) return 1.0 / 3.0 + 1.0 / initial_susceptibility();
  return h / M;
}

}  // namespace odemag
