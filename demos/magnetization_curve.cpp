// The paper's Fig. 11: magnetization M of a single-cell soft magnet against
// the applied field H, swept up to 2 H_s and back, (a) three saturations at
// one demagnetising factor, (b) four demagnetising factors at one
// saturation, next to the theory M = min(H / gamma_D, Ms). Usage:
//   demo_magnetization_curve [OUT_DIR]     (default out/magnetization_curve)
// Writes OUT_DIR/magnetization_curve.csv, .dat and .gp, then runs gnuplot on
// the .gp (no shell) for magnetization_curve.png, reported only when written;
// without gnuplot there is no PNG, which the exit status ignores. Exit 1: the
// curves miss the theory or a file cannot be written; 2: bad command line
// (--help or -h prints the usage).
#include <spawn.h>
#include <sys/wait.h>

#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "cli/cli.h"
#include "magnetics/relax/threads.h"
#include "magnetics/relax/relax.h"

extern char** environ;

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

// A path inside a single-quoted gnuplot string.
std::string gnuplot_quoted(const std::filesystem::path& path) {
  std::string q = "'";
  for (char c : path.string()) q += c == '\'' ? std::string("''") : std::string(1, c);
  return q + "'";
}

// Runs `gnuplot SCRIPT` without a shell: its exit status, or -1 when gnuplot
// is not installed (not on PATH).
int run_gnuplot(const std::filesystem::path& script) {
  std::string arg0 = "gnuplot", arg1 = script.string();
  char* argv[] = {arg0.data(), arg1.data(), nullptr};
  pid_t pid = 0;
  const int err = posix_spawnp(&pid, "gnuplot", nullptr, nullptr, argv, environ);
  if (err == ENOENT) return -1;
  if (err != 0) return 127;
  int raw = 0;
  while (waitpid(pid, &raw, 0) < 0 && errno == EINTR) {
  }
  return WIFEXITED(raw) ? WEXITSTATUS(raw) : 128;
}

const char kUsage[] =
    "usage: demo_magnetization_curve [OUT_DIR]\n"
    "  Sweeps H up and down for the paper's Fig. 11 and writes\n"
    "  OUT_DIR/magnetization_curve.csv (default OUT_DIR: out/magnetization_curve),\n"
    "  and magnetization_curve.png when gnuplot is installed.\n";

// OUT_DIR from the command line; throws cli::UsageError.
std::filesystem::path output_directory(const cli::Arguments& a) {
  if (a.positional.size() > 1) throw cli::UsageError("unexpected argument '" + a.positional[1] + "'");
  const std::filesystem::path out = a.positional.empty() ? "out/magnetization_curve" : a.positional[0];
  if (out.empty()) throw cli::UsageError("OUT_DIR must not be empty");
  return out;
}

int write_curves(const std::filesystem::path& out) {
  std::error_code ec;
  std::filesystem::create_directories(out, ec);
  if (ec) {
    std::fprintf(stderr, "demo_magnetization_curve: %s: %s\n", out.string().c_str(), ec.message().c_str());
    return 1;
  }
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
  if (!csv || !dat) {
    std::fprintf(stderr, "demo_magnetization_curve: cannot write %s\n", out.string().c_str());
    return 1;
  }
  std::printf("largest |M - theory| / Ms over both sweeps: %.2e\n", worst);
  const int status = worst < 5e-3 ? 0 : 1;

  // Blocks 0-2: panel (a); 3-6: panel (b).
  const std::filesystem::path plot = out / "magnetization_curve.gp", png = out / "magnetization_curve.png";
  const std::string data = gnuplot_quoted(out / "magnetization_curve.dat");
  std::ofstream gp(plot);
  gp << "set terminal pngcairo size 1100,450 font ',10'\n"
     << "set output " << gnuplot_quoted(png) << "\n"
     << "set key left top\nset grid\nset xlabel 'H (MA/m)'\nset ylabel 'M (MA/m)'\n"
     << "set multiplot layout 1,2\n"
     << "set title '(a) three saturations, gamma_D = 0.5 (dashed: theory)'\n"
     << "plot for [i=0:2] " << data << " index i using 1:2 with points pt 7 ps 0.5 "
     << "title word('0.5 1.0 1.5', i+1).' MA/m', for [i=0:2] '' index i using 1:3 with lines dt 2 lc rgb 'gray40' notitle\n"
     << "set title '(b) four demagnetising factors, Ms = 1 MA/m'\n"
     << "plot for [i=3:6] " << data << " index i using 1:2 with points pt 7 ps 0.5 "
     << "title 'gamma_D = '.word('0.34 0.5 1 2', i-2), for [i=3:6] '' index i using 1:3 with lines dt 2 lc rgb 'gray40' notitle\n"
     << "unset multiplot\n";
  gp.close();
  const std::string csv_name = (out / "magnetization_curve.csv").string();
  std::filesystem::remove(png, ec);  // a PNG from an earlier run is not this run's
  const int rc = run_gnuplot(plot);
  if (rc == -1)
    std::printf("gnuplot not found: wrote %s and %s (no PNG)\n", csv_name.c_str(), plot.string().c_str());
  else if (rc == 0 && std::filesystem::exists(png))
    std::printf("wrote %s and %s\n", csv_name.c_str(), png.string().c_str());
  else
    std::fprintf(stderr, "demo_magnetization_curve: gnuplot %s wrote no PNG (exit status %d); wrote %s\n",
                 plot.string().c_str(), rc, csv_name.c_str());
  return status;
}

}  // namespace

int main(int argc, char** argv) {
  odemag::restart_with_passive_omp_wait(argv);  // docs/benchmarks.md "Threads and waiting"
  return cli::program_main("demo_magnetization_curve", kUsage, {argv + 1, argv + argc}, {},
                           [](const cli::Arguments& a) { return write_curves(output_directory(a)); });
}
