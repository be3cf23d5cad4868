// The points file of `odemag field`.
#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <sstream>

#include "cli/cli.h"
#include "odemag/constants.h"
#include "odemag/scene.h"

namespace odemag::cli {

namespace {

std::string trim(const std::string& s) {
  size_t b = 0, e = s.size();
  while (b < e && std::isspace(static_cast<unsigned char>(s[b]))) ++b;
  while (e > b && std::isspace(static_cast<unsigned char>(s[e - 1]))) --e;
  return s.substr(b, e - b);
}

// The comma-separated fields of a line, trimmed.
std::vector<std::string> split_fields(const std::string& line) {
  std::vector<std::string> fields;
  size_t start = 0;
  for (;;) {
    const size_t comma = line.find(',', start);
    fields.push_back(trim(line.substr(start, comma - start)));
    if (comma == std::string::npos) return fields;
    start = comma + 1;
  }
}

bool parse_double(const std::string& text, double& x) {
  if (text.empty()) return false;
  char* end = nullptr;
  x = std::strtod(text.c_str(), &end);
  // Underflow (1e-320: a subnormal, 1e-400: zero) rounds correctly; overflow is infinite.
  return *end == '\0' && std::isfinite(x);
}

bool is_header(const std::vector<std::string>& fields) {
  static const char* names[] = {"x", "y", "z"};
  if (fields.size() != 3) return false;
  for (size_t i = 0; i < 3; ++i)
    if (fields[i].size() != 1 || std::tolower(static_cast<unsigned char>(fields[i][0])) != names[i][0])
      return false;
  return true;
}

// Printable excerpt of a bad line for the message.
std::string excerpt(const std::string& line) {
  std::string s;
  for (char c : line.substr(0, 60)) s += std::isprint(static_cast<unsigned char>(c)) ? c : '?';
  return line.size() > 60 ? s + "..." : s;
}

// The whole stream, up to a bound: `--points /dev/zero` must not take all the
// memory. Throws SceneError(file, "", ...).
std::string read_bounded(std::istream& in, const std::string& file) {
  constexpr size_t kMaxPointsBytes = size_t{256} << 20;
  std::string text;
  char buffer[65536];
  while (in.read(buffer, sizeof buffer) || in.gcount() > 0) {
    text.append(buffer, static_cast<size_t>(in.gcount()));
    if (text.size() > kMaxPointsBytes) throw SceneError(file, "", "the points file is larger than 256 MiB");
  }
  if (in.bad()) throw SceneError(file, "", "cannot read the file");
  return text;
}

}  // namespace

std::vector<Vec3> parse_points(const std::string& text, const std::string& file) {
  std::vector<Vec3> points;
  std::istringstream in(text);
  std::string raw;
  bool first = true;
  for (int line_number = 1; std::getline(in, raw); ++line_number) {
    std::string line = raw;
    if (const size_t hash = line.find('#'); hash != std::string::npos) line.resize(hash);
    line = trim(line);
    if (line.empty()) continue;
    const std::vector<std::string> fields = split_fields(line);
    const bool header = first && is_header(fields);
    first = false;
    if (header) continue;
    Vec3 p;
    bool ok = fields.size() == 3;
    for (int a = 0; ok && a < 3; ++a) ok = parse_double(fields[static_cast<size_t>(a)], p[a]);
    if (!ok)
      throw SceneError(file, "line " + std::to_string(line_number),
                       "expected three finite numbers x,y,z, got '" + excerpt(trim(raw)) + "'");
    if (norm(p) > ranges::kLength.max) {
      std::ostringstream bound;
      bound << ranges::kLength.max;
      throw SceneError(file, "line " + std::to_string(line_number),
                       "the point '" + excerpt(trim(raw)) + "' is farther than the largest accepted length, " +
                           bound.str() + " m, from the origin (docs/scene-format.md \"Ranges\")");
    }
    points.push_back(p);
  }
  return points;
}

std::vector<Vec3> read_points(const std::string& path) {
  if (path == "-") return parse_points(read_bounded(std::cin, "<stdin>"), "<stdin>");
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec)) throw SceneError(path, "", "cannot open: is a directory");
  std::ifstream in(path, std::ios::binary);
  if (!in) throw SceneError(path, "", std::string("cannot open: ") + std::strerror(errno));
  return parse_points(read_bounded(in, path), path);
}

}  // namespace odemag::cli
