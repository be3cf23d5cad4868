// The odemag command-line program (README.md "Using it"): argument parsing,
// the points reader and the subcommands. main.cpp dispatches; every command
// returns its exit status or throws (UsageError, SceneError: exit 2; any
// other exception: exit 1).
#pragma once

#include <sys/types.h>

#include <cstdio>
#include <functional>
#include <map>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include <memory>

#include "engine/simulation/frame_writer.h"
#include "odemag/scene.h"
#include "magnetics/model/backend.h"
#include "odemag/vec3.h"

namespace odemag {
class Simulation;
}

namespace odemag::cli {

// Bad command line: exit 2 with "odemag: MESSAGE".
class UsageError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// A command's arguments: positionals in order, and `--name value` options.
struct Arguments {
  std::vector<std::string> positional;
  std::map<std::string, std::string> options;  // name without the dashes -> value

  std::optional<std::string> option(const std::string& name) const;
};

// Splits args (after the command word) into positionals and options. Every
// option takes a value, given as `--name value` or `--name=value`; "--" ends
// the options; "-" is a positional. Throws UsageError for an option not in
// `known`, a missing value or an option given twice.
Arguments parse_arguments(const std::string& command, const std::vector<std::string>& args,
                          const std::vector<std::string>& known);

// The work a command takes on without being told (usage_text, README "Using
// it"): a scene beyond a limit is refused with exit 2 and the estimate; the
// flags raise the limits.
constexpr double kDefaultMaxCellPairs = 1e8;  // --max-cell-pairs: per field evaluation
constexpr double kDefaultMaxSteps = 1e7;      // --max-steps: rigid steps of a run
// Time per cell pair of one field evaluation on the reference machine, for
// the estimates in messages (docs/benchmarks.md "5. Work limits": 4 to 6 ns).
constexpr double kSecondsPerCellPair = 5e-9;

// The command line of a program built on this parser (the demo programs,
// demos): `--help` or `-h` before any "--" prints usage to stdout
// and returns 0; otherwise args are parsed with `known` and given to body,
// whose status is returned. A UsageError from the parser or from body (which
// checks its own options before writing anything) prints one line
// "PROGRAM: MESSAGE" on stderr and returns 2.
int program_main(const std::string& program, const char* usage, const std::vector<std::string>& args,
                 const std::vector<std::string>& known, const std::function<int(const Arguments&)>& body);

// Options shared by the commands that solve a scene.
struct SolveOptions {
  std::optional<std::string> backend;  // --backend: overrides solver.backend
  std::optional<int> threads;          // --threads: overrides solver.threads
  double max_cell_pairs = kDefaultMaxCellPairs;  // --max-cell-pairs
};
// Throws SceneError (exit 2, with the estimate) when one evaluation of the
// scene's responsive field would sum more cell pairs than o.max_cell_pairs.
void check_cell_pairs(const SceneDescription& scene, const SolveOptions& o);
SolveOptions solve_options(const Arguments& args);

// The whole command line of each command (args after the command word),
// checked without reading or writing any file: the run_* functions start
// with these, and tests/fuzz/fuzz_cli.cpp fuzzes them. Throw UsageError.
struct SolveCommandLine {
  std::string scene;
  SolveOptions solve;
};
struct FieldCommandLine {
  std::string scene, points;
  SolveOptions solve;
};
struct RunCommandLine {
  std::string scene, out;
  SolveOptions solve;
  std::optional<double> duration, frame_rate, time_step;  // override the scene's simulation.*
  std::optional<int> width, height;                       // override the scene's camera.*
  double max_steps = kDefaultMaxSteps;                    // --max-steps
  bool frames = true, quiet = false;
  bool state_every_step = false;  // --state-every-step: a state line after every rigid step, not only per frame
  // --video FILE.mp4|FILE.gif (relative to the current directory): the frames
  // encoded by the ffmpeg program after the run; needs the frames.
  std::optional<std::string> video;
};
struct SweepCommandLine {
  enum class Mode { local, expand, variant, gather, dask, slurm };
  std::string spec, out;
  Mode mode = Mode::local;
  size_t variant = 0;  // --variant I
  int jobs = 1;        // --jobs N (default: one per core)
  std::string dask;    // --dask local[:N] | ADDRESS
  bool quiet = false;
};
SweepCommandLine parse_sweep_command(std::vector<std::string> args);
SolveCommandLine parse_solve_command(const std::vector<std::string>& args);
FieldCommandLine parse_field_command(const std::vector<std::string>& args);
RunCommandLine parse_run_command(const std::vector<std::string>& args);

// Points for `odemag field`: one "x,y,z" per line; blank lines, '#' comments
// and a first line "x,y,z" are skipped. Throws SceneError(file, "line N", ...).
std::vector<Vec3> parse_points(const std::string& text, const std::string& file);
// Reads the points file ("-": standard input); `file` in messages.
std::vector<Vec3> read_points(const std::string& path);

// The scene file of a command: its one positional argument.
std::string scene_argument(const std::string& command, const Arguments& args);
// The backend the options or the scene ask for; a fallback notice goes to
// stderr as one line. An unavailable backend is a usage or scene error.
std::unique_ptr<MagneticBackend> scene_backend(const SceneDescription& scene, const SolveOptions& o);

// The commands. solve and field write their whole output at once; run writes
// its files atomically (docs/hard-cases.md "Output safety"). Each returns the exit status.
int run_solve(const std::vector<std::string>& args);
int run_field(const std::vector<std::string>& args);

// Frames of a running simulation (engine/simulation/frame_writer.h; the OSMesa renderer
// in render provides one; without it `run` writes no frames).
using FrameWriterFactory =
    std::function<std::unique_ptr<FrameWriter>(const SceneDescription& scene)>;
int run_simulation(const std::vector<std::string>& args, const FrameWriterFactory& frames);

// `odemag sweep SPEC --out DIR ...` (docs/sweeps.md): runs the variants of a
// sweep spec (engine/scene/sweep.h) and writes DIR/results.csv; also the
// steps the Dask and Slurm runners call (--expand, --variant I, --gather).
int run_sweep(const std::vector<std::string>& args, const FrameWriterFactory& frames);

// The numbers of a run's summary.json that a sweep can collect, as key paths
// ("steps", "magnetic_ms.mean"); run.cpp writes them.
const std::vector<std::string>& summary_figures();

// Starts the program (argv `args`, without a shell; stdout to /dev/null when
// quiet_stdout) and returns its pid; wait_program returns its exit status (a
// signal: 128 + the signal number). Throw std::runtime_error.
pid_t start_program(const std::string& program, std::vector<std::string> args, bool quiet_stdout = false);
int wait_program(pid_t pid);

// The text with control characters (newlines included) replaced by spaces:
// messages on stderr are one line each.
std::string one_line(const std::string& text);

// Writes text to stdout in one piece; throws std::runtime_error when it fails.
void write_stdout(const std::string& text);

// Writes a whole file atomically: to PATH.tmp-PID, fsync, rename over PATH.
// Throws std::runtime_error (naming the file) on failure, leaving PATH as it was.
void write_file_atomically(const std::string& path, const std::string& content);

// A file written piece by piece (per-frame state): it is PATH.partial until
// finish() renames it to PATH, so an interrupted run never leaves a
// truncated file under the final name.
class StreamedFile {
 public:
  explicit StreamedFile(std::string path);
  ~StreamedFile();
  StreamedFile(const StreamedFile&) = delete;
  StreamedFile& operator=(const StreamedFile&) = delete;
  void append(const std::string& text);
  void finish();

 private:
  std::string path_, partial_;
  std::FILE* file_ = nullptr;
};

// Usage text for --help.
const char* usage_text();

}  // namespace odemag::cli
