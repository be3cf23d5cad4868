// Colours for odemag renderings: the force colour map, a rainbow map, and a
// small palette for the usual bodies.
#pragma once

#include <array>

namespace odemag {

using RenderColor = std::array<float, 3>;  // RGB, each 0..1

// Rainbow colour map (VIBGYOR, as in the paper's Fig. 14): t = 0 violet
// (weakest) through indigo, blue, green, yellow, orange to t = 1 red
// (strongest); the hue falls monotonically from 270 to 0 degrees. t is clamped
// to [0, 1]; NaN maps to 0.
RenderColor rainbow(double t);

// Force colour map (scene render.force_colors; the legend's colour bar):
// t = 0 (weakest) dark teal through green to t = 1 (strongest) yellow,
// piecewise linear in RGB with brightness rising with t. Its hues (about 175
// down to 50 degrees) stay clear of the pole colours (north red, about 4
// degrees; south blue, about 222 degrees), so a strongly pulled body is never
// mistaken for a north pole. t is clamped to [0, 1]; NaN maps to 0.
RenderColor force_color(double t);

// Hue in degrees [0, 360) of an RGB colour (0 for greys); the inverse of the
// hue part of rainbow(), used to check or sort colours.
double hue_degrees(const RenderColor& c);

namespace palette {
inline constexpr RenderColor iron{0.55f, 0.56f, 0.58f};       // iron balls, plates
inline constexpr RenderColor steel{0.70f, 0.71f, 0.74f};      // nails, pins
inline constexpr RenderColor dark_steel{0.35f, 0.36f, 0.39f};
inline constexpr RenderColor crane{0.95f, 0.68f, 0.12f};      // crane yellow
inline constexpr RenderColor wood{0.72f, 0.55f, 0.36f};
inline constexpr RenderColor field_line{0.45f, 0.45f, 0.47f}; // magnetic field lines
inline constexpr RenderColor copper{0.80f, 0.45f, 0.20f};     // coils carried by bodies
inline constexpr RenderColor north{0.85f, 0.15f, 0.12f};      // magnet N pole
inline constexpr RenderColor south{0.15f, 0.30f, 0.85f};      // magnet S pole
}  // namespace palette

}  // namespace odemag
