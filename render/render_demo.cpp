// Renders a demonstration frame (a bar magnet over the checkered ground, iron
// balls, field lines, a caption) to a PNG and reports the time per frame.
//
//   odemag_render_demo [output.png] [width height supersample]
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <numbers>
#include <string>

#include "render/colors.h"
#include "render/png_writer.h"
#include "render/renderer.h"

namespace {

using odemag::Mat3;
using odemag::RenderLine;
using odemag::RenderPrimitive;
using odemag::RenderFrame;
using odemag::Vec3;

Mat3 rotation_z(double angle) {
  Mat3 r;
  r.m[0][0] = std::cos(angle);
  r.m[0][1] = -std::sin(angle);
  r.m[1][0] = std::sin(angle);
  r.m[1][1] = std::cos(angle);
  return r;
}

RenderFrame demo_scene(int width, int height) {
  RenderFrame scene;
  scene.camera.position = {0.085, -0.15, 0.085};
  scene.camera.target = {0.0, -0.01, 0.025};
  scene.camera.width = width;
  scene.camera.height = height;
  scene.ground_extent = 0.12;
  scene.ground_tile = 0.02;

  // A 60 x 12 x 12 mm bar magnet, north towards its +x, held 30 mm above the
  // ground and turned a little about z.
  const Vec3 centre{0.0, 0.0, 0.03};
  const Mat3 yaw = rotation_z(0.15);
  RenderPrimitive magnet = RenderPrimitive::box(centre, {0.06, 0.012, 0.012}, yaw, {0.5f, 0.5f, 0.5f});
  magnet.pole_axis = {1.0, 0.0, 0.0};
  scene.primitives.push_back(magnet);

  // Three iron balls (radius 5 mm) on the ground.
  scene.primitives.push_back(RenderPrimitive::sphere({0.045, 0.015, 0.005}, 0.005, odemag::palette::iron));
  scene.primitives.push_back(RenderPrimitive::sphere({-0.05, -0.02, 0.005}, 0.005, odemag::palette::iron));
  scene.primitives.push_back(RenderPrimitive::sphere({0.01, -0.045, 0.005}, 0.005, odemag::palette::iron));
  // A nail lying on the ground.
  Mat3 lying;  // body z along world y
  lying.m[1][1] = 0.0; lying.m[1][2] = -1.0; lying.m[2][1] = 1.0; lying.m[2][2] = 0.0;
  scene.primitives.push_back(RenderPrimitive::cylinder({-0.035, -0.055, 0.0015}, 0.0015, 0.04,
                                                       rotation_z(1.2) * lying, odemag::palette::steel));

  // Dipole field lines r = k sin^2(theta) (theta from the magnet's axis) in
  // planes through the axis, turned by psi about it.
  for (double psi : {-1.0, 0.0, 1.0}) {
    for (double k : {0.024, 0.036, 0.052}) {
      RenderLine line;
      line.color = odemag::palette::field_line;
      line.width = 1.5f;
      for (int i = 0; i <= 160; ++i) {
        const double theta = 0.12 + (std::numbers::pi - 0.24) * i / 160.0;
        const double r = k * std::sin(theta) * std::sin(theta);
        const Vec3 local{r * std::cos(theta), r * std::sin(theta) * std::sin(psi),
                         r * std::sin(theta) * std::cos(psi)};
        line.points.push_back(centre + yaw * local);
      }
      scene.lines.push_back(line);
    }
  }
  scene.text = {"t = 0.40 s", "bar magnet + 3 iron balls"};
  return scene;
}

}  // namespace

int main(int argc, char** argv) {
  const std::string out = argc > 1 ? argv[1] : "render_demo.png";
  const int width = argc > 3 ? std::atoi(argv[2]) : 640;
  const int height = argc > 3 ? std::atoi(argv[3]) : 480;
  const int supersample = argc > 4 ? std::atoi(argv[4]) : 2;
  try {
    odemag::OffscreenRenderer renderer(width, height, supersample);
    const RenderFrame scene = demo_scene(width, height);
    auto rgb = renderer.render(scene);  // warm-up
    const int frames = 20;
    const auto t0 = std::chrono::steady_clock::now();
    for (int i = 0; i < frames; ++i) rgb = renderer.render(scene);
    const auto t1 = std::chrono::steady_clock::now();
    std::string error;
    if (!odemag::write_png(out, width, height, rgb, &error)) {
      std::fprintf(stderr, "%s\n", error.c_str());
      return 1;
    }
    const auto t2 = std::chrono::steady_clock::now();
    const double render_ms = std::chrono::duration<double, std::milli>(t1 - t0).count() / frames;
    const double png_ms = std::chrono::duration<double, std::milli>(t2 - t1).count();
    std::printf("%dx%d supersample %d: %.1f ms/frame render, %.1f ms PNG write; wrote %s\n", width,
                height, supersample, render_ms, png_ms, out.c_str());
  } catch (const std::exception& e) {
    std::fprintf(stderr, "odemag_render_demo: %s\n", e.what());
    return 1;
  }
  return 0;
}
