// Running a program of this project from a test (tests/cli, tests/demos): a
// shell command with its stdout and stderr caught in files, and the small
// text helpers such tests share.
#pragma once

#include <sys/wait.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

namespace odemag::test_support {

// s as one word for sh.
inline std::string shell_quote(const std::string& s) {
  std::string q = "'";
  for (char c : s) q += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return q + "'";
}

inline std::string read_file(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

inline std::vector<std::string> lines(const std::string& text) {
  std::vector<std::string> out;
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);) out.push_back(line);
  return out;
}

struct ProgramRun {
  int status = -1;  // exit status; -1: killed by a signal
  std::string out, err;
};

// Runs the sh command (its words already quoted) with stdin from
// `input_file` (empty: /dev/null), stdout and stderr caught in scratch/.
inline ProgramRun run_program(const std::string& command, const std::filesystem::path& scratch,
                              const std::filesystem::path& input_file = {}) {
  const std::filesystem::path out = scratch / "stdout.txt", err = scratch / "stderr.txt";
  const std::string full = command + " <" + (input_file.empty() ? "/dev/null" : shell_quote(input_file.string())) +
                           " >" + shell_quote(out.string()) + " 2>" + shell_quote(err.string());
  const int raw = std::system(full.c_str());
  ProgramRun r;
  r.status = WIFEXITED(raw) ? WEXITSTATUS(raw) : -1;
  r.out = read_file(out);
  r.err = read_file(err);
  return r;
}

}  // namespace odemag::test_support
