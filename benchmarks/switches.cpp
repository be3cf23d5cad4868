// What each cost-saving switch of the magnetic solve buys, in time and in
// force error (docs/benchmarks.md "Switches").
//
// Per scene (demos/scenes/*.json): the scene is simulated once with its own
// settings and the magnetic inputs of a window of consecutive rigid steps are
// recorded (body poses, active flags, magnetization scales, H_E, mutual
// induction). Each configuration then replays that window on its own model
// and state, warm-started from step to step as in a simulation (the first
// step, a cold relaxation, is not timed), with `magnetic_step` (relaxation,
// forces and torques: the work of T_m) on the CPU backend. Time: ms per step.
// Error: per step max_b |F_b - F_ref,b| / max_b |F_ref,b| over the magnetic
// bodies, F_ref from the reference configuration (the scene's settings with
// tolerance 1e-10, cap 500); the table gives the largest and the median over
// the window.
//
// Configurations (`kind`: switch = an option of the code toggled; emulated =
// the code has no switch, the cost is produced through the API; estimate = a
// measured cost added to the default's time; none = no such feature):
//   reference, default (the scene's solver settings);
//   intra-body tensors not cached (estimate: every intra-body pair's Newell
//     tensor evaluated at every field evaluation, timed here);
//   intra-body tensor = point dipole (switch: IntraBodyTensor, the paper's);
//   inert bodies with cells (emulated: inert materials replaced by a soft one
//     with chi = 1e-5 on the scene's finest lattice);
//   anisotropy term for isotropic materials (emulated: H_K = 1e-12 A/m, so the
//     term is computed; its effect on M is 1e-18 relative);
//   no early exit (switch: tolerance 0, fixed 30 or 200 outer iterations);
//   Newton polish off, Anderson mixing off, mutual induction off (switches);
//   skipping steps in which nothing changed (switch: RelaxOptions::skip_unchanged);
//   skipping single bodies whose state did not change (none: the share of
//     unchanged bodies and steps in the window is reported);
//   far-interaction approximation (switch: RelaxOptions::far_field_theta 0.3,
//     0.5, 0.7, in scenes of 64 responsive cells or more).
//
// Usage: switches [--out DIR] [--threads N] [--scenes a,b,...] [--crane-start T] [--crane-steps N]
//                 [--budget S]
// Windows: the first 300 steps of each scene; the crane's 100 steps from
// 0.75 s (the magnet reaches the heap at 0.8 s). A configuration stops
// replaying when it has used --budget seconds (default 3; at least one step;
// four times that for the reference and the default); its "x default"
// compares the same steps, its error the steps the reference replayed.
// Replays shorter than 0.5 s are repeated (up to 3) and the fastest kept.
// Writes DIR/switches.csv and DIR/switches.md (DIR: benchmarks/results). Run
// from the repository root. Runs itself again with OMP_WAIT_POLICY=passive
// when that is unset.
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include "benchmarks/bench_common.h"
#include "benchmarks/timed_backend.h"
#include "odemag/scene.h"
#include "odemag/simulation.h"
#include "magnetics/model/backend.h"
#include "magnetics/cells/demag_tensor.h"
#include "magnetics/relax/relax.h"

using namespace odemag;

namespace {

double seconds_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

struct Snapshot {
  std::vector<BodyPose> pose;
  std::vector<uint8_t> active;
  std::vector<double> scale;
  Vec3 external_field;
  bool mutual_induction = true;
};

// Runs the scene with its own settings to t_start, then records `steps` rigid
// steps (the magnetic inputs of each step's last substep).
std::vector<Snapshot> record_window(const SceneDescription& scene, double t_start, int steps, int threads) {
  Simulation sim(scene, make_cpu_backend(threads));
  sim.advance_to(t_start);
  std::vector<Snapshot> snaps;
  for (int k = 0; k < steps; ++k) {
    if (sim.time() + 0.5 * scene.simulation.time_step >= scene.simulation.duration) break;
    sim.step();
    const MagneticState& s = sim.magnetics().state();
    snaps.push_back({s.pose, s.active, s.magnetization_scale, s.external_field,
                     sim.magnetics().options().mutual_induction});
  }
  return snaps;
}

struct Config {
  std::string name, setting, kind;  // kind: switch, emulated, estimate, none
  RelaxOptions options;
  IntraBodyTensor tensor = IntraBodyTensor::cell_average;
  bool inert_cells = false;
  bool anisotropy_everywhere = false;
};

// The finest lattice spacing of the scene's lattice bodies (5 mm if none).
double finest_spacing(const SceneDescription& scene) {
  double h = 0.0;
  for (size_t b = 0; b < scene.bodies.size(); ++b) {
    const double s = scene.body_cell_size(static_cast<int>(b));
    if (s > 0.0 && !is_inert(scene.materials.at(scene.bodies[b].material))) h = h > 0.0 ? std::min(h, s) : s;
  }
  return h > 0.0 ? h : 0.005;
}

MagneticModel build_model(const SceneDescription& scene, const Config& c) {
  MagneticModel model(c.tensor);
  for (size_t b = 0; b < scene.bodies.size(); ++b) {
    const BodyDescription& body = scene.bodies[b];
    Material material = scene.materials.at(body.material);
    double h = scene.body_cell_size(static_cast<int>(b));
    if (c.inert_cells && is_inert(material)) {
      SoftMaterial weak;  // wood, glass: |chi| ~ 1e-5
      weak.saturation = 1e6;
      weak.susceptibility = 1e-5;
      material = weak;
      h = finest_spacing(scene);
    }
    if (auto* soft = std::get_if<SoftMaterial>(&material); soft && c.anisotropy_everywhere && !soft->anisotropic())
      soft->anisotropy_field = 1e-12;
    model.add_body(body.name, body.shape, material, h);
  }
  return model;
}

struct Replay {
  int cells = 0, responsive = 0, steps = 0;
  std::vector<double> ms;
  double iterations = 0, field_evaluations = 0;  // means per step
  double field_s = 0, local_s = 0, forces_s = 0, total_s = 0;
  int not_converged = 0;
  std::vector<std::vector<Vec3>> forces;
};

// Replays steps 1 .. max_steps of the window (fewer when budget_s runs out,
// at least one).
Replay replay(const SceneDescription& scene, const std::vector<Snapshot>& snaps, const Config& c, int threads,
              int max_steps, double budget_s) {
  Replay r;
  const MagneticModel model = build_model(scene, c);
  MagneticState state = make_state(model, scene.seed);
  TimedBackend backend(make_cpu_backend(threads));
  RelaxOptions options = c.options;
  auto load = [&](const Snapshot& s) {
    state.pose = s.pose;
    state.active = s.active;
    state.magnetization_scale = s.scale;
    state.external_field = s.external_field;
    options.mutual_induction = c.options.mutual_induction && s.mutual_induction;
  };
  load(snaps[0]);
  magnetic_step(model, state, options, backend);  // cold start, not timed
  backend.reset();
  r.cells = model.cell_count(), r.responsive = model.responsive_cell_count();
  const int n = std::min(static_cast<int>(snaps.size()), max_steps + 1);
  for (int k = 1; k < n && (k == 1 || r.total_s < budget_s); ++k) {
    load(snaps[k]);
    const auto t0 = std::chrono::steady_clock::now();
    const RelaxReport report = magnetic_step(model, state, options, backend);
    const double s = seconds_since(t0);
    r.ms.push_back(1e3 * s);
    r.total_s += s;
    r.iterations += report.iterations;
    r.field_evaluations += report.field_evaluations;
    if (!report.converged) ++r.not_converged;
    r.forces.push_back(state.force);
  }
  r.steps = static_cast<int>(r.ms.size());
  r.iterations /= std::max(1, r.steps);
  r.field_evaluations /= std::max(1, r.steps);
  r.field_s = backend.field_s, r.local_s = backend.local_s, r.forces_s = backend.forces_s;
  return r;
}

// Seconds to evaluate every intra-body pair's cube-cube tensor of the
// scene's responsive lattice bodies once: what one field evaluation would add
// without the cached tables.
double uncached_tensor_seconds(const MagneticModel& model, long* pairs) {
  double sink = 0.0;
  *pairs = 0;
  const auto t0 = std::chrono::steady_clock::now();
  for (const MagneticBody& body : model.bodies()) {
    if (!body.responsive() || body.cell_count() < 2) continue;
    const auto& idx = body.cells.lattice_index;
    for (int i = 0; i < body.cell_count(); ++i)
      for (int j = 0; j < body.cell_count(); ++j) {
        if (i == j) continue;
        double t[6];
        cube_demag_tensor(idx[i][0] - idx[j][0], idx[i][1] - idx[j][1], idx[i][2] - idx[j][2], body.cells.spacing, t);
        sink += t[0];
        ++*pairs;
      }
  }
  const double s = seconds_since(t0);
  if (sink == 12345.678) std::fprintf(stderr, " ");  // keep the loop
  return s;
}

double median(std::vector<double> x) {
  if (x.empty()) return 0.0;
  std::sort(x.begin(), x.end());
  return x[x.size() / 2];
}

struct Row {
  std::string scene, name, setting, kind, note;
  int steps = 0, cells = 0, responsive = 0, not_converged = 0;
  double ms_mean = 0, ms_median = 0, ratio = 0, iterations = 0, field_evaluations = 0;
  double field_pct = 0, local_pct = 0, forces_pct = 0;
  double error_max = -1, error_median = -1;  // -1: not applicable
};

// Per step: max_b |F_b - F_ref,b| / max_b |F_ref,b| over bodies magnetic in the scene.
void force_errors(const SceneDescription& scene, const Replay& r, const Replay& ref, double* worst, double* med) {
  std::vector<double> e;
  for (size_t k = 0; k < std::min(r.forces.size(), ref.forces.size()); ++k) {
    double num = 0.0, den = 0.0;
    for (size_t b = 0; b < scene.bodies.size(); ++b) {
      if (is_inert(scene.materials.at(scene.bodies[b].material))) continue;
      num = std::max(num, norm(r.forces[k][b] - ref.forces[k][b]));
      den = std::max(den, norm(ref.forces[k][b]));
    }
    e.push_back(den > 0.0 ? num / den : 0.0);
  }
  *worst = e.empty() ? 0.0 : *std::max_element(e.begin(), e.end());
  *med = median(e);
}

Row make_row(const std::string& scene_name, const Config& c, const Replay& r, double default_ms) {
  Row row;
  row.scene = scene_name, row.name = c.name, row.setting = c.setting, row.kind = c.kind;
  row.steps = r.steps, row.cells = r.cells, row.responsive = r.responsive, row.not_converged = r.not_converged;
  row.ms_mean = r.steps ? 1e3 * r.total_s / r.steps : 0.0;
  row.ms_median = median(r.ms);
  row.ratio = default_ms > 0.0 ? row.ms_mean / default_ms : 1.0;
  row.iterations = r.iterations, row.field_evaluations = r.field_evaluations;
  if (r.total_s > 0.0) {
    row.field_pct = 100.0 * r.field_s / r.total_s;
    row.local_pct = 100.0 * r.local_s / r.total_s;
    row.forces_pct = 100.0 * r.forces_s / r.total_s;
  }
  return row;
}


}  // namespace

int main(int argc, char** argv) {
  odemag::restart_with_passive_omp_wait(argv);
  std::string out_dir = "benchmarks/results", scene_list = "iron_plate,thin_iron_plate,wood_plate,nail_and_balls,crane";
  int threads = 2, crane_steps = 100;
  double crane_start = 0.75, budget = 3.0;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    auto next = [&] { return bench::option_value(argc, argv, i, "switches"); };
    if (a == "--out") out_dir = next();
    else if (a == "--threads") threads = std::atoi(next().c_str());
    else if (a == "--scenes") scene_list = next();
    else if (a == "--crane-start") crane_start = std::atof(next().c_str());
    else if (a == "--crane-steps") crane_steps = std::atoi(next().c_str());
    else if (a == "--budget") budget = std::atof(next().c_str());
    else {
      std::fprintf(stderr,
                   "usage: switches [--out DIR] [--threads N] [--scenes a,b] [--crane-start T] [--crane-steps N] "
                   "[--budget S]\n");
      return 2;
    }
  }

  std::vector<Row> rows;
  for (const std::string& name : bench::split(scene_list)) {
    const SceneDescription scene = load_scene("demos/scenes/" + name + ".json");
    const bool crane = name == "crane";
    const double t_start = crane ? crane_start : 0.0;
    const int window = crane ? crane_steps : 300;
    auto t0 = std::chrono::steady_clock::now();
    const std::vector<Snapshot> snaps = record_window(scene, t_start, window + 1, threads);
    std::fprintf(stderr, "switches: %s: recorded %zu steps from t = %g s in %.1f s\n", name.c_str(), snaps.size(),
                 t_start, seconds_since(t0));

    bool has_inert = false, has_isotropic = false, has_lattice = false;
    for (const BodyDescription& b : scene.bodies) {
      const Material& m = scene.materials.at(b.material);
      has_inert |= is_inert(m);
      if (const auto* soft = std::get_if<SoftMaterial>(&m)) has_isotropic |= !soft->anisotropic();
    }
    const RelaxOptions base = scene.solver.relax;
    std::vector<Config> configs;
    Config reference{"reference", "tolerance 1e-10, cap 500", "switch", base};
    reference.options.tolerance = 1e-10;
    reference.options.max_iterations = 500;
    configs.push_back(reference);
    char setting[80];
    std::snprintf(setting, sizeof setting, "scene settings (tolerance %g, cap %d)", base.tolerance, base.max_iterations);
    configs.push_back({"default", setting, "switch", base});
    {
      const MagneticModel m = build_model(scene, configs.back());
      for (const MagneticBody& b : m.bodies()) has_lattice |= b.responsive() && b.cell_count() > 1;
    }
    if (has_lattice) {
      Config c{"intra-body tensor", "point dipole (paper) instead of cube-cube", "switch", base};
      c.tensor = IntraBodyTensor::point_dipole;
      configs.push_back(c);
    }
    if (has_inert) {
      Config c{"inert bodies", "with cells (soft, chi 1e-5)", "emulated", base};
      c.inert_cells = true;
      configs.push_back(c);
    }
    if (has_isotropic) {
      Config c{"anisotropy term", "computed for isotropic materials (H_K 1e-12 A/m)", "emulated", base};
      c.anisotropy_everywhere = true;
      configs.push_back(c);
    }
    for (int fixed : {30, 200}) {
      Config c{"early exit", "off: fixed " + std::to_string(fixed) + " iterations", "switch", base};
      c.options.tolerance = 0.0;
      c.options.max_iterations = fixed;
      configs.push_back(c);
    }
    {
      Config c{"Newton polish", "off (LLG steps only)", "switch", base};
      c.options.local.newton = false;
      configs.push_back(c);
      Config c2{"Newton polish", "off, LLG to the inner tolerance", "switch", base};
      c2.options.local.newton = false;
      c2.options.local.llg_switch = 1e-8;
      c2.options.local.max_llg_steps = 1000;
      configs.push_back(c2);
      Config d{"Anderson mixing", "off (depth 0: plain fixed point)", "switch", base};
      d.options.anderson_depth = 0;
      configs.push_back(d);
      Config e{"mutual induction", "off", "switch", base};
      e.options.mutual_induction = false;
      configs.push_back(e);
    }
    {
      Config c{"skip unchanged steps", "on (solver.skip_unchanged)", "switch", base};
      c.options.skip_unchanged = true;
      configs.push_back(c);
    }
    if (build_model(scene, configs[1]).responsive_cell_count() >= 512)
      for (double theta : {0.3, 0.5, 0.7}) {
        char opening[40];
        std::snprintf(opening, sizeof opening, "theta %g", theta);
        Config c{"far-field approximation", opening, "switch", base};
        c.options.far_field_theta = theta;
        configs.push_back(c);
      }

    Replay ref, def;
    double default_ms = 0.0;
    const size_t first_row = rows.size();
    std::vector<std::vector<double>> step_ms;  // per configuration
    for (const Config& c : configs) {
      // Up to 3 replays while they are short (the machine may be shared):
      // the fastest counts; results are deterministic.
      // The reference and the default, against which the others are
      // measured, get four times the budget.
      const double b = c.name == "reference" || c.name == "default" ? 4.0 * budget : budget;
      t0 = std::chrono::steady_clock::now();
      Replay r = replay(scene, snaps, c, threads, window, b);
      for (int again = 1; again < 3 && r.total_s < 0.5; ++again) {
        Replay s = replay(scene, snaps, c, threads, window, b);
        if (s.total_s < r.total_s) r = std::move(s);
      }
      Row row = make_row(name, c, r, default_ms);
      if (c.name == "reference") {
        ref = r;
        row.error_max = row.error_median = 0.0;
      } else {
        force_errors(scene, r, ref, &row.error_max, &row.error_median);
      }
      if (c.name == "default") {
        def = r;
        default_ms = row.ms_mean;
        row.ratio = 1.0;
      }
      if (r.steps + 1 < static_cast<int>(snaps.size()))
        row.note = "first " + std::to_string(r.steps) + " steps of the window (time budget); ";
      if (c.name == "intra-body tensor")
        row.note += "model change: error is the difference from the cube-cube tensor";
      if (c.name == "inert bodies") row.note += "model change: error is the weak material's effect";
      if (c.name == "mutual induction") row.note += "model change";
      if (c.name == "early exit") row.note += "a step whose residual is exactly 0 stops early";
      if (c.name == "Newton polish")
        row.note += c.options.local.llg_switch < 1e-2 ? "inner LLG until the relative torque is 1e-8 (at most 1000 steps)"
                                                      : "inner LLG stops at relative torque 1e-2 (llg_switch) or 60 steps";
      rows.push_back(row);
      step_ms.push_back(r.ms);
      std::fprintf(stderr, "switches: %s / %s %s: %.3g ms per step, %.3g iterations, error %.2g (%.1f s)\n",
                   name.c_str(), c.name.c_str(), c.setting.c_str(), row.ms_mean, row.iterations, row.error_max,
                   seconds_since(t0));
    }

    // Time against the default's over the same steps (a configuration cut
    // short by the budget replays only the first steps).
    for (size_t i = 0; i < step_ms.size(); ++i) {
      double mine = 0.0, theirs = 0.0;
      for (size_t k = 0; k < step_ms[i].size() && k < def.ms.size(); ++k) mine += step_ms[i][k], theirs += def.ms[k];
      rows[first_row + i].ratio = theirs > 0.0 ? mine / theirs : 0.0;
    }

    // Intra-body tensors computed at every field evaluation instead of cached.
    if (has_lattice) {
      const MagneticModel m = build_model(scene, configs[1]);
      long pairs = 0;
      double s = uncached_tensor_seconds(m, &pairs);
      s = std::min(s, uncached_tensor_seconds(m, &pairs));
      t0 = std::chrono::steady_clock::now();
      const MagneticModel again = build_model(scene, configs[1]);
      const double build_ms = 1e3 * seconds_since(t0);
      Row row = make_row(name, {"intra-body tensors", "not cached (Newell tensor per pair per field evaluation)",
                                "estimate", base},
                         def, default_ms);
      row.ms_mean += 1e3 * s * def.field_evaluations;
      row.ms_median += 1e3 * s * def.field_evaluations;
      row.ratio = row.ms_mean / default_ms;
      row.error_max = row.error_median = -1;
      char note[200];
      std::snprintf(note, sizeof note,
                    "%ld intra pairs x %.0f ns per tensor x %.1f field evaluations per step added; same values; "
                    "building all tables once: %.2f ms",
                    pairs, 1e9 * s / static_cast<double>(std::max(1L, pairs)), def.field_evaluations, build_ms);
      row.note = note;
      row.field_pct = row.local_pct = row.forces_pct = 0.0;
      rows.push_back(row);
      (void)again;
    }

    // Bodies whose inputs did not change between consecutive steps, and the
    // share of the default's time spent on steps where nothing changed (what
    // skipping such steps would save; skipping single bodies saves less, as
    // the field of the moving ones still changes everywhere).
    {
      long body_steps = 0, unchanged_bodies = 0, unchanged_steps = 0;
      double unchanged_ms = 0.0, all_ms = 0.0;
      for (size_t k = 1; k < snaps.size(); ++k) {
        bool all = snaps[k].scale == snaps[k - 1].scale && snaps[k].active == snaps[k - 1].active &&
                   norm(snaps[k].external_field - snaps[k - 1].external_field) == 0.0 &&
                   snaps[k].mutual_induction == snaps[k - 1].mutual_induction;
        for (size_t b = 0; b < scene.bodies.size(); ++b) {
          if (is_inert(scene.materials.at(scene.bodies[b].material)) || !snaps[k].active[b]) continue;
          const BodyPose &p = snaps[k].pose[b], &q = snaps[k - 1].pose[b];
          double dr = 0.0;
          for (int i = 0; i < 3; ++i)
            for (int j = 0; j < 3; ++j) dr = std::max(dr, std::fabs(p.rotation.m[i][j] - q.rotation.m[i][j]));
          const bool same = norm(p.position - q.position) < 1e-7 && dr < 1e-6;
          ++body_steps;
          unchanged_bodies += same;
          all = all && same;
        }
        unchanged_steps += all;
        if (k - 1 < def.ms.size()) {
          all_ms += def.ms[k - 1];
          if (all) unchanged_ms += def.ms[k - 1];
        }
      }
      Row row;
      row.scene = name, row.name = "skip unchanged bodies", row.setting = "per body: not implemented", row.kind = "none";
      row.steps = static_cast<int>(snaps.size()) - 1;
      char note[240];
      std::snprintf(note, sizeof note,
                    "%.0f%% of magnetic body-steps moved < 0.1 um and turned < 1e-6; %.0f%% of steps had no change "
                    "at all, %.0f%% of the default's time",
                    100.0 * static_cast<double>(unchanged_bodies) / static_cast<double>(std::max(1L, body_steps)),
                    100.0 * static_cast<double>(unchanged_steps) / std::max(1, row.steps),
                    all_ms > 0.0 ? 100.0 * unchanged_ms / all_ms : 0.0);
      row.note = note;
      rows.push_back(row);
    }
  }
  // CSV and markdown.
  auto num = [](double v, const char* f = "%.3g") {
    char b[40];
    std::snprintf(b, sizeof b, f, v);
    return std::string(b);
  };
  const std::string csv_path = out_dir + "/switches.csv", md_path = out_dir + "/switches.md";
  FILE *csv, *md;
  if (!bench::open_reports(out_dir, csv_path, md_path, csv, md)) return 1;
  std::fprintf(csv,
               "scene,switch,setting,kind,steps,cells,responsive_cells,ms_per_step_mean,ms_per_step_median,"
               "time_vs_default,iterations_mean,field_evaluations_mean,steps_not_converged,field_pct,local_pct,"
               "forces_pct,force_error_max,force_error_median,note\n");
  std::fprintf(md,
               "CPU backend, %d threads (OMP_WAIT_POLICY=passive). Time: relaxation + forces per replayed rigid step "
               "(ms, mean); error: max_b |F_b - F_ref,b| / max_b |F_ref,b| against the reference, largest / median "
               "over the window; split: share of the time in field evaluations / local cell relaxation / forces.\n\n"
               "| scene | switch | setting | kind | steps | cells | ms per step | x default | iterations | split "
               "%% | force error max / median | note |\n|---|---|---|---|---|---|---|---|---|---|---|---|\n",
               threads);
  for (const Row& r : rows) {
    const bool timed = r.ms_mean > 0.0;
    std::fprintf(csv, "%s,%s,\"%s\",%s,%d,%d,%d,%.4f,%.4f,%.3f,%.2f,%.2f,%d,%.1f,%.1f,%.1f,%s,%s,\"%s\"\n",
                 r.scene.c_str(), r.name.c_str(), r.setting.c_str(), r.kind.c_str(), r.steps, r.cells, r.responsive,
                 r.ms_mean, r.ms_median, r.ratio, r.iterations, r.field_evaluations, r.not_converged, r.field_pct,
                 r.local_pct, r.forces_pct, r.error_max >= 0 ? num(r.error_max, "%.3e").c_str() : "",
                 r.error_median >= 0 ? num(r.error_median, "%.3e").c_str() : "", r.note.c_str());
    const std::string split_text = r.field_pct + r.local_pct + r.forces_pct > 0.0
                                       ? num(r.field_pct, "%.0f") + " / " + num(r.local_pct, "%.0f") + " / " +
                                             num(r.forces_pct, "%.0f")
                                       : "";
    std::fprintf(md, "| %s | %s | %s | %s | %s | %s | %s | %s | %s | %s | %s | %s |\n", r.scene.c_str(),
                 r.name.c_str(), r.setting.c_str(), r.kind.c_str(), r.steps ? std::to_string(r.steps).c_str() : "",
                 r.cells ? std::to_string(r.cells).c_str() : "", timed ? num(r.ms_mean).c_str() : "",
                 timed ? num(r.ratio, "%.2f").c_str() : "",
                 timed ? (num(r.iterations) + (r.not_converged ? " (" + std::to_string(r.not_converged) + " capped)" : ""))
                             .c_str()
                       : "",
                 split_text.c_str(),
                 r.error_max >= 0 ? (num(r.error_max, "%.1e") + " / " + num(r.error_median, "%.1e")).c_str() : "",
                 r.note.c_str());
  }
  std::fclose(csv);
  std::fclose(md);
  std::fprintf(stderr, "switches: wrote %s and %s\n", csv_path.c_str(), md_path.c_str());
  return 0;
}
