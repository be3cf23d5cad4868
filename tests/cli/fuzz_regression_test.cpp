// The fuzzers' committed corpora in the ordinary build (docs/testing.md).
// tests/fuzz/corpus/scene (seeds, edge cases and the inputs that once crashed
// the loader): each must load or be rejected with a SceneError that names the
// file; no other exception. tests/fuzz/corpus/cli (argv split at NUL bytes):
// each command line is accepted or rejected with a UsageError.
#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <exception>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "cli/cli.h"
#include "odemag/scene.h"

namespace odemag {
namespace {

namespace fs = std::filesystem;

std::vector<fs::path> corpus_files(const char* which = "scene") {
  std::vector<fs::path> files;
  for (const auto& entry : fs::directory_iterator(fs::path(ODEMAG_SOURCE_DIR) / "tests/fuzz/corpus" / which))
    if (entry.is_regular_file()) files.push_back(entry.path());
  std::sort(files.begin(), files.end());
  return files;
}

std::string contents(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

TEST(FuzzRegression, CorpusIsThere) {
  EXPECT_GE(corpus_files("scene").size(), 20u);
  EXPECT_GE(corpus_files("cli").size(), 10u);
}

TEST(FuzzRegression, EverySceneInputLoadsOrThrowsSceneError) {
  int accepted = 0, rejected = 0;
  for (const fs::path& path : corpus_files()) {
    SCOPED_TRACE(path.filename().string());
    const std::string file = path.string();
    try {
      const SceneDescription scene = parse_scene(contents(path), file);
      EXPECT_FALSE(scene.bodies.empty());
      ++accepted;
    } catch (const SceneError& e) {
      EXPECT_EQ(e.file(), file);
      EXPECT_FALSE(e.message().empty());
      EXPECT_EQ(std::string(e.what()).rfind(file + ": ", 0), 0u) << e.what();
      ++rejected;
    } catch (const std::exception& e) {
      ADD_FAILURE() << "not a SceneError: " << e.what();
    } catch (...) {
      ADD_FAILURE() << "not a SceneError: an exception of another type";
    }
  }
  // The seeds include the demo scenes and the examples, which load.
  EXPECT_GT(accepted, 0);
  EXPECT_GT(rejected, 0);
}

// load_scene reads the same bytes from the file: the same outcome.
TEST(FuzzRegression, LoadSceneAgreesWithParseScene) {
  for (const fs::path& path : corpus_files()) {
    SCOPED_TRACE(path.filename().string());
    const std::string file = path.string();
    std::string parsed, loaded;
    try {
      parse_scene(contents(path), file);
    } catch (const SceneError& e) {
      parsed = e.what();
    }
    try {
      load_scene(file);
    } catch (const SceneError& e) {
      loaded = e.what();
    }
    EXPECT_EQ(parsed, loaded);
  }
}

double seconds_to_parse(const std::string& text) {
  const auto start = std::chrono::steady_clock::now();
  try {
    parse_scene(text, "big.json");
  } catch (const SceneError&) {
  }
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

// Fuzzing findings that are about time, not crashes: each input below once
// took time quadratic in its size (the unterminated nest: minutes in Release,
// over 40 minutes under ASan); now each takes a fraction of a second (a few
// seconds under the sanitizers). The bounds are loose so that a loaded
// machine does not fail them: they catch a return of the quadratic cases at
// this size, not small slowdowns.
TEST(FuzzRegression, DeepNestingFailsAtOnce) {
  // An unterminated nest: the error message once rebuilt the path per level.
  EXPECT_LT(seconds_to_parse(R"({"materials": )" + std::string(1000000, '[')), 5.0);
  EXPECT_LT(seconds_to_parse(std::string(500000, '[') + std::string(500000, ']')), 5.0);
  const SceneError e = [] {
    try {
      parse_scene(R"({"title": )" + std::string(100, '[') + std::string(100, ']') + "}", "deep.json");
    } catch (const SceneError& error) {
      return error;
    }
    return SceneError("", "", "accepted");
  }();
  EXPECT_NE(e.message().find("nested more than 64 levels"), std::string::npos) << e.what();
  EXPECT_EQ(e.key().rfind("title[0][0]", 0), 0u) << e.key();
}

TEST(FuzzRegression, ManyBodiesAndEventsParseInLinearTime) {
  // nlohmann's parse with a callback was quadratic in an array of objects.
  const int n = 20000;
  std::string bodies, events;
  for (int i = 0; i < n; ++i) {
    if (i > 0) {
      bodies += ',';
      events += ',';
    }
    bodies += R"({"name": "b)";
    bodies += std::to_string(i);
    bodies += R"(", "shape": {"sphere": 0.01}, "material": "w"})";
    events += R"({"time": 0, "action": "remove", "body": "b)";
    events += std::to_string(n - 1 - i);
    events += R"("})";
  }
  const std::string text =
      R"({"materials": {"w": {"type": "inert"}}, "bodies": [)" + bodies + R"(], "timeline": [)" + events + "]}";
  EXPECT_LT(seconds_to_parse(text), 10.0);
  const SceneDescription scene = parse_scene(text, "big.json");
  EXPECT_EQ(scene.bodies.size(), static_cast<size_t>(n));
  EXPECT_EQ(scene.timeline.back().body, "b0");
}

// Values that overflowed or underflowed in the loader's own arithmetic.
TEST(FuzzRegression, ExtremeButFiniteNumbers) {
  const std::string materials = R"({"materials": {"m": {"type": "permanent", "magnetization": [0, 0, 1e6]}}, )";
  // A quaternion is a direction: [1e300, ...] once overflowed to a "zero quaternion".
  const SceneDescription q = parse_scene(
      materials + R"("bodies": [{"name": "a", "shape": {"sphere": 0.01}, "material": "m",
                                 "orientation": [1e300, 0, 0, 1e300]}]})",
      "q.json");
  EXPECT_NEAR(q.bodies[0].orientation.w, std::sqrt(0.5), 1e-15);
  EXPECT_NEAR(q.bodies[0].orientation.z, std::sqrt(0.5), 1e-15);
  // A camera 2e308 m from its target was accepted with an infinite view direction.
  for (const std::string camera : {R"({"position": [-1e308, 0, 0], "target": [1e308, 0, 0]})",
                                   R"({"position": [0, 0, 0], "target": [1e-200, 0, 0]})",
                                   R"({"up": [0, 0, 1e300]})", R"({"up": [0, 0, 1e-300]})"}) {
    SCOPED_TRACE(camera);
    try {
      parse_scene(materials + R"("bodies": [{"name": "a", "shape": {"sphere": 0.01}, "material": "m"}],
                                 "camera": )" + camera + "}",
                  "c.json");
      ADD_FAILURE() << "accepted";
    } catch (const SceneError& e) {
      EXPECT_EQ(e.key().rfind("camera.", 0), 0u) << e.what();
    }
  }
}

// The words of a command line: the input split at NUL bytes (as fuzz_cli does).
std::vector<std::string> words(const std::string& data) {
  std::vector<std::string> w;
  if (data.empty()) return w;
  size_t start = 0;
  for (;;) {
    const size_t nul = data.find('\0', start);
    w.push_back(data.substr(start, nul == std::string::npos ? std::string::npos : nul - start));
    if (nul == std::string::npos) return w;
    start = nul + 1;
  }
}

TEST(FuzzRegression, EveryCommandLineIsAcceptedOrAUsageError) {
  for (const fs::path& path : corpus_files("cli")) {
    SCOPED_TRACE(path.filename().string());
    const std::vector<std::string> w = words(contents(path));
    if (w.empty()) continue;
    const std::vector<std::string> args(w.begin() + 1, w.end());
    try {
      if (w[0] == "solve") cli::parse_solve_command(args);
      if (w[0] == "field") cli::parse_field_command(args);
      if (w[0] == "run") cli::parse_run_command(args);
      if (w[0] == "sweep") cli::parse_sweep_command(args);
    } catch (const cli::UsageError& e) {
      EXPECT_FALSE(std::string(e.what()).empty());
    } catch (const std::exception& e) {
      ADD_FAILURE() << "not a UsageError: " << e.what();
    }
  }
}

}  // namespace
}  // namespace odemag
