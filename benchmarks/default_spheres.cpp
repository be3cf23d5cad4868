// Two soft lattice balls as a user writes them, every solver key at its
// default (refined contact zones on), through solve_scene (what `odemag
// solve` runs), against the exact two-sphere series
// (tests/support/contact_references.h): the force on the upper ball for
// R/h, gap, susceptibility and a uniform field along or across the line of
// centres (docs/validation.md "Lattice balls with the default settings").
// CSV on stdout:
//   R_over_h,gap_over_R,chi,field,cells_per_ball,iterations,converged,force_error,seconds
// Usage: default_spheres [--threads N] [--quick] [--plain]
//   --quick: R/h 4 only; --plain: solver.contact_refinement false (the plain
//   lattice, for comparison).
#include <chrono>
#include <cstdio>
#include <cstring>
#include <string>

#include "odemag/scene.h"
#include "odemag/solve.h"
#include "tests/support/contact_references.h"

using namespace odemag;

namespace {

constexpr double kR = 0.01;   // ball radius, m
constexpr double kH0 = 1e3;   // applied field, A/m

SceneDescription two_balls(double R_over_h, double gap_over_R, double chi, bool across, int threads,
                           bool plain) {
  SceneDescription scene;
  scene.gravity = {0, 0, 0};
  SoftMaterial soft;
  soft.saturation = 1e12;  // linear: saturation far above the fields here
  soft.susceptibility = chi;
  scene.materials["soft"] = soft;
  for (int b = 0; b < 2; ++b) {
    BodyDescription body;
    body.name = b == 0 ? "lower" : "upper";
    body.shape = Sphere{kR};
    body.material = "soft";
    body.cell_size = kR / R_over_h;
    body.fixed = true;
    body.position = {0.0, 0.0, b == 0 ? 0.0 : (2.0 + gap_over_R) * kR};
    scene.bodies.push_back(body);
  }
  scene.external_field = across ? Vec3{kH0, 0.0, 0.0} : Vec3{0.0, 0.0, kH0};
  scene.solver.threads = threads;
  if (plain) scene.solver.contact_refinement = false;
  return scene;
}

}  // namespace

int main(int argc, char** argv) {
  int threads = 1;
  bool quick = false, plain = false;
  for (int i = 1; i < argc; ++i) {
    if (!std::strcmp(argv[i], "--threads") && i + 1 < argc) {
      threads = std::atoi(argv[++i]);
    } else if (!std::strcmp(argv[i], "--quick")) {
      quick = true;
    } else if (!std::strcmp(argv[i], "--plain")) {
      plain = true;
    } else {
      std::fprintf(stderr, "usage: default_spheres [--threads N] [--quick] [--plain]\n");
      return 2;
    }
  }
  std::printf("R_over_h,gap_over_R,chi,field,cells_per_ball,iterations,converged,force_error,seconds\n");
  const double ratios[] = {4.0, 5.0, 6.0};
  for (double R_over_h : ratios) {
    if (quick && R_over_h != 4.0) continue;
    for (double gap : {0.02, 0.05, 0.2, 1.0, 4.0})
      for (double chi : {10.0, 1000.0, 1e4})
        for (bool across : {false, true}) {
          const SceneDescription scene = two_balls(R_over_h, gap, chi, across, threads, plain);
          const auto ref = reference::two_linear_spheres_in_uniform_field(
              kR, chi, kR, chi, {0, 0, 0}, {0.0, 0.0, (2.0 + gap) * kR}, scene.external_field);
          const auto t0 = std::chrono::steady_clock::now();
          const SceneSolution s = solve_scene(scene);
          const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
          const double error = norm(s.bodies[1].force - ref.force_on_2) / norm(ref.force_on_2);
          std::printf("%g,%g,%g,%s,%d,%d,%d,%.4e,%.3f\n", R_over_h, gap, chi, across ? "across" : "along",
                      s.bodies[1].cells, s.report.iterations, s.report.converged ? 1 : 0, error, seconds);
          std::fflush(stdout);
        }
  }
}
