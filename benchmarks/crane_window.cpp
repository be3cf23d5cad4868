// A short window of the crane scene, for instruction counts
// (docs/benchmarks.md "Where the crane's time goes"): the remanence phase after the coil is off
// costs most of the run, and reaching it takes thousands of steps, so the
// state at the window's start is saved once and the window replayed from it.
//
//   crane_window --scene PATH --save-at T --snapshot FILE
//       runs the scene to time T and writes the rigid bodies' states and the
//       magnetic moments to FILE (binary, not portable; a scratch file).
//   crane_window --scene PATH --snapshot FILE --steps N [--magnetization-scale S]
//       [--threads N] [--label TEXT] [--no-precondition]
//       rebuilds the scene without its time line (the crane held where its
//       track ends, at magnetization scale S, default 0: coil off), puts the
//       saved states back, and steps N times. Under valgrind --tool=callgrind
//       --instr-atstart=no only these steps are counted. Prints the window's
//       T_m, T_r, outer iterations, substeps, balls above 0.1 m, and an
//       FNV-1a hash of the final positions. --no-precondition: without the
//       outer loop's block preconditioner (RelaxOptions::precondition_bodies).
//   crane_window --scene PATH --steps N [--duration-start 0]
//       without --snapshot: the first N steps of the scene as it is.
#include <valgrind/callgrind.h>

#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <ctime>
#include <string>
#include <vector>

#include "benchmarks/bench_common.h"
#include "odemag/scene.h"
#include "odemag/simulation.h"
#include "engine/simulation/rigid_world.h"

using namespace odemag;

namespace {

struct BodySnapshot {
  double position[3], quaternion[4], velocity[3], angular_velocity[3];
};

template <class T>
void write_vector(FILE* f, const std::vector<T>& v) {
  const uint64_t n = v.size();
  std::fwrite(&n, sizeof n, 1, f);
  if (n) std::fwrite(v.data(), sizeof(T), n, f);
}

template <class T>
bool read_vector(FILE* f, std::vector<T>& v) {
  uint64_t n = 0;
  if (std::fread(&n, sizeof n, 1, f) != 1) return false;
  v.resize(n);
  return n == 0 || std::fread(v.data(), sizeof(T), n, f) == n;
}

double process_cpu_s() {
  timespec ts{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
  return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
}

}  // namespace

int main(int argc, char** argv) {
  odemag::restart_with_passive_omp_wait(argv);
  std::string scene_path = std::string(ODEMAG_SOURCE_DIR) + "/demos/scenes/crane_small.json", snapshot,
              label = "window";
  double save_at = -1.0, scale = 0.0;
  int steps = 100, threads = 2;
  bool histories = false, plain = false;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--scene") scene_path = bench::option_value(argc, argv, i, "crane_window");
    else if (a == "--save-at") save_at = std::stod(bench::option_value(argc, argv, i, "crane_window"));
    else if (a == "--snapshot") snapshot = bench::option_value(argc, argv, i, "crane_window");
    else if (a == "--steps") steps = std::stoi(bench::option_value(argc, argv, i, "crane_window"));
    else if (a == "--threads") threads = std::stoi(bench::option_value(argc, argv, i, "crane_window"));
    else if (a == "--magnetization-scale") scale = std::stod(bench::option_value(argc, argv, i, "crane_window"));
    else if (a == "--label") label = bench::option_value(argc, argv, i, "crane_window");
    else if (a == "--histories") histories = true;
    else if (a == "--no-precondition") plain = true;
    else {
      std::fprintf(stderr, "crane_window: unknown argument '%s'\n", a.c_str());
      return 2;
    }
  }
  SceneDescription scene = load_scene(scene_path);
  scene.solver.threads = threads;
  if (plain) scene.solver.relax.precondition_bodies = false;
  const bool saving = save_at >= 0.0, replaying = !saving && !snapshot.empty();
  if (saving) {
    Simulation sim(scene);
    sim.magnetics().compute();  // as `odemag run` does before its first frame
    sim.advance_to(save_at);
    FILE* f = std::fopen(snapshot.c_str(), "wb");
    if (!f) return 1;
    std::vector<BodySnapshot> bodies(sim.world().body_count());
    for (int b = 0; b < sim.world().body_count(); ++b) {
      dBodyID id = sim.world().body(b);
      if (!id) continue;
      const dReal *p = dBodyGetPosition(id), *q = dBodyGetQuaternion(id), *v = dBodyGetLinearVel(id),
                  *w = dBodyGetAngularVel(id);
      for (int k = 0; k < 3; ++k)
        bodies[b].position[k] = p[k], bodies[b].velocity[k] = v[k], bodies[b].angular_velocity[k] = w[k];
      for (int k = 0; k < 4; ++k) bodies[b].quaternion[k] = q[k];
    }
    write_vector(f, bodies);
    const MagneticState& st = sim.magnetics().state();
    write_vector(f, st.moments);
    write_vector(f, st.magnetization);
    write_vector(f, st.applied_field);
    write_vector(f, st.noise_counter);
    std::fclose(f);
    std::printf("saved %s at t = %.4f\n", snapshot.c_str(), sim.time());
    return 0;
  }
  if (replaying) {
    // The crane stays where its track ends (its scene position), at the given scale.
    std::vector<TimelineEvent> kept;
    std::string crane;
    for (const TimelineEvent& ev : scene.timeline) {
      if (ev.kind == TimelineEvent::Kind::keyframes) {
        const int b = scene.find_body(ev.body);
        const Keyframe& last = ev.keys.back();
        scene.bodies[b].position = last.position;
        continue;
      }
      if (ev.kind == TimelineEvent::Kind::scale_magnetization) {
        crane = ev.body;
        continue;
      }
      kept.push_back(ev);
    }
    if (!crane.empty()) {
      TimelineEvent off;
      off.kind = TimelineEvent::Kind::scale_magnetization;
      off.body = crane;
      off.value = scale;
      kept.push_back(off);
    }
    scene.timeline = kept;
  }
  Simulation sim(scene);
  if (replaying) {
    FILE* f = std::fopen(snapshot.c_str(), "rb");
    if (!f) return 1;
    std::vector<BodySnapshot> bodies;
    MagneticState& st = sim.magnetics().state();
    std::vector<Vec3> moments, magnetization, applied;
    std::vector<uint64_t> counters;
    if (!read_vector(f, bodies) || !read_vector(f, moments) || !read_vector(f, magnetization) ||
        !read_vector(f, applied) || !read_vector(f, counters) ||
        static_cast<int>(bodies.size()) != sim.world().body_count() || moments.size() != st.moments.size()) {
      std::fprintf(stderr, "crane_window: %s does not belong to this scene\n", snapshot.c_str());
      return 1;
    }
    std::fclose(f);
    for (int b = 0; b < sim.world().body_count(); ++b) {
      dBodyID id = sim.world().body(b);
      if (!id || scene.bodies[b].fixed) continue;
      const BodySnapshot& s = bodies[b];
      dBodySetPosition(id, s.position[0], s.position[1], s.position[2]);
      const dQuaternion q{s.quaternion[0], s.quaternion[1], s.quaternion[2], s.quaternion[3]};
      dBodySetQuaternion(id, q);
      dBodySetLinearVel(id, s.velocity[0], s.velocity[1], s.velocity[2]);
      dBodySetAngularVel(id, s.angular_velocity[0], s.angular_velocity[1], s.angular_velocity[2]);
    }
    st.moments = moments;
    st.magnetization = magnetization;
    st.applied_field = applied;
    st.noise_counter = counters;
    st.last_solve.valid = false;
  } else {
    sim.magnetics().compute();
  }
  const double cpu0 = process_cpu_s();
  CALLGRIND_START_INSTRUMENTATION;
  for (int s = 0; s < steps; ++s) {
    sim.step();
    if (!histories) continue;
    // The residual after each outer iteration of the step's last relaxation.
    const RelaxReport& r = sim.magnetics().last_report();
    std::printf("step %d, last relaxation: %d iterations, LLG %ld, Newton %ld, residuals", s, r.iterations,
                r.llg_steps, r.newton_steps);
    for (double x : r.residual_history) std::printf(" %.2e", x);
    std::printf("\n");
  }
  CALLGRIND_STOP_INSTRUMENTATION;
  const double cpu = process_cpu_s() - cpu0;
  double tm = 0, tr = 0, tmax = 0;
  long it = 0, sub = 0, maxit = 0, llg = 0, newton = 0;
  for (const StepReport& r : sim.records()) {
    tm += r.magnetic_ms, tr += r.rigid_ms, tmax = std::max(tmax, r.magnetic_ms + r.rigid_ms);
    it += r.iterations, sub += r.substeps, maxit = std::max<long>(maxit, r.iterations);
    llg += r.llg_steps, newton += r.newton_steps;
  }
  const double n = static_cast<double>(std::max<size_t>(1, sim.records().size()));
  int above = 0;
  uint64_t hash = 1469598103934665603ULL;
  for (int b = 0; b < sim.world().body_count(); ++b) {
    const Vec3 x = sim.world().pose(b).position;
    if (scene.bodies[b].name.rfind("ball_", 0) == 0 && x.z > 0.1) ++above;
    for (int a = 0; a < 3; ++a) {
      const double v = x[a];
      unsigned char bytes[sizeof(double)];
      std::memcpy(bytes, &v, sizeof(double));
      for (unsigned char c : bytes) hash = (hash ^ c) * 1099511628211ULL;
    }
  }
  std::printf(
      "%s: %d steps, T_m mean %.3g ms, T_r mean %.3g ms, max T_m+T_r %.3g ms, CPU %.2f s, iterations/step %.3g "
      "(max %ld), substeps/step %.3g, LLG steps/step %.4g, Newton steps/step %.4g, balls above 0.1 m %d, hash %016llx\n",
      label.c_str(), steps, tm / n, tr / n, tmax, cpu, static_cast<double>(it) / n, maxit,
      static_cast<double>(sub) / n, static_cast<double>(llg) / n, static_cast<double>(newton) / n, above,
      static_cast<unsigned long long>(hash));
  return 0;
}
