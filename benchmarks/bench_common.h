// Small pieces shared by the benchmark programs.
#pragma once

#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <sstream>
#include <string>
#include <vector>

#include "odemag/material.h"
#include "magnetics/model/model.h"
#include "magnetics/kernels/rng.h"
#include "magnetics/model/state.h"
#include "magnetics/relax/threads.h"

namespace odemag::bench {

// The value of command-line option argv[i] (argv[i + 1], and i moves on to
// it); when the option is last, says "<program>: <option> needs a value" and
// exits with status 2.
inline std::string option_value(int argc, char** argv, int& i, const char* program) {
  if (i + 1 >= argc) {
    std::fprintf(stderr, "%s: %s needs a value\n", program, argv[i]);
    std::exit(2);
  }
  return argv[++i];
}

// Opens the CSV and the markdown report for writing; false (the reason on
// stderr, for out_dir) when either cannot be opened.
inline bool open_reports(const std::string& out_dir, const std::string& csv_path, const std::string& md_path,
                         FILE*& csv, FILE*& md) {
  csv = std::fopen(csv_path.c_str(), "w");
  md = std::fopen(md_path.c_str(), "w");
  if (!csv || !md) {
    std::perror(out_dir.c_str());
    return false;
  }
  return true;
}

// "a,b,c" -> {"a", "b", "c"} (or at another separator).
inline std::vector<std::string> split(const std::string& s, char separator = ',') {
  std::vector<std::string> out;
  std::stringstream in(s);
  std::string item;
  while (std::getline(in, item, separator)) out.push_back(item);
  return out;
}

// N soft one-cell steel balls (R = 5 mm, chi 1000, Ms 1.6e6 A/m) scattered in
// a cube of side 11 mm x N^(1/3), magnetized randomly (5e5 A/m): a crane heap
// for the pair kernels.
struct BallHeap {
  MagneticModel model;
  MagneticState state;
  explicit BallHeap(int n) {
    SoftMaterial steel;
    steel.saturation = 1.6e6;
    steel.susceptibility = 1000;
    const double side = 0.011 * std::cbrt(static_cast<double>(n));
    for (int i = 0; i < n; ++i) model.add_body(std::to_string(i), Sphere{0.005}, steel, 0.0);
    state = make_state(model, 5);
    for (int i = 0; i < n; ++i) {
      state.pose[i].position = side * Vec3{unit_interval(hash_key(1, i, 0, 0)), unit_interval(hash_key(1, i, 1, 0)),
                                           unit_interval(hash_key(1, i, 2, 0))};
      state.magnetization[i] = 5e5 * random_unit_vector(hash_key(2, i, 0, 0));
    }
    for (int i = 0; i < n; ++i) state.cell_position[i] = state.pose[i].position;
  }
};

}  // namespace odemag::bench
