#include "render/colors.h"

#include <algorithm>
#include <cmath>

namespace odemag {
namespace {

// HSV (h in degrees) to RGB.
RenderColor hsv(double h, double s, double v) {
  h = std::fmod(h, 360.0);
  if (h < 0.0) h += 360.0;
  const double c = v * s;
  const double hp = h / 60.0;
  const double x = c * (1.0 - std::fabs(std::fmod(hp, 2.0) - 1.0));
  double r = 0, g = 0, b = 0;
  switch (static_cast<int>(hp)) {
    case 0: r = c; g = x; break;
    case 1: r = x; g = c; break;
    case 2: g = c; b = x; break;
    case 3: g = x; b = c; break;
    case 4: r = x; b = c; break;
    default: r = c; b = x; break;
  }
  const double m = v - c;
  return {static_cast<float>(r + m), static_cast<float>(g + m), static_cast<float>(b + m)};
}

}  // namespace

RenderColor rainbow(double t) {
  if (!(t >= 0.0)) t = 0.0;  // also catches NaN
  if (t > 1.0) t = 1.0;
  // Violet (270 deg) down to red (0 deg). Slightly desaturated and darkened so
  // that the yellow-green middle still reads against a light background.
  return hsv(270.0 * (1.0 - t), 0.9, 0.92);
}

RenderColor force_color(double t) {
  if (!(t >= 0.0)) t = 0.0;  // also catches NaN
  if (t > 1.0) t = 1.0;
  constexpr RenderColor stops[3] = {{0.05f, 0.45f, 0.40f},   // weakest: dark teal
                                    {0.35f, 0.70f, 0.28f},   // green
                                    {0.98f, 0.86f, 0.10f}};  // strongest: yellow
  const double u = 2.0 * t;
  const int i = std::min(1, static_cast<int>(u));
  const auto f = static_cast<float>(u - i);
  RenderColor c{};
  for (std::size_t k = 0; k < 3; ++k)
    c[k] = stops[i][k] + f * (stops[i + 1][k] - stops[i][k]);
  return c;
}

double hue_degrees(const RenderColor& c) {
  const double r = c[0], g = c[1], b = c[2];
  const double mx = std::max({r, g, b}), mn = std::min({r, g, b});
  const double d = mx - mn;
  if (d <= 0.0) return 0.0;
  double h;
  if (mx == r)
    h = 60.0 * std::fmod((g - b) / d, 6.0);
  else if (mx == g)
    h = 60.0 * ((b - r) / d + 2.0);
  else
    h = 60.0 * ((r - g) / d + 4.0);
  if (h < 0.0) h += 360.0;
  return h;
}

}  // namespace odemag
