// Scaling of the CPU magnetic solve with the cell count (docs/benchmarks.md
// "Scaling"): 64 .. 16384 responsive cells next to a permanent magnet, one
// and two threads. Two layouts of the same cubic block:
//   lattice: one soft-iron body (chi 1000, Ms 1.7e6 A/m, h = 1/512 m) of
//            nx x ny x nz cells; every responsive pair is intra-body, summed
//            from the body's cached tensor table;
//   balls:   nx x ny x nz one-cell steel balls (chi 1000, Ms 1.6e6 A/m,
//            R = 5 mm, 1 um apart), each its own body; every responsive pair
//            goes through the dense AVX-512 dipole kernel (a crane heap).
// The magnet is a one-cell box (M_r = 8e5 A/m towards the block) the width
// of the block, one cell spacing above it.
//
// Per layout, size and thread count: one cold relaxation (moments in random
// opposite pairs, tolerance 1e-6; its iteration cap is lowered so that it
// stays within --budget seconds, default 6, then `converged` is 0), the time
// per outer iteration split into field evaluations, local cell relaxation and
// the rest (benchmarks/timed_backend.h), the time of one responsive-field
// evaluation (best of several), the pairs it sums, ns per pair and GFLOP/s
// against the machine's peak, the same from CPU time (core-ns per pair,
// GFLOP/s per core: what a shared machine's time slicing does not distort),
// and one force evaluation.
//
// Flops per pair (counted from magnetics/kernels/kernels.h and the loops of
// magnetics/relax/cpu_backend.cpp; +, -, * one each, the inverse square root one,
// the max of r^2 and s^2 not counted):
//   field kernel (inter-body): offset 3, contact distance 1, r^2 5, s^2 1,
//     1/r 1, powers and q 4, A 6, B 4, r.mu and B (r.mu) 6, H += 12: 43;
//   force-and-field kernel: offset 3, contact 1, r^2 5, s^2 1, 1/r 1, powers
//     and q 4, A 6, B 4, C 2, r.mu_a 5, r.mu_b 5, radial term 9, F += 21,
//     B (r.mu_a) 1, H += 12: 80;
//   intra-body table: symmetric 3x3 times vector 15, H += 3: 18.
// The AVX-512 inverse square root executes an estimate and two Newton steps
// (10 more flops than counted).
//
// Peak: cores x FMA units per core x 8 doubles per AVX-512 vector x 2 flops
// per FMA x clock, the clock from /proc/cpuinfo "cpu MHz" (--ghz overrides),
// 2 FMA units (--fma-units overrides).
//
// Usage: cpu_scaling [--out DIR] [--max-cells N] [--budget S] [--layouts lattice,balls]
//                    [--threads 1,2] [--ghz G] [--fma-units U]
// Writes DIR/cpu_scaling.csv and DIR/cpu_scaling.md (DIR: benchmarks/results).
// Runs itself again with OMP_WAIT_POLICY=passive when that is unset.
#include <time.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "benchmarks/bench_common.h"
#include "benchmarks/timed_backend.h"
#include "magnetics/model/backend.h"
#include "magnetics/relax/relax.h"

using namespace odemag;

namespace {

constexpr double kFieldFlops = 43.0, kForceFlops = 80.0, kIntraFlops = 18.0;

double seconds_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

// CPU seconds of the process, all threads (OpenMP threads wait passively, so
// this is work): CPU seconds per wall second shows how many cores a
// measurement really had on a shared machine.
double cpu_seconds() {
  timespec ts;
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
  return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
}

struct Machine {
  std::string model = "unknown CPU";
  int cpus = 1;
  double ghz = 0.0;
  int fma_units = 2;
  double peak(int cores) const { return cores * fma_units * 8.0 * 2.0 * ghz; }  // GFLOP/s
};

Machine read_machine(double ghz, int fma_units) {
  Machine m;
  std::ifstream in("/proc/cpuinfo");
  std::string line;
  while (std::getline(in, line)) {
    const auto colon = line.find(':');
    if (colon == std::string::npos) continue;
    const std::string key = line.substr(0, line.find_last_not_of(" \t", colon - 1) + 1);
    std::string value = line.substr(colon + 1);
    value.erase(0, value.find_first_not_of(' '));
    if (key == "model name" && m.model == "unknown CPU") m.model = value;
    if (key == "cpu MHz" && m.ghz == 0.0) m.ghz = std::atof(value.c_str()) / 1000.0;
  }
  m.cpus = static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
  if (ghz > 0.0) m.ghz = ghz;
  if (fma_units > 0) m.fma_units = fma_units;
  return m;
}

// nx x ny x nz = n (a power of two), as near a cube as possible.
std::array<int, 3> block_dims(int n) {
  std::array<int, 3> d{1, 1, 1};
  for (int k = 0; d[0] * d[1] * d[2] < n; k = (k + 1) % 3) d[k] *= 2;
  return d;
}

struct Setup {
  MagneticModel model;
  MagneticState state;  // cold: random opposite pairs
  int responsive = 0;
};

Setup make_setup(const std::string& layout, int n) {
  const auto d = block_dims(n);
  Setup s;
  double top = 0.0, width_x = 0.0, width_y = 0.0, gap = 0.0;
  std::vector<Vec3> positions;
  if (layout == "lattice") {
    const double h = 1.0 / 512.0;  // a power of two: nx h / h is exact
    SoftMaterial iron;
    iron.saturation = 1.7e6;
    iron.susceptibility = 1000;
    s.model.add_body("iron", Box{{d[0] * h, d[1] * h, d[2] * h}}, iron, h);
    positions.push_back({});
    top = 0.5 * d[2] * h, width_x = d[0] * h, width_y = d[1] * h, gap = h;
  } else {
    const double R = 0.005, pitch = 2 * R + 1e-6;
    SoftMaterial steel;
    steel.saturation = 1.6e6;
    steel.susceptibility = 1000;
    for (int k = 0; k < d[2]; ++k)
      for (int j = 0; j < d[1]; ++j)
        for (int i = 0; i < d[0]; ++i) {
          s.model.add_body("ball", Sphere{R}, steel, 0.0);
          positions.push_back({(i - 0.5 * (d[0] - 1)) * pitch, (j - 0.5 * (d[1] - 1)) * pitch,
                               (k - 0.5 * (d[2] - 1)) * pitch});
        }
    top = 0.5 * (d[2] - 1) * pitch + R, width_x = d[0] * pitch, width_y = d[1] * pitch, gap = R;
  }
  const double magnet_height = 0.5 * std::max(width_x, width_y);
  s.model.add_body("magnet", Box{{width_x, width_y, magnet_height}}, PermanentMaterial{{0, 0, -8e5}}, 0.0);
  positions.push_back({0, 0, top + gap + 0.5 * magnet_height});
  s.state = make_state(s.model, 1);
  for (int b = 0; b < s.model.body_count(); ++b) s.state.pose[b].position = positions[b];
  place_cells(s.model, s.state);
  s.responsive = s.model.responsive_cell_count();
  return s;
}

// Pairs one responsive-field evaluation sums: inter-body (dipole kernel) and
// intra-body (tensor table), as the CPU backend does; and the pairs of one
// force evaluation (every cell against every cell of another body).
struct PairCounts {
  double inter = 0, intra = 0, force = 0;
};

PairCounts count_pairs(const MagneticModel& model) {
  PairCounts p;
  double responsive = 0, all = 0;
  for (const MagneticBody& b : model.bodies()) {
    all += b.cell_count();
    if (b.responsive()) responsive += b.cell_count();
  }
  for (const MagneticBody& b : model.bodies()) {
    const double c = b.cell_count();
    if (b.responsive()) {
      p.inter += c * (responsive - c);
      p.intra += c * (c - 1);
    }
    p.force += c * (all - c);
  }
  return p;
}

// Best wall time (s) of repeated calls: at least 2 and until min_seconds in
// all (at most 200); *cores: CPU seconds per wall second of the best call;
// *cpu: the least CPU seconds of a call (all threads).
template <class F>
double best_time(F&& call, double min_seconds, double* cores, double* cpu) {
  double best = 1e300, total = 0.0;
  int n = 0;
  *cpu = 1e300;
  while (n < 2 || (total < min_seconds && n < 200)) {
    const double c0 = cpu_seconds();
    const auto t0 = std::chrono::steady_clock::now();
    call();
    const double t = seconds_since(t0), c = cpu_seconds() - c0;
    if (t < best) best = t, *cores = c / t;
    *cpu = std::min(*cpu, c);
    total += t, ++n;
  }
  return best;
}

struct Row {
  std::string layout;
  int cells = 0, responsive = 0, bodies = 0, threads = 0, cap = 0, iterations = 0, field_evaluations = 0;
  bool converged = false;
  double relax_ms = 0, ms_per_iteration = 0, field_ms = 0;
  // Split of ms_per_iteration: responsive-field evaluations, local cell
  // relaxation (relax_cells), and the rest (begin_step, fixed field, Anderson
  // mixing, residuals).
  double field_ms_per_iteration = 0, local_ms_per_iteration = 0, other_ms_per_iteration = 0;
  double inter_pairs = 0, intra_pairs = 0, ns_per_pair = 0, flops_per_pair = 0, gflops = 0;
  double force_ms = 0, force_pairs = 0, force_ns_per_pair = 0, force_gflops = 0;
  double peak = 0;
  // CPU seconds per wall second: of the best field evaluation, of the
  // relaxation. Near the thread count when the cores were free (a loop below
  // 20000 pairs runs on one thread); lower: the machine was shared.
  double field_cores = 0, relax_cores = 0;
  // From CPU time instead of wall time (immune to time slicing on a shared
  // machine, not to shared caches): core-ns per pair and GFLOP/s per core of
  // the field evaluation; equal to ns_per_pair x threads and gflops / threads
  // on free cores with perfect parallel speedup.
  double core_ns_per_pair = 0, gflops_per_core = 0;
};


}  // namespace

int main(int argc, char** argv) {
  odemag::restart_with_passive_omp_wait(argv);
  std::string out_dir = "benchmarks/results", layouts = "lattice,balls", thread_list = "1,2";
  int max_cells = 16384, fma_units = 0;
  double budget = 6.0, ghz = 0.0;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    auto next = [&] { return bench::option_value(argc, argv, i, "cpu_scaling"); };
    if (a == "--out") out_dir = next();
    else if (a == "--max-cells") max_cells = std::atoi(next().c_str());
    else if (a == "--budget") budget = std::atof(next().c_str());
    else if (a == "--layouts") layouts = next();
    else if (a == "--threads") thread_list = next();
    else if (a == "--ghz") ghz = std::atof(next().c_str());
    else if (a == "--fma-units") fma_units = std::atoi(next().c_str());
    else {
      std::fprintf(stderr,
                   "usage: cpu_scaling [--out DIR] [--max-cells N] [--budget S] [--layouts lattice,balls] "
                   "[--threads 1,2] [--ghz G] [--fma-units U]\n");
      return 2;
    }
  }
  const Machine machine = read_machine(ghz, fma_units);
  std::vector<int> threads;
  for (const std::string& t : bench::split(thread_list)) threads.push_back(std::atoi(t.c_str()));
  std::fprintf(stderr, "cpu_scaling: %s, %d CPUs, %.2f GHz, %d FMA units: peak %.1f GFLOP/s per core\n",
               machine.model.c_str(), machine.cpus, machine.ghz, machine.fma_units, machine.peak(1));

  std::vector<Row> rows;
  for (const std::string& layout : bench::split(layouts)) {
    if (layout != "lattice" && layout != "balls") {
      std::fprintf(stderr, "cpu_scaling: unknown layout '%s'\n", layout.c_str());
      return 2;
    }
    for (int n = 64; n <= max_cells; n *= 2) {
      const Setup setup = make_setup(layout, n);
      const PairCounts pairs = count_pairs(setup.model);
      for (int t : threads) {
        auto timed = std::make_unique<TimedBackend>(make_cpu_backend(t));
        TimedBackend& clock = *timed;
        std::unique_ptr<MagneticBackend> backend = std::move(timed);
        Row r;
        r.layout = layout, r.cells = setup.model.cell_count(), r.responsive = setup.responsive;
        r.bodies = setup.model.body_count(), r.threads = t;
        r.inter_pairs = pairs.inter, r.intra_pairs = pairs.intra, r.force_pairs = pairs.force;
        r.flops_per_pair = (pairs.inter * kFieldFlops + pairs.intra * kIntraFlops) / (pairs.inter + pairs.intra);
        r.peak = machine.peak(t);

        // One responsive-field evaluation (the moments' values do not matter).
        MagneticState state = setup.state;
        backend->begin_step(setup.model, state);
        std::vector<Vec3> H(setup.model.cell_count());
        double field_cpu = 0.0;
        const double field_s =
            best_time([&] { backend->responsive_field(setup.model, state, H); }, 0.3, &r.field_cores, &field_cpu);
        r.field_ms = 1e3 * field_s;
        r.ns_per_pair = 1e9 * field_s / (pairs.inter + pairs.intra);
        r.gflops = (pairs.inter * kFieldFlops + pairs.intra * kIntraFlops) / field_s * 1e-9;
        r.core_ns_per_pair = 1e9 * field_cpu / (pairs.inter + pairs.intra);
        r.gflops_per_core = (pairs.inter * kFieldFlops + pairs.intra * kIntraFlops) / field_cpu * 1e-9;

        // One cold relaxation within the budget.
        RelaxOptions options;
        r.cap = static_cast<int>(std::clamp(budget / field_s, 3.0, 200.0));
        options.max_iterations = r.cap;
        state = setup.state;
        clock.reset();
        const double c0 = cpu_seconds();
        const auto t0 = std::chrono::steady_clock::now();
        const RelaxReport report = relax(setup.model, state, options, *backend);
        const double relax_s = seconds_since(t0);
        r.relax_cores = (cpu_seconds() - c0) / relax_s;
        r.iterations = report.iterations, r.field_evaluations = report.field_evaluations;
        r.converged = report.converged;
        r.relax_ms = 1e3 * relax_s;
        r.ms_per_iteration = r.relax_ms / std::max(1, report.iterations);
        const double per_iteration = 1e3 / std::max(1, report.iterations);
        r.field_ms_per_iteration = clock.field_s * per_iteration;
        r.local_ms_per_iteration = clock.local_s * per_iteration;
        r.other_ms_per_iteration = r.ms_per_iteration - r.field_ms_per_iteration - r.local_ms_per_iteration;

        // One force evaluation from the relaxed state.
        double force_cores = 0.0, force_cpu = 0.0;
        const double force_s = best_time([&] { backend->forces(setup.model, state); }, 0.2, &force_cores, &force_cpu);
        r.force_ms = 1e3 * force_s;
        r.force_ns_per_pair = pairs.force > 0 ? 1e9 * force_s / pairs.force : 0.0;
        r.force_gflops = pairs.force * kForceFlops / force_s * 1e-9;
        rows.push_back(r);
        std::fprintf(stderr,
                     "cpu_scaling: %s %5d cells, %d thread(s): %3d iterations%s, %.3g ms/iteration, field %.3g ms "
                     "(%.3g ns/pair, %.3g GFLOP/s, %.2f CPU s per s), forces %.3g ms\n",
                     layout.c_str(), r.cells, t, r.iterations, r.converged ? "" : " (capped)", r.ms_per_iteration,
                     r.field_ms, r.ns_per_pair, r.gflops, r.field_cores, r.force_ms);
      }
    }
  }

  const std::string csv_path = out_dir + "/cpu_scaling.csv", md_path = out_dir + "/cpu_scaling.md";
  FILE* csv = std::fopen(csv_path.c_str(), "w");
  if (!csv) {
    std::perror(csv_path.c_str());
    return 1;
  }
  std::fprintf(csv, "# %s, %d CPUs, %.2f GHz, %d FMA units x 8 doubles x 2 flops: peak %.1f GFLOP/s per core\n",
               machine.model.c_str(), machine.cpus, machine.ghz, machine.fma_units, machine.peak(1));
  std::fprintf(csv,
               "layout,cells,responsive_cells,bodies,threads,iteration_cap,iterations,converged,field_evaluations,"
               "relax_ms,ms_per_iteration,field_ms_per_iteration,local_ms_per_iteration,other_ms_per_iteration,field_ms,inter_pairs,intra_pairs,ns_per_pair,"
               "flops_per_pair,gflops,peak_gflops,fraction_of_peak,force_ms,force_pairs,force_ns_per_pair,"
               "force_gflops,field_cpu_per_wall,relax_cpu_per_wall,core_ns_per_pair,gflops_per_core\n");
  for (const Row& r : rows)
    std::fprintf(csv, "%s,%d,%d,%d,%d,%d,%d,%d,%d,%.4f,%.4f,%.4f,%.4f,%.4f,%.5f,%.0f,%.0f,%.4f,%.2f,%.3f,%.1f,%.4f,%.5f,%.0f,%.4f,%.3f,%.2f,%.2f,%.4f,%.3f\n",
                 r.layout.c_str(), r.cells, r.responsive, r.bodies, r.threads, r.cap, r.iterations,
                 r.converged ? 1 : 0, r.field_evaluations, r.relax_ms, r.ms_per_iteration, r.field_ms_per_iteration,
                 r.local_ms_per_iteration, r.other_ms_per_iteration,
                 r.field_ms, r.inter_pairs, r.intra_pairs, r.ns_per_pair, r.flops_per_pair, r.gflops, r.peak,
                 r.gflops / r.peak, r.force_ms, r.force_pairs, r.force_ns_per_pair, r.force_gflops, r.field_cores, r.relax_cores, r.core_ns_per_pair, r.gflops_per_core);
  std::fclose(csv);

  // Markdown: one row per layout and size, the thread counts side by side.
  FILE* md = std::fopen(md_path.c_str(), "w");
  if (!md) {
    std::perror(md_path.c_str());
    return 1;
  }
  std::fprintf(md,
               "Machine: %s, %d CPUs; peak %.1f GFLOP/s per core (%d FMA units x 8 doubles x 2 flops x %.2f GHz). "
               "Cold relaxation, tolerance 1e-6; iterations marked * were stopped by the time budget. "
               "Columns per thread count (%s). Cores busy: CPU seconds per wall second of the field evaluation "
               "(below the thread count: the machine was shared, or the loop had too few pairs to use two threads).\n\n",
               machine.model.c_str(), machine.cpus, machine.peak(1), machine.fma_units, machine.ghz,
               thread_list.c_str());
  // Rows of one layout and size, one per thread count.
  std::map<std::pair<std::string, int>, std::vector<const Row*>> groups;
  std::vector<std::pair<std::string, int>> order;
  for (const Row& r : rows) {
    const auto key = std::make_pair(r.layout, r.responsive);
    if (!groups.count(key)) order.push_back(key);
    groups[key].push_back(&r);
  }
  auto num = [](double v) {
    char b[32];
    std::snprintf(b, sizeof b, "%.3g", v);
    return std::string(b);
  };
  std::string last_layout;
  for (const auto& key : order) {
    const auto& g = groups[key];
    if (key.first != last_layout) {
      if (!last_layout.empty()) std::fprintf(md, "\n");
      last_layout = key.first;
      std::fprintf(md, "**%s** (%s)\n\n", key.first.c_str(),
                   key.first == "lattice"
                       ? "one soft-iron body next to a one-cell magnet; intra-body tensor table, 18 flops per pair"
                       : "one-cell steel balls next to a one-cell magnet; dense dipole kernel, 43 flops per pair "
                         "(field), 80 (force and field)");
      std::fprintf(md,
                   "| responsive cells | iterations | ms per iteration | field / local / rest per iteration "
                   "(%d threads) | field evaluation ms | cores busy | ns per pair | GFLOP/s | %% of peak | core-ns per "
                   "pair (CPU time) | GFLOP/s per core (CPU time) | force ms | force ns per pair |\n"
                   "|---|---|---|---|---|---|---|---|---|---|---|---|---|\n",
                   g.back()->threads);
    }
    auto join = [&](auto value) {
      std::string s;
      for (size_t i = 0; i < g.size(); ++i) s += (i ? " / " : "") + value(*g[i]);
      return s;
    };
    const Row* best = g.back();  // the relaxation that got furthest
    for (const Row* r : g)
      if (r->iterations > best->iterations || (r->converged && !best->converged)) best = r;
    const Row& last = *g.back();
    const std::string split_text = num(100.0 * last.field_ms_per_iteration / last.ms_per_iteration) + "% / " +
                                   num(100.0 * last.local_ms_per_iteration / last.ms_per_iteration) + "% / " +
                                   num(100.0 * last.other_ms_per_iteration / last.ms_per_iteration) + "%";
    std::fprintf(md, "| %d | %d%s | %s | %s | %s | %s | %s | %s | %s | %s | %s | %s | %s |\n", key.second,
                 best->iterations,
                 best->converged ? "" : "*", join([&](const Row& r) { return num(r.ms_per_iteration); }).c_str(),
                 split_text.c_str(), join([&](const Row& r) { return num(r.field_ms); }).c_str(),
                 join([&](const Row& r) { return num(r.field_cores); }).c_str(),
                 join([&](const Row& r) { return num(r.ns_per_pair); }).c_str(),
                 join([&](const Row& r) { return num(r.gflops); }).c_str(),
                 join([&](const Row& r) { return num(100.0 * r.gflops / r.peak); }).c_str(),
                 join([&](const Row& r) { return num(r.core_ns_per_pair); }).c_str(),
                 join([&](const Row& r) { return num(r.gflops_per_core); }).c_str(),
                 join([&](const Row& r) { return num(r.force_ms); }).c_str(),
                 join([&](const Row& r) {
                   return r.force_pairs > 2.0 * r.responsive ? num(r.force_ns_per_pair) : std::string("-");
                 }).c_str());
  }
  std::fclose(md);
  std::fprintf(stderr, "cpu_scaling: wrote %s and %s\n", csv_path.c_str(), md_path.c_str());
  return 0;
}
