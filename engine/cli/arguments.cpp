// Command-line arguments of the odemag subcommands.
#include <algorithm>
#include <cerrno>
#include <cstdlib>

#include "engine/cli/cli.h"

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

SolveOptions solve_options(const Arguments& args) {
  SolveOptions o;
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

const char* usage_text() {
  return "usage: odemag COMMAND [ARGS]\n"
         "\n"
         "commands:\n"
         "  solve SCENE [--backend cpu|cuda|auto] [--threads N]\n"
         "      Relax the magnetization with every body held in place and print JSON:\n"
         "      per body its cell count, moment (A m^2), force (N) and torque (N m),\n"
         "      all in the world frame, then the iteration count and the residual.\n"
         "  field SCENE --points FILE [--backend cpu|cuda|auto] [--threads N]\n"
         "      Relax as 'solve' does, then print CSV x,y,z,Bx,By,Bz,Hx,Hy,Hz (T, A/m)\n"
         "      at the points of FILE (lines 'x,y,z' in m; '-' reads standard input).\n"
         "  run SCENE --out DIR [--duration T] [--time-step DT] [--frame-rate F]\n"
         "                     [--frames yes|no] [--width W] [--height H] [--quiet yes|no]\n"
         "                     [--backend cpu|cuda|auto] [--threads N]\n"
         "      Simulate with ODE for T s (default: the scene's simulation.duration) and\n"
         "      write to DIR: frame_NNNNN.png (when built with the renderer), state.jsonl\n"
         "      (one JSON line per frame: per body pose, velocities, moment, force,\n"
         "      torque) and summary.json (per-step T_m and T_r, iterations, outcomes).\n"
         "      Files appear under their final names only when complete.\n"
         "  help, --help\n"
         "      Print this text.\n"
         "\n"
         "--backend overrides the scene's solver.backend, --threads its solver.threads\n"
         "(0: all cores). Scene files are JSON in SI units (docs/scene-format.md).\n"
         "\n"
         "exit status: 0 done; 2 bad input or usage (one message on stderr naming the\n"
         "file and the offending key); 1 any other failure.\n";
}

}  // namespace odemag::cli
