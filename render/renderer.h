// Headless offscreen renderer for odemag scenes: OSMesa (software OpenGL,
// llvmpipe), fixed-function lighting, supersampled and box-filtered to RGB8.
//
// Coordinates are world coordinates in metres with +z up (the ground plane is
// z = ground_height). One OffscreenRenderer owns one OSMesa context; use it
// from one thread at a time (OSMesa contexts are current per thread, and
// render() makes this renderer's context current on the calling thread).
#pragma once

#include <array>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "render/colors.h"
#include "odemag/vec3.h"

namespace odemag {

struct RenderCamera {
  Vec3 position{0.0, -1.0, 0.5};
  Vec3 target{0.0, 0.0, 0.0};
  Vec3 up{0.0, 0.0, 1.0};
  double fov_degrees = 40.0;  // vertical field of view
  // The size a caller should construct its OffscreenRenderer with; render()
  // always draws at the renderer's own size, with aspect = width / height.
  int width = 640, height = 480;
};

// A triangle surface in its body's frame (m): three vertices per triangle,
// each with its normal.
struct RenderSurface {
  std::vector<float> positions;  // xyz
  std::vector<float> normals;    // xyz
  double radius = 0.0;           // of the sphere about the origin holding it
};

struct RenderPrimitive {
  enum class Kind { sphere, box, cylinder, surface };
  Kind kind = Kind::sphere;
  // sphere: (R, R, R) (unequal values give an ellipsoid); box: full edge
  // lengths (lx, ly, lz); cylinder: (R, R, length) with its axis along body
  // z; surface: (1, 1, 1), the surface in `surface`.
  Vec3 size{0.01, 0.01, 0.01};
  std::shared_ptr<const RenderSurface> surface;
  Mat3 rotation;  // body -> world
  Vec3 position;  // world position of the centre
  RenderColor color{0.62f, 0.63f, 0.66f};
  // Body frame. Non-zero: the body is a magnet, drawn split by the plane
  // through its centre perpendicular to pole_axis; the +pole_axis half in
  // north_color, the other half in south_color (and `color` is unused).
  Vec3 pole_axis;
  RenderColor north_color{0.85f, 0.15f, 0.12f};
  RenderColor south_color{0.15f, 0.30f, 0.85f};
  bool cast_shadow = true;  // onto the ground plane
  // 1: opaque. Less: translucent (e.g. glass), alpha-blended over what lies
  // behind it (seen through the body, what is behind keeps 1 - opacity of
  // its colour); drawn after the opaque solids and the lines, farthest
  // first, without writing depth, and casting no shadow.
  float opacity = 1.0f;

  static RenderPrimitive sphere(const Vec3& centre, double radius, const RenderColor& color);
  static RenderPrimitive box(const Vec3& centre, const Vec3& edges, const Mat3& rotation,
                             const RenderColor& color);
  static RenderPrimitive cylinder(const Vec3& centre, double radius, double length,
                                  const Mat3& rotation, const RenderColor& color);
  static RenderPrimitive of_surface(const Vec3& centre, std::shared_ptr<const RenderSurface> surface,
                                    const Mat3& rotation, const RenderColor& color);
};

// A polyline (GL line strip), drawn after the solids with depth testing, so
// solids hide the parts behind them. width is in output pixels.
struct RenderLine {
  std::vector<Vec3> points;
  RenderColor color{0.5f, 0.5f, 0.5f};
  float width = 1.5f;
};

// A legend band across the bottom of the image (drawn when any part is on):
// pole colour swatches, a colour bar, a scale bar. Items that do not fit on a
// row go to another row.
struct RenderLegend {
  bool poles = false;  // "north" and "south" swatches in these colours
  RenderColor north = palette::north;
  RenderColor south = palette::south;
  // Colour bar: samples of the colour map from the low end of the range to
  // the high end (empty: no bar), labelled "<label> <low> .. <high> <unit>".
  std::vector<RenderColor> colorbar;
  double colorbar_low = 0.0, colorbar_high = 0.0;
  std::string colorbar_label = "|F|";
  std::string colorbar_unit = "N";  // SI unit; values get a prefix (m, µ, ...)
  // Scale bar: a length of 1, 2 or 5 x 10^k m as it appears at the distance
  // of the camera target (scale_bar_for).
  bool scale_bar = false;

  bool any() const { return poles || !colorbar.empty() || scale_bar; }
};

struct RenderFrame {
  RenderCamera camera;
  RenderColor background{0.93f, 0.94f, 0.96f};
  // Checkerboard ground plane in light greys: the square |x|, |y| <=
  // ground_extent around the world origin at z = ground_height, tiles of
  // ground_tile (0: ground_extent / 8). Not drawn when the camera is below it.
  bool ground = true;
  double ground_height = 0.0;
  double ground_extent = 1.0;
  double ground_tile = 0.0;
  bool shadows = true;  // hard shadows of the primitives on the ground plane
  std::vector<RenderPrimitive> primitives;
  std::vector<RenderLine> lines;  // e.g. magnetic field lines
  // Caption paragraphs, e.g. "t = 0.40 s" and the scene title, each wrapped
  // to the image width (render/text.h: DejaVu Sans with FreeType, or
  // the built-in 5x7 font), in a band across the top of the finished image
  // on a translucent panel of the background colour.
  std::vector<std::string> text;
  RenderColor text_color{0.10f, 0.10f, 0.12f};
  RenderLegend legend;
};

// Pixel size of the caption and legend font for an image `height` pixels
// tall: about height / 30, at least 9.
int caption_pixel_size(int height);

// The scale bar for a camera and an image `height` pixels tall: the longest
// length L = {1, 2, 5} x 10^k m that spans at most max_pixels pixels at the
// distance d of the camera target, where one metre spans
// height / (2 d tan(fov / 2)) pixels; and its label ("2 cm", "5 mm", "1 m").
struct ScaleBar {
  double metres = 0.0;
  double pixels = 0.0;
  std::string label;
};
ScaleBar scale_bar_for(const RenderCamera& camera, int height, double max_pixels);

class OffscreenRenderer {
 public:
  // Output size width x height; the scene is drawn at supersample times that
  // size and box-filtered down (1 disables anti-aliasing). Throws
  // std::invalid_argument for bad sizes and std::runtime_error if OSMesa
  // cannot create the context.
  OffscreenRenderer(int width, int height, int supersample = 2);
  ~OffscreenRenderer();
  OffscreenRenderer(OffscreenRenderer&&) noexcept;
  OffscreenRenderer& operator=(OffscreenRenderer&&) noexcept;
  OffscreenRenderer(const OffscreenRenderer&) = delete;
  OffscreenRenderer& operator=(const OffscreenRenderer&) = delete;

  int width() const;
  int height() const;
  int supersample() const;

  // Renders the scene and returns tightly packed RGB8 rows, top row first:
  // width * height * 3 bytes. Throws std::runtime_error if the context cannot
  // be made current.
  std::vector<std::uint8_t> render(const RenderFrame& scene);

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

// Draws `text` into a tightly packed RGB8 image (top row first) with the
// built-in 5x7 font (TextFont's fallback; captions use TextFont), each font pixel a scale x scale block, the glyph cell's
// top-left corner at (x, y); one line, no wrapping, clipped to the image.
// Returns the x just after the last glyph.
int draw_text_rgb(std::vector<std::uint8_t>& rgb, int width, int height, int x, int y,
                  const std::string& text, const RenderColor& color, int scale = 1);

}  // namespace odemag
