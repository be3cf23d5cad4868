// The far-field approximation of the responsive field (docs/model.md "Far
// field") against the exact pair sum: a heap of N one-cell steel balls
// (R = 5 mm, random magnetizations of 5e5 A/m, scattered in a cube of side
// 11 mm x N^(1/3), as in benchmarks/pair_kernels.cpp), N = 1024 .. 131072.
// For theta = 0 (exact; up to --max-exact cells) and each --thetas value: the
// time of one responsive-field evaluation of the CPU backend (best of
// several, after begin_step, which builds the tree), the tree build time,
// pairs summed exactly and node expansions used, and the error against the
// exact sum at 512 sampled cells (RMS over them of |dH| / RMS |H|, and the
// largest |dH| / largest |H|).
//
// Usage: far_field_scaling [--out DIR] [--max-cells N] [--max-exact N] [--thetas 0.3,0.5,0.7]
//                          [--threads T]
// Writes DIR/far_field_scaling.csv and .md (DIR: benchmarks/results). Runs
// itself again with OMP_WAIT_POLICY=passive when that is unset.
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <sstream>
#include <string>
#include <vector>

#include "benchmarks/bench_common.h"
#include "magnetics/model/backend.h"
#include "magnetics/relax/far_field.h"
#include "magnetics/kernels/kernels.h"
#include "magnetics/model/model.h"
#include "magnetics/kernels/rng.h"
#include "magnetics/model/state.h"

using namespace odemag;

namespace {

double seconds_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

struct Heap : bench::BallHeap {
  using BallHeap::BallHeap;
  // The exact field at cell i of every other cell.
  Vec3 exact_field(int i) const {
    Vec3 h;
    const double r = model.body(i).cells.contact_radius;
    for (int j = 0; j < model.cell_count(); ++j) {
      if (j == i) continue;
      const double s = r + model.body(j).cells.contact_radius;
      h += dipole_field(state.cell_position[i] - state.cell_position[j],
                        model.body(j).cells.cell_volume * state.magnetization[j], s * s);
    }
    return h;
  }
};

struct Row {
  int cells = 0, threads = 0;
  double theta = 0, build_ms = 0, field_ms = 0, near_pairs = 0, far_interactions = 0, rms_error = 0, max_error = 0;
};


}  // namespace

int main(int argc, char** argv) {
  odemag::restart_with_passive_omp_wait(argv);
  std::string out_dir = "benchmarks/results", theta_list = "0.3,0.5,0.7";
  int max_cells = 131072, max_exact = 16384, threads = 2;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (i + 1 >= argc) {
      std::fprintf(stderr,
                   "usage: far_field_scaling [--out DIR] [--max-cells N] [--max-exact N] [--thetas 0.3,0.5,0.7] "
                   "[--threads T]\n");
      return 2;
    }
    const std::string v = argv[++i];
    if (a == "--out") out_dir = v;
    else if (a == "--max-cells") max_cells = std::atoi(v.c_str());
    else if (a == "--max-exact") max_exact = std::atoi(v.c_str());
    else if (a == "--thetas") theta_list = v;
    else if (a == "--threads") threads = std::atoi(v.c_str());
    else {
      std::fprintf(stderr, "far_field_scaling: unknown option %s\n", a.c_str());
      return 2;
    }
  }
  std::vector<double> thetas{0.0};
  for (const std::string& t : bench::split(theta_list)) thetas.push_back(std::atof(t.c_str()));

  std::vector<Row> rows;
  for (int n = 1024; n <= max_cells; n *= 2) {
    const Heap heap(n);
    // Sampled cells and their exact fields.
    std::vector<int> sample;
    for (int k = 0; k < 512; ++k) sample.push_back(static_cast<int>((static_cast<long>(k) * n) / 512));
    std::vector<Vec3> exact;
    for (int i : sample) exact.push_back(heap.exact_field(i));
    for (double theta : thetas) {
      if (theta == 0.0 && n > max_exact) continue;
      auto backend = make_cpu_backend(threads);
      backend->set_far_field(theta);
      MagneticState state = heap.state;
      Row r;
      r.cells = n, r.threads = threads, r.theta = theta;
      auto t0 = std::chrono::steady_clock::now();
      backend->begin_step(heap.model, state);
      r.build_ms = 1e3 * seconds_since(t0);
      std::vector<Vec3> H(n);
      double best = 1e300, spent = 0.0;
      for (int rep = 0; rep < 20 && (rep < 2 || spent < 1.0); ++rep) {
        t0 = std::chrono::steady_clock::now();
        backend->responsive_field(heap.model, state, H);
        const double s = seconds_since(t0);
        best = std::min(best, s), spent += s;
      }
      r.field_ms = 1e3 * best;
      double num = 0.0, den = 0.0, worst = 0.0, largest = 0.0;
      for (size_t k = 0; k < sample.size(); ++k) {
        const double d = norm(H[sample[k]] - exact[k]);
        num += d * d, den += squared_norm(exact[k]);
        worst = std::max(worst, d), largest = std::max(largest, norm(exact[k]));
      }
      r.rms_error = std::sqrt(num / den), r.max_error = worst / largest;
      if (theta > 0.0) {
        // The tree's work, from a tree built alone (the backend's is private).
        std::vector<double> x(n), y(n), z(n), radius(n);
        std::vector<int> body(n);
        for (int i = 0; i < n; ++i) {
          const Vec3& p = state.cell_position[i];
          x[i] = p.x, y[i] = p.y, z[i] = p.z, radius[i] = heap.model.body(i).cells.contact_radius, body[i] = i;
        }
        FarFieldTree tree;
        tree.build(x.data(), y.data(), z.data(), radius.data(), body.data(), n, theta);
        r.near_pairs = static_cast<double>(tree.near_pairs());
        r.far_interactions = static_cast<double>(tree.far_interactions());
      } else {
        r.near_pairs = static_cast<double>(n) * (n - 1);
      }
      rows.push_back(r);
      std::fprintf(stderr, "far_field_scaling: %6d cells theta %.2f: field %.3g ms (build %.3g ms), error rms %.2e max %.2e\n",
                   n, theta, r.field_ms, r.build_ms, r.rms_error, r.max_error);
    }
  }

  char model[256] = "unknown";
  if (FILE* f = std::fopen("/proc/cpuinfo", "r")) {
    char line[512];
    while (std::fgets(line, sizeof line, f))
      if (std::sscanf(line, "model name : %255[^\n]", model) == 1) break;
    std::fclose(f);
  }
  const std::string csv_path = out_dir + "/far_field_scaling.csv", md_path = out_dir + "/far_field_scaling.md";
  FILE *csv, *md;
  if (!bench::open_reports(out_dir, csv_path, md_path, csv, md)) return 1;
  std::fprintf(csv, "# %s, %d threads\ncells,theta,threads,field_ms,build_ms,near_pairs,far_interactions,"
                    "ns_per_pair_equivalent,rms_error,max_error\n",
               model, threads);
  std::fprintf(md,
               "Machine: %s, %d threads. One responsive-field evaluation of N one-cell balls (best of several); "
               "build: begin_step with the tree; error against the exact sum at 512 sampled cells. theta 0: the "
               "exact O(N^2) sum.\n\n| cells | theta | field ms | x faster than exact | build ms | pairs summed exactly "
               "| node expansions | ns per pair (N^2 equivalent) | RMS error | max error |\n"
               "|---|---|---|---|---|---|---|---|---|---|\n",
               model, threads);
  for (const Row& r : rows) {
    double exact_ms = 0.0;
    for (const Row& e : rows)
      if (e.cells == r.cells && e.theta == 0.0) exact_ms = e.field_ms;
    const double equivalent = 1e6 * r.field_ms / (static_cast<double>(r.cells) * (r.cells - 1));
    std::fprintf(csv, "%d,%g,%d,%.5g,%.5g,%.0f,%.0f,%.4g,%.3e,%.3e\n", r.cells, r.theta, r.threads, r.field_ms,
                 r.build_ms, r.near_pairs, r.far_interactions, equivalent, r.rms_error, r.max_error);
    char faster[32] = "-";
    if (exact_ms > 0.0) std::snprintf(faster, sizeof faster, "%.3g", exact_ms / r.field_ms);
    std::fprintf(md, "| %d | %g | %.3g | %s | %.3g | %.3g | %.3g | %.3g | %.1e | %.1e |\n", r.cells, r.theta,
                 r.field_ms, faster, r.build_ms, r.near_pairs, r.far_interactions, equivalent, r.rms_error,
                 r.max_error);
  }
  std::fclose(csv);
  std::fclose(md);
  std::fprintf(stderr, "far_field_scaling: wrote %s and %s\n", csv_path.c_str(), md_path.c_str());
  return 0;
}
