// Mesh bodies (docs/benchmarks.md "Mesh bodies"):
// 1. load and build: a binary STL of a UV sphere of about 100,000 triangles
//    (written here), through the scene loader (Assimp, joining vertices, the
//    checks, centring) and the model (cells, boundary correction) at about
//    2000 cells;
// 2. one field evaluation (a relaxation iteration of a soft body) of a mesh
//    body of N cells against a box of N cells;
// 3. T_r of a trimesh contact beside the primitive's: a meshed ball resting
//    on a meshed plate against a sphere on a box.
// Prints CSV: measurement,case,value,unit.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "magnetics/model/backend.h"
#include "magnetics/model/model.h"
#include "magnetics/model/state.h"
#include "magnetics/relax/relax.h"
#include "odemag/constants.h"
#include "odemag/scene.h"
#include "odemag/simulation.h"
#include "tests/support/mesh_builders.h"

using namespace odemag;
using Clock = std::chrono::steady_clock;

namespace {

double seconds_since(Clock::time_point t) { return std::chrono::duration<double>(Clock::now() - t).count(); }

// A UV sphere of radius R (mm in the file): n rings of 2n segments.
void write_sphere_stl(const std::string& path, double R, int n) {
  std::vector<Vec3> v;
  // The poles and the seam exactly shared (identical coordinates join).
  auto at = [&](int i, int j) {
    if (i == 0) return Vec3{0.0, 0.0, R};
    if (i == n) return Vec3{0.0, 0.0, -R};
    const double t = kPi * i / n, p = 2.0 * kPi * (j % (2 * n)) / (2 * n);
    return Vec3{R * std::sin(t) * std::cos(p), R * std::sin(t) * std::sin(p), R * std::cos(t)};
  };
  std::vector<std::array<Vec3, 3>> tris;
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < 2 * n; ++j) {
      const Vec3 a = at(i, j), b = at(i + 1, j), c = at(i + 1, j + 1), d = at(i, j + 1);
      if (i > 0) tris.push_back({a, b, d});
      if (i < n - 1) tris.push_back({b, c, d});
    }
  std::ofstream out(path, std::ios::binary);
  out << std::string(80, ' ');
  const auto count = static_cast<uint32_t>(tris.size());
  out.write(reinterpret_cast<const char*>(&count), 4);
  for (const auto& t : tris) {
    float data[12] = {};
    for (int k = 0; k < 3; ++k)
      for (int a = 0; a < 3; ++a) data[3 + 3 * k + a] = static_cast<float>(t[k][a]);
    out.write(reinterpret_cast<const char*>(data), sizeof data);
    out.write("\0\0", 2);
  }
}

SoftMaterial linear_soft() {
  SoftMaterial m;
  m.saturation = 1e12;
  m.susceptibility = 1000.0;
  return m;
}

// Seconds per relaxation iteration of one soft body in a uniform field
// (50 iterations, tolerance 0, best of 3).
double seconds_per_iteration(const Shape& shape, double h, int* cells) {
  MagneticModel model;
  model.add_body("body", shape, linear_soft(), h);
  *cells = model.cell_count();
  auto backend = make_cpu_backend(1);
  double best = 1e300;
  for (int rep = 0; rep < 3; ++rep) {
    MagneticState state = make_state(model, 7);
    state.external_field = {1e3, 2e3, 0.0};
    RelaxOptions o;
    o.tolerance = 0.0;
    o.max_iterations = 50;
    const auto t = Clock::now();
    const RelaxReport r = relax(model, state, o, *backend);
    best = std::min(best, seconds_since(t) / std::max(1, r.iterations));
  }
  return best;
}

// Mean T_r (ms) of the rigid steps of a ball resting on a plate, after 0.5 s.
double resting_rigid_ms(const Shape& ball, const Shape& plate) {
  SceneDescription s;
  s.file = "rest";
  s.simulation.ground = false;
  s.materials["wood"] = InertMaterial{};
  BodyDescription p;
  p.name = "plate", p.shape = plate, p.material = "wood", p.fixed = true;
  BodyDescription b;
  b.name = "ball", b.shape = ball, b.material = "wood", b.position = {0, 0, 0.0075}, b.density = 700.0;
  s.bodies = {p, b};
  s.simulation.time_step = 0.001;
  Simulation sim(s);
  for (int k = 0; k < 500; ++k) sim.step();
  double total = 0.0;
  const size_t first = sim.records().size();
  for (int k = 0; k < 1000; ++k) sim.step();
  for (size_t k = first; k < sim.records().size(); ++k) total += sim.records()[k].rigid_ms;
  return total / static_cast<double>(sim.records().size() - first);
}

}  // namespace

int main() {
  std::printf("measurement,case,value,unit\n");
  // 1. Load and build.
  const auto dir = std::filesystem::temp_directory_path() / "odemag_mesh_body_bench";
  std::filesystem::create_directories(dir);
  write_sphere_stl((dir / "sphere.stl").string(), 10.0, 158);
  std::ofstream(dir / "scene.json") << R"({"cell_size": 0.0016,
    "materials": {"iron": {"type": "soft", "saturation": 1.6e6, "susceptibility": 1000}},
    "bodies": [{"name": "ball", "shape": {"mesh": {"file": "sphere.stl", "scale": 0.001}}, "material": "iron"}]})";
  double load_best = 1e300, build_best = 1e300;
  size_t triangles = 0;
  int cells = 0;
  for (int rep = 0; rep < 3; ++rep) {
    const auto t0 = Clock::now();
    const SceneDescription scene = load_scene((dir / "scene.json").string());
    load_best = std::min(load_best, seconds_since(t0));
    triangles = std::get<Mesh>(scene.bodies[0].shape).triangles().size();
    const auto t1 = Clock::now();
    MagneticModel model;
    model.add_body("ball", scene.bodies[0].shape, linear_soft(), scene.body_cell_size(0));
    build_best = std::min(build_best, seconds_since(t1));
    cells = model.cell_count();
  }
  std::printf("load,%zu triangles,%.3f,s\n", triangles, load_best);
  std::printf("build,%d cells,%.3f,s\n", cells, build_best);
  std::printf("load_and_build,%zu triangles,%.3f,s\n", triangles, load_best + build_best);
  std::filesystem::remove_all(dir);

  // 2. Field evaluations: a mesh body and a box of about the same cells.
  for (double h : {0.002, 0.0013}) {
    int mesh_cells = 0, box_cells = 0;
    const Mesh ball = test::ellipsoid_mesh(0.01, 0.01, 0.01, 5);
    const double mesh_s = seconds_per_iteration(ball, h, &mesh_cells);
    // A cube of the same cell count.
    const int n = static_cast<int>(std::lround(std::cbrt(mesh_cells)));
    const double box_s = seconds_per_iteration(Box{{n * h, n * h, n * h}}, h, &box_cells);
    std::printf("iteration,mesh ball %d cells,%.3f,ms\n", mesh_cells, mesh_s * 1e3);
    std::printf("iteration,box %d cells,%.3f,ms\n", box_cells, box_s * 1e3);
    std::printf("iteration_per_cell_pair,mesh ball %d cells,%.3f,ns\n", mesh_cells,
                mesh_s * 1e9 / (static_cast<double>(mesh_cells) * mesh_cells));
    std::printf("iteration_per_cell_pair,box %d cells,%.3f,ns\n", box_cells,
                box_s * 1e9 / (static_cast<double>(box_cells) * box_cells));
  }

  // 3. T_r of resting contacts.
  const double R = 0.005;
  const Mesh ball = test::ellipsoid_mesh(R, R, R, 3);
  const Mesh plate = test::box_surface_mesh({0.06, 0.06, 0.004}, 4);
  std::printf("rigid_step,sphere on box,%.4f,ms\n", resting_rigid_ms(Sphere{R}, Box{{0.06, 0.06, 0.004}}));
  std::printf("rigid_step,mesh ball (1280 triangles) on box,%.4f,ms\n", resting_rigid_ms(ball, Box{{0.06, 0.06, 0.004}}));
  std::printf("rigid_step,sphere on mesh plate (192 triangles),%.4f,ms\n", resting_rigid_ms(Sphere{R}, plate));
  std::printf("rigid_step,mesh ball on mesh plate,%.4f,ms\n", resting_rigid_ms(ball, plate));
  return 0;
}
