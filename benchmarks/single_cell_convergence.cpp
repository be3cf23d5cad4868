// Iterations and error of the per-cell relaxation against the exact single-cell
// answer M = min(|H_A| / gamma_D, Ms) along H_A, for |H_A| = 1e1 .. 1e7 A/m
// (docs/model.md "Relaxation: two levels instead of Algorithm 1" shows it).
// Compares the paper's plain LLG iteration (Algorithm 1 on one cell) with the
// two-level inner solver.
// Output: CSV on stdout.
#include <cmath>
#include <cstdio>
#include <vector>

#include "magnetics/kernels/llg.h"
#include "magnetics/kernels/rng.h"

using namespace odemag;

int main() {
  std::printf("scheme,moments_per_cell,H_A,llg_steps,newton_steps,relative_error\n");
  const double Ms = 1.7e6, chi = 5000.0;
  for (int n : {2, 4}) {
    for (double H = 1e1; H <= 1.01e7; H *= 10.0) {
      SoftCellParams p;
      p.Ms = Ms;
      p.gamma_D = 1.0 / 3.0 + 1.0 / chi;
      p.easy_axis = {0, 0, 1};
      p.n = n;
      const Vec3 H_A = H * normalized(Vec3{1.0, 0.4, -0.2});
      const double exact = std::fmin(H / p.gamma_D, Ms);
      auto error = [&](const std::vector<Vec3>& m) {
        const Vec3 M = Ms * mean_moment(m.data(), n);
        return norm(M - exact * normalized(H_A)) / exact;
      };
      for (int scheme = 0; scheme < 2; ++scheme) {
        std::vector<Vec3> m(n), hc(n);
        for (int k = 0; k < n; k += 2) {
          m[k] = random_unit_vector(hash_key(3, 0, k, 0));
          m[k + 1] = -m[k];
        }
        bool history = false;
        uint64_t counter = 0;
        LocalRelaxOptions o;
        LocalRelaxResult r{};
        if (scheme == 0) {  // paper: plain LLG steps until 1e-6 relative error or 20000 steps
          o.single_step = true;
          o.tolerance = 0.0;
          long steps = 0;
          while (error(m) > 1e-6 && steps < 20000) {
            relax_soft_cell(p, H_A, m.data(), hc.data(), history, counter, 11, o);
            ++steps;
          }
          r.llg_steps = static_cast<int>(steps);
        } else {
          r = relax_soft_cell(p, H_A, m.data(), hc.data(), history, counter, 11, o);
        }
        std::printf("%s,%d,%.0e,%d,%d,%.3e\n", scheme == 0 ? "llg" : "two_level", n, H, r.llg_steps,
                    r.newton_steps, error(m));
      }
    }
  }
  return 0;
}
