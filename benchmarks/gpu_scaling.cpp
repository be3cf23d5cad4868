// Scaling of the CPU and CUDA backends with the number of soft cells
// (docs/gpu.md "Benchmark"): time per responsive-field evaluation, per local
// relaxation (relax_cells) and per outer relaxation iteration (relax_cells +
// responsive_field), per force evaluation; ns per pair interaction and the
// achieved GFLOP/s; and the time per magnetic step of a scene like the
// paper's crane magnet (Fig. 17, 690 cells). Output: CSV on stdout, notes on
// stderr.
//
// Usage: gpu_scaling [--max-cells N] [--min-cells N] [--cpu-max-cells N]
//                    [--threads N] [--no-cpu] [--no-cuda]
// Sizes: 64, 128, 256, 512, 1k, 2k, 5k, 10k, 20k, 50k, 100k cells, those in
// [--min-cells, --max-cells] (default 1000 .. 100000). The first relax_cells
// and forces call of each scene is not timed (lazy kernel loading).
//
// Flops per pair interaction (a division and a square root count as one each):
//   field, dipole kernel (kernels.h dipole_field): offset 3, |r|^2 5, contact
//     distance 2, coefficients A and B 6, T mu (dot 5, scale 1, A mu 3,
//     (B r.mu) r 3, sum 3), accumulate 3                                = 34
//   field, intra-body table (symmetric_times + accumulate)              = 18
//   force + field of one pair (cell_forces_kernel: shared offset and
//     coefficients 18, dipole_force 48, dipole_field 18)                = 84
// Pairs counted are those that interact: responsive field, cells of different
// bodies (dipole) plus ordered pairs of distinct cells of one body (table);
// forces, ordered pairs of cells of different bodies.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "gpu/cuda_backend.h"
#include "magnetics/model/backend.h"
#include "magnetics/relax/relax.h"
#include "magnetics/kernels/rng.h"
#include "tests/support/magnetic_setup.h"

using namespace odemag;

namespace {

constexpr double kFieldFlopsDipole = 34.0;
constexpr double kFieldFlopsTable = 18.0;
constexpr double kForceFlops = 84.0;

using Clock = std::chrono::steady_clock;

double ms_since(Clock::time_point t0) {
  return std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
}

SoftMaterial iron() { return test_support::soft_material(1.7e6, 5000.0); }

struct Scene {
  std::string name;
  MagneticModel model;
  std::vector<BodyPose> poses;
};

// Interacting pairs (see the top of the file).
struct Pairs {
  double field_dipole = 0, field_table = 0, force = 0;
};

Pairs count_pairs(const MagneticModel& model) {
  double responsive = 0, all = 0, same_responsive = 0, same_all = 0, table = 0;
  for (const MagneticBody& body : model.bodies()) {
    const double n = body.cell_count();
    all += n, same_all += n * n;
    if (!body.responsive()) continue;
    responsive += n, same_responsive += n * n, table += n * (n - 1);
  }
  return {responsive * responsive - same_responsive, table, all * all - same_all};
}

int add_body(Scene& s, const std::string& name, const Shape& shape, const Material& material,
             double cell_size, const Vec3& position) {
  const int b = s.model.add_body(name, shape, material, cell_size);
  s.poses.resize(s.model.body_count());
  s.poses[b].position = position;
  return b;
}

// n one-cell iron balls (radius 1 mm) heaped on a jittered grid below a bar
// magnet of 128 fixed cells.
std::unique_ptr<Scene> heap_of_balls(int n) {
  auto s = std::make_unique<Scene>();
  s->name = "balls";
  const int side = std::max(1, static_cast<int>(std::lround(std::sqrt(n / 8.0))));
  const double pitch = 0.0022;
  add_body(*s, "magnet", Box{{0.04, 0.04, 0.01}}, PermanentMaterial{{0, 0, 1e6}, 0.0}, 0.005,
           {0, 0, 0.02});
  for (int i = 0; i < n; ++i) {
    const int ix = i % side, iy = (i / side) % side, iz = i / (side * side);
    const double jx = 2e-4 * (unit_interval(hash_key(9, 1, i, 0)) - 0.5);
    const double jy = 2e-4 * (unit_interval(hash_key(9, 2, i, 0)) - 0.5);
    add_body(*s, "ball", Sphere{0.001}, iron(), 0.0,
             {(ix - 0.5 * side) * pitch + jx, (iy - 0.5 * side) * pitch + jy, -iz * pitch});
  }
  return s;
}

// One iron block of about n lattice cells (1 mm) below the same magnet: the
// intra-body (offset tensor) path.
std::unique_ptr<Scene> lattice_block(int n) {
  auto s = std::make_unique<Scene>();
  s->name = "lattice";
  const int k = std::max(1, static_cast<int>(std::lround(std::cbrt(static_cast<double>(n)))));
  const double h = 0.001;
  add_body(*s, "magnet", Box{{0.04, 0.04, 0.01}}, PermanentMaterial{{0, 0, 1e6}, 0.0}, 0.005,
           {0, 0, 0.02 + 0.5 * k * h});
  add_body(*s, "block", Box{{k * h, k * h, k * h}}, iron(), h, {0, 0, 0});
  return s;
}

// Like the paper's crane scene (Fig. 17): a lattice crane magnet above a heap
// of one-cell iron balls (radius 5 mm), about `total` cells in all.
std::unique_ptr<Scene> crane(int total) {
  auto s = std::make_unique<Scene>();
  s->name = "crane";
  add_body(*s, "crane", Cylinder{0.04, 0.02}, PermanentMaterial{{0, 0, 1.1e6}, 0.0}, 0.008, {0, 0, 0.03});
  const int balls = std::max(1, total - s->model.cell_count());
  const int side = 10;
  const double pitch = 0.0102;
  for (int i = 0; i < balls; ++i) {
    const int ix = i % side, iy = (i / side) % side, iz = i / (side * side);
    add_body(*s, "ball", Sphere{0.005}, iron(), 0.0,
             {(ix - 4.5) * pitch, (iy - 4.5) * pitch, 0.0149 - pitch * iz});
  }
  return s;
}

MagneticState initial_state(const Scene& s) {
  MagneticState state = make_state(s.model, 1);
  for (int b = 0; b < s.model.body_count(); ++b) state.pose[b] = s.poses[b];
  place_cells(s.model, state);
  return state;
}

// Mean ms of f over at least one run, repeated until min_ms have passed or max_runs.
double mean_ms(const std::function<void()>& f, double min_ms = 300.0, int max_runs = 20) {
  int runs = 0;
  const Clock::time_point t0 = Clock::now();
  double elapsed = 0.0;
  do {
    f();
    ++runs;
    elapsed = ms_since(t0);
  } while (elapsed < min_ms && runs < max_runs);
  return elapsed / runs;
}

struct Row {
  double field_ms = 0, relax_ms = 0, forces_ms = 0, step_ms = 0, step_iterations = 0;
  long llg_steps = 0, newton_steps = 0;
  CudaCallStats relax, field;  // CUDA only: per-call averages
};

CudaCallStats per_call(CudaCallStats s) {
  if (s.calls > 0) {
    const double n = static_cast<double>(s.calls);
    s.upload_ms /= n, s.kernel_ms /= n, s.download_ms /= n, s.wall_ms /= n;
    s.upload_bytes /= n, s.download_bytes /= n;
  }
  return s;
}

Row measure(const Scene& scene, MagneticBackend& backend, bool magnetic_steps) {
  Row row;
  const MagneticModel& model = scene.model;
  const MagneticState start = initial_state(scene);
  MagneticState state = start;
  const int n = model.cell_count();
  std::vector<Vec3> H_fixed(n), H_resp(n), H_A(n);
  backend.begin_step(model, state);
  backend.fixed_field(model, state, H_fixed);
  backend.responsive_field(model, state, H_resp);  // warm-up
  reset_cuda_backend_stats(backend);
  row.field_ms = mean_ms([&] { backend.responsive_field(model, state, H_resp); });
  row.field = per_call(cuda_backend_stats(backend).responsive_field);
  for (int c = 0; c < n; ++c) H_A[c] = H_fixed[c] + H_resp[c];

  // One local relaxation of every cell from the initial moments (the first
  // iteration of a cold relaxation, the costliest); state restored untimed.
  // The first call is discarded: with lazy module loading (CUDA 12.2 and
  // later) it also loads the relax kernel.
  const LocalRelaxOptions local;
  double relax_total = 0.0;
  const int relax_runs = 3;
  state = start;
  backend.begin_step(model, state);
  backend.relax_cells(model, state, H_A, local);
  reset_cuda_backend_stats(backend);
  for (int run = 0; run < relax_runs; ++run) {
    state = start;
    backend.begin_step(model, state);
    const Clock::time_point t0 = Clock::now();
    const LocalStats s = backend.relax_cells(model, state, H_A, local);
    relax_total += ms_since(t0);
    row.llg_steps = s.llg_steps, row.newton_steps = s.newton_steps;
  }
  row.relax_ms = relax_total / relax_runs;
  row.relax = per_call(cuda_backend_stats(backend).relax_cells);

  backend.begin_step(model, state);
  backend.forces(model, state);  // discarded, as the first relax_cells above
  row.forces_ms = mean_ms([&] { backend.forces(model, state); });

  if (magnetic_steps) {
    // One cold step, then warm steps with the balls lifted 0.2 mm per step.
    state = start;
    magnetic_step(model, state, RelaxOptions{}, backend);
    const int steps = 10;
    double total = 0.0;
    long iterations = 0;
    for (int step = 0; step < steps; ++step) {
      for (int b = 1; b < model.body_count(); ++b) state.pose[b].position.z += 2e-4;
      const Clock::time_point t0 = Clock::now();
      iterations += magnetic_step(model, state, RelaxOptions{}, backend).iterations;
      total += ms_since(t0);
    }
    row.step_ms = total / steps;
    row.step_iterations = static_cast<double>(iterations) / steps;
  }
  return row;
}

void print_row(const Scene& scene, const std::string& backend, const Row& r) {
  const Pairs pairs = count_pairs(scene.model);
  const double field_pairs = pairs.field_dipole + pairs.field_table;
  const double field_flops = kFieldFlopsDipole * pairs.field_dipole + kFieldFlopsTable * pairs.field_table;
  const double field_ns = r.field_ms * 1e6 / field_pairs, force_ns = r.forces_ms * 1e6 / pairs.force;
  std::printf("%s,%s,%d,%d,%.0f,%.0f,%.0f,%.4f,%.4f,%.4f,%.4f,%.4f,%.4f,%.1f,%.2f,%.2f,%ld,%ld,",
              scene.name.c_str(), backend.c_str(), scene.model.responsive_cell_count(),
              scene.model.cell_count(), pairs.field_dipole, pairs.field_table, pairs.force, r.field_ms,
              r.relax_ms, r.relax_ms + r.field_ms, r.forces_ms, field_ns, force_ns,
              field_flops / field_pairs, field_flops / (r.field_ms * 1e6), kForceFlops / force_ns,
              r.llg_steps, r.newton_steps);
  if (r.step_ms > 0)
    std::printf("%.3f,%.1f,", r.step_ms, r.step_iterations);
  else
    std::printf(",,");
  if (backend == "cuda")
    std::printf("%.4f,%.4f,%.4f,%.4f,%.4f,%.4f,%.0f\n", r.field.upload_ms, r.field.kernel_ms,
                r.field.download_ms, r.relax.upload_ms, r.relax.kernel_ms, r.relax.download_ms,
                r.relax.download_bytes);
  else
    std::printf(",,,,,,\n");
  std::fflush(stdout);
}

struct Options {
  int min_cells = 1000, max_cells = 100000, cpu_max_cells = 20000, threads = 0;
  bool cpu = true, cuda = true;
};

[[noreturn]] void usage(int status) {
  std::fprintf(status ? stderr : stdout,
               "usage: gpu_scaling [--max-cells N] [--min-cells N] [--cpu-max-cells N] [--threads N]\n"
               "                   [--no-cpu] [--no-cuda]\n");
  std::exit(status);
}

Options parse(int argc, char** argv) {
  Options o;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    auto value = [&]() -> int {
      if (i + 1 >= argc) usage(2);
      char* end = nullptr;
      const long v = std::strtol(argv[++i], &end, 10);
      if (*end != '\0' || v < 0) usage(2);
      return static_cast<int>(v);
    };
    if (a == "--max-cells") o.max_cells = value();
    else if (a == "--min-cells") o.min_cells = value();
    else if (a == "--cpu-max-cells") o.cpu_max_cells = value();
    else if (a == "--threads") o.threads = value();
    else if (a == "--no-cpu") o.cpu = false;
    else if (a == "--no-cuda") o.cuda = false;
    else if (a == "--help" || a == "-h") usage(0);
    else usage(2);
  }
  return o;
}

}  // namespace

int main(int argc, char** argv) {
  const Options o = parse(argc, argv);
  std::unique_ptr<MagneticBackend> cpu = make_cpu_backend(o.threads);
  std::unique_ptr<MagneticBackend> cuda;
  if (o.cuda) {
    std::string why;
    cuda = make_cuda_backend(&why);
    if (!cuda) std::fprintf(stderr, "gpu_scaling: skipping CUDA: %s\n", why.c_str());
  }
  std::printf(
      "case,backend,responsive_cells,cells,field_dipole_pairs,field_table_pairs,force_pairs,field_ms,"
      "relax_cells_ms,iteration_ms,forces_ms,"
      "field_ns_per_pair,forces_ns_per_pair,field_flops_per_pair,field_gflops,forces_gflops,"
      "relax_llg_steps,relax_newton_steps,step_ms,step_iterations,field_upload_ms,field_kernel_ms,"
      "field_download_ms,relax_upload_ms,relax_kernel_ms,relax_download_ms,relax_download_bytes\n");
  auto run = [&](const Scene& scene, bool steps) {
    const int cells = scene.model.responsive_cell_count();
    if (o.cpu && cells <= o.cpu_max_cells) print_row(scene, "cpu", measure(scene, *cpu, steps));
    else if (o.cpu)
      std::fprintf(stderr, "gpu_scaling: %s with %d cells: CPU skipped (--cpu-max-cells %d)\n",
                   scene.name.c_str(), cells, o.cpu_max_cells);
    if (cuda) print_row(scene, "cuda", measure(scene, *cuda, steps));
  };
  run(*crane(690), true);
  for (const int n : {64, 128, 256, 512, 1000, 2000, 5000, 10000, 20000, 50000, 100000}) {
    if (n < o.min_cells || n > o.max_cells) continue;
    run(*heap_of_balls(n), false);
    run(*lattice_block(n), false);
  }
  return 0;
}
