// A scene file run from a program of your own (docs/embedding.md "Scenes
// from a program"): loads the scene given as the first argument, relaxes it
// at t = 0 (solve_scene, as `odemag solve`) and steps it for 0.1 s
// (Simulation, as `odemag run`), printing each body's force at t = 0 and its
// position at the end. Exits 0 when every number is finite, 2 on a bad
// scene, 1 otherwise.
#include <cmath>
#include <cstdio>
#include <exception>

#include <odemag/odemag.h>

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: scene_minimal SCENE.json\n");
    return 2;
  }
  try {
    const odemag::SceneDescription scene = odemag::load_scene(argv[1]);
    const odemag::SceneSolution solved = odemag::solve_scene(scene);
    odemag::Simulation sim(scene);
    sim.advance_to(0.1);
    bool finite = true;
    for (size_t b = 0; b < scene.bodies.size(); ++b) {
      const odemag::Vec3 f = solved.bodies[b].force;
      const odemag::Vec3 p = sim.pose(static_cast<int>(b)).position;
      std::printf("%s: force at t = 0 (%g, %g, %g) N, position at t = %g s (%g, %g, %g) m\n",
                  scene.bodies[b].name.c_str(), f.x, f.y, f.z, sim.time(), p.x, p.y, p.z);
      finite = finite && odemag::is_finite(f) && odemag::is_finite(p);
    }
    return finite ? 0 : 1;
  } catch (const odemag::SceneError& e) {
    std::fprintf(stderr, "%s\n", e.what());
    return 2;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "scene_minimal: %s\n", e.what());
    return 1;
  }
}
