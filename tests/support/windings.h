// A rounded-rectangle coil's copper by its definition (magnetics/sources/coil.h),
// for tests that check what comes near it: the points at distance
// inner_corner_radius..outer_corner_radius from the core rectangle, |w| <=
// height / 2, in the coil's frame (u, v, w off its centre).
#pragma once

#include <algorithm>
#include <cmath>

#include "magnetics/sources/coil.h"

namespace odemag::test_support {

// Distance (m) of the point (u, v) from the core rectangle |u| <= a, |v| <= b (0 inside it).
inline double core_rectangle_distance(const RoundedRectangleCoil& c, double u, double v) {
  return std::hypot(std::max(std::abs(u) - c.core_half_width, 0.0),
                    std::max(std::abs(v) - c.core_half_depth, 0.0));
}

// Distance (m) of the point (u, v, w) from the copper (0 inside it).
inline double distance_from_copper(const RoundedRectangleCoil& c, double u, double v, double w) {
  const double d = core_rectangle_distance(c, u, v);
  return std::max(
      {c.inner_corner_radius - d, d - c.outer_corner_radius, std::abs(w) - 0.5 * c.height, 0.0});
}

}  // namespace odemag::test_support
