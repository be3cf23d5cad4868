// The paper's Fig. 11: magnetization M of a single-cell soft magnet against
// the applied field H, swept up to 2 H_s and back, (a) three saturations at
// one demagnetising factor, (b) four demagnetising factors at one
// saturation, next to the theory M = min(H / gamma_D, Ms). Writes CSV and,
// when gnuplot is installed, a PNG. Usage: demo_magnetization_curve [OUT_DIR]
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "magnetics/relax.h"

using namespace odemag;

namespace {

struct CurveMaterial {
  const char* label;
  double Ms, gamma_D;
};

// (H, M along H) over the sweep up and down.
std::vector<std::pair<double, double>> sweep(const CurveMaterial& m, double H_max) {
  MagneticModel model;
  SoftMaterial soft;
  soft.saturation = m.Ms;
  soft.susceptibility = 1.0 / (m.gamma_D - 1.0 / 3.0);
  model.add_body("cell", Sphere{0.005}, soft, 0.0);
  MagneticState state = make_state(model, 11);
  auto backend = make_cpu_backend(1);
  RelaxOptions o;
  o.tolerance = 1e-10;
  std::vector<std::pair<double, double>> curve;
  const int n = 60;
  for (int i = -n; i <= n; ++i) {
    const double H = H_max * (1.0 - std::abs(static_cast<double>(i)) / n);  // 0 -> H_max -> 0
    state.external_field = {0, 0, H};
    relax(model, state, o, *backend);
    curve.push_back({H, state.magnetization[0].z});
  }
  return curve;
}

}  // namespace

int main(int argc, char** argv) {
  const std::filesystem::path out = argc > 1 ? argv[1] : "out/magnetization_curve";
  std::filesystem::create_directories(out);
  const CurveMaterial panel_a[] = {{"Ms = 0.5 MA/m", 0.5e6, 0.5}, {"Ms = 1.0 MA/m", 1.0e6, 0.5}, {"Ms = 1.5 MA/m", 1.5e6, 0.5}};
  const CurveMaterial panel_b[] = {{"gamma_D = 0.34", 1.0e6, 0.34}, {"gamma_D = 0.5", 1.0e6, 0.5},
                              {"gamma_D = 1", 1.0e6, 1.0}, {"gamma_D = 2", 1.0e6, 2.0}};
  std::ofstream csv(out / "magnetization_curve.csv");
  std::ofstream dat(out / "magnetization_curve.dat");  // one gnuplot block per material
  csv << "panel,material,Ms,gamma_D,H,M,M_theory\n";
  double worst = 0.0;
  auto run_panel = [&](const char* panel, const CurveMaterial* materials, int count, double H_max) {
    for (int k = 0; k < count; ++k) {
      const CurveMaterial& m = materials[k];
      dat << "# " << panel << " " << m.label << "\n";
      for (const auto& [H, M] : sweep(m, H_max)) {
        const double theory = std::min(H / m.gamma_D, m.Ms);
        worst = std::max(worst, std::abs(M - theory) / m.Ms);
        csv << panel << ",\"" << m.label << "\"," << m.Ms << "," << m.gamma_D << "," << H << "," << M << ","
            << theory << "\n";
        dat << H / 1e6 << " " << M / 1e6 << " " << theory / 1e6 << "\n";
      }
      dat << "\n\n";
    }
  };
  run_panel("a", panel_a, 3, 1.5e6);
  run_panel("b", panel_b, 4, 2.5e6);
  csv.close();
  dat.close();
  std::printf("largest |M - theory| / Ms over both sweeps: %.2e\n", worst);

  // Blocks 0-2: panel (a); 3-6: panel (b).
  const std::filesystem::path plot = out / "magnetization_curve.gp";
  const std::string data = (out / "magnetization_curve.dat").string();
  std::ofstream gp(plot);
  gp << "set terminal pngcairo size 1100,450 font ',10'\n"
     << "set output '" << (out / "magnetization_curve.png").string() << "'\n"
     << "set key left top\nset grid\nset xlabel 'H (MA/m)'\nset ylabel 'M (MA/m)'\n"
     << "set multiplot layout 1,2\n"
     << "set title '(a) three saturations, gamma_D = 0.5 (dashed: theory)'\n"
     << "plot for [i=0:2] '" << data << "' index i using 1:2 with points pt 7 ps 0.5 "
     << "title word('0.5 1.0 1.5', i+1).' MA/m', for [i=0:2] '' index i using 1:3 with lines dt 2 lc rgb 'gray40' notitle\n"
     << "set title '(b) four demagnetising factors, Ms = 1 MA/m'\n"
     << "plot for [i=3:6] '" << data << "' index i using 1:2 with points pt 7 ps 0.5 "
     << "title 'gamma_D = '.word('0.34 0.5 1 2', i-2), for [i=3:6] '' index i using 1:3 with lines dt 2 lc rgb 'gray40' notitle\n"
     << "unset multiplot\n";
  gp.close();
  if (std::system("command -v gnuplot >/dev/null 2>&1") == 0) {
    const std::string command = "gnuplot '" + plot.string() + "'";
    if (std::system(command.c_str()) == 0)
      std::printf("wrote %s\n", (out / "magnetization_curve.png").string().c_str());
  } else {
    std::printf("gnuplot not found: wrote %s and %s\n", (out / "magnetization_curve.csv").string().c_str(),
                plot.string().c_str());
  }
  return worst < 5e-3 ? 0 : 1;
}
