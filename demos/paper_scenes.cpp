// The paper's scenes (demos/scenes/), each simulated with `odemag run` into
// OUT/<scene>/ (frames, state.jsonl, summary.json); then the outcomes next to
// what the paper reports. Usage:
//   demo_paper_scenes [--out DIR] [--only NAME] [--frames yes|no]
// --out defaults to ./out, --only to every scene, --frames to yes. --help or
// -h prints the usage; a bad command line exits 2 with one line on stderr,
// before anything is written.
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "render/scene_view.h"
#include "cli/cli.h"
#include "magnetics/relax/threads.h"

namespace {

using odemag::cli::UsageError;

struct PaperScene {
  const char* name;
  const char* claim;  // what the paper shows
};

const PaperScene kScenes[] = {
    {"ball_chain", "Fig. 12a: a chain of induced balls (mutual induction)"},
    {"ball_chain_no_induction", "Fig. 12c: fewer balls lifted without mutual induction"},
    {"wood_plate", "Fig. 13a: the wood plate does not stop the ball"},
    {"iron_plate", "Fig. 13b: the iron plate shields the ball until it is removed"},
    {"thin_iron_plate", "Fig. 15a: a thin iron plate lets one ball be lifted"},
    {"thick_iron_plate", "Fig. 15b: a thick iron plate lets none be lifted"},
    {"nail_and_balls", "Fig. 16: the nail picks balls up by remanence"},
    {"nail_no_anisotropy", "a nail without anisotropy keeps no remanence"},
    {"crane", "Fig. 17: the crane holds fewer balls as its magnetization falls, a few when off"},
};

const char kUsage[] =
    "usage: demo_paper_scenes [--out DIR] [--only NAME] [--frames yes|no]\n"
    "  Simulates the paper's scenes with `odemag run` into DIR/<scene>/ (default\n"
    "  DIR: out) and prints each outcome next to the paper's claim.\n"
    "  --only NAME: that scene only; --frames no: no PNG frames.\n";

struct Options {
  std::string out = "out", only, frames = "yes";
};

// The options, checked before anything is written; throws UsageError.
Options read_options(const odemag::cli::Arguments& a) {
  if (!a.positional.empty()) throw UsageError("unexpected argument '" + a.positional[0] + "'");
  Options o;
  o.out = a.option("out").value_or(o.out);
  o.frames = a.option("frames").value_or(o.frames);
  if (o.out.empty()) throw UsageError("--out must not be empty");
  if (o.frames != "yes" && o.frames != "no") throw UsageError("--frames must be yes or no, not '" + o.frames + "'");
  if (const auto only = a.option("only")) {
    std::string names;
    for (const PaperScene& s : kScenes) {
      if (*only == s.name) o.only = *only;
      names += (names.empty() ? "" : ", ") + std::string(s.name);
    }
    if (o.only.empty()) throw UsageError("unknown scene '" + *only + "' for --only (scenes: " + names + ")");
  }
  return o;
}

int run_scenes(const Options& opt) {
  int status = 0;
  for (const PaperScene& s : kScenes) {
    if (!opt.only.empty() && opt.only != s.name) continue;
    const std::string scene = std::string(ODEMAG_SCENES_DIR) + "/" + s.name + ".json";
    const std::string dir = (std::filesystem::path(opt.out) / s.name).string();
    std::printf("== %s: %s\n", s.name, s.claim);
    std::fflush(stdout);
    try {
      const int rc = odemag::cli::run_simulation({scene, "--out", dir, "--frames", opt.frames, "--quiet", "yes"},
                                                 odemag::make_png_frame_writer);
      if (rc != 0) status = rc;
      std::ifstream in(std::filesystem::path(dir) / "summary.json");
      const nlohmann::json summary = nlohmann::json::parse(in);
      std::printf("   outcomes %s; %d cells, T_m median %.3f ms, T_r median %.3f ms; frames in %s\n",
                  summary["outcomes"].dump().c_str(), summary["cells"].get<int>(),
                  summary["magnetic_ms"]["median"].get<double>(), summary["rigid_ms"]["median"].get<double>(),
                  dir.c_str());
    } catch (const std::exception& e) {
      std::fprintf(stderr, "demo_paper_scenes: %s: %s\n", s.name, e.what());
      status = 1;
    }
  }
  return status;
}

}  // namespace

int main(int argc, char** argv) {
  odemag::restart_with_passive_omp_wait(argv);  // docs/benchmarks.md "Threads and waiting"
  return odemag::cli::program_main("demo_paper_scenes", kUsage, {argv + 1, argv + argc}, {"out", "only", "frames"},
                                   [](const odemag::cli::Arguments& a) { return run_scenes(read_options(a)); });
}
