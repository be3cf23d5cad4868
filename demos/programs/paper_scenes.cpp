// The paper's scenes (demos/scenes/), each simulated with `odemag run` into
// OUT/<scene>/ (frames, state.jsonl, summary.json); then the outcomes next to
// what the paper reports. Usage:
//   demo_paper_scenes [--out DIR] [--only NAME] [--frames yes|no]
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "demos/view/scene_view.h"
#include "demos/cli/cli.h"

namespace {

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

}  // namespace

int main(int argc, char** argv) {
  std::string out = "out", only, frames = "yes";
  for (int i = 1; i + 1 < argc; i += 2) {
    const std::string key = argv[i], value = argv[i + 1];
    if (key == "--out") out = value;
    else if (key == "--only") only = value;
    else if (key == "--frames") frames = value;
    else {
      std::fprintf(stderr, "usage: demo_paper_scenes [--out DIR] [--only NAME] [--frames yes|no]\n");
      return 2;
    }
  }
  int status = 0;
  for (const PaperScene& s : kScenes) {
    if (!only.empty() && only != s.name) continue;
    const std::string scene = std::string(ODEMAG_SCENES_DIR) + "/" + s.name + ".json";
    const std::string dir = (std::filesystem::path(out) / s.name).string();
    std::printf("== %s: %s\n", s.name, s.claim);
    std::fflush(stdout);
    try {
      const int rc = odemag::cli::run_simulation({scene, "--out", dir, "--frames", frames, "--quiet", "yes"},
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
