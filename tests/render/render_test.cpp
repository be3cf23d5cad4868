// Tests of the headless renderer: pixels where the geometry is, magnet pole
// colours, depth testing, lines, translucency, captions (FreeType text,
// wrapping), the legend, the PNG writer and the colour maps.
#include <png.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <numbers>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "render/colors.h"
#include "render/png_writer.h"
#include "render/renderer.h"
#include "render/text.h"

namespace odemag {
namespace {

constexpr int kW = 64, kH = 48;

struct Pixel {
  int r, g, b;
};

Pixel at(const std::vector<std::uint8_t>& rgb, int width, int x, int y) {
  const std::size_t i = (static_cast<std::size_t>(y) * static_cast<std::size_t>(width) + static_cast<std::size_t>(x)) * 3;
  return {rgb[i], rgb[i + 1], rgb[i + 2]};
}

// A scene without ground, looked at from (0, -0.5, 0) towards the origin:
// +x is to the right of the image, +z up.
RenderFrame front_scene() {
  RenderFrame scene;
  scene.ground = false;
  scene.camera.position = {0.0, -0.5, 0.0};
  scene.camera.target = {0.0, 0.0, 0.0};
  scene.camera.up = {0.0, 0.0, 1.0};
  scene.camera.fov_degrees = 40.0;
  scene.camera.width = kW;
  scene.camera.height = kH;
  return scene;
}

// Pixel column/row of a world point for front_scene()'s camera, computed
// independently of the renderer (pinhole camera, vertical fov 40 degrees).
void project_front(const Vec3& p, double* col, double* row) {
  const double depth = p.y + 0.5;
  const double f = 1.0 / std::tan(20.0 * std::numbers::pi / 180.0);
  const double ndc_x = p.x / depth * f / (static_cast<double>(kW) / kH);
  const double ndc_y = p.z / depth * f;
  *col = 0.5 * (ndc_x + 1.0) * kW - 0.5;
  *row = 0.5 * (1.0 - ndc_y) * kH - 0.5;
}

bool red_dominant(const Pixel& p) { return p.r > 2 * p.g && p.r > 2 * p.b; }
bool green_dominant(const Pixel& p) { return p.g > 2 * p.r && p.g > 2 * p.b; }
bool blue_dominant(const Pixel& p) { return p.b > 2 * p.r && p.b > 2 * p.g; }

void expect_background(const Pixel& p, const RenderColor& bg) {
  EXPECT_NEAR(p.r, static_cast<int>(std::lround(bg[0] * 255.0f)), 3);
  EXPECT_NEAR(p.g, static_cast<int>(std::lround(bg[1] * 255.0f)), 3);
  EXPECT_NEAR(p.b, static_cast<int>(std::lround(bg[2] * 255.0f)), 3);
}

TEST(RenderPixels, SphereAtCentreAndBoxWhereItProjects) {
  RenderFrame scene = front_scene();
  scene.primitives.push_back(RenderPrimitive::sphere({0, 0, 0}, 0.08, {0.9f, 0.1f, 0.1f}));
  const Vec3 box_centre{-0.14, 0.0, 0.0};
  scene.primitives.push_back(RenderPrimitive::box(box_centre, {0.05, 0.05, 0.05}, Mat3{}, {0.1f, 0.8f, 0.1f}));

  OffscreenRenderer renderer(kW, kH, 2);
  ASSERT_EQ(renderer.width(), kW);
  ASSERT_EQ(renderer.height(), kH);
  const std::vector<std::uint8_t> rgb = renderer.render(scene);
  ASSERT_EQ(rgb.size(), static_cast<std::size_t>(kW * kH * 3));

  expect_background(at(rgb, kW, 0, 0), scene.background);
  expect_background(at(rgb, kW, kW - 1, kH - 1), scene.background);
  const Pixel centre = at(rgb, kW, kW / 2, kH / 2);
  EXPECT_TRUE(red_dominant(centre)) << centre.r << "," << centre.g << "," << centre.b;

  double col = 0, row = 0;
  project_front(box_centre, &col, &row);
  ASSERT_LT(col, kW / 2 - 8);  // the box is well left of the centre
  const Pixel box = at(rgb, kW, static_cast<int>(std::lround(col)), static_cast<int>(std::lround(row)));
  EXPECT_TRUE(green_dominant(box)) << box.r << "," << box.g << "," << box.b;
  // Mirror location (right of centre): background, not the box.
  const Pixel mirror = at(rgb, kW, kW - 1 - static_cast<int>(std::lround(col)), static_cast<int>(std::lround(row)));
  EXPECT_FALSE(green_dominant(mirror));
  expect_background(mirror, scene.background);
}

TEST(RenderPixels, BoxAboveCentreAppearsInUpperHalf) {
  // Guards the vertical flip: +z must be up in the image (top row first).
  RenderFrame scene = front_scene();
  const Vec3 box_centre{0.0, 0.0, 0.1};
  scene.primitives.push_back(RenderPrimitive::box(box_centre, {0.05, 0.05, 0.05}, Mat3{}, {0.1f, 0.8f, 0.1f}));
  OffscreenRenderer renderer(kW, kH);
  const auto rgb = renderer.render(scene);
  double col = 0, row = 0;
  project_front(box_centre, &col, &row);
  ASSERT_LT(row, kH / 2 - 6);
  const int c = static_cast<int>(std::lround(col)), r = static_cast<int>(std::lround(row));
  EXPECT_TRUE(green_dominant(at(rgb, kW, c, r)));
  expect_background(at(rgb, kW, c, kH - 1 - r), scene.background);
}

TEST(RenderMagnet, PolesColourTheirHalves) {
  RenderFrame scene = front_scene();
  RenderPrimitive magnet = RenderPrimitive::box({0, 0, 0}, {0.2, 0.05, 0.05}, Mat3{}, {0.5f, 0.5f, 0.5f});
  magnet.pole_axis = {1.0, 0.0, 0.0};
  scene.primitives.push_back(magnet);
  OffscreenRenderer renderer(kW, kH);
  auto rgb = renderer.render(scene);

  double left = 0, right = 0, row = 0;
  project_front({-0.06, -0.025, 0.0}, &left, &row);
  project_front({0.06, -0.025, 0.0}, &right, &row);
  const int r = static_cast<int>(std::lround(row));
  const Pixel south = at(rgb, kW, static_cast<int>(std::lround(left)), r);
  const Pixel north = at(rgb, kW, static_cast<int>(std::lround(right)), r);
  EXPECT_TRUE(blue_dominant(south)) << south.r << "," << south.g << "," << south.b;
  EXPECT_GT(north.r, 2 * north.b) << north.r << "," << north.g << "," << north.b;
  EXPECT_GT(north.r, 2 * north.g);
  // The split is at the centre plane: just either side of the middle column.
  EXPECT_GT(at(rgb, kW, kW / 2 - 2, r).b, at(rgb, kW, kW / 2 - 2, r).r);
  EXPECT_GT(at(rgb, kW, kW / 2 + 1, r).r, at(rgb, kW, kW / 2 + 1, r).b);

  // Turned half a turn about z, the body's +x points to world -x: the
  // colours swap sides.
  Mat3 half_turn;
  half_turn.m[0][0] = -1.0;
  half_turn.m[1][1] = -1.0;
  scene.primitives[0].rotation = half_turn;
  rgb = renderer.render(scene);
  const Pixel left2 = at(rgb, kW, static_cast<int>(std::lround(left)), r);
  const Pixel right2 = at(rgb, kW, static_cast<int>(std::lround(right)), r);
  EXPECT_GT(left2.r, 2 * left2.b);
  EXPECT_TRUE(blue_dominant(right2));
}

// A triangle surface (a mesh body) is drawn lit by its normals and split
// into its pole colours like a primitive: a box's 12 triangles, the face
// towards the camera lit, the pole halves red and blue.
TEST(RenderMagnet, SurfaceMagnetSplitsAndIsLit) {
  auto surface = std::make_shared<RenderSurface>();
  const double e[3] = {0.1, 0.025, 0.025};
  // Two triangles per face, counter-clockwise from outside, flat normals.
  for (int axis = 0; axis < 3; ++axis)
    for (int side : {-1, 1}) {
      const int u = (axis + 1) % 3, v = (axis + 2) % 3;
      double q[4][3];
      const double cu[4] = {-1, 1, 1, -1}, cv[4] = {-1, -1, 1, 1};
      for (int k = 0; k < 4; ++k) {
        q[k][axis] = side * e[axis];
        q[k][u] = cu[k] * e[u];
        q[k][v] = side * cv[k] * e[v];
      }
      for (int k : {0, 1, 2, 0, 2, 3}) {
        surface->positions.insert(surface->positions.end(),
                                  {static_cast<float>(q[k][0]), static_cast<float>(q[k][1]), static_cast<float>(q[k][2])});
        float n[3] = {0, 0, 0};
        n[axis] = static_cast<float>(side);
        surface->normals.insert(surface->normals.end(), {n[0], n[1], n[2]});
      }
    }
  surface->radius = 0.11;
  RenderFrame scene = front_scene();
  RenderPrimitive magnet = RenderPrimitive::of_surface({0, 0, 0}, surface, Mat3{}, {0.5f, 0.5f, 0.5f});
  magnet.pole_axis = {1.0, 0.0, 0.0};
  scene.primitives.push_back(magnet);
  OffscreenRenderer renderer(kW, kH);
  const auto rgb = renderer.render(scene);
  double left = 0, right = 0, row = 0;
  project_front({-0.06, -0.025, 0.0}, &left, &row);
  project_front({0.06, -0.025, 0.0}, &right, &row);
  const int r = static_cast<int>(std::lround(row));
  const Pixel south = at(rgb, kW, static_cast<int>(std::lround(left)), r);
  const Pixel north = at(rgb, kW, static_cast<int>(std::lround(right)), r);
  EXPECT_TRUE(blue_dominant(south)) << south.r << "," << south.g << "," << south.b;
  EXPECT_GT(north.r, 2 * north.b) << north.r << "," << north.g << "," << north.b;
  EXPECT_GT(north.r, 2 * north.g);
  EXPECT_GT(north.r, 60);  // lit: the face's normal points at the camera
}

TEST(RenderMagnet, CylinderAndSphereMagnetsSplit) {
  for (const auto kind : {RenderPrimitive::Kind::cylinder, RenderPrimitive::Kind::sphere}) {
    RenderFrame scene = front_scene();
    RenderPrimitive magnet;
    magnet.kind = kind;
    magnet.size = {0.08, 0.08, 0.08};
    magnet.pole_axis = {0.0, 0.0, 1.0};  // north up
    scene.primitives.push_back(magnet);
    OffscreenRenderer renderer(kW, kH);
    const auto rgb = renderer.render(scene);
    const Pixel top = at(rgb, kW, kW / 2, kH / 2 - 5);
    const Pixel bottom = at(rgb, kW, kW / 2, kH / 2 + 5);
    EXPECT_GT(top.r, 2 * top.b) << static_cast<int>(kind);
    EXPECT_TRUE(blue_dominant(bottom)) << static_cast<int>(kind);
  }
}

TEST(RenderDepth, NearSphereHidesFarSphereInEitherDrawOrder) {
  RenderFrame scene = front_scene();
  const RenderPrimitive near_blue = RenderPrimitive::sphere({0, -0.2, 0}, 0.04, {0.1f, 0.2f, 0.9f});
  const RenderPrimitive far_red = RenderPrimitive::sphere({0, 0.2, 0}, 0.15, {0.9f, 0.1f, 0.1f});
  OffscreenRenderer renderer(kW, kH);
  for (int order = 0; order < 2; ++order) {
    scene.primitives = order == 0 ? std::vector{near_blue, far_red} : std::vector{far_red, near_blue};
    const auto rgb = renderer.render(scene);
    const Pixel centre = at(rgb, kW, kW / 2, kH / 2);
    EXPECT_TRUE(blue_dominant(centre)) << "order " << order << ": " << centre.r << "," << centre.g << "," << centre.b;
    // Beside the small near sphere the far red one shows.
    EXPECT_TRUE(red_dominant(at(rgb, kW, kW / 2 + 12, kH / 2))) << "order " << order;
  }
}

TEST(RenderLines, LineDrawnAndHiddenBehindSolid) {
  RenderFrame scene = front_scene();
  scene.primitives.push_back(RenderPrimitive::sphere({0, 0, 0}, 0.06, {0.9f, 0.1f, 0.1f}));
  RenderLine line;  // horizontal, behind the sphere
  line.points = {{-0.3, 0.1, 0.0}, {0.0, 0.1, 0.0}, {0.3, 0.1, 0.0}};
  line.color = {0.0f, 0.0f, 0.0f};
  line.width = 2.0f;
  scene.lines.push_back(line);
  OffscreenRenderer renderer(kW, kH);
  const auto rgb = renderer.render(scene);
  const Pixel beside = at(rgb, kW, 6, kH / 2);  // left of the sphere: the line
  EXPECT_LT(beside.r + beside.g + beside.b, 3 * 100) << beside.r << "," << beside.g << "," << beside.b;
  EXPECT_TRUE(red_dominant(at(rgb, kW, kW / 2, kH / 2)));  // sphere hides it
  expect_background(at(rgb, kW, 6, 4), scene.background);
}

TEST(RenderGround, CheckerboardBelowHorizonBackgroundAbove) {
  RenderFrame scene;
  scene.camera.position = {0.0, -0.6, 0.3};
  scene.camera.target = {0.0, 0.0, 0.0};
  scene.ground_extent = 0.5;
  OffscreenRenderer renderer(kW, kH);
  const auto rgb = renderer.render(scene);
  expect_background(at(rgb, kW, kW / 2, 0), scene.background);  // sky
  const Pixel ground = at(rgb, kW, kW / 2, kH * 3 / 4);
  const int bg = static_cast<int>(std::lround(scene.background[0] * 255.0f));
  EXPECT_LT(ground.r, bg - 10);  // grey tiles, darker than the background
  EXPECT_NEAR(ground.r, ground.g, 12);
  EXPECT_NEAR(ground.g, ground.b, 12);
}

// Shadows of a floating sphere and of a cylinder standing on the ground.
// The scene is drawn at scale s (metres per unit) to cover both the
// centimetre scenes of the demos and larger ones.
int expect_solid_shadow(RenderPrimitive body, double s, int min_darker) {
  RenderFrame scene;
  scene.camera.position = {0.0, -0.6 * s, 0.4 * s};
  scene.camera.target = {0.0, 0.0, 0.0};
  scene.ground_extent = 0.5 * s;
  body.position = s * body.position;
  body.size = s * body.size;
  scene.primitives.push_back(body);
  OffscreenRenderer renderer(kW, kH);
  const auto lit = renderer.render(scene);
  scene.shadows = false;
  const auto unlit = renderer.render(scene);
  int darker = 0, sphere = 0;
  for (int y = 0; y < kH; ++y) {
    for (int x = 0; x < kW; ++x) {
      const Pixel a = at(lit, kW, x, y), b = at(unlit, kW, x, y);
      if (red_dominant(b)) ++sphere;
      if (a.r < b.r - 20 && a.g < b.g - 20 && a.b < b.b - 20) ++darker;
      EXPECT_LE(a.g, b.g) << x << "," << y;  // shadows only darken
    }
  }
  // The shadow on the ground is a filled patch comparable to the body's own
  // size on screen (not hidden under the body, not speckled).
  EXPECT_GT(sphere, 50);
  EXPECT_GT(darker, min_darker) << "body pixels " << sphere;
  return darker;
}

TEST(RenderGround, BodiesCastSolidShadows) {
  // The same scene at any scale gives the same image, shadows included.
  int sphere_shadow = -1, cylinder_shadow = -1;
  for (double s : {0.1, 1.0, 10.0}) {
    SCOPED_TRACE(s);
    const int a = expect_solid_shadow(RenderPrimitive::sphere({0.0, 0.0, 0.12}, 0.06, {0.9f, 0.1f, 0.1f}), s, 40);
    const int b = expect_solid_shadow(
        RenderPrimitive::cylinder({0.0, 0.0, 0.06}, 0.04, 0.12, Mat3{}, {0.9f, 0.1f, 0.1f}), s, 20);
    if (sphere_shadow >= 0) {
      EXPECT_NEAR(a, sphere_shadow, 3);
      EXPECT_NEAR(b, cylinder_shadow, 3);
    }
    sphere_shadow = a;
    cylinder_shadow = b;
  }
}

TEST(RenderText, CaptionDrawsDarkPixelsTopLeft) {
  RenderFrame scene = front_scene();
  OffscreenRenderer renderer(kW, kH);
  const auto plain = renderer.render(scene);
  scene.text = {"t = 0.40 s"};
  const auto captioned = renderer.render(scene);
  int dark = 0;
  for (int y = 0; y < 14; ++y)
    for (int x = 0; x < kW; ++x)
      if (at(captioned, kW, x, y).r < 80) ++dark;
  EXPECT_GT(dark, 20);
  // The lower part of the image is unchanged.
  for (int y = kH / 2; y < kH; ++y)
    for (int x = 0; x < kW; ++x) ASSERT_EQ(at(captioned, kW, x, y).g, at(plain, kW, x, y).g);
}

TEST(RenderText, GlyphShapes) {
  std::vector<std::uint8_t> rgb(12 * 9 * 3, 255);
  const int end = draw_text_rgb(rgb, 12, 9, 1, 1, "I-", {0.0f, 0.0f, 0.0f});
  EXPECT_EQ(end, 13);
  // 'I': top bar columns 2..4 of the cell (x 2..4), stem at x 3.
  EXPECT_EQ(at(rgb, 12, 2, 1).r, 0);
  EXPECT_EQ(at(rgb, 12, 3, 4).r, 0);
  EXPECT_EQ(at(rgb, 12, 2, 4).r, 255);
  // '-': row 3 of the second cell (x 7..11).
  EXPECT_EQ(at(rgb, 12, 7, 4).r, 0);
  EXPECT_EQ(at(rgb, 12, 11, 4).r, 0);
  EXPECT_EQ(at(rgb, 12, 9, 2).r, 255);
}

// A larger blank frame for captions and legends.
constexpr int kLW = 240, kLH = 180;

RenderFrame blank_scene(int width, int height) {
  RenderFrame scene = front_scene();
  scene.camera.width = width;
  scene.camera.height = height;
  return scene;
}

bool dark(const Pixel& p) { return p.r < 128 && p.g < 128 && p.b < 128; }

// Lowest image row (largest y) holding a dark pixel in rows [0, rows), -1 if none.
int lowest_dark_row(const std::vector<std::uint8_t>& rgb, int width, int rows) {
  int lowest = -1;
  for (int y = 0; y < rows; ++y)
    for (int x = 0; x < width; ++x)
      if (dark(at(rgb, width, x, y))) lowest = y;
  return lowest;
}

TEST(RenderText, CaptionGlyphsHaveDescenders) {
  if (!text_uses_freetype()) GTEST_SKIP() << "built without FreeType: the 5x7 font has no descenders";
  OffscreenRenderer renderer(kLW, kLH);
  RenderFrame scene = blank_scene(kLW, kLH);
  scene.text = {"xxxx"};
  const int x_bottom = lowest_dark_row(renderer.render(scene), kLW, kLH / 2);
  scene.text = {"gygy"};
  const int g_bottom = lowest_dark_row(renderer.render(scene), kLW, kLH / 2);
  ASSERT_GT(x_bottom, 0);
  // 'g' and 'y' reach below the baseline, where 'x' ends.
  EXPECT_GE(g_bottom, x_bottom + 2) << "x ends at row " << x_bottom << ", g/y at " << g_bottom;

  // The same with TextFont directly: ink below the baseline for "gy", none for "x".
  const TextFont font(20);
  ASSERT_TRUE(font.freetype());
  EXPECT_GE(font.descent(), 3);
  const int w = 60, h = 40, baseline = 25;
  std::vector<std::uint8_t> gy(static_cast<std::size_t>(w * h * 3), 255), x(gy);
  EXPECT_GT(font.draw(gy, w, h, 2, baseline, "gy", {0.0f, 0.0f, 0.0f}), 2 + 10);
  font.draw(x, w, h, 2, baseline, "x", {0.0f, 0.0f, 0.0f});
  int below_gy = 0, below_x = 0, partial = 0;
  for (int yy = 0; yy < h; ++yy)
    for (int xx = 0; xx < w; ++xx) {
      const int v = at(gy, w, xx, yy).r;
      if (v > 0 && v < 255) ++partial;  // anti-aliased edges
      if (yy > baseline + 1 && v < 128) ++below_gy;
      if (yy > baseline + 1 && at(x, w, xx, yy).r < 128) ++below_x;
    }
  EXPECT_GT(below_gy, 6);
  EXPECT_EQ(below_x, 0);
  EXPECT_GT(partial, 10);
}

TEST(RenderText, LongCaptionWrapsWithinTheWidth) {
  OffscreenRenderer renderer(kLW, kLH);
  RenderFrame scene = blank_scene(kLW, kLH);
  scene.text = {"Wrap"};
  const int one_line_bottom = lowest_dark_row(renderer.render(scene), kLW, kLH);
  ASSERT_GT(one_line_bottom, 0);
  scene.text = {"A long title: it goes on about magnetised steel balls and nails, and about how "
                "they are lifted, carried and lowered, well past the width of the picture"};
  const auto rgb = renderer.render(scene);
  // No ink in the right margin (the background there is untouched)...
  for (int y = 0; y < kLH; ++y)
    for (int x = kLW - 3; x < kLW; ++x) expect_background(at(rgb, kLW, x, y), scene.background);
  // ... and the caption takes several lines, none of them cut off.
  const int bottom = lowest_dark_row(rgb, kLW, kLH);
  EXPECT_GT(bottom, 2 * one_line_bottom) << "one line ends at row " << one_line_bottom;
  EXPECT_LT(bottom, kLH / 2);
  int right_half = 0;  // text beyond the first colon and the first line
  for (int y = one_line_bottom + 4; y <= bottom; ++y)
    for (int x = kLW / 2; x < kLW; ++x) right_half += dark(at(rgb, kLW, x, y)) ? 1 : 0;
  EXPECT_GT(right_half, 30);
}

std::array<int, 3> bytes(const RenderColor& c) {
  return {static_cast<int>(std::lround(c[0] * 255.0f)), static_cast<int>(std::lround(c[1] * 255.0f)),
          static_cast<int>(std::lround(c[2] * 255.0f))};
}

int count_exact(const std::vector<std::uint8_t>& rgb, int width, int y0, int y1, const RenderColor& color) {
  const auto c = bytes(color);
  int n = 0;
  for (int y = y0; y < y1; ++y)
    for (int x = 0; x < width; ++x) {
      const Pixel p = at(rgb, width, x, y);
      if (p.r == c[0] && p.g == c[1] && p.b == c[2]) ++n;
    }
  return n;
}

TEST(RenderLegend, PoleSwatchesUseThePoleColours) {
  OffscreenRenderer renderer(kLW, kLH);
  RenderFrame scene = blank_scene(kLW, kLH);
  const auto plain = renderer.render(scene);
  EXPECT_EQ(count_exact(plain, kLW, 0, kLH, palette::north), 0);
  scene.legend.poles = true;
  EXPECT_EQ(scene.legend.north, palette::north);
  EXPECT_EQ(scene.legend.south, palette::south);
  const auto rgb = renderer.render(scene);
  // Filled swatches in the band at the bottom, nothing in the upper part.
  EXPECT_GE(count_exact(rgb, kLW, kLH * 3 / 4, kLH, palette::north), 16);
  EXPECT_GE(count_exact(rgb, kLW, kLH * 3 / 4, kLH, palette::south), 16);
  for (int y = 0; y < kLH * 3 / 4; ++y)
    for (int x = 0; x < kLW; ++x) ASSERT_EQ(at(rgb, kLW, x, y).g, at(plain, kLW, x, y).g);
  // Other pole colours are drawn as given.
  scene.legend.north = {0.9f, 0.5f, 0.0f};
  EXPECT_GE(count_exact(renderer.render(scene), kLW, kLH * 3 / 4, kLH, scene.legend.north), 16);
}

TEST(RenderLegend, ColourBarShowsTheMap) {
  OffscreenRenderer renderer(kLW, kLH);
  RenderFrame scene = blank_scene(kLW, kLH);
  for (int i = 0; i <= 4; ++i) scene.legend.colorbar.push_back(force_color(i / 4.0));
  scene.legend.colorbar_high = 0.012;
  const auto rgb = renderer.render(scene);
  // Both ends of the map appear (bar samples at the pixel centres: within a
  // few levels of the end colours).
  for (const RenderColor& end : {force_color(0.0), force_color(1.0)}) {
    const auto c = bytes(end);
    int near = 0;
    for (int y = kLH * 3 / 4; y < kLH; ++y)
      for (int x = 0; x < kLW; ++x) {
        const Pixel p = at(rgb, kLW, x, y);
        if (std::abs(p.r - c[0]) + std::abs(p.g - c[1]) + std::abs(p.b - c[2]) < 24) ++near;
      }
    EXPECT_GE(near, 4);
  }
}

// Longest horizontal run of pixels of exactly `color` in rows [y0, y1).
int longest_run(const std::vector<std::uint8_t>& rgb, int width, int y0, int y1, const RenderColor& color) {
  const auto c = bytes(color);
  int best = 0;
  for (int y = y0; y < y1; ++y) {
    int run = 0;
    for (int x = 0; x < width; ++x) {
      const Pixel p = at(rgb, width, x, y);
      run = (p.r == c[0] && p.g == c[1] && p.b == c[2]) ? run + 1 : 0;
      best = std::max(best, run);
    }
  }
  return best;
}

TEST(RenderLegend, ScaleBarMatchesTheCameraGeometry) {
  OffscreenRenderer renderer(kLW, kLH);
  struct Case {
    double distance, fov;
  };
  for (const Case& c : {Case{0.5, 40.0}, Case{0.13, 40.0}, Case{3.0, 25.0}, Case{0.02, 60.0}}) {
    SCOPED_TRACE(c.distance);
    RenderFrame scene = blank_scene(kLW, kLH);
    scene.camera.position = {0.0, -c.distance, 0.0};
    scene.camera.fov_degrees = c.fov;
    const auto plain = renderer.render(scene);
    scene.legend.scale_bar = true;
    const auto rgb = renderer.render(scene);
    const int bar = longest_run(rgb, kLW, kLH * 3 / 4, kLH, scene.text_color);
    EXPECT_EQ(longest_run(plain, kLW, 0, kLH, scene.text_color), 0);
    // Pixels per metre at the target: the image height spans
    // 2 d tan(fov / 2) metres there.
    const double per_metre = kLH / (2.0 * c.distance * std::tan(c.fov / 2.0 * std::numbers::pi / 180.0));
    const double metres = bar / per_metre;
    // The bar's length is 1, 2 or 5 times a power of ten...
    const double decade = std::pow(10.0, std::floor(std::log10(metres * 1.02)));
    double nearest = 0.0;
    for (double m : {1.0, 2.0, 5.0, 10.0})
      if (std::abs(m * decade - metres) < std::abs(nearest - metres)) nearest = m * decade;
    EXPECT_NEAR(bar, nearest * per_metre, 1.0) << metres << " m";
    // ... and a readable part of the width.
    EXPECT_GE(bar, 20);
    EXPECT_LE(bar, kLW / 2);
    const ScaleBar sb = scale_bar_for(scene.camera, kLH, 0.2 * kLW);
    EXPECT_NEAR(sb.metres, nearest, 1e-9 * nearest);
    EXPECT_NEAR(sb.pixels, bar, 1.0);
  }
  RenderCamera camera;
  camera.position = {0.0, -0.5, 0.0};
  camera.target = {0.0, 0.0, 0.0};
  EXPECT_EQ(scale_bar_for(camera, 480, 100.0).label, "5 cm");  // 100 px span 7.6 cm there
  EXPECT_EQ(scale_bar_for(camera, 480, 1500.0).label, "1 m");
  EXPECT_EQ(scale_bar_for(camera, 480, 10.0).label, "5 mm");
}

TEST(RenderTranslucent, BallBehindGlassShows) {
  RenderFrame scene = front_scene();
  scene.primitives.push_back(RenderPrimitive::sphere({0, 0.05, 0}, 0.04, {0.9f, 0.1f, 0.1f}));
  RenderPrimitive glass = RenderPrimitive::box({0, -0.02, 0}, {0.2, 0.01, 0.2}, Mat3{}, {0.75f, 0.85f, 0.9f});
  scene.primitives.push_back(glass);
  OffscreenRenderer renderer(kW, kH);
  const Pixel opaque = at(renderer.render(scene), kW, kW / 2, kH / 2);
  EXPECT_LT(opaque.r, opaque.b) << "an opaque pane hides the ball";
  scene.primitives[1].opacity = 0.3f;
  const auto rgb = renderer.render(scene);
  const Pixel through = at(rgb, kW, kW / 2, kH / 2);
  EXPECT_GT(through.r, through.g + 60) << through.r << "," << through.g << "," << through.b;
  // The pane still tints the background around the ball.
  const Pixel pane = at(rgb, kW, kW / 2 - 10, kH / 2);  // beside the ball, in front of the pane
  const auto bg = bytes(scene.background);
  EXPECT_GT(std::abs(pane.r - bg[0]) + std::abs(pane.g - bg[1]) + std::abs(pane.b - bg[2]), 6);
  // Draw order does not matter: glass listed first.
  std::swap(scene.primitives[0], scene.primitives[1]);
  const Pixel swapped = at(renderer.render(scene), kW, kW / 2, kH / 2);
  EXPECT_NEAR(swapped.r, through.r, 2);
  EXPECT_NEAR(swapped.g, through.g, 2);
}

TEST(RenderSetup, RejectsBadSizes) {
  EXPECT_THROW(OffscreenRenderer(0, 10), std::invalid_argument);
  EXPECT_THROW(OffscreenRenderer(10, 10, 0), std::invalid_argument);
  EXPECT_THROW(OffscreenRenderer(10000, 10, 2), std::invalid_argument);
}

// ---------------------------------------------------------------- PNG

std::filesystem::path scratch_dir(const std::string& name) {
  const auto dir = std::filesystem::temp_directory_path() /
                   ("odemag_render_test_" + name + "_" + std::to_string(::getpid()));
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  return dir;
}

bool read_png_rgb(const std::string& path, int* width, int* height, std::vector<std::uint8_t>* rgb) {
  png_image image{};
  image.version = PNG_IMAGE_VERSION;
  if (!png_image_begin_read_from_file(&image, path.c_str())) return false;
  image.format = PNG_FORMAT_RGB;
  rgb->assign(PNG_IMAGE_SIZE(image), 0);
  if (!png_image_finish_read(&image, nullptr, rgb->data(), 0, nullptr)) {
    png_image_free(&image);
    return false;
  }
  *width = static_cast<int>(image.width);
  *height = static_cast<int>(image.height);
  return true;
}

TEST(RenderPng, RoundTripBytes) {
  const auto dir = scratch_dir("png");
  const int w = 7, h = 5;
  std::vector<std::uint8_t> rgb(static_cast<std::size_t>(w * h * 3));
  for (std::size_t i = 0; i < rgb.size(); ++i) rgb[i] = static_cast<std::uint8_t>((i * 37 + 11) % 256);
  const std::string path = (dir / frame_filename(3)).string();
  EXPECT_EQ(frame_filename(3), "frame_00003.png");
  std::string error;
  ASSERT_TRUE(write_png(path, w, h, rgb, &error)) << error;
  int rw = 0, rh = 0;
  std::vector<std::uint8_t> back;
  ASSERT_TRUE(read_png_rgb(path, &rw, &rh, &back));
  EXPECT_EQ(rw, w);
  EXPECT_EQ(rh, h);
  EXPECT_EQ(back, rgb);

  // Overwriting works too, and no temporary files are left behind.
  for (auto& v : rgb) v = static_cast<std::uint8_t>(255 - v);
  ASSERT_TRUE(write_png(path, w, h, rgb, &error)) << error;
  ASSERT_TRUE(read_png_rgb(path, &rw, &rh, &back));
  EXPECT_EQ(back, rgb);
  int files = 0;
  for (const auto& entry : std::filesystem::directory_iterator(dir)) {
    ++files;
    EXPECT_EQ(entry.path().filename().string(), "frame_00003.png");
  }
  EXPECT_EQ(files, 1);
  std::filesystem::remove_all(dir);
}

TEST(RenderPng, MissingDirectoryFailsWithMessageAndNoFile) {
  const auto dir = scratch_dir("png_missing");
  const auto path = dir / "no_such_dir" / "frame.png";
  std::vector<std::uint8_t> rgb(4 * 4 * 3, 128);
  std::string error;
  EXPECT_FALSE(write_png(path.string(), 4, 4, rgb, &error));
  EXPECT_FALSE(error.empty());
  EXPECT_NE(error.find("no_such_dir"), std::string::npos) << error;
  EXPECT_FALSE(std::filesystem::exists(path));
  EXPECT_TRUE(std::filesystem::is_empty(dir));
  EXPECT_FALSE(write_png(path.string(), 4, 4, rgb));  // null error pointer is fine
  std::filesystem::remove_all(dir);
}

TEST(RenderPng, FailureAfterEncodingLeavesNoTemporaryFile) {
  // The target is an existing non-empty directory: the temporary file is
  // written, then rename(2) fails; it must be cleaned up.
  const auto dir = scratch_dir("png_rename");
  const auto target = dir / "frame_00000.png";
  std::filesystem::create_directories(target / "occupied");
  std::vector<std::uint8_t> rgb(4 * 4 * 3, 77);
  std::string error;
  EXPECT_FALSE(write_png(target.string(), 4, 4, rgb, &error));
  EXPECT_NE(error.find("rename"), std::string::npos) << error;
  int entries = 0;
  for (const auto& entry : std::filesystem::directory_iterator(dir)) {
    ++entries;
    EXPECT_EQ(entry.path().filename(), "frame_00000.png");
  }
  EXPECT_EQ(entries, 1);
  EXPECT_TRUE(std::filesystem::is_directory(target / "occupied"));
  std::filesystem::remove_all(dir);
}

TEST(RenderPng, WrongBufferSizeFails) {
  const auto dir = scratch_dir("png_size");
  std::string error;
  EXPECT_FALSE(write_png((dir / "a.png").string(), 4, 4, std::vector<std::uint8_t>(10), &error));
  EXPECT_FALSE(error.empty());
  EXPECT_TRUE(std::filesystem::is_empty(dir));
  std::filesystem::remove_all(dir);
}

TEST(RenderPng, RenderedFrameRoundTrips) {
  const auto dir = scratch_dir("png_frame");
  RenderFrame scene = front_scene();
  scene.primitives.push_back(RenderPrimitive::sphere({0, 0, 0}, 0.08, {0.9f, 0.1f, 0.1f}));
  OffscreenRenderer renderer(kW, kH);
  const auto rgb = renderer.render(scene);
  const std::string path = (dir / "f.png").string();
  std::string error;
  ASSERT_TRUE(write_png(path, kW, kH, rgb, &error)) << error;
  int rw = 0, rh = 0;
  std::vector<std::uint8_t> back;
  ASSERT_TRUE(read_png_rgb(path, &rw, &rh, &back));
  EXPECT_EQ(back, rgb);
  std::filesystem::remove_all(dir);
}

// ---------------------------------------------------------------- rainbow

TEST(RenderRainbow, VioletToRedWithFallingHue) {
  const RenderColor v = rainbow(0.0);
  EXPECT_GT(v[2], v[1]);
  EXPECT_GT(v[0], v[1]);
  EXPECT_GT(v[2], v[0]);  // violet: more blue than red
  const RenderColor r = rainbow(1.0);
  EXPECT_GT(r[0], 2 * r[1]);
  EXPECT_GT(r[0], 2 * r[2]);
  const RenderColor mid = rainbow(0.5);  // green
  EXPECT_GT(mid[1], mid[0]);
  EXPECT_GT(mid[1], mid[2]);
  double previous = hue_degrees(rainbow(0.0));
  EXPECT_NEAR(previous, 270.0, 1.0);
  for (int i = 1; i <= 20; ++i) {
    const double h = hue_degrees(rainbow(i / 20.0));
    EXPECT_LT(h, previous) << "t = " << i / 20.0;
    previous = h;
  }
  EXPECT_NEAR(hue_degrees(rainbow(0.5)), 135.0, 1.0);
  // Clamped outside [0, 1]; NaN is the weakest.
  EXPECT_EQ(rainbow(-1.0), rainbow(0.0));
  EXPECT_EQ(rainbow(2.0), rainbow(1.0));
  EXPECT_EQ(rainbow(std::nan("")), rainbow(0.0));
}

TEST(RenderForceColours, DistinctFromThePoleColours) {
  const double north = hue_degrees(palette::north), south = hue_degrees(palette::south);
  auto hue_gap = [](double a, double b) {
    const double d = std::fmod(std::abs(a - b), 360.0);
    return std::min(d, 360.0 - d);
  };
  double previous_brightness = -1.0;
  for (int i = 0; i <= 20; ++i) {
    const RenderColor c = force_color(i / 20.0);
    SCOPED_TRACE(i);
    EXPECT_GT(hue_gap(hue_degrees(c), north), 40.0);
    EXPECT_GT(hue_gap(hue_degrees(c), south), 40.0);
    EXPECT_FALSE(c[0] > 2 * c[1] && c[0] > 2 * c[2]);  // never red
    const double brightness = c[0] + c[1] + c[2];
    EXPECT_GT(brightness, previous_brightness);  // weak dark, strong bright
    previous_brightness = brightness;
  }
  EXPECT_EQ(force_color(-1.0), force_color(0.0));
  EXPECT_EQ(force_color(2.0), force_color(1.0));
  EXPECT_EQ(force_color(std::nan("")), force_color(0.0));
}

}  // namespace
}  // namespace odemag
