// Outer iterations to convergence of the two-level relaxation and of the
// paper's Algorithm 1 for a few configurations, cold (moments in random
// opposite pairs) and warm (after a 0.2 mm move of the soft bodies, as in a
// rigid step), the two-level one with and without its block preconditioner
// (two_level / two_level_plain). docs/model.md shows the table. Output: CSV on stdout.
#include <chrono>
#include <cstdio>
#include <functional>
#include <string>

#include "magnetics/relax/relax.h"

using namespace odemag;

namespace {

SoftMaterial iron(double chi = 5000.0, double H_K = 0.0) {
  SoftMaterial m;
  m.saturation = 1.7e6;
  m.susceptibility = chi;
  m.anisotropy_field = H_K;
  m.easy_axis = {0, 0, 1};
  return m;
}

struct Config {
  std::string name;
  std::function<void(MagneticModel&, MagneticState&)> build;  // adds bodies; body 0 is the magnet
};

// precondition: RelaxOptions::precondition_bodies (two-level only).
void run(const Config& config, RelaxScheme scheme, bool precondition = true) {
  MagneticModel model;
  model.add_body("magnet", Box{{0.04, 0.01, 0.01}}, PermanentMaterial{{0, 0, 1e6}, 0.0}, 0.005);
  MagneticState probe;
  config.build(model, probe);
  MagneticState state = make_state(model, 3);
  for (int b = 0; b < model.body_count(); ++b) state.pose[b] = probe.pose[b];
  auto backend = make_cpu_backend(2);
  RelaxOptions o;
  o.scheme = scheme;
  o.precondition_bodies = precondition;
  o.max_iterations = scheme == RelaxScheme::paper ? 5000 : 200;
  for (int pass = 0; pass < 2; ++pass) {
    if (pass == 1)
      for (int b = 1; b < model.body_count(); ++b) state.pose[b].position.z -= 2e-4;
    const auto t0 = std::chrono::steady_clock::now();
    const RelaxReport r = relax(model, state, o, *backend);
    const double ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
    std::printf("%s,%d,%s,%s,%d,%d,%.2e,%ld,%ld,%.3f\n", config.name.c_str(), model.responsive_cell_count(),
                scheme == RelaxScheme::paper ? "paper" : precondition ? "two_level" : "two_level_plain", pass == 0 ? "cold" : "warm",
                r.iterations, r.converged ? 1 : 0, r.residual, r.llg_steps, r.newton_steps, ms);
  }
}

}  // namespace

int main() {
  const std::vector<Config> configs = {
      {"ball_below_magnet",
       [](MagneticModel& m, MagneticState& s) {
         m.add_body("ball", Sphere{0.006}, iron(), 0.0);
         s.pose.resize(2);
         s.pose[1].position = {0, 0, -0.012};
       }},
      {"ball_chain_6",
       [](MagneticModel& m, MagneticState& s) {
         s.pose.resize(7);
         for (int i = 0; i < 6; ++i) {
           m.add_body("ball" + std::to_string(i), Sphere{0.005}, iron(), 0.0);
           s.pose[i + 1].position = {0, 0, -0.0101 - 0.0101 * i};
         }
       }},
      {"plate_5x5x1",
       [](MagneticModel& m, MagneticState& s) {
         m.add_body("plate", Box{{0.04, 0.04, 0.008}}, iron(), 0.008);
         s.pose.resize(2);
         s.pose[1].position = {0, 0, -0.015};
       }},
      {"cube_5x5x5_chi3999",
       [](MagneticModel& m, MagneticState& s) {
         m.add_body("cube", Box{{0.01, 0.01, 0.01}}, iron(3999.0), 0.002);
         s.pose.resize(2);
         s.pose[1].position = {0.0, 0, -0.0125};
       }},
      {"nail_anisotropic",
       [](MagneticModel& m, MagneticState& s) {
         m.add_body("nail", Cylinder{0.002, 0.03}, iron(5000.0, 8e5), 0.002);
         s.pose.resize(2);
         s.pose[1].position = {0.0, 0, -0.0205};
       }},
  };
  std::printf("configuration,responsive_cells,scheme,start,iterations,converged,residual,llg_steps,newton_steps,ms\n");
  for (const Config& c : configs) {
    run(c, RelaxScheme::two_level);
    run(c, RelaxScheme::two_level, false);
    run(c, RelaxScheme::paper);
  }
  return 0;
}
