// odemag: the command-line program (README.md "Using it").
//
// Exit status: 0 done; 2 bad input or usage, with one line on stderr naming
// the file and the offending key; 1 anything else. Commands build their whole
// output in memory and write it at the end, so a failure leaves no partial output.
#include <cstdio>
#include <exception>
#include <new>
#include <string>
#include <vector>

#include "cli/cli.h"
#include "magnetics/relax/threads.h"
#ifdef ODEMAG_WITH_RENDERER
#include "render/scene_view.h"
#endif
#include "odemag/scene.h"

namespace {

using odemag::cli::one_line;

int usage_error(const std::string& message) {
  std::fprintf(stderr, "odemag: %s\n", one_line(message).c_str());
  return 2;
}

int dispatch(const std::string& command, const std::vector<std::string>& args) {
  if (command == "help" || command == "--help" || command == "-h") {
    odemag::cli::write_stdout(odemag::cli::usage_text());
    return 0;
  }
  if (command == "solve") return odemag::cli::run_solve(args);
  if (command == "field") return odemag::cli::run_field(args);
  // PNG frames where the program is built with the renderer.
#ifdef ODEMAG_WITH_RENDERER
  const odemag::cli::FrameWriterFactory frames = odemag::make_png_frame_writer;
#else
  const odemag::cli::FrameWriterFactory frames;
#endif
  if (command == "run") return odemag::cli::run_simulation(args, frames);
  if (command == "sweep") return odemag::cli::run_sweep(args, frames);
  throw odemag::cli::UsageError("unknown command '" + command + "' (commands: solve, field, run, sweep, help)");
}

}  // namespace

int main(int argc, char** argv) {
  odemag::restart_with_passive_omp_wait(argv);  // docs/benchmarks.md "Threads and waiting"
  if (argc < 2) return usage_error("missing command; usage: odemag solve|field|run|sweep|help ... (see odemag --help)");
  const std::string command = argv[1];
  const std::vector<std::string> args(argv + 2, argv + argc);
  try {
    return dispatch(command, args);
  } catch (const odemag::cli::UsageError& e) {
    return usage_error(e.what());
  } catch (const odemag::SceneError& e) {
    return usage_error(e.what());
  } catch (const std::bad_alloc&) {
    std::fprintf(stderr, "odemag: out of memory\n");
    return 1;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "odemag: %s\n", one_line(e.what()).c_str());
    return 1;
  } catch (...) {
    std::fprintf(stderr, "odemag: unexpected failure\n");
    return 1;
  }
}
