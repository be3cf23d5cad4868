// The pseudo time step of the LLG update (docs/model.md "LLG integration",
// pseudo time step): largest rise of the cell free energy per step, relative
// to the field scale S, for tau = 0.1 .. 2 in dt = tau (1 + alpha^2) / (gamma0 S),
// over 3000 steps from a generic start, for several fields and anisotropies.
// The scheme is energy-stable (App. B) where the rise is at round-off.
// Output: CSV on stdout.
#include <algorithm>
#include <cstdio>
#include <vector>

#include "magnetics/kernels/llg.h"

using namespace odemag;

int main() {
  struct Case {
    const char* name;
    Vec3 H_A;
    double H_K;
  };
  const Case cases[] = {{"weak_1e3", {1e3, 0, 0}, 0.0},          {"moderate_2e5", {2e5, 1e5, 0}, 0.0},
                        {"saturating_3e6", {3e6, 0, 1e6}, 0.0},  {"anisotropic_1e5", {1e5, 0, -2e5}, 8e5},
                        {"anisotropic_zero", {0, 0, 0}, 8e5},     {"zero_field", {0, 0, 0}, 0.0}};
  std::printf("tau,case,max_relative_energy_rise,final_relative_torque\n");
  for (double tau : {0.1, 0.25, 0.5, 0.6, 0.7, 0.8, 1.0, 1.5, 2.0}) {
    for (const Case& k : cases) {
      SoftCellParams p;
      p.Ms = 1.7e6;
      p.gamma_D = 1.0 / 3.0 + 1.0 / 5000.0;
      p.H_K = k.H_K;
      p.easy_axis = {0, 0, 1};
      std::vector<Vec3> m = {normalized(Vec3{0.2, 0.9, 0.1}), normalized(Vec3{-0.5, 0.1, 0.8})};
      Vec3 hc_prev[2];
      bool history = false;
      const double c = cayley_coefficient(p, k.H_A, tau), S = llg_field_scale(p, k.H_A);
      double g = cell_free_energy(p, k.H_A, m.data()), worst = 0.0;
      for (int i = 0; i < 3000; ++i) {
        llg_step(p, k.H_A, m.data(), hc_prev, history, c, 0.0, 0);
        const double next = cell_free_energy(p, k.H_A, m.data());
        worst = std::max(worst, (next - g) / S);
        g = next;
      }
      std::printf("%.2f,%s,%.3e,%.3e\n", tau, k.name, worst, cell_torque_residual(p, k.H_A, m.data()));
    }
  }
  return 0;
}
