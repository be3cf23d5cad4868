// Validation against finite-element fields (docs/validation.md).
//
// Two ANSYS data sets (benchmarks/data/*/README.md): three recoil magnets of
// different orientations (fem-cuboids), and one recoil magnet next to a
// soft-iron cube of chi = 3999 (fem-softmag). Each cuboid becomes a Box body
// on a lattice of spacing h = (shortest edge) / k: magnets as recoil
// permanent material M = J / mu0 + chi H_inside, the soft cube as a linear
// material without remanence (PermanentMaterial{0, chi}) or as an LLG soft
// material far from saturation (SoftMaterial{Ms = 1e7, chi}). After the
// relaxation, B along the sensor lines (field_at_points) is compared with the
// FEM values: relative RMS error sqrt(sum |B - B_fem|^2 / sum |B_fem|^2) per
// line and over all lines (components the data set gives only).
//
// Variants: recoil / soft_linear (the data set's susceptibilities), chi0
// (magnets without recoil: uniformly magnetized cuboids), for fem-cuboids also
// recoil with the point-dipole intra-body tensor, for fem-softmag also the
// LLG soft cube with Ms = 1e7 A/m (soft_llg, unsaturated) and with an iron's
// Ms = 1.6e6 A/m (soft_llg_iron), and the magnet alone (no cube).
//
// Usage: fem_validation [--data DIR] [--profiles DIR] [--max-k K]
//                       [--threads N] [--budget SECONDS] [--tolerance T]
// CSV on stdout; with --profiles, B along the lines (FEM and each variant at
// its finest h) in DIR/fem_<dataset>_profile.csv.
#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "magnetics/model/backend.h"
#include "odemag/constants.h"
#include "magnetics/relax/relax.h"

using namespace odemag;

namespace {

struct Cuboid {
  Vec3 size;      // full edges, m
  Vec3 position;  // centre, world, m
  Mat3 rotation;  // cuboid frame -> world
  Vec3 J;         // remanent polarization mu0 M_r, cuboid frame, T
  double chi = 0.0;
  bool soft() const { return norm(J) == 0.0 && chi > 0.0; }
};

struct SensorLine {
  Vec3 first, last;
  std::vector<double> distance_mm;  // from the data file
  std::vector<Vec3> B_fem;          // T; components not given are 0
  std::vector<Vec3> points;         // world, m
};

struct Dataset {
  std::string name;
  std::vector<Cuboid> cuboids;
  std::vector<SensorLine> lines;
  std::array<bool, 3> given{true, true, true};  // which B components the data has
  double shortest_edge = 0.0;
};

Vec3 vec(const nlohmann::json& a) { return {a.at(0).get<double>(), a.at(1).get<double>(), a.at(2).get<double>()}; }

std::vector<double> split_numbers(const std::string& line) {
  std::vector<double> v;
  std::stringstream ss(line);
  std::string cell;
  while (std::getline(ss, cell, ',')) v.push_back(std::stod(cell));
  return v;
}

Dataset load(const std::filesystem::path& dir) {
  Dataset d;
  d.name = dir.filename().string();
  std::ifstream js(dir / "setup.json");
  if (!js) throw std::runtime_error("cannot open " + (dir / "setup.json").string());
  const nlohmann::json setup = nlohmann::json::parse(js);
  d.shortest_edge = 1e300;
  for (const auto& m : setup.at("magnets")) {
    if (m.at("shape").get<std::string>() != "cuboid") throw std::runtime_error("only cuboids");
    Cuboid c;
    c.size = vec(m.at("dimension"));
    c.position = vec(m.at("position"));
    const auto& R = m.at("rotation_matrix");
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) c.rotation.m[i][j] = R.at(i).at(j).get<double>();
    c.J = vec(m.at("polarization"));
    c.chi = m.at("susceptibility").get<double>();
    d.shortest_edge = std::min({d.shortest_edge, c.size.x, c.size.y, c.size.z});
    d.cuboids.push_back(c);
  }
  for (const auto& l : setup.at("sensor_lines")) {
    SensorLine s;
    s.first = vec(l.at("first"));
    s.last = vec(l.at("last"));
    d.lines.push_back(s);
  }
  std::ifstream csv(dir / "data.csv");
  if (!csv) throw std::runtime_error("cannot open " + (dir / "data.csv").string());
  std::string line;
  std::getline(csv, line);  // header
  const size_t n_lines = d.lines.size();
  while (std::getline(csv, line)) {
    if (line.empty()) continue;
    const std::vector<double> v = split_numbers(line);
    const bool xyz = v.size() == 1 + 3 * n_lines, xz = v.size() == 1 + 2 * n_lines;
    if (!xyz && !xz) throw std::runtime_error("unexpected column count in " + d.name);
    if (xz) d.given = {true, false, true};
    for (size_t i = 0; i < n_lines; ++i) {
      SensorLine& s = d.lines[i];
      s.distance_mm.push_back(v[0]);
      s.B_fem.push_back(xyz ? Vec3{v[1 + 3 * i], v[2 + 3 * i], v[3 + 3 * i]}
                            : Vec3{v[1 + 2 * i], 0.0, v[2 + 2 * i]});
    }
  }
  for (SensorLine& s : d.lines) {
    const Vec3 dir_unit = normalized(s.last - s.first);
    for (double mm : s.distance_mm) s.points.push_back(s.first + (1e-3 * mm) * dir_unit);
  }
  return d;
}

enum class SoftModel { linear, llg, iron };

struct Variant {
  std::string name;
  bool recoil = true;            // magnets keep their chi (false: chi = 0)
  bool include_soft = true;      // the soft cube is present
  SoftModel soft = SoftModel::linear;
  IntraBodyTensor tensor = IntraBodyTensor::cell_average;
};

struct RunResult {
  int k = 0;
  int cells = 0;
  RelaxReport report;
  double relax_s = 0.0, probe_s = 0.0;
  std::vector<double> line_error;
  double total_error = 0.0;
  double max_M_soft = 0.0;           // largest |M| of the soft cube's cells, A/m
  std::vector<std::vector<Vec3>> B;  // per line
};

double seconds_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

RunResult run(const Dataset& d, const Variant& v, double h, const RelaxOptions& options,
              MagneticBackend& backend) {
  MagneticModel model(v.tensor);
  std::vector<int> cuboid_of_body;
  for (size_t i = 0; i < d.cuboids.size(); ++i) {
    const Cuboid& c = d.cuboids[i];
    Material material;
    if (c.soft()) {
      if (!v.include_soft) continue;
      if (v.soft == SoftModel::linear) {
        material = PermanentMaterial{{0.0, 0.0, 0.0}, c.chi};
      } else {
        SoftMaterial s;
        // llg: far above the fields here (unsaturated, linear, as the FEM
        // model); iron: a real iron's saturation, to show what it changes.
        s.saturation = v.soft == SoftModel::llg ? 1e7 : 1.6e6;
        s.susceptibility = c.chi;
        material = s;
      }
    } else {
      material = PermanentMaterial{(1.0 / kMu0) * c.J, v.recoil ? c.chi : 0.0};
    }
    model.add_body("cuboid" + std::to_string(i), Box{c.size}, material, h);
    cuboid_of_body.push_back(static_cast<int>(i));
  }
  RunResult r;
  r.cells = model.cell_count();
  // Cold relaxations from the same start, repeated while they take less than
  // 0.5 s in all (at most 5): the best time.
  MagneticState state;
  double spent = 0.0;
  r.relax_s = 1e300;
  for (int rep = 0; rep < 5 && (rep == 0 || spent < 0.5); ++rep) {
    state = make_state(model, 1);
    for (int b = 0; b < model.body_count(); ++b) {
      const Cuboid& c = d.cuboids[cuboid_of_body[b]];
      state.pose[b].rotation = c.rotation;
      state.pose[b].position = c.position;
    }
    const auto t_rep = std::chrono::steady_clock::now();
    r.report = relax(model, state, options, backend);
    const double t = seconds_since(t_rep);
    r.relax_s = std::min(r.relax_s, t);
    spent += t;
  }
  for (int b = 0; b < model.body_count(); ++b) {
    if (!d.cuboids[cuboid_of_body[b]].soft()) continue;
    const MagneticBody& body = model.body(b);
    for (int i = 0; i < body.cell_count(); ++i)
      r.max_M_soft = std::max(r.max_M_soft, norm(state.magnetization[body.first_cell + i]));
  }

  const auto t0 = std::chrono::steady_clock::now();
  double num_all = 0.0, den_all = 0.0;
  for (const SensorLine& s : d.lines) {
    std::vector<Vec3> B, H;
    field_at_points(model, state, backend, s.points, B, H);
    double num = 0.0, den = 0.0;
    for (size_t p = 0; p < B.size(); ++p)
      for (int a = 0; a < 3; ++a) {
        if (!d.given[a]) continue;
        const double e = B[p][a] - s.B_fem[p][a];
        num += e * e;
        den += s.B_fem[p][a] * s.B_fem[p][a];
      }
    r.line_error.push_back(std::sqrt(num / den));
    num_all += num;
    den_all += den;
    r.B.push_back(std::move(B));
  }
  r.probe_s = seconds_since(t0);
  r.total_error = std::sqrt(num_all / den_all);
  return r;
}

void write_profile(const std::filesystem::path& file, const Dataset& d,
                   const std::vector<std::pair<std::string, RunResult>>& finest, int stride) {
  std::FILE* f = std::fopen(file.string().c_str(), "w");
  if (!f) throw std::runtime_error("cannot write " + file.string());
  for (const auto& [name, r] : finest) std::fprintf(f, "# %s: k = %d, %d cells\n", name.c_str(), r.k, r.cells);
  std::fprintf(f, "line,distance_mm,Bx_fem,By_fem,Bz_fem");
  for (const auto& [name, r] : finest) std::fprintf(f, ",Bx_%s,By_%s,Bz_%s", name.c_str(), name.c_str(), name.c_str());
  std::fprintf(f, "\n");
  for (size_t l = 0; l < d.lines.size(); ++l) {
    const SensorLine& s = d.lines[l];
    for (size_t p = 0; p < s.points.size(); ++p) {
      if (p % static_cast<size_t>(stride) != 0 && p + 1 != s.points.size()) continue;
      std::fprintf(f, "%zu,%.6g", l, s.distance_mm[p]);
      for (int a = 0; a < 3; ++a) {
        if (d.given[a]) std::fprintf(f, ",%.6g", s.B_fem[p][a]);
        else std::fprintf(f, ",");
      }
      for (const auto& [name, r] : finest)
        std::fprintf(f, ",%.6g,%.6g,%.6g", r.B[l][p].x, r.B[l][p].y, r.B[l][p].z);
      std::fprintf(f, "\n");
    }
    std::fprintf(f, "\n\n");  // gnuplot data blocks, one per line
  }
  std::fclose(f);
}

}  // namespace

int main(int argc, char** argv) {
  std::filesystem::path data_dir = std::filesystem::path(__FILE__).parent_path() / "data";
  std::filesystem::path profile_dir;
  int max_k = 16, threads = 2;
  double budget = 90.0, tolerance = 1e-8;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    auto next = [&]() -> std::string {
      if (i + 1 >= argc) throw std::runtime_error(a + " needs a value");
      return argv[++i];
    };
    if (a == "--data") data_dir = next();
    else if (a == "--profiles") profile_dir = next();
    else if (a == "--max-k") max_k = std::stoi(next());
    else if (a == "--threads") threads = std::stoi(next());
    else if (a == "--budget") budget = std::stod(next());
    else if (a == "--tolerance") tolerance = std::stod(next());
    else {
      std::fprintf(stderr, "unknown argument %s\n", a.c_str());
      return 2;
    }
  }
  RelaxOptions options;
  options.tolerance = tolerance;
  options.max_iterations = 2000;
  auto backend = make_cpu_backend(threads);

  const std::vector<int> divisions = {1, 2, 4, 6, 8, 12, 16, 24, 32};
  std::printf("dataset,variant,k,h_mm,cells,iterations,converged,residual,relax_s,probe_s,"
              "err_line0,err_line1,err_line2,err_total,max_M_soft\n");
  std::fflush(stdout);
  for (const char* name : {"fem-cuboids", "fem-softmag"}) {
    const Dataset d = load(data_dir / name);
    std::vector<Variant> variants;
    if (d.name == "fem-cuboids") {
      variants = {{"recoil", true, true, SoftModel::linear, IntraBodyTensor::cell_average},
                  {"chi0", false, true, SoftModel::linear, IntraBodyTensor::cell_average},
                  {"recoil_point_dipole", true, true, SoftModel::linear, IntraBodyTensor::point_dipole}};
    } else {
      variants = {{"soft_linear", true, true, SoftModel::linear, IntraBodyTensor::cell_average},
                  {"soft_llg", true, true, SoftModel::llg, IntraBodyTensor::cell_average},
                  {"soft_llg_iron", true, true, SoftModel::iron, IntraBodyTensor::cell_average},
                  {"chi0", false, true, SoftModel::linear, IntraBodyTensor::cell_average},
                  {"magnet_alone", true, false, SoftModel::linear, IntraBodyTensor::cell_average}};
    }
    std::vector<std::pair<std::string, RunResult>> finest;
    for (const Variant& v : variants) {
      RunResult last;
      int last_cells = 0;
      double last_time = 0.0;
      for (int k : divisions) {
        if (k > max_k) break;
        const double h = d.shortest_edge / k;
        // Predict the cost from the last run (O(N^2) fields, iterations ~ same).
        double cells_estimate = 0.0;
        for (const Cuboid& c : d.cuboids) {
          if (c.soft() && !v.include_soft) continue;
          cells_estimate += std::round(c.size.x / h) * std::round(c.size.y / h) * std::round(c.size.z / h);
        }
        if (last_cells > 0 && last_time * std::pow(cells_estimate / last_cells, 2.0) > budget) {
          std::fprintf(stderr, "%s %s: skipping k = %d and finer (predicted %.0f s > budget %.0f s)\n",
                       d.name.c_str(), v.name.c_str(), k,
                       last_time * std::pow(cells_estimate / last_cells, 2.0), budget);
          break;
        }
        RunResult r = run(d, v, h, options, *backend);
        r.k = k;
        std::printf("%s,%s,%d,%.6g,%d,%d,%d,%.3g,%.4g,%.4g", d.name.c_str(), v.name.c_str(), k, 1e3 * h,
                    r.cells, r.report.iterations, r.report.converged ? 1 : 0, r.report.residual, r.relax_s,
                    r.probe_s);
        for (size_t l = 0; l < 3; ++l) {
          if (l < r.line_error.size()) std::printf(",%.5f", r.line_error[l]);
          else std::printf(",");
        }
        std::printf(",%.5f,%.4g\n", r.total_error, r.max_M_soft);
        std::fflush(stdout);
        last_cells = r.cells;
        last_time = r.relax_s + r.probe_s;
        last = std::move(r);
      }
      if (last_cells > 0) finest.emplace_back(v.name, std::move(last));
    }
    if (!profile_dir.empty())
      write_profile(profile_dir / ("fem_" + d.name.substr(4) + "_profile.csv"), d, finest,
                    d.lines.front().points.size() > 500 ? 4 : 1);
  }
  return 0;
}
