// The stability suite as a report (docs/hard-cases.md): runs every
// hard case of tests/engine/stability_test.cpp (same scenes, from
// tests/support/stability_cases.h), longer where the test is kept short, and
// writes DIR/stability.csv and DIR/stability.md.
//
//   stability_report [--out DIR] [--crane-duration T] [--only SUBSTRING]
//
// Run from the repository root with DIR = benchmarks/results.
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <sstream>
#include <string>
#include <vector>

#include "tests/support/stability_cases.h"

#ifndef ODEMAG_SOURCE_DIR
#define ODEMAG_SOURCE_DIR "."
#endif

namespace odemag::stability {
namespace {

struct Row {
  std::string group, parameter;
  CaseResult result;
  bool overlapping = false;  // bodies started inside each other
  std::string check;         // a case-specific number (moment against theory), or empty
};

// The energy rise relative to the energy available to motion (0 when none is).
double relative_rise(const Row& row) {
  const double a = available_energy(row.result, row.overlapping);
  return row.result.max_energy_rise > 0.0 ? row.result.max_energy_rise / std::max(a, 1e-300) : 0.0;
}

std::string number(double x, int digits = 3) {
  char b[48];
  std::snprintf(b, sizeof b, "%.*g", digits, x);
  return b;
}

std::string csv_line(const Row& row) {
  const CaseResult& r = row.result;
  std::ostringstream o;
  o << row.group << "," << row.parameter << "," << r.bodies << "," << r.cells << "," << r.time_step
    << "," << r.duration << "," << r.steps << "," << r.max_substeps << "," << r.max_substeps_wanted
    << "," << r.iterations << "," << r.max_step_iterations << "," << (r.converged ? 1 : 0) << ","
    << number(r.max_speed, 6) << "," << number(r.max_angular_speed, 6) << ","
    << number(r.max_force, 6) << "," << number(r.max_torque, 6) << ","
    << (r.has_magnetic_energy ? 1 : 0) << "," << number(r.initial_energy, 9) << ","
    << number(r.initial_magnetic_energy, 9) << "," << number(r.max_energy_rise, 6) << ","
    << number(available_energy(r, row.overlapping), 6) << "," << number(relative_rise(row), 6)
    << "," << number(r.max_kinetic, 6) << "," << number(r.min_ground_clearance, 6) << ","
    << number(r.max_penetration, 6) << "," << number(r.final_penetration, 6) << ","
    << number(r.largest_magnetization_ratio, 12) << "," << (r.finite ? 1 : 0) << ","
    << number(r.wall_seconds, 4) << "," << row.check;
  return o.str();
}

std::string md_line(const Row& row) {
  const CaseResult& r = row.result;
  std::ostringstream o;
  const std::string rise = number(r.max_energy_rise, 2) + " / " +
                           number(available_energy(r, row.overlapping), 2) + " J" +
                           (r.has_magnetic_energy ? "" : " no U_m");
  o << "| " << row.group << " | " << row.parameter << " | " << r.bodies << " / " << r.cells << " | "
    << number(r.time_step * 1e3, 3) << " ms x " << r.steps << " | " << r.max_substeps
    << (r.max_substeps_wanted > r.max_substeps
            ? " (wanted " + std::to_string(r.max_substeps_wanted) + ")"
            : "")
    << " | " << r.iterations << " (" << r.max_step_iterations << ")"
    << (r.converged ? "" : " not conv.") << " | " << number(r.max_speed, 3) << " | "
    << number(r.max_force, 3) << " | " << rise << " | "
    << (std::isfinite(r.min_ground_clearance) ? number(r.min_ground_clearance, 3)
                                              : std::string("-"))
    << " | "
    << (r.bodies > 1 && r.bodies <= kPenetrationBodies
            ? number(r.max_penetration, 3) + " / " + number(r.final_penetration, 3)
            : std::string("-"))
    << " | "
    << (r.largest_magnetization_ratio > 0 ? number(r.largest_magnetization_ratio, 10)
                                          : std::string("-"))
    << " | " << (r.finite ? "yes" : "NO") << " | " << number(r.wall_seconds, 3) << " | "
    << (row.check.empty() ? "-" : row.check) << " |";
  return o.str();
}

// Relative error of a soft sphere's moment against the uniform sphere:
// m = V 3 chi / (chi + 3) H below saturation, V Ms H/|H| above.
double sphere_moment_error(const Vec3& moment, double R, double chi, double Ms, double H) {
  const double V = 4.0 / 3.0 * kPi * R * R * R;
  const double linear = std::isinf(chi) ? 3.0 : 3.0 * chi / (chi + 3.0);
  const double M = std::min(linear * H, Ms);
  return norm(moment - Vec3{0, 0, V * M}) / (V * M);
}

}  // namespace
}  // namespace odemag::stability

int main(int argc, char** argv) {
  using namespace odemag;
  using namespace odemag::stability;
  std::string out_dir = "benchmarks/results", only;
  double crane_duration = 1.0;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--out" && i + 1 < argc) {
      out_dir = argv[++i];
    } else if (a == "--crane-duration" && i + 1 < argc) {
      crane_duration = std::atof(argv[++i]);
    } else if (a == "--only" && i + 1 < argc) {
      only = argv[++i];
    } else {
      std::fprintf(stderr,
                   "usage: stability_report [--out DIR] [--crane-duration T] [--only SUBSTRING]\n");
      return 2;
    }
  }

  std::vector<Row> rows;
  auto run = [&](const std::string& group, const std::string& parameter,
                 const SceneDescription& scene, const RunOptions& options,
                 const std::function<std::string(const CaseResult&)>& check = {},
                 bool overlapping = false) {
    if (!only.empty() && (group + " " + parameter).find(only) == std::string::npos) return;
    Row row{group, parameter, run_case(group, scene, options), overlapping, ""};
    if (check) row.check = check(row.result);
    std::fprintf(stderr, "%s\n", md_line(row).c_str());
    rows.push_back(row);
  };
  RunOptions half_second;
  half_second.duration = 0.5;

  // Coincident cell centres and interpenetration.
  run("coincident", "two magnets", coincident_magnets(), half_second, {}, true);
  run("coincident", "magnet + soft ball", coincident_magnet_and_ball(), half_second, {}, true);
  run("coincident", "two lattice magnets", coincident_lattice_magnets(), half_second, {}, true);
  run("interpenetrating", "ball half inside magnet", ball_half_inside_magnet(), half_second, {},
      true);
  run("interpenetrating", "two magnets overlapping", overlapping_magnets(), half_second, {}, true);

  // 10 ms steps with NdFeB, and the same scene at 1 ms for comparison.
  RunOptions one_second;
  one_second.duration = 1.0;
  for (double dt : {0.010, 0.004, 0.001})
    run("strong magnets", "dt " + number(dt * 1e3) + " ms", strong_magnets(dt), one_second);

  // Crane heap.
  {
    RunOptions crane;
    crane.duration = crane_duration;
    crane.magnetic_energy = false;
    for (int balls : {1000}) {
      const SceneDescription s = crane_scene(balls, ODEMAG_SOURCE_DIR);
      run("crane heap", std::to_string(balls) + " balls, " + number(crane_duration) + " s", s,
          crane);
    }
  }

  // External fields, soft and permanent balls.
  RunOptions short_run;
  short_run.duration = 0.1;
  for (int e = -3; e <= 7; ++e) {
    const double H = std::pow(10.0, e);
    run("field, soft ball", "H = 1e" + std::to_string(e) + " A/m", ball_in_field(H, false),
        short_run, [&](const CaseResult& r) {
          return "moment error " +
                 number(sphere_moment_error(r.final_moments[0], 0.005, 5000.0, 1.7e6, H), 2);
        });
  }
  for (int e = -3; e <= 7; ++e) {
    const double H = std::pow(10.0, e);
    run("field, magnet", "H = 1e" + std::to_string(e) + " A/m", ball_in_field(H, true),
        half_second);
  }
  for (int e = -3; e <= 7; e += 2) {
    const double H = std::pow(10.0, e);
    run("field, soft lattice ball", "H = 1e" + std::to_string(e) + " A/m",
        ball_in_field(H, false, 5000.0, 0.002), short_run, [&](const CaseResult& r) {
          return "moment vs sphere " +
                 number(sphere_moment_error(r.final_moments[0], 0.005, 5000.0, 1.7e6, H), 2);
        });
  }

  // Susceptibility.
  std::vector<double> chis;
  for (int e = 0; e <= 6; ++e) chis.push_back(std::pow(10.0, e));
  chis.push_back(std::numeric_limits<double>::infinity());
  for (double chi : chis) {
    const std::string p = std::isinf(chi) ? "chi = inf" : "chi = 1e" + number(std::log10(chi));
    run("susceptibility, field", p + ", one cell", ball_in_field(1e3, false, chi), short_run,
        [&](const CaseResult& r) {
          return "moment error " +
                 number(sphere_moment_error(r.final_moments[0], 0.005, chi, 1.7e6, 1e3), 2);
        });
    run("susceptibility, field", p + ", lattice", ball_in_field(1e3, false, chi, 0.002), short_run,
        [&](const CaseResult& r) {
          return "moment vs sphere " +
                 number(sphere_moment_error(r.final_moments[0], 0.005, chi, 1.7e6, 1e3), 2);
        });
    run("susceptibility, onto magnet", p + ", one cell", soft_ball_onto_magnet(chi, 0.0),
        half_second);
    run("susceptibility, onto magnet", p + ", lattice", soft_ball_onto_magnet(chi, 0.003),
        half_second);
  }

  // Object size; 1 mm objects also with enough substeps, or a shorter step.
  for (int e = -3; e <= 0; ++e) {
    const double scale = std::pow(10.0, e);
    run("size", "scale 1e" + std::to_string(e), scaled_ball_onto_magnet(scale), one_second);
  }
  {
    SceneDescription s = scaled_ball_onto_magnet(1e-3);
    s.simulation.max_substeps = 1024;
    run("size", "scale 1e-3, max_substeps 1024", s, one_second);
    s = scaled_ball_onto_magnet(1e-3);
    s.simulation.time_step = 0.0005;
    run("size", "scale 1e-3, dt 0.5 ms", s, one_second);
  }

  // Outputs.
  std::filesystem::create_directories(out_dir);
  {
    std::ofstream csv(out_dir + "/stability.csv");
    csv << "case,parameter,bodies,cells,time_step,duration,steps,max_substeps,max_substeps_wanted,"
           "iterations,max_step_iterations,"
           "converged,max_speed,max_angular_speed,max_force,max_torque,has_magnetic_energy,initial_"
           "energy,"
           "initial_magnetic_energy,max_energy_rise,available_energy,relative_energy_rise,max_"
           "kinetic,min_ground_clearance,"
           "max_penetration,final_penetration,"
           "max_magnetization_ratio,finite,wall_seconds,check\n";
    for (const Row& row : rows) csv << csv_line(row) << "\n";
  }
  {
    std::ofstream md(out_dir + "/stability.md");
    md << "# Stability suite results\n\n"
          "Written by `build/bin/stability_report --out benchmarks/results` "
          "(benchmarks/stability_report.cpp; "
          "scenes in tests/support/stability_cases.h, asserted on by "
          "tests/engine/stability_test.cpp; "
          "discussion in docs/hard-cases.md). Every number is sampled at every substep. Columns: "
          "bodies / "
          "cells; rigid step x steps; the most substeps of a step (and, when the substep rule "
          "wanted more "
          "than max_substeps, how many); outer relaxation iterations in all (the most in one "
          "step); the largest "
          "speed (m/s) and magnetic force (N) of any body; energy rise: the largest rise of E = "
          "kinetic + "
          "gravity + magnetic free energy above E(0), next to the energy that motion can "
          "physically take up "
          "(the drop of the potential energy along the run, plus for bodies started inside each "
          "other the "
          "work of separating them against the overlap core); \"no U_m\": the magnetic energy is "
          "not tracked "
          "(electromagnets), E = kinetic + gravity; ground clearance: the lowest point of any "
          "dynamic body above "
          "the floor in units of its smallest half extent (-0.05: a ball 5% of its radius into the "
          "floor); "
          "penetration: the deepest overlap of two bodies (ODE's contact depth less the collision "
          "skins) in "
          "units of the smaller one's smallest half extent, over the run and at its end; the "
          "largest |M| / Ms "
          "of a soft cell; whether every number stayed finite; wall time in s (one thread, a "
          "shared 2-core "
          "machine); check: the moment against the uniform sphere (linear below saturation, Ms V "
          "above).\n\n"
          "| case | parameter | bodies / cells | steps | substeps | iterations | max abs(v) | max "
          "abs(F) | "
          "energy rise | ground clearance | penetration max / end | max abs(M)/Ms | finite | wall "
          "s | check |\n"
          "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|\n";
    for (const Row& row : rows) md << md_line(row) << "\n";
  }
  return 0;
}
