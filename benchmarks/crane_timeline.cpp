// The crane (paper Fig. 17) step by step: per rigid step the magnetic time
// T_m, the rigid time T_r, outer iterations and substeps, and, every
// --probe-every steps, the time of one dense field evaluation of the same
// cells at that moment (MagneticBackend::responsive_field: the dipole sums
// over every cell pair, the intra-body tables, the near-field and boundary
// terms), so that T_m can be stated in field evaluations, a measure that does
// not depend on the machine (docs/benchmarks.md "Where the crane's time goes").
//
//   crane_timeline [--scene PATH] [--duration T] [--threads N] [--probe-every N]
//                  [--bin-steps N] --csv FILE [--label TEXT]
//
// Writes FILE: one row per bin of --bin-steps steps (default 10): the bin's
// start time, its steps' mean and largest T_m and T_r (ms), mean iterations
// and substeps and the latest dense-evaluation time (ms). Prints the scene's
// outcomes and, per phase of the crane's time line (descent 0-0.8 s, grip
// 0.8-1.3, lift 1.3-2.3, hold 2.3-3.0, reduced 3.0-4.0, off 4.0-5.0), a
// markdown row: mean T_m, T_r and T_m + T_r, largest T_m + T_r, mean
// iterations and substeps, and T_m over the phase's mean dense evaluation.
#include <algorithm>
#include <chrono>
#include <cstdint>
#include <cstring>
#include <cstdio>
#include <string>
#include <vector>

#include "benchmarks/bench_common.h"
#include "odemag/scene.h"
#include "odemag/simulation.h"
#include "engine/simulation/rigid_world.h"
#include "magnetics/model/backend.h"

using namespace odemag;

namespace {

struct Phase {
  const char* name;
  double begin, end;  // s
};
// The crane scene's time line (demos/scenes/crane.json): keyframes down to the
// heap by 0.8 s, held there until 1.3 s, up by 2.3 s; magnetization ramped to
// 0.15 over 3.0-3.3 s and to 0 over 4.0-4.2 s.
const Phase kPhases[] = {{"descent", 0.0, 0.8}, {"grip", 0.8, 1.3},    {"lift", 1.3, 2.3},
                         {"hold", 2.3, 3.0},    {"reduced", 3.0, 4.0}, {"off", 4.0, 1e9}};

struct Probe {
  double time, ms;
};

// Fastest of three dense responsive-field evaluations at the current state.
double dense_evaluation_ms(MagneticForces& magnetics) {
  std::vector<Vec3> H(magnetics.model().cell_count());
  double best = 1e300;
  for (int k = 0; k < 3; ++k) {
    const auto t0 = std::chrono::steady_clock::now();
    magnetics.backend().responsive_field(magnetics.model(), magnetics.state(), H);
    best = std::min(best, std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count());
  }
  return best;
}

}  // namespace

int main(int argc, char** argv) {
  odemag::restart_with_passive_omp_wait(argv);
  std::string scene_path = std::string(ODEMAG_SOURCE_DIR) + "/demos/scenes/crane.json", csv, label = "odemag";
  double duration = -1.0;
  int threads = 2, probe_every = 50, bin_steps = 10;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--scene") scene_path = bench::option_value(argc, argv, i, "crane_timeline");
    else if (a == "--duration") duration = std::stod(bench::option_value(argc, argv, i, "crane_timeline"));
    else if (a == "--threads") threads = std::stoi(bench::option_value(argc, argv, i, "crane_timeline"));
    else if (a == "--probe-every") probe_every = std::stoi(bench::option_value(argc, argv, i, "crane_timeline"));
    else if (a == "--bin-steps") bin_steps = std::stoi(bench::option_value(argc, argv, i, "crane_timeline"));
    else if (a == "--csv") csv = bench::option_value(argc, argv, i, "crane_timeline");
    else if (a == "--label") label = bench::option_value(argc, argv, i, "crane_timeline");
    else {
      std::fprintf(stderr, "crane_timeline: unknown argument '%s'\n", a.c_str());
      return 2;
    }
  }
  if (csv.empty() || probe_every < 1 || bin_steps < 1) {
    std::fprintf(stderr, "crane_timeline: --csv FILE is required; --probe-every and --bin-steps >= 1\n");
    return 2;
  }
  SceneDescription scene = load_scene(scene_path);
  scene.solver.threads = threads;
  if (duration > 0.0) scene.simulation.duration = duration;
  Simulation sim(scene);
  sim.magnetics().compute();  // as `odemag run` does before its first frame
  std::vector<Probe> probes;
  const auto wall0 = std::chrono::steady_clock::now();
  while (sim.time() + 0.5 * scene.simulation.time_step < scene.simulation.duration) {
    sim.step();
    if (sim.steps() % probe_every == 0) probes.push_back({sim.time(), dense_evaluation_ms(sim.magnetics())});
  }
  sim.finish();
  const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall0).count();
  const std::vector<StepReport>& records = sim.records();

  // Latest probe at or before time t (the first one before any).
  auto probe_at = [&](double t) {
    double ms = probes.empty() ? 0.0 : probes.front().ms;
    for (const Probe& p : probes)
      if (p.time <= t + 1e-9) ms = p.ms;
    return ms;
  };
  FILE* out = std::fopen(csv.c_str(), "w");
  if (!out) {
    std::fprintf(stderr, "crane_timeline: cannot write %s\n", csv.c_str());
    return 1;
  }
  std::fprintf(out, "label,time_s,steps,T_m_mean_ms,T_m_max_ms,T_r_mean_ms,T_r_max_ms,iterations_mean,substeps_mean,dense_evaluation_ms\n");
  for (size_t b = 0; b < records.size(); b += bin_steps) {
    const size_t e = std::min(records.size(), b + bin_steps);
    double tm = 0, tmx = 0, tr = 0, trx = 0, it = 0, sub = 0;
    for (size_t k = b; k < e; ++k) {
      tm += records[k].magnetic_ms, tmx = std::max(tmx, records[k].magnetic_ms);
      tr += records[k].rigid_ms, trx = std::max(trx, records[k].rigid_ms);
      it += records[k].iterations, sub += records[k].substeps;
    }
    const double n = static_cast<double>(e - b);
    std::fprintf(out, "%s,%.4f,%zu,%.4g,%.4g,%.4g,%.4g,%.4g,%.4g,%.4g\n", label.c_str(), records[b].time, e - b,
                 tm / n, tmx, tr / n, trx, it / n, sub / n, probe_at(records[b].time));
  }
  std::fclose(out);

  // FNV-1a over the final body positions: equal for runs whose motion is bit-identical.
  uint64_t hash = 1469598103934665603ULL;
  for (int b = 0; b < sim.world().body_count(); ++b) {
    const Vec3 x = sim.world().pose(b).position;
    for (int a = 0; a < 3; ++a) {
      const double v = x[a];
      unsigned char bytes[sizeof(double)];
      std::memcpy(bytes, &v, sizeof(double));
      for (unsigned char c : bytes) hash = (hash ^ c) * 1099511628211ULL;
    }
  }
  std::printf("%s: %s, %zu steps in %.1f s wall, positions hash %016llx", label.c_str(), scene_path.c_str(),
              records.size(), wall, static_cast<unsigned long long>(hash));
  for (const auto& [name, value] : sim.outcomes()) std::printf(", %s %g", name.c_str(), value);
  std::printf("\n| phase | steps | T_m mean | T_r mean | T_m + T_r mean | T_m + T_r max | iterations mean | substeps mean | dense evaluation | T_m / evaluation |\n");
  std::printf("|---|---|---|---|---|---|---|---|---|---|\n");
  auto row = [&](const char* name, double t0, double t1) {
    double tm = 0, tr = 0, mx = 0, it = 0, sub = 0, ev = 0;
    int n = 0, m = 0;
    for (const StepReport& r : records) {
      if (r.time < t0 - 1e-9 || r.time >= t1 - 1e-9) continue;
      tm += r.magnetic_ms, tr += r.rigid_ms, mx = std::max(mx, r.magnetic_ms + r.rigid_ms);
      it += r.iterations, sub += r.substeps, ++n;
    }
    for (const Probe& p : probes)
      if (p.time > t0 + 1e-9 && p.time <= t1 + 1e-9) ev += p.ms, ++m;
    if (n == 0) return;
    ev = m > 0 ? ev / m : probe_at(t0);
    std::printf("| %s | %d | %.3g | %.3g | %.3g | %.3g | %.3g | %.3g | %.3g | %.3g |\n", name, n, tm / n,
                tr / n, (tm + tr) / n, mx, it / n, sub / n, ev, tm / n / ev);
  };
  for (const Phase& p : kPhases) row(p.name, p.begin, p.end);
  row("whole run", 0.0, 1e9);
  return 0;
}
