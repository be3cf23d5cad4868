// libFuzzer target: the odemag command line. The input split at NUL bytes is
// argv after the program name (the command word, then its arguments). Every
// command line must be accepted or rejected with a UsageError, as main.cpp
// does before it opens any file; anything else is a bug (docs/testing.md).
// Nothing here reads or writes a file: the checks run, the commands do not.
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "cli/cli.h"

namespace {

// main.cpp's dispatch, with the commands replaced by their argument checks.
void check_command_line(const std::vector<std::string>& words) {
  using namespace odemag::cli;
  if (words.empty()) return;  // main: "missing command"
  const std::string& command = words[0];
  const std::vector<std::string> args(words.begin() + 1, words.end());
  if (command == "help" || command == "--help" || command == "-h") return;
  if (command == "solve") {
    (void)parse_solve_command(args);
    return;
  }
  if (command == "field") {
    (void)parse_field_command(args);
    return;
  }
  if (command == "run") {
    const RunCommandLine c = parse_run_command(args);
    // What the checks promise (cli.h): values in range, an output directory.
    if (c.out.empty()) __builtin_trap();
    if (c.duration && !(*c.duration >= 0.0)) __builtin_trap();
    if (c.time_step && !(*c.time_step > 0.0)) __builtin_trap();
    if (c.frame_rate && !(*c.frame_rate > 0.0)) __builtin_trap();
    if (c.width && (*c.width < 16 || *c.width > 8192)) __builtin_trap();
    if (c.height && (*c.height < 16 || *c.height > 8192)) __builtin_trap();
    if (c.solve.threads && (*c.solve.threads < 0 || *c.solve.threads > 65536)) __builtin_trap();
    return;
  }
  if (command == "sweep") {
    const SweepCommandLine c = parse_sweep_command(args);
    if (c.out.empty() || c.jobs < 1 || c.jobs > 1024) __builtin_trap();
    return;
  }
  throw UsageError("unknown command '" + command + "'");
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  std::vector<std::string> words;
  const char* p = reinterpret_cast<const char*>(data);
  const char* end = p + size;
  if (size > 0) {
    for (;;) {
      const char* nul = p;
      while (nul < end && *nul != '\0') ++nul;
      words.emplace_back(p, nul);
      if (nul == end) break;
      p = nul + 1;
    }
  }
  try {
    check_command_line(words);
  } catch (const odemag::cli::UsageError& e) {
    // main prints it on one line and exits 2.
    (void)odemag::cli::one_line(e.what());
  }
  return 0;
}
