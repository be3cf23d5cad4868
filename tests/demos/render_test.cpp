// Tests of the headless renderer: pixels where the geometry is, magnet pole
// colours, depth testing, lines, captions, the PNG writer and the rainbow map.
#include <png.h>
#include <unistd.h>

#include <cmath>
#include <cstdint>
#include <filesystem>
#include <numbers>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "demos/render/colors.h"
#include "demos/render/png_writer.h"
#include "demos/render/renderer.h"

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

}  // namespace
}  // namespace odemag
