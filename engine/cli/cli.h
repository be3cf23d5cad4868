// The odemag command-line program (INTERFACE.md "Commands"): argument parsing,
// the points reader and the subcommands. main.cpp dispatches; every command
// returns its exit status or throws (UsageError, SceneError: exit 2; any
// other exception: exit 1).
#pragma once

#include <map>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "magnetics/vec3.h"

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

// Options shared by the commands that solve a scene.
struct SolveOptions {
  std::optional<std::string> backend;  // --backend: overrides solver.backend
  std::optional<int> threads;          // --threads: overrides solver.threads
};
SolveOptions solve_options(const Arguments& args);

// Points for `odemag field`: one "x,y,z" per line; blank lines, '#' comments
// and a first line "x,y,z" are skipped. Throws SceneError(file, "line N", ...).
std::vector<Vec3> parse_points(const std::string& text, const std::string& file);
// Reads the points file ("-": standard input); `file` in messages.
std::vector<Vec3> read_points(const std::string& path);

// The commands: each writes its whole output at once and returns the exit status.
int run_solve(const std::vector<std::string>& args);
int run_field(const std::vector<std::string>& args);

// The text with control characters (newlines included) replaced by spaces:
// messages on stderr are one line each.
std::string one_line(const std::string& text);

// Writes text to stdout in one piece; throws std::runtime_error when it fails.
void write_stdout(const std::string& text);

// Usage text for --help.
const char* usage_text();

}  // namespace odemag::cli
