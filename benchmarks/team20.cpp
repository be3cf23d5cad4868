// TEAM workshop problem 20 (tests/support/team20.h, docs/validation.md
// "TEAM 20"): the force on the steel pole and Bz at the gap probes P1, P2 at
// 1000, 3000, 4500 and 5000 ampere-turns against the measured values, for
// cell edges h (mm), with the setup time (kernel FFTs, coil field), the solve
// time (Newton-GMRES from M = 0 at each excitation), the iterations and the
// field evaluations (matvecs: GMRES iterations, restarts and residuals).
//
// Usage: team20 [--out DIR] [--h 5,2.5x2.5x5,2.5] [--graded 2.5/1.5/10,...]
//               [--graded-name STEM] [--ampere-turns 1000,...] [--threads T]
//               [--newton-variable flux|field] [--dense | --single] [--tolerance T]
// (--h: FFT lattices of edge h, or edges hx x hy x hz, in mm, written to
// DIR/team20.csv and .md; --graded: the quarter model with mirror planes and
// graded cells h_min/growth/h_max (mm; growth 1: uniform),
// team20::GradedProblem, written to DIR/STEM.csv and .md, only when given,
// STEM team20_graded unless --graded-name says otherwise; --ampere-turns: a
// subset of the four excitations; the Newton variable b = H + M, the
// default, or H: magnetics/static/bh_lattice_solve.h; --dense: the quarter's
// operator stored dense instead of as a hierarchical matrix, --single: the
// hierarchical matrix in single precision; --tolerance:
// the solve's, on |G| / |M| of magnetics/static/bh_lattice_solve.h, 1e-4 unless
// given).
// DIR: benchmarks/results. Runs itself again with OMP_WAIT_POLICY=passive
// when that is unset.
#include <omp.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "benchmarks/bench_common.h"
#include "tests/support/team20.h"

using namespace odemag;

namespace {

// "h" or "hx x hy x hz" (mm).
Vec3 edges(const std::string& s) {
  Vec3 h;
  size_t at = 0;
  for (int a = 0; a < 3; ++a) {
    const size_t x = s.find('x', at);
    h[a] = std::stod(s.substr(at, x == std::string::npos ? std::string::npos : x - at));
    if (x == std::string::npos) {
      for (int b = a + 1; b < 3; ++b) h[b] = h[a];
      break;
    }
    at = x + 1;
  }
  return h;
}

struct Row {
  std::string resolution;
  double a, b, c;  // hx, hy, hz (mm), or h_min (mm), growth, h_max (mm)
  int cells, pole_cells, unknown_cells, threads;
  double setup, solve;
};

void write_row(FILE* csv, FILE* md, const Row& w, const team20::Measured& m, const team20::Result& r) {
  const double F = -r.force_pole.z;  // toward the bar
  const double eF = F / m.force - 1.0, e1 = r.Bz_P1 / m.Bz_P1 - 1.0, e2 = r.Bz_P2 / m.Bz_P2 - 1.0;
  const double balance = norm(r.force_from_yoke + r.force_on_yoke) / norm(r.force_from_yoke);
  const bool graded = w.unknown_cells != w.cells;
  std::fprintf(csv, "%.4f,%.4f,%.4f,%d,%d,", w.a, w.b, w.c, w.cells, w.pole_cells);
  if (graded) std::fprintf(csv, "%d,", w.unknown_cells);
  std::fprintf(csv, "%d,%.3f,%.0f,%.3f,%d,%d,%d,%.2e,%.3f,%.1f,%.4f,%.4f,%.2f,%.4f,%.4f,%.2f,%.4f,%.1e\n", w.threads, w.setup,
               m.ampere_turns, w.solve, r.report.newton_iterations, r.report.krylov_iterations, r.report.matvecs,
               r.report.residual, F, m.force, eF, r.Bz_P1, m.Bz_P1, e1, r.Bz_P2, m.Bz_P2, e2, balance);
  std::fprintf(md, "| %s | %d |", w.resolution.c_str(), w.cells);
  if (graded) std::fprintf(md, " %d |", w.unknown_cells);
  std::fprintf(md, " %.2f | %.0f | %.3f | %d / %d / %d | %.2f | %.1f | %+.1f%% | %.3f | %+.1f%% | %.3f | %+.1f%% |\n",
               w.setup, m.ampere_turns, w.solve, r.report.newton_iterations, r.report.krylov_iterations, r.report.matvecs, F,
               m.force, 100 * eF, r.Bz_P1, 100 * e1, r.Bz_P2, 100 * e2);
  std::printf("%s mm cells %d (unknowns %d) AT %.0f: F %.2f N (%+.1f%%) Bz P1 %.3f (%+.1f%%) P2 %.3f (%+.1f%%) solve %.3f s, "
              "%d Newton %d GMRES %d matvecs, residual %.1e, balance %.1e\n",
              w.resolution.c_str(), w.cells, w.unknown_cells, m.ampere_turns, F, 100 * eF, r.Bz_P1, 100 * e1, r.Bz_P2,
              100 * e2, w.solve, r.report.newton_iterations, r.report.krylov_iterations, r.report.matvecs, r.report.residual,
              balance);
  std::fflush(stdout);
}

const char* kColumns =
    "threads,setup_s,ampere_turns,solve_s,newton,gmres,matvecs,residual,force_N,force_measured_N,force_error,Bz_P1_T,"
    "Bz_P1_measured_T,Bz_P1_error,Bz_P2_T,Bz_P2_measured_T,Bz_P2_error,momentum_balance\n";
const char* kTableHead =
    " setup (s) | AT | solve (s) | Newton / GMRES / matvecs | F (N) | meas. | err | Bz P1 (T) | err | Bz P2 (T) | err |\n";

// "h_min/growth/h_max" (mm); h_min 0 when malformed or out of range.
team20::Grading grading(const std::string& spec) {
  const auto parts = bench::split(spec, '/');
  team20::Grading g{0.0, 1.0, 0.0};
  try {
    if (parts.size() == 3) g = {std::stod(parts[0]), std::stod(parts[1]), std::stod(parts[2])};
  } catch (const std::exception&) {
    return {0.0, 1.0, 0.0};
  }
  if (!(g.h_min > 0.0 && g.growth >= 1.0 && g.h_max >= g.h_min && g.h_max < 1e3)) g.h_min = 0.0;
  return g;
}

double seconds_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

}  // namespace

int main(int argc, char** argv) {
  odemag::restart_with_passive_omp_wait(argv);
  std::string out = "benchmarks/results";
  std::vector<std::string> hs = {"5", "2.5x2.5x5", "2.5"}, gradings;
  std::string graded_name = "team20_graded";
  int threads = 2;
  std::vector<double> excitations;  // empty: the four measured
  BhNewtonVariable variable = BhNewtonVariable::flux_density;
  auto storage = team20::GradedProblem::Storage::compressed;
  double tolerance = 1e-4;  // the force is then converged to 5 digits (docs/validation.md "TEAM 20")
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--out") {
      out = bench::option_value(argc, argv, i, "team20");
    } else if (a == "--h") {
      hs = bench::split(bench::option_value(argc, argv, i, "team20"));
    } else if (a == "--graded") {
      gradings = bench::split(bench::option_value(argc, argv, i, "team20"));
    } else if (a == "--graded-name") {
      graded_name = bench::option_value(argc, argv, i, "team20");
      if (graded_name.empty() || graded_name.find('/') != std::string::npos) {
        std::fprintf(stderr, "team20: --graded-name wants a file name stem, not '%s'\n", graded_name.c_str());
        return 2;
      }
    } else if (a == "--ampere-turns") {
      for (const std::string& v : bench::split(bench::option_value(argc, argv, i, "team20"))) excitations.push_back(std::stod(v));
    } else if (a == "--threads") {
      threads = std::stoi(bench::option_value(argc, argv, i, "team20"));
    } else if (a == "--newton-variable" && i + 1 < argc &&
               (std::string(argv[i + 1]) == "flux" || std::string(argv[i + 1]) == "field")) {
      variable = std::string(argv[++i]) == "flux" ? BhNewtonVariable::flux_density : BhNewtonVariable::field;
    } else if (a == "--dense") {
      storage = team20::GradedProblem::Storage::dense;
    } else if (a == "--single") {
      storage = team20::GradedProblem::Storage::compressed_single;
    } else if (a == "--tolerance") {
      try {
        tolerance = std::stod(bench::option_value(argc, argv, i, "team20"));
      } catch (const std::exception&) {
        tolerance = 0.0;
      }
      if (!(tolerance > 0.0 && tolerance < 1.0)) {
        std::fprintf(stderr, "team20: --tolerance wants a number in (0, 1)\n");
        return 2;
      }
    } else {
      std::fprintf(stderr,
                   "usage: team20 [--out DIR] [--h 5,2.5x2.5x5,...] [--graded h_min/growth/h_max,...] [--graded-name STEM] "
                   "[--ampere-turns 1000,...] [--threads T] [--newton-variable flux|field] [--dense | --single] [--tolerance T]\n");
      return 2;
    }
  }
  for (const std::string& spec : gradings)
    if (grading(spec).h_min <= 0.0) {
      std::fprintf(stderr, "team20: a grading is h_min/growth/h_max (mm), 0 < h_min <= h_max, growth >= 1; not %s\n",
                   spec.c_str());
      return 2;
    }
  omp_set_num_threads(threads);
  BhSolveOptions options;
  options.tolerance = tolerance;
  options.variable = variable;
  auto wanted = [&](const team20::Measured& m) {
    return excitations.empty() || std::find(excitations.begin(), excitations.end(), m.ampere_turns) != excitations.end();
  };
  // Each wanted excitation from M = 0 on problem p (team20::Problem or
  // GradedProblem), one row each; w: the row's resolution and sizes.
  auto solve_excitations = [&](const auto& p, Row w, FILE* csv, FILE* md) {
    for (const auto& m : team20::kMeasured) {
      if (!wanted(m)) continue;
      std::vector<Vec3> M(p.demag.cells());
      const auto t1 = std::chrono::steady_clock::now();
      const team20::Result r = team20::solve(p, m.ampere_turns, M, options);
      w.solve = seconds_since(t1);
      write_row(csv, md, w, m, r);
    }
  };
  const char* newton = variable == BhNewtonVariable::flux_density ? "b = H + M" : "H";
  // DIR/<stem>.csv and .md with their headers, the rows of body(csv, md).
  auto reports = [&](const std::string& stem, const std::string& csv_head, const std::string& md_head, const auto& body) {
    FILE *csv = nullptr, *md = nullptr;
    if (!bench::open_reports(out, out + "/" + stem + ".csv", out + "/" + stem + ".md", csv, md)) return false;
    std::fprintf(csv, "%s%s", csv_head.c_str(), kColumns);
    const std::string table = md_head + kTableHead;
    std::fprintf(md, "%s|", table.c_str());
    const long columns = std::count(table.begin() + static_cast<long>(table.rfind("\n\n")), table.end(), '|') - 1;
    for (long c = 0; c < columns; ++c) std::fprintf(md, "---|");
    std::fprintf(md, "\n");
    body(csv, md);
    std::fclose(csv);
    std::fclose(md);
    return true;
  };
  char tolerance_text[32];
  std::snprintf(tolerance_text, sizeof tolerance_text, "%g", tolerance);
  const std::string solve_line =
      std::string(" Solve: Newton-GMRES in ") + newton + " from M = 0, tolerance " + tolerance_text + ".";
  const std::string thread_count = std::to_string(threads) + " thread(s).";
  if (!hs.empty() &&
      !reports("team20", "hx_mm,hy_mm,hz_mm,cells,pole_cells,",
               "# TEAM 20: force on the pole and gap flux density against the measured values\n\n"
               "benchmarks/team20 (docs/validation.md \"TEAM 20\"), " + thread_count + solve_line +
                   " Errors relative to the measured values (COMPEL 14(2/3), 1995).\n\n| h (mm) | cells |",
               [&](FILE* csv, FILE* md) {
                 for (const std::string& hstr : hs) {
                   const Vec3 h = edges(hstr);
                   const auto t0 = std::chrono::steady_clock::now();
                   const team20::Problem p(h, true);
                   const double setup = seconds_since(t0);
                   solve_excitations(p, {hstr, h.x, h.y, h.z, p.demag.cells(), p.pole_cells(), p.demag.cells(), threads, setup, 0.0},
                                     csv, md);
                 }
               }))
    return 1;
  if (!gradings.empty() &&
      !reports(graded_name, "h_min_mm,growth,h_max_mm,cells,pole_cells,unknown_cells,",
               "# TEAM 20 on graded cells with mirror planes\n\n"
               "benchmarks/team20 --graded (docs/validation.md \"TEAM 20\"), " + thread_count +
                   " The quarter x, y >= 0 with its images in x = 0 and y = 0, cells h_min at the refined faces growing by "
                   "`growth` per cell up to h_max (team20::GradedProblem), the sum of magnetics/static/cuboid_demag.h stored " +
                   (storage == team20::GradedProblem::Storage::dense
                        ? "dense"
                        : storage == team20::GradedProblem::Storage::compressed
                              ? "as a hierarchical matrix (magnetics/static/hmatrix.h)"
                              : "as a hierarchical matrix (magnetics/static/hmatrix.h) in single precision") +
                   ", the forces by stored bilinear forms (setup)." +
                   solve_line + " Cells: the whole problem's (four times the unknown cells).\n\n"
                   "| h_min / growth / h_max (mm) | cells | unknown cells |",
               [&](FILE* csv, FILE* md) {
                 for (const std::string& spec : gradings) {
                   const team20::Grading g = grading(spec);
                   const auto t0 = std::chrono::steady_clock::now();
                   const team20::GradedProblem p(g, true, storage);
                   const double setup = seconds_since(t0);
                   solve_excitations(p, {spec, g.h_min, g.growth, g.h_max, p.full_cells(), 4 * p.pole_cells, p.demag.cells(),
                                         threads, setup, 0.0},
                                     csv, md);
                 }
               }))
    return 1;
  return 0;
}
