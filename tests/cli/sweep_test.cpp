// `odemag sweep` end to end (docs/sweeps.md): key paths and their errors,
// grid expansion, the table against the variant scenes run one by one with
// `odemag run` (scenes built here by hand, not by key path), resume, and a
// failing variant.
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "cli/cli.h"
#include "engine/scene/sweep.h"
#include "tests/support/program_run.h"

namespace odemag {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;
using test_support::lines;
using test_support::ProgramRun;
using test_support::read_file;
using test_support::shell_quote;

const std::string kOdemag = ODEMAG_BINARY_DIR "/bin/odemag";
const std::string kBallChain = ODEMAG_SOURCE_DIR "/demos/scenes/ball_chain.json";

TEST(KeyPath, ParsesKeysAndIndices) {
  const std::vector<KeyPathStep> s = parse_key_path("bodies[3].position[2]");
  ASSERT_EQ(s.size(), 4u);
  EXPECT_EQ(s[0].key, "bodies");
  EXPECT_EQ(s[0].index, -1);
  EXPECT_EQ(s[1].index, 3);
  EXPECT_EQ(s[2].key, "position");
  EXPECT_EQ(s[3].index, 2);
  const std::vector<KeyPathStep> m = parse_key_path("materials.steel.susceptibility");
  ASSERT_EQ(m.size(), 3u);
  EXPECT_EQ(m[1].key, "steel");
  EXPECT_EQ(parse_key_path("a[0][1]").size(), 3u);
}

TEST(KeyPath, RejectsMalformedPaths) {
  for (const char* bad : {"", "a..b", "a.", ".a", "a[", "a[x]", "a[-1]", "[0]", "a]", "a[1]b", "a[]"})
    EXPECT_THROW(parse_key_path(bad), std::invalid_argument) << bad;
}

// Lines of a CSV table split into cells (the sweep's cells need no quoting here).
std::vector<std::vector<std::string>> csv(const std::string& text) {
  std::vector<std::vector<std::string>> rows;
  for (const std::string& line : lines(text)) {
    std::vector<std::string> cells;
    size_t start = 0;
    for (size_t comma; (comma = line.find(',', start)) != std::string::npos; start = comma + 1)
      cells.push_back(line.substr(start, comma - start));
    cells.push_back(line.substr(start));
    rows.push_back(cells);
  }
  return rows;
}

class Sweep : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("odemag_sweep_" + std::to_string(::getpid()) + "_" +
                                        ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
    fs::copy_file(kBallChain, dir_ / "base.json");  // the spec names it relative to its folder
  }
  void TearDown() override {
    std::error_code ec;
    fs::remove_all(dir_, ec);
  }
  fs::path write(const std::string& name, const std::string& text) {
    std::ofstream(dir_ / name, std::ios::binary) << text;
    return dir_ / name;
  }
  ProgramRun odemag(const std::string& args) {
    return test_support::run_program(shell_quote(kOdemag) + " " + args, dir_);
  }
  ProgramRun sweep(const fs::path& spec, const std::string& extra = "") {
    return odemag("sweep " + shell_quote(spec.string()) + " --out " + shell_quote((dir_ / "out").string()) +
                  " --quiet yes " + extra);
  }
  // A spec on the ball chain, shortened to 0.1 s, with `body` as its grid or variants.
  fs::path spec(const std::string& body, const std::string& collect = R"(["balls_lifted", "steps", "iterations.mean"])") {
    return write("spec.json", R"({"scene": "base.json", "set": {"simulation.duration": 0.1}, )" + body +
                                  R"(, "collect": )" + collect + R"(, "run": ["--backend", "cpu"]})");
  }
  // A rejected spec or command line: exit 2, one stderr line naming the
  // spec (when given) and the key, and nothing written.
  void expect_rejected(const fs::path& spec_file, const std::string& extra, const std::string& key) {
    fs::remove_all(dir_ / "out");
    const ProgramRun r = sweep(spec_file, extra);
    EXPECT_EQ(r.status, 2) << r.err;
    const auto err = lines(r.err);
    ASSERT_EQ(err.size(), 1u) << r.err;
    EXPECT_NE(err[0].find(key), std::string::npos) << r.err;
    if (extra.empty()) {
      EXPECT_EQ(err[0].rfind("odemag: " + spec_file.string() + ": ", 0), 0u) << r.err;
    }
    EXPECT_FALSE(fs::exists(dir_ / "out")) << r.err;
  }
  fs::path dir_;
};

TEST_F(Sweep, BadSpecsAndFlagsNameTheFileAndTheKeyAndWriteNothing) {
  const std::string grid = R"("grid": {"materials.steel.susceptibility": [10, 100]})";
  expect_rejected(spec(R"("grid": {"materials.stel.susceptibility": [10]})"), "", "materials.stel.susceptibility");
  expect_rejected(spec(R"("grid": {"bodies[99].position[2]": [0.1]})"), "", "bodies[99].position[2]");
  expect_rejected(spec(R"("grid": {"simulation.duration.x": [1]})"), "", "simulation.duration.x");
  expect_rejected(spec(R"("grid": {"materials..steel": [1]})"), "", "materials..steel");
  // A new last key is written, then the loader rejects what the format does not know.
  expect_rejected(spec(R"("grid": {"materials.steel.susceptibilty": [10]})"), "", "materials.steel.susceptibilty");
  // A value the loader refuses names the variant.
  expect_rejected(spec(R"("variants": [{"materials.steel.susceptibility": 10}, {"materials.steel.susceptibility": "x"}])"),
                  "", "variant 1");
  expect_rejected(spec(grid + R"(, "variants": [{}])"), "", "variants");
  expect_rejected(spec(R"("grid": {"simulation.duration": [1]})"), "", "simulation.duration");  // also in set
  expect_rejected(spec(grid, R"(["balls_lifted", "no_such_figure"])"), "", "collect[1]");
  expect_rejected(write("spec.json", R"({"scene": "base.json", "grid": {"seed": [1]}, "colect": []})"), "", "colect");
  expect_rejected(write("spec.json", R"({"scene": "base.json", "grid": {"seed": [1]}, "run": ["--frames", "maybe"]})"),
                  "", "run");
  expect_rejected(write("spec.json", R"({"scene": "base.json", "grid": {"seed": [1], "seed": [2]}})"), "", "seed");
  expect_rejected(write("spec.json", R"({"scene": "base.json", "grid": )"), "", "invalid JSON");
  expect_rejected(spec(grid), "--jobs 0", "--jobs");
  expect_rejected(spec(grid), "--variant 2", "--variant 2");
  expect_rejected(spec(grid), "--expand --gather", "at most one");
  // A bad base scene names the scene file.
  write("base.json", R"({"gravity": [0, 0]})");
  const ProgramRun r = sweep(spec(grid));
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find((dir_ / "base.json").string() + ": gravity"), std::string::npos) << r.err;
}

// --out that is a file, or a missing folder for --gather, is bad input
// (exit 2, one line naming --out), as for `odemag run`; nothing is written.
TEST_F(Sweep, OutThatIsAFileOrAMissingGatherFolderExitsTwo) {
  const fs::path s = spec(R"("grid": {"seed": [1, 2]})");
  const fs::path file = write("a_file", "keep me");
  for (const char* mode : {"", "--expand", "--slurm", "--variant 0", "--gather", "--dask local:1"}) {
    const ProgramRun r =
        odemag("sweep " + shell_quote(s.string()) + " --out " + shell_quote(file.string()) + " " + std::string(mode));
    EXPECT_EQ(r.status, 2) << mode << ": " << r.err;
    ASSERT_EQ(lines(r.err).size(), 1u) << r.err;
    EXPECT_EQ(r.err.rfind("odemag: --out " + file.string() + ": exists and is not a directory", 0), 0u) << r.err;
    EXPECT_EQ(read_file(file), "keep me");
  }
  const ProgramRun r = odemag("sweep " + shell_quote(s.string()) + " --out " + shell_quote((dir_ / "none").string()) +
                              " --gather");
  EXPECT_EQ(r.status, 2) << r.err;
  ASSERT_EQ(lines(r.err).size(), 1u) << r.err;
  EXPECT_NE(r.err.find("no such directory"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(dir_ / "none"));
  const ProgramRun below = odemag("sweep " + shell_quote(s.string()) + " --out " +
                                  shell_quote((file / "out").string()) + " --expand");
  EXPECT_EQ(below.status, 2) << below.err;
  EXPECT_NE(below.err.find("is not a directory"), std::string::npos) << below.err;
}

// A scene with a mesh file named relative to its folder: each variant,
// written to its own folder, names the file by its absolute path and runs.
TEST_F(Sweep, VariantsReadTheBaseScenesMeshFiles) {
  fs::create_directories(dir_ / "meshes");
  fs::copy_file(fs::path(ODEMAG_SOURCE_DIR) / "examples/meshes/needle.obj", dir_ / "meshes/needle.obj");
  std::string base = read_file(fs::path(ODEMAG_SOURCE_DIR) / "examples/compass_needle_mesh.json");
  write("base.json", base);
  const fs::path s = write("spec.json", R"({"scene": "base.json", "set": {"simulation.duration": 0.05},
    "grid": {"external_field[0]": [1000, 2000]}, "collect": ["steps"], "run": ["--backend", "cpu"]})");
  const ProgramRun r = sweep(s);
  ASSERT_EQ(r.status, 0) << r.err;
  const json scene = json::parse(read_file(dir_ / "out" / "variants" / "0001" / "scene.json"));
  EXPECT_EQ(scene["bodies"][1]["shape"]["mesh"]["file"].get<std::string>(),
            fs::absolute(dir_ / "meshes/needle.obj").lexically_normal().string());
  EXPECT_TRUE(fs::exists(dir_ / "out" / "variants" / "0001" / "summary.json"));
}

TEST_F(Sweep, GridExpandsInOrderTheFirstKeySlowest) {
  const ProgramRun r = sweep(spec(R"("grid": {"materials.steel.susceptibility": [10, 100, 1000],
                                              "bodies[5].position[2]": [0.005, 0.006]})"),
                             "--expand");
  ASSERT_EQ(r.status, 0) << r.err;
  const json list = json::parse(read_file(dir_ / "out" / "variants.json"));
  ASSERT_EQ(list["count"], 6);
  const double chi[] = {10, 10, 100, 100, 1000, 1000}, z[] = {0.005, 0.006, 0.005, 0.006, 0.005, 0.006};
  for (int i = 0; i < 6; ++i) {
    const fs::path dir = dir_ / "out" / "variants" / ("000" + std::to_string(i));
    EXPECT_EQ(list["variants"][i]["dir"], "variants/000" + std::to_string(i));
    const json scene = json::parse(read_file(dir / "scene.json"));
    EXPECT_EQ(scene["materials"]["steel"]["susceptibility"].get<double>(), chi[i]);
    EXPECT_EQ(scene["bodies"][5]["position"][2].get<double>(), z[i]);
    EXPECT_EQ(scene["simulation"]["duration"].get<double>(), 0.1);  // set: every variant
    EXPECT_EQ(scene["bodies"][6], json::parse(read_file(dir_ / "base.json"))["bodies"][6]);  // the rest as the base
    EXPECT_FALSE(fs::exists(dir / "summary.json"));  // expanded, not run
  }
  EXPECT_FALSE(fs::exists(dir_ / "out" / "results.csv"));
}

TEST_F(Sweep, TableEqualsTheVariantsRunOneByOneAndResumesWithoutRerunning) {
  const std::vector<double> chi = {10, 1000};
  const std::vector<bool> induction = {true, false};
  const fs::path spec_file = spec(R"("grid": {"materials.steel.susceptibility": [10, 1000],
                                              "solver.mutual_induction": [true, false]})",
                                  R"(["balls_lifted", "steps", "iterations.mean", "magnetic_ms.max"])");
  const ProgramRun r = sweep(spec_file, "--jobs 2");
  ASSERT_EQ(r.status, 0) << r.err;
  const std::string table = read_file(dir_ / "out" / "results.csv");
  const auto rows = csv(table);
  ASSERT_EQ(rows.size(), 5u) << table;
  EXPECT_EQ(rows[0], (std::vector<std::string>{"variant", "materials.steel.susceptibility", "solver.mutual_induction",
                                               "balls_lifted", "steps", "iterations.mean", "magnetic_ms.max", "status"}));
  // The independent path: each variant scene written here and run by hand.
  const json base = json::parse(read_file(dir_ / "base.json"));
  for (size_t i = 0; i < 4; ++i) {
    json scene = base;
    scene["simulation"]["duration"] = 0.1;
    scene["materials"]["steel"]["susceptibility"] = chi[i / 2];
    scene["solver"]["mutual_induction"] = static_cast<bool>(induction[i % 2]);
    const fs::path file = write("hand_" + std::to_string(i) + ".json", scene.dump());
    const fs::path out = dir_ / ("hand_" + std::to_string(i));
    const ProgramRun run = odemag("run " + shell_quote(file.string()) + " --out " + shell_quote(out.string()) +
                                  " --frames no --quiet yes --threads 1 --backend cpu");
    ASSERT_EQ(run.status, 0) << run.err;
    const json summary = json::parse(read_file(out / "summary.json"));
    const std::vector<std::string>& row = rows[i + 1];
    EXPECT_EQ(row[0], std::to_string(i));
    EXPECT_EQ(row[1], i / 2 ? "1000" : "10");  // as the spec wrote it
    EXPECT_EQ(row[2], induction[i % 2] ? "true" : "false");
    EXPECT_EQ(row[3], summary["outcomes"]["balls_lifted"].dump());
    EXPECT_EQ(row[4], summary["steps"].dump());
    EXPECT_EQ(row[5], summary["iterations"]["mean"].dump());  // bit for bit
    EXPECT_FALSE(row[6].empty());                             // a timing: present, not reproducible
    EXPECT_EQ(row[7], "ok");
  }
  EXPECT_NE(rows[1][5], rows[2][5]);  // mutual induction changed the iterations: the overrides took

  // Resume: variant 2's results lost (as by a crash), a stale run folder left;
  // only variant 2 runs again (the others' summaries, with their wall times,
  // stay byte for byte), and the table is the same.
  const fs::path v = dir_ / "out" / "variants";
  std::vector<std::string> summaries;
  for (int i = 0; i < 4; ++i) summaries.push_back(read_file(v / ("000" + std::to_string(i)) / "summary.json"));
  fs::remove(v / "0002" / "summary.json");
  fs::create_directories(v / "0002" / ".run-crashed-1");
  fs::remove(dir_ / "out" / "results.csv");
  ASSERT_EQ(sweep(spec_file).status, 0);
  const auto again = csv(read_file(dir_ / "out" / "results.csv"));
  ASSERT_EQ(again.size(), rows.size());
  for (size_t i = 0; i < rows.size(); ++i)
    for (size_t c = 0; c < rows[i].size(); ++c)
      if (c != 6 || i != 3) {  // variant 2's timing is new
        EXPECT_EQ(again[i][c], rows[i][c]) << i << " " << c;
      }
  for (int i : {0, 1, 3}) EXPECT_EQ(read_file(v / ("000" + std::to_string(i)) / "summary.json"), summaries[i]);
  EXPECT_NE(read_file(v / "0002" / "summary.json"), summaries[2]);
  EXPECT_FALSE(fs::exists(v / "0002" / ".run-crashed-1"));  // the local runner cleared it
  // A summary for another scene (the spec changed) is not reused.
  const std::string changed = read_file(spec_file);
  write("spec.json", std::string(changed).replace(changed.find("0.1"), 3, "0.2"));
  ASSERT_EQ(sweep(spec_file).status, 0);
  const auto longer = csv(read_file(dir_ / "out" / "results.csv"));
  for (size_t i = 1; i < longer.size(); ++i) EXPECT_EQ(longer[i][4], "50");  // 0.2 s of 4 ms steps
  // A sweep that stops on a bad spec leaves the table it had, byte for byte.
  const std::string kept = read_file(dir_ / "out" / "results.csv");
  write("spec.json", std::string(changed).replace(changed.find("susceptibility"), 14, "susceptibilty"));
  ASSERT_EQ(sweep(spec_file).status, 2);
  EXPECT_EQ(read_file(dir_ / "out" / "results.csv"), kept);
  // No temporary files left beside the table.
  for (const fs::directory_entry& e : fs::directory_iterator(dir_ / "out"))
    EXPECT_EQ(e.path().filename().string().find(".tmp"), std::string::npos) << e.path();
}

TEST_F(Sweep, AFailingVariantIsMarkedAndTheOthersAreKept) {
  // Variant 1 asks for more rigid steps than --max-steps allows: its run fails.
  const fs::path spec_file = write("spec.json", R"({"scene": "base.json", "set": {"simulation.duration": 0.1},
    "variants": [{"seed": 1}, {"simulation.time_step": 1e-5}, {"seed": 3}],
    "collect": ["steps"], "run": ["--max-steps", "1000", "--backend", "cpu"]})");
  const ProgramRun r = sweep(spec_file);
  EXPECT_EQ(r.status, 1);
  EXPECT_NE(r.err.find("1 of 3 variants did not finish (0001"), std::string::npos) << r.err;
  const auto rows = csv(read_file(dir_ / "out" / "results.csv"));
  ASSERT_EQ(rows.size(), 4u);
  EXPECT_EQ(rows[0], (std::vector<std::string>{"variant", "seed", "simulation.time_step", "steps", "status"}));
  EXPECT_EQ(rows[1], (std::vector<std::string>{"0", "1", "", "25", "ok"}));
  EXPECT_EQ(rows[2], (std::vector<std::string>{"1", "", "1e-05", "", "failed"}));
  EXPECT_EQ(rows[3], (std::vector<std::string>{"2", "3", "", "25", "ok"}));
  EXPECT_NE(read_file(dir_ / "out" / "variants" / "0001" / "error.txt").find("--max-steps"), std::string::npos);
}

TEST_F(Sweep, EverySummaryFigureIsInARunsSummary) {
  const ProgramRun r = odemag("run " + shell_quote((dir_ / "base.json").string()) + " --out " +
                              shell_quote((dir_ / "run").string()) + " --duration 0.02 --frames no --quiet yes --backend cpu");
  ASSERT_EQ(r.status, 0) << r.err;
  const json summary = json::parse(read_file(dir_ / "run" / "summary.json"));
  for (std::string f : cli::summary_figures()) {
    for (char& ch : f) ch = ch == '.' ? '/' : ch;
    ASSERT_TRUE(summary.contains(json::json_pointer("/" + f))) << f;
    EXPECT_TRUE(summary.at(json::json_pointer("/" + f)).is_number()) << f;
  }
}

TEST_F(Sweep, SlurmScriptsRunEachVariantAndThenTheGather) {
  const ProgramRun r = sweep(spec(R"("grid": {"seed": [1, 2, 3]})"), "--slurm");
  ASSERT_EQ(r.status, 0) << r.err;
  const std::string out = (dir_ / "out").string();
  EXPECT_EQ(r.out, "jobid=$(sbatch --parsable " + out + "/sweep.sbatch) && sbatch --dependency=afterok:${jobid%%;*} " +
                       out + "/gather.sbatch\n");
  const std::string array = read_file(dir_ / "out" / "sweep.sbatch");
  EXPECT_NE(array.find("\n#SBATCH --array=0-2\n"), std::string::npos) << array;
  EXPECT_NE(array.find("--out '" + out + "' --variant \"$SLURM_ARRAY_TASK_ID\"\n"), std::string::npos) << array;
  EXPECT_NE(read_file(dir_ / "out" / "gather.sbatch").find("--out '" + out + "' --gather\n"), std::string::npos);
  // Without Slurm: each array task's command, then the gather's, by hand.
  for (int task = 0; task < 3; ++task)
    ASSERT_EQ(test_support::run_program("SLURM_ARRAY_TASK_ID=" + std::to_string(task) + " bash " +
                                            shell_quote(out + "/sweep.sbatch"), dir_).status, 0);
  ASSERT_EQ(test_support::run_program("bash " + shell_quote(out + "/gather.sbatch"), dir_).status, 0);
  const auto rows = csv(read_file(dir_ / "out" / "results.csv"));
  ASSERT_EQ(rows.size(), 4u);
  for (int i = 1; i < 4; ++i) EXPECT_EQ(rows[i].back(), "ok");
}

}  // namespace
}  // namespace odemag
