// Command-line arguments of the odemag subcommands.
#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>

#include "cli/cli.h"

namespace odemag::cli {

std::optional<std::string> Arguments::option(const std::string& name) const {
  const auto it = options.find(name);
  if (it == options.end()) return std::nullopt;
  return it->second;
}

Arguments parse_arguments(const std::string& command, const std::vector<std::string>& args,
                          const std::vector<std::string>& known) {
  Arguments out;
  bool options_done = false;
  for (size_t i = 0; i < args.size(); ++i) {
    const std::string& a = args[i];
    if (options_done || a == "-" || a.rfind("-", 0) != 0) {
      out.positional.push_back(a);
      continue;
    }
    if (a == "--") {
      options_done = true;
      continue;
    }
    if (a.rfind("--", 0) != 0)
      throw UsageError("unknown option " + a + " for '" + command + "' (see odemag --help)");
    std::string name = a.substr(2), value;
    bool has_value = false;
    if (const size_t eq = name.find('='); eq != std::string::npos) {
      value = name.substr(eq + 1);
      name.resize(eq);
      has_value = true;
    }
    if (std::find(known.begin(), known.end(), name) == known.end())
      throw UsageError("unknown option --" + name + " for '" + command + "' (see odemag --help)");
    if (!has_value) {
      if (i + 1 >= args.size()) throw UsageError("option --" + name + " needs a value");
      value = args[++i];
    }
    if (!out.options.emplace(name, value).second)
      throw UsageError("option --" + name + " is given twice");
  }
  return out;
}

int program_main(const std::string& program, const char* usage, const std::vector<std::string>& args,
                 const std::vector<std::string>& known, const std::function<int(const Arguments&)>& body) {
  for (const std::string& a : args) {
    if (a == "--") break;
    if (a == "--help" || a == "-h") {
      write_stdout(usage);
      return 0;
    }
  }
  try {
    return body(parse_arguments(program, args, known));
  } catch (const UsageError& e) {
    std::string message = e.what();  // the parser points at odemag's help
    if (const size_t at = message.find("odemag --help"); at != std::string::npos)
      message.replace(at, 13, program + " --help");
    std::fprintf(stderr, "%s: %s\n", program.c_str(), one_line(message).c_str());
    return 2;
  }
}

namespace {

// --NAME as a finite number >= 0 (> 0 unless allow_zero); nullopt when absent.
std::optional<double> number_option(const Arguments& a, const std::string& name, bool allow_zero) {
  const auto v = a.option(name);
  if (!v) return std::nullopt;
  char* end = nullptr;
  const double x = std::strtod(v->c_str(), &end);
  if (end == v->c_str() || *end != '\0' || !std::isfinite(x) || x < 0.0 || (!allow_zero && x == 0.0))
    throw UsageError("--" + name + ": expected a " + (allow_zero ? "non-negative" : "positive") +
                     " number, got '" + *v + "'");
  return x;
}

std::optional<int> int_option(const Arguments& a, const std::string& name, int lo, int hi) {
  const std::optional<double> x = number_option(a, name, true);
  if (!x) return std::nullopt;
  if (*x != std::floor(*x) || *x < lo || *x > hi)
    throw UsageError("--" + name + ": expected an integer from " + std::to_string(lo) + " to " +
                     std::to_string(hi));
  return static_cast<int>(*x);
}

bool yes_no_option(const Arguments& a, const std::string& name, bool fallback) {
  const auto v = a.option(name);
  if (!v) return fallback;
  if (*v == "yes" || *v == "true" || *v == "1") return true;
  if (*v == "no" || *v == "false" || *v == "0") return false;
  throw UsageError("--" + name + ": expected yes or no, got '" + *v + "'");
}

}  // namespace

SolveOptions solve_options(const Arguments& args) {
  SolveOptions o;
  o.max_cell_pairs = number_option(args, "max-cell-pairs", false).value_or(kDefaultMaxCellPairs);
  if (auto b = args.option("backend")) {
    if (*b != "cpu" && *b != "cuda" && *b != "auto")
      throw UsageError("--backend must be cpu, cuda or auto, not '" + *b + "'");
    o.backend = *b;
  }
  if (auto t = args.option("threads")) {
    errno = 0;
    char* end = nullptr;
    const long n = std::strtol(t->c_str(), &end, 10);
    if (t->empty() || *end != '\0' || errno != 0 || n < 0 || n > 65536)
      throw UsageError("--threads must be an integer from 0 (all cores) to 65536, not '" + *t + "'");
    o.threads = static_cast<int>(n);
  }
  return o;
}

SolveCommandLine parse_solve_command(const std::vector<std::string>& args) {
  const Arguments a = parse_arguments("solve", args, {"backend", "threads", "max-cell-pairs"});
  SolveCommandLine c;
  c.solve = solve_options(a);
  c.scene = scene_argument("solve", a);
  return c;
}

FieldCommandLine parse_field_command(const std::vector<std::string>& args) {
  const Arguments a = parse_arguments("field", args, {"points", "backend", "threads", "max-cell-pairs"});
  FieldCommandLine c;
  c.solve = solve_options(a);
  c.scene = scene_argument("field", a);
  const std::optional<std::string> points = a.option("points");
  if (!points) throw UsageError("'field' needs --points FILE (see odemag --help)");
  c.points = *points;
  return c;
}

RunCommandLine parse_run_command(const std::vector<std::string>& args) {
  const Arguments a = parse_arguments(
      "run", args,
      {"out", "duration", "frame-rate", "time-step", "frames", "width", "height", "backend", "threads", "quiet",
       "max-cell-pairs", "max-steps", "state-every-step", "video"});
  RunCommandLine c;
  c.scene = scene_argument("run", a);
  const auto out = a.option("out");
  if (!out || out->empty()) throw UsageError("'run' needs --out DIR (see odemag --help)");
  c.out = *out;
  c.solve = solve_options(a);
  c.duration = number_option(a, "duration", true);
  c.frame_rate = number_option(a, "frame-rate", false);
  c.time_step = number_option(a, "time-step", false);
  c.width = int_option(a, "width", 16, 8192);
  c.height = int_option(a, "height", 16, 8192);
  c.max_steps = number_option(a, "max-steps", false).value_or(kDefaultMaxSteps);
  c.frames = yes_no_option(a, "frames", true);
  c.quiet = yes_no_option(a, "quiet", false);
  c.state_every_step = yes_no_option(a, "state-every-step", false);
  if (const auto video = a.option("video")) {  // encoded in run.cpp (encode_video)
    const std::string ext = std::filesystem::path(*video).extension().string();
    if (ext != ".mp4" && ext != ".gif")
      throw UsageError("--video " + *video + ": the file name must end in .mp4 or .gif");
    if (!c.frames) throw UsageError("--video is made from the frames: it cannot go with --frames no");
    c.video = *video;
  }
  return c;
}

const char* usage_text() {
  return "usage: odemag COMMAND [ARGS]\n"
         "\n"
         "commands:\n"
         "  solve SCENE [--backend cpu|cuda|auto] [--threads N] [--max-cell-pairs N]\n"
         "      Relax the magnetization with every body held in place and print JSON:\n"
         "      per body its cell count, moment (A m^2), force (N) and torque (N m),\n"
         "      all in the world frame, then the iteration count and the residual.\n"
         "  field SCENE --points FILE [--backend cpu|cuda|auto] [--threads N] [--max-cell-pairs N]\n"
         "      Relax as 'solve' does, then print CSV x,y,z,Bx,By,Bz,Hx,Hy,Hz (T, A/m)\n"
         "      at the points of FILE (lines 'x,y,z' in m; '-' reads standard input),\n"
         "      every number the shortest text that reads back as the same double.\n"
         "  run SCENE --out DIR [--duration T] [--time-step DT] [--frame-rate F]\n"
         "                     [--frames yes|no] [--width W] [--height H] [--quiet yes|no]\n"
         "                     [--backend cpu|cuda|auto] [--threads N]\n"
         "                     [--max-cell-pairs N] [--max-steps N] [--video FILE]\n"
         "                     [--state-every-step yes|no]\n"
         "      Simulate with ODE for T s (default: the scene's simulation.duration) and\n"
         "      write to DIR: frame_NNNNN.png (when built with the renderer), state.jsonl\n"
         "      (one JSON line per frame, or per rigid step with --state-every-step yes:\n"
         "      the step, the frame, the time, per body pose, velocities, moment, force,\n"
         "      torque) and summary.json (per-step T_m and T_r, iterations, outcomes).\n"
         "      Files appear under their final names only when complete; a previous\n"
         "      run's frames, state.jsonl and summary.json in DIR are replaced (summary.json\n"
         "      exists only after a run that finished).\n"
         "      --video FILE.mp4 or FILE.gif (relative to the current directory, not to\n"
         "      DIR) also encodes the frames at the frame rate with the ffmpeg program\n"
         "      (apt-get install ffmpeg): H.264 MP4 or a paletted GIF; the PNG frames stay.\n"
         "  sweep SPEC --out DIR [--jobs N] [--quiet yes|no]\n"
         "  sweep SPEC --out DIR --dask local[:N]|ADDRESS\n"
         "  sweep SPEC --out DIR --slurm | --expand | --variant I | --gather\n"
         "      Run the variants of a sweep spec (JSON: a base scene, overrides by key\n"
         "      path such as materials.steel.susceptibility or bodies[3].position[2], as\n"
         "      a grid or a list, the figures to collect; docs/sweeps.md), each as 'run'\n"
         "      into DIR/variants/NNNN (--frames no unless the spec's run says), N at a\n"
         "      time (default: one per core), and write the table DIR/results.csv.\n"
         "      Finished variants are reused. --dask runs them on a Dask LocalCluster\n"
         "      of N workers (default 2) or the scheduler at ADDRESS (python3 -m\n"
         "      odemag.sweeps); --slurm writes DIR/sweep.sbatch (a job array) and\n"
         "      DIR/gather.sbatch and prints the sbatch line. --expand writes the variant\n"
         "      scenes and DIR/variants.json, --variant I runs one, --gather writes the table.\n"
         "  help, --help\n"
         "      Print this text.\n"
         "\n"
         "--backend overrides the scene's solver.backend, --threads its solver.threads\n"
         "(0: all cores). Scene files are JSON in SI units (docs/scene-format.md).\n"
         "\n"
         "work limits: a scene whose field evaluation sums more than 1e8 cell pairs\n"
         "(about 10,000 soft cells; raise with --max-cell-pairs N), or a run of more\n"
         "than 1e7 rigid steps (duration / time step; raise with --max-steps N), is\n"
         "refused with exit status 2 and an estimate of its cost. Long solves and runs\n"
         "report their progress and an estimate of the time left on stderr.\n"
         "\n"
         "exit status: 0 done; 2 bad input or usage (one message on stderr naming the\n"
         "file and the offending key); 1 any other failure.\n";
}

}  // namespace odemag::cli
