// `odemag solve` and `odemag field`: relax a scene with its bodies held in
// place, then report per-body moments and forces, or the field at points.
#include <unistd.h>

#include <algorithm>
#include <charconv>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <memory>

#include <nlohmann/json.hpp>

#include "cli/cli.h"
#include "odemag/solve.h"
#include "odemag/scene.h"
#include "magnetics/relax/relax.h"
#include "engine/simulation/magnetic_system.h"
#include "gpu/backend_choice.h"

namespace odemag::cli {

namespace {

void warn_if_not_converged(const SceneDescription& scene, const RelaxReport& report) {
  if (report.converged) return;
  std::fprintf(stderr,
               "odemag: warning: %s: the relaxation did not converge in %d iterations "
               "(residual %.3g, solver.tolerance %.3g)\n",
               one_line(scene.file).c_str(), report.iterations, report.residual,
               scene.solver.relax.tolerance);
}

void require_finite(const SceneDescription& scene, bool finite) {
  if (!finite)
    throw std::runtime_error(scene.file +
                             ": the relaxation produced non-finite values (try a smaller "
                             "solver.time_step_factor)");
}

// Progress lines of a relaxation that takes long: from 2 s on, every second
// on a terminal (every 10 s otherwise), the iteration, the residual and the
// iterations left at the rate the residual fell over the last five.
class SolveProgress {
 public:
  SolveProgress(double tolerance, int max_iterations)
      : tolerance_(tolerance), max_iterations_(max_iterations), tty_(isatty(STDERR_FILENO)) {}
  void operator()(const RelaxReport& report) {
    const auto now = std::chrono::steady_clock::now();
    const double elapsed = std::chrono::duration<double>(now - started_).count();
    const std::vector<double>& r = report.residual_history;
    if (elapsed < 2.0 || now - shown_ < std::chrono::seconds(tty_ ? 1 : 10) || r.empty() || r.back() <= tolerance_)
      return;
    shown_ = now;
    std::string left = "no estimate yet";
    if (r.size() > 5 && r.back() > 0.0 && r[r.size() - 6] > 0.0) {
      const double rate = std::log(r.back() / r[r.size() - 6]) / 5.0;  // log residual per iteration
      const double per_iteration = elapsed / static_cast<double>(r.size());
      if (rate < 0.0) {
        const double more = std::min(std::ceil(std::log(tolerance_ / r.back()) / rate),
                                     static_cast<double>(max_iterations_ - report.iterations));
        char text[96];
        std::snprintf(text, sizeof text, "about %.0f more iterations at the recent rate (~%.0f s)", more,
                      more * per_iteration);
        left = text;
      } else {
        left = "the residual is not falling";
      }
    }
    std::fprintf(stderr, "odemag solve: iteration %d, residual %.2e (tolerance %.2e), %.0f s; %s\n",
                 report.iterations, r.back(), tolerance_, elapsed, left.c_str());
    std::fflush(stderr);
  }

 private:
  double tolerance_;
  int max_iterations_;
  bool tty_;
  std::chrono::steady_clock::time_point started_ = std::chrono::steady_clock::now(), shown_{};
};

// A double as the shortest text that reads back as the same double.
std::string round_trip(double x) {
  char text[64];
  const std::to_chars_result r = std::to_chars(text, text + sizeof text, x);
  return std::string(text, r.ptr);
}

std::string number(double x) { return nlohmann::json(x).dump(); }
std::string vector(const Vec3& v) {
  std::string s = "[";
  s += number(v.x);
  s += ", ";
  s += number(v.y);
  s += ", ";
  s += number(v.z);
  s += "]";
  return s;
}

}  // namespace

// The scene file: the one positional argument.
std::string scene_argument(const std::string& command, const Arguments& args) {
  if (args.positional.empty())
    throw UsageError("'" + command + "' needs a scene file (see odemag --help)");
  if (args.positional.size() > 1)
    throw UsageError("'" + command + "' takes one scene file; unexpected argument '" +
                     args.positional[1] + "'");
  return args.positional[0];
}

void check_cell_pairs(const SceneDescription& scene, const SolveOptions& o) {
  const SceneCellCounts cells = count_scene_cells(scene);
  const double pairs = cells.pairs_per_field_evaluation();
  if (!(pairs > o.max_cell_pairs)) return;
  char text[512];
  std::snprintf(text, sizeof text,
                "one evaluation of the responsive field sums %.3g cell pairs (%.0f responsive cells, %.0f "
                "magnetized), more than the limit %.3g: about %.2g s per evaluation on the 2-core reference "
                "machine, and a relaxation takes tens of evaluations (up to solver.max_iterations = %d); "
                "use a larger cell_size, or raise the limit with --max-cell-pairs N",
                pairs, cells.responsive, cells.magnetized, o.max_cell_pairs, pairs * kSecondsPerCellPair,
                scene.solver.relax.max_iterations);
  throw SceneError(scene.file, "", text);
}

// The backend the options or the scene ask for. A fallback notice goes to
// stderr as one line.
std::unique_ptr<MagneticBackend> scene_backend(const SceneDescription& scene, const SolveOptions& o) {
  std::string notice;
  std::unique_ptr<MagneticBackend> backend;
  try {
    backend = make_backend(o.backend ? backend_kind(*o.backend) : scene.solver.backend,
                           o.threads.value_or(scene.solver.threads), &notice, cpu_only_feature(scene));
  } catch (const std::invalid_argument& e) {
    if (o.backend) throw UsageError(std::string("--backend: ") + e.what());
    throw SceneError(scene.file, "solver.backend", e.what());
  }
  if (!notice.empty()) std::fprintf(stderr, "%s\n", one_line(notice).c_str());
  return backend;
}

std::string one_line(const std::string& text) {
  std::string s = text;
  for (char& c : s)
    if (static_cast<unsigned char>(c) < 0x20 || c == 0x7f) c = ' ';
  return s;
}

void write_stdout(const std::string& text) {
  if (std::fwrite(text.data(), 1, text.size(), stdout) != text.size() || std::fflush(stdout) != 0)
    throw std::runtime_error("cannot write to standard output");
}

int run_solve(const std::vector<std::string>& args) {
  const SolveCommandLine c = parse_solve_command(args);
  const SolveOptions& options = c.solve;
  const SceneDescription scene = load_scene(c.scene);
  for (const std::string& n : scene.notices) std::fprintf(stderr, "odemag solve: %s\n", n.c_str());
  check_cell_pairs(scene, options);
  const std::unique_ptr<MagneticBackend> backend = scene_backend(scene, options);
  for (const std::string& notice : scene_notices(scene)) std::fprintf(stderr, "odemag solve: %s\n", notice.c_str());
  const RelaxOptions& relax_options = scene.solver.relax;
  const SceneSolution solution =
      solve_scene(scene, *backend, SolveProgress(relax_options.tolerance, relax_options.max_iterations));
  const RelaxReport& report = solution.report;

  // One line per body, in scene order; bodies not present report zeros.
  bool finite = !std::isnan(report.residual);
  std::string out = "{\n  \"bodies\": [";
  for (size_t b = 0; b < scene.bodies.size(); ++b) {
    const SolvedBody& body = solution.bodies[b];
    finite = finite && is_finite(body.moment) && is_finite(body.force) && is_finite(body.torque);
    out += b == 0 ? "\n    " : ",\n    ";
    out += "{\"name\": " + nlohmann::json(scene.bodies[b].name).dump() +
           ", \"present\": " + (body.present ? "true" : "false") +
           ", \"cells\": " + std::to_string(body.cells) + ", \"moment\": " + vector(body.moment) +
           ", \"force\": " + vector(body.force) + ", \"torque\": " + vector(body.torque) + "}";
  }
  require_finite(scene, finite);
  out += "\n  ],\n";
  out += "  \"iterations\": " + std::to_string(report.iterations) + ",\n";
  out += "  \"residual\": " + number(report.residual) + ",\n";
  out += "  \"converged\": " + std::string(report.converged ? "true" : "false") + ",\n";
  out += "  \"field_evaluations\": " + std::to_string(report.field_evaluations) + ",\n";
  out += "  \"backend\": " + nlohmann::json(backend->name()).dump() + "\n}\n";
  warn_if_not_converged(scene, report);
  write_stdout(out);
  return 0;
}

int run_field(const std::vector<std::string>& args) {
  const FieldCommandLine c = parse_field_command(args);
  const SolveOptions& options = c.solve;

  const SceneDescription scene = load_scene(c.scene);
  for (const std::string& n : scene.notices) std::fprintf(stderr, "odemag field: %s\n", n.c_str());
  check_cell_pairs(scene, options);
  const std::vector<Vec3> points = read_points(c.points);
  const std::unique_ptr<MagneticBackend> backend = scene_backend(scene, options);
  for (const std::string& notice : scene_notices(scene)) std::fprintf(stderr, "odemag field: %s\n", notice.c_str());
  const RelaxOptions& relax_options = scene.solver.relax;
  const SceneField field =
      scene_field(scene, *backend, points, SolveProgress(relax_options.tolerance, relax_options.max_iterations));

  // Every number with round-trip precision: reading the CSV back gives the doubles computed.
  bool finite = true;
  std::string out = "x,y,z,Bx,By,Bz,Hx,Hy,Hz\n";
  for (size_t p = 0; p < points.size(); ++p) {
    const Vec3 &x = points[p], &b = field.B[p], &h = field.H[p];
    finite = finite && is_finite(b) && is_finite(h);
    const double row[9] = {x.x, x.y, x.z, b.x, b.y, b.z, h.x, h.y, h.z};
    for (int k = 0; k < 9; ++k) {
      out += round_trip(row[k]);
      out += k < 8 ? ',' : '\n';
    }
  }
  require_finite(scene, finite);
  warn_if_not_converged(scene, field.report);
  write_stdout(out);
  return 0;
}

}  // namespace odemag::cli
