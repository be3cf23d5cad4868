// The demo programs' command lines (demos): --help prints the usage
// and a bad command line exits 2 with one stderr line, neither writing
// anything; demo_magnetization_curve writes its CSV and reports the PNG only
// when gnuplot (run without a shell) wrote one. The long demo_paper_scenes
// job is never run: a regression that starts it hits the timeout instead.
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "tests/support/program_run.h"

namespace odemag {
namespace {

namespace fs = std::filesystem;

const std::string kPaperScenes = ODEMAG_BINARY_DIR "/bin/demo_paper_scenes";
const std::string kCurve = ODEMAG_BINARY_DIR "/bin/demo_magnetization_curve";

using test_support::lines;
using test_support::ProgramRun;
using test_support::read_file;
using test_support::shell_quote;

size_t count(const std::string& text, const std::string& what) {
  size_t n = 0;
  for (size_t at = text.find(what); at != std::string::npos; at = text.find(what, at + 1)) ++n;
  return n;
}

// A scratch directory per test; the programs run in its empty work/.
class DemoPrograms : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() /
           ("odemag_demo_programs_" + std::to_string(::getpid()) + "_" +
            ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir_);
    fs::create_directories(work_ = dir_ / "work");
  }
  void TearDown() override {
    std::error_code ec;
    fs::remove_all(dir_, ec);
  }

  // Runs the program in work/ with the (already quoted) arguments, with PATH
  // set to `path` when it is given.
  ProgramRun run(const std::string& program, const std::string& args, const std::string& path = "") {
    // 124: killed by the timeout (a regression that starts the long job).
    return test_support::run_program("cd " + shell_quote(work_.string()) + " && timeout 120 env " +
                                         (path.empty() ? "" : "PATH=" + shell_quote(path) + " ") +
                                         shell_quote(program) + " " + args,
                                     dir_);
  }

  // A fake gnuplot in bin/ running `body` (sh); bin/ is the PATH to pass to run().
  std::string fake_gnuplot(const std::string& body) {
    const fs::path bin = dir_ / "bin", script = bin / "gnuplot";
    fs::create_directories(bin);
    std::ofstream(script) << "#!/bin/sh\n" << body << "\n";
    fs::permissions(script, fs::perms::owner_all);
    return bin.string();
  }

  void clear_work() {
    fs::remove_all(work_);
    fs::create_directories(work_);
  }
  void expect_work_empty(const std::string& args) {
    EXPECT_TRUE(fs::is_empty(work_)) << args << ": wrote " << fs::directory_iterator(work_)->path();
  }

  void expect_help(const std::string& program, const std::string& name, const std::string& args) {
    clear_work();
    const ProgramRun r = run(program, args);
    EXPECT_EQ(r.status, 0) << args << ": " << r.err;
    EXPECT_EQ(r.out.rfind("usage: " + name + " ", 0), 0u) << args << ": " << r.out;
    EXPECT_EQ(r.err, "") << args;
    expect_work_empty(args);
  }

  // Exit 2, nothing on stdout, one stderr line "NAME: ...", nothing written.
  std::string expect_usage_error(const std::string& program, const std::string& name, const std::string& args) {
    clear_work();
    const ProgramRun r = run(program, args);
    EXPECT_EQ(r.status, 2) << args << ": " << r.out << r.err;
    EXPECT_EQ(r.out, "") << args;
    const auto err = lines(r.err);
    EXPECT_EQ(err.size(), 1u) << args << ": " << r.err;
    EXPECT_EQ(r.err.rfind(name + ": ", 0), 0u) << args << ": " << r.err;
    EXPECT_EQ(count(r.err, "odemag --help"), 0u) << args << ": " << r.err;  // the program's own help
    expect_work_empty(args);
    return r.err;
  }

  fs::path dir_, work_;
};

TEST_F(DemoPrograms, PaperScenesHelpPrintsUsageAndWritesNothing) {
  for (const char* args : {"--help", "-h", "--frames no --help", "--out elsewhere -h"})
    expect_help(kPaperScenes, "demo_paper_scenes", args);
}

TEST_F(DemoPrograms, PaperScenesRejectsBadCommandLines) {
  for (const char* args : {"--out", "--only", "--frobnicate x", "-x", "extra", "--out a extra", "--out a --out b",
                           "--out ''", "--frames maybe", "--frames=", "--frames 1", "--only ''"})
    expect_usage_error(kPaperScenes, "demo_paper_scenes", args);
}

TEST_F(DemoPrograms, PaperScenesRejectsAnUnknownSceneListingTheNames) {
  const std::string err = expect_usage_error(kPaperScenes, "demo_paper_scenes", "--only typo --frames no");
  EXPECT_NE(err.find("'typo'"), std::string::npos) << err;
  for (const char* scene : {"ball_chain", "ball_chain_no_induction", "iron_plate", "nail_and_balls", "crane"})
    EXPECT_NE(err.find(scene), std::string::npos) << scene << ": " << err;
}

TEST_F(DemoPrograms, MagnetizationCurveHelpPrintsUsageAndWritesNothing) {
  for (const char* args : {"--help", "-h", "dir --help"})
    expect_help(kCurve, "demo_magnetization_curve", args);
}

TEST_F(DemoPrograms, MagnetizationCurveRejectsBadCommandLines) {
  for (const char* args : {"a b", "--frobnicate", "--out dir", "-x", "''"})
    expect_usage_error(kCurve, "demo_magnetization_curve", args);
}

// With whatever gnuplot this machine has (or none): the CSV, and the PNG
// reported exactly when it exists.
TEST_F(DemoPrograms, MagnetizationCurveWritesCsvAndReportsPngOnlyWhenWritten) {
  const ProgramRun r = run(kCurve, "curve");
  EXPECT_EQ(r.status, 0) << r.out << r.err;
  EXPECT_EQ(read_file(work_ / "curve" / "magnetization_curve.csv").rfind("panel,material,", 0), 0u);
  const bool png = fs::exists(work_ / "curve" / "magnetization_curve.png");
  EXPECT_EQ(count(r.out, "magnetization_curve.png"), png ? 1u : 0u) << r.out;
}

TEST_F(DemoPrograms, MagnetizationCurveWithoutGnuplotSaysSoOnce) {
  fs::create_directories(dir_ / "empty");
  const ProgramRun r = run(kCurve, "curve", (dir_ / "empty").string());
  EXPECT_EQ(r.status, 0) << r.out << r.err;
  EXPECT_EQ(count(r.out + r.err, "gnuplot"), 1u) << r.out << r.err;
  EXPECT_EQ(count(r.out + r.err, ".png"), 0u) << r.out << r.err;
  EXPECT_TRUE(fs::exists(work_ / "curve" / "magnetization_curve.csv"));
}

// gnuplot exits 0 but writes nothing; a PNG left from an earlier run is not reported.
TEST_F(DemoPrograms, MagnetizationCurveReportsNoPngGnuplotDidNotWrite) {
  const std::string path = fake_gnuplot("exit 0");
  fs::create_directories(work_ / "curve");
  std::ofstream(work_ / "curve" / "magnetization_curve.png") << "stale";
  const ProgramRun r = run(kCurve, "curve", path);
  EXPECT_EQ(r.status, 0) << r.out << r.err;
  EXPECT_EQ(count(r.out, ".png"), 0u) << r.out;
  EXPECT_EQ(lines(r.err).size(), 1u) << r.err;
  EXPECT_FALSE(fs::exists(work_ / "curve" / "magnetization_curve.png"));
  EXPECT_TRUE(fs::exists(work_ / "curve" / "magnetization_curve.csv"));
}

// gnuplot gets the script as one argument, however the directory is named
// (no shell), and its failure is reported.
TEST_F(DemoPrograms, MagnetizationCurveRunsGnuplotWithoutAShell) {
  const std::string path = fake_gnuplot("printf '%s\\n' \"$#\" \"$@\" > \"${0%/*}/args\"\nexit 3");
  const std::string out = "it's a $(dir)";
  const ProgramRun r = run(kCurve, shell_quote(out), path);
  EXPECT_EQ(r.status, 0) << r.out << r.err;
  EXPECT_EQ(read_file(fs::path(path) / "args"), "1\n" + out + "/magnetization_curve.gp\n");
  EXPECT_EQ(count(r.out, ".png"), 0u) << r.out;
  const auto err = lines(r.err);
  ASSERT_EQ(err.size(), 1u) << r.err;
  EXPECT_NE(err[0].find("exit status 3"), std::string::npos) << r.err;
  EXPECT_TRUE(fs::exists(work_ / out / "magnetization_curve.csv"));
}

}  // namespace
}  // namespace odemag
