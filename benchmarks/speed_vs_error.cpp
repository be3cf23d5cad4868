// Time against error for three studies (docs/validation.md):
//  sphere: a soft lattice sphere (chi = 10, 1000, infinite) in a uniform
//          field against the exact moment 4 pi R^3 chi / (chi + 3) H0, as the
//          lattice is refined (one cell, then h = R/1 .. R/8);
//  cuboid: a permanent box on a lattice of spacing h = e/k (e its shortest
//          edge) against the closed-form cuboid field on planes at a gap g
//          below a face: "dipole" is the field the relaxation uses (the
//          point-dipole lattice sum, read as the applied field of tiny probe
//          cells: recoil spheres with M_r = 0 and chi_r = 1e-12), "probe" is
//          field_at_points (the exact fields of the lattice cubes);
//  crane:  a box magnet above a heap of ~200 touching one-cell steel balls:
//          force error against a tolerance-1e-10 reference, for tolerance
//          1e-2 .. 1e-8 and iteration caps 2 .. 200, cold (moments in random
//          opposite pairs) and warm (converged state, magnet lifted 0.2 mm).
//
// CSV on stdout, one row per run:
//   study,case,param_name,param,h_mm,cells,iterations,converged,seconds,error_max,error_rms
// Times are the best of up to 5 repetitions (while they take < 0.5 s in all).
// sphere: error_max = |m - m_ref| / |m_ref| (total moment), error_rms =
//         relative RMS error of the induced field (H - H0, field_at_points)
//         on a sphere of radius 1.5 R (128 points) against the exact dipole
//         field of m_ref; seconds = relaxation (tolerance 1e-8).
// cuboid: error_max = max |H - H_ref| / max |H_ref| over the plane,
//         error_rms = sqrt(sum |H - H_ref|^2 / sum |H_ref|^2); seconds =
//         relaxation (dipole) or field_at_points (probe) for the plane.
// crane:  error_max = max_b |F_b - F_ref,b| / max_b |F_ref,b|, error_rms =
//         sqrt(sum_b |F_b - F_ref,b|^2 / sum_b |F_ref,b|^2); seconds =
//         relaxation plus forces (best of 3).
//
// Usage: speed_vs_error [--threads N] [--study sphere|cuboid|crane]
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <limits>
#include <string>
#include <vector>

#include "magnetics/model/backend.h"
#include "odemag/constants.h"
#include "magnetics/relax/relax.h"
#include "tests/support/reference_fields.h"

using namespace odemag;
namespace ref = odemag::reference;

namespace {

double seconds_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

void row(const char* study, const std::string& c, const char* param_name, double param, double h_mm,
         int cells, int iterations, bool converged, double seconds, double error_max, double error_rms) {
  std::printf("%s,%s,%s,%g,%.6g,%d,%d,%d,%.6f,%.4e,%.4e\n", study, c.c_str(), param_name, param, h_mm, cells,
              iterations, converged ? 1 : 0, seconds, error_max, error_rms);
  std::fflush(stdout);
}

// ---- sphere --------------------------------------------------------------------

void sphere_study(MagneticBackend& backend) {
  const double R = 0.01;
  const Vec3 H0 = 1e3 * normalized(Vec3{0.3, -0.4, 0.85});
  const double inf = std::numeric_limits<double>::infinity();
  for (double chi : {10.0, 1000.0, inf}) {
    const std::string name = std::isinf(chi) ? "chi=inf" : "chi=" + std::to_string(static_cast<int>(chi));
    const Vec3 m_ref = ref::soft_sphere_moment(R, chi, 1e9, H0);
    for (int k : {0, 1, 2, 3, 4, 6, 8}) {  // 0: one cell; else h = R / k
      SoftMaterial s;
      s.saturation = 1.6e6;  // |M| = 3 kA/m: far from saturation
      s.susceptibility = chi;
      MagneticModel model;
      model.add_body("sphere", Sphere{R}, s, k == 0 ? 0.0 : R / k);
      RelaxOptions o;
      o.tolerance = 1e-8;
      o.max_iterations = 2000;
      // Cold relaxations, repeated while they take less than 0.5 s in all
      // (at most 5): the best time.
      MagneticState state;
      RelaxReport r;
      double t = 1e300, spent = 0.0;
      for (int rep = 0; rep < 5 && (rep == 0 || spent < 0.5); ++rep) {
        state = make_state(model, 1);
        state.external_field = H0;
        const auto t0 = std::chrono::steady_clock::now();
        r = relax(model, state, o, backend);
        const double dt = seconds_since(t0);
        t = std::min(t, dt);
        spent += dt;
      }
      const Vec3 m = body_moment(model, state, 0);
      // Exterior field on a sphere of radius 1.5 R: exact = the dipole m_ref.
      std::vector<Vec3> points, B, H;
      for (int i = 0; i < 8; ++i)
        for (int j = 0; j < 16; ++j) {
          const double theta = kPi * (i + 0.5) / 8.0, phi = 2.0 * kPi * j / 16.0;
          points.push_back(1.5 * R * Vec3{std::sin(theta) * std::cos(phi), std::sin(theta) * std::sin(phi),
                                          std::cos(theta)});
        }
      field_at_points(model, state, backend, points, B, H);
      double num = 0.0, den = 0.0;
      for (size_t p = 0; p < points.size(); ++p) {
        const Vec3 H_ref = H0 + ref::point_dipole_H(m_ref, points[p]);
        num += squared_norm(H[p] - H_ref);
        den += squared_norm(H_ref - H0);
      }
      const double field_rms = std::sqrt(num / den);
      const double m_par = dot(m, m_ref) / dot(m_ref, m_ref) - 1.0;
      std::fprintf(stderr, "sphere %s R/h=%d: moment along H0 %+.4f relative\n", name.c_str(), k, m_par);
      row("sphere", name, "R_over_h", k, k == 0 ? 0.0 : 1e3 * R / k, model.cell_count(), r.iterations,
          r.converged, t, norm(m - m_ref) / norm(m_ref), field_rms);
    }
  }
}

// ---- cuboid --------------------------------------------------------------------

void cuboid_study(MagneticBackend& backend) {
  const Vec3 size{0.02, 0.01, 0.005};
  const double e = 0.005;  // shortest edge
  const Vec3 M_body{3e5, -5e5, 8e5};
  const Mat3 R = rotation_from_quaternion(0.9, 0.2, -0.3, 0.25);
  const Vec3 centre{0.01, -0.02, 0.03};
  const ref::CuboidMagnet exact{size, M_body, R, centre};
  // Planes below the bottom face (body frame z = -c/2 - g), 13 x 13 points
  // over twice the box's x and y extent.
  for (double gap_e : {0.1, 0.5, 1.0, 2.0}) {
    std::vector<Vec3> points;
    for (int i = 0; i < 13; ++i)
      for (int j = 0; j < 13; ++j) {
        const Vec3 local{size.x * (-1.0 + i / 6.0), size.y * (-1.0 + j / 6.0), -0.5 * size.z - gap_e * e};
        points.push_back(centre + R * local);
      }
    std::vector<Vec3> H_ref;
    double H_ref_max = 0.0, den = 0.0;
    for (const Vec3& p : points) {
      H_ref.push_back(exact.field(p).H);
      H_ref_max = std::max(H_ref_max, norm(H_ref.back()));
      den += squared_norm(H_ref.back());
    }
    auto errors = [&](const std::vector<Vec3>& H, double& emax, double& erms) {
      double num = 0.0;
      emax = 0.0;
      for (size_t p = 0; p < H.size(); ++p) {
        num += squared_norm(H[p] - H_ref[p]);
        emax = std::max(emax, norm(H[p] - H_ref[p]) / H_ref_max);
      }
      erms = std::sqrt(num / den);
    };
    char gap_name[32];
    std::snprintf(gap_name, sizeof gap_name, "gap=%ge", gap_e);
    struct ProbeRow {
      int k;
      double h;
      int cells;
      double seconds, emax, erms;
    };
    std::vector<ProbeRow> probe_rows;  // printed after the dipole rows of this plane
    for (int k : {1, 2, 4, 8, 16}) {
      const double h = e / k;
      MagneticModel model;
      model.add_body("box", Box{size}, PermanentMaterial{M_body, 0.0}, h);
      for (size_t p = 0; p < points.size(); ++p)
        model.add_body("probe" + std::to_string(p), Sphere{1e-6}, PermanentMaterial{{}, 1e-12}, 0.0);
      MagneticState state = make_state(model, 1);
      state.pose[0].rotation = R;
      state.pose[0].position = centre;
      for (size_t p = 0; p < points.size(); ++p) state.pose[1 + p].position = points[p];
      RelaxOptions o;
      o.tolerance = 1e-10;
      auto t0 = std::chrono::steady_clock::now();
      const RelaxReport r = relax(model, state, o, backend);
      const double t_relax = seconds_since(t0);
      std::vector<Vec3> H_dipole;
      for (size_t p = 0; p < points.size(); ++p)
        H_dipole.push_back(state.applied_field[model.body(1 + static_cast<int>(p)).first_cell]);
      const int magnet_cells = model.body(0).cell_count();
      double emax = 0.0, erms = 0.0;
      errors(H_dipole, emax, erms);
      row("cuboid", std::string("dipole ") + gap_name, "e_over_h", k, 1e3 * h, magnet_cells, r.iterations,
          r.converged, t_relax, emax, erms);
      // The probes: the magnet alone (no probe cells needed).
      MagneticModel alone;
      alone.add_body("box", Box{size}, PermanentMaterial{M_body, 0.0}, h);
      MagneticState s2 = make_state(alone, 1);
      s2.pose[0].rotation = R;
      s2.pose[0].position = centre;
      relax(alone, s2, o, backend);  // places the cells
      std::vector<Vec3> B, H;
      t0 = std::chrono::steady_clock::now();
      field_at_points(alone, s2, backend, points, B, H);
      const double t_probe = seconds_since(t0);
      errors(H, emax, erms);
      probe_rows.push_back({k, h, magnet_cells, t_probe, emax, erms});
    }
    for (const ProbeRow& p : probe_rows)
      row("cuboid", std::string("probe ") + gap_name, "e_over_h", p.k, 1e3 * p.h, p.cells, 0, true, p.seconds,
          p.emax, p.erms);
  }
}

// ---- crane ---------------------------------------------------------------------

struct Crane {
  MagneticModel model;
  std::vector<BodyPose> poses;
};

// A 120 x 120 x 30 mm magnet (M = -1.2e6 A/m along z, lattice 12 mm: 200
// cells) whose bottom face is at z = 0, and below it a square pyramid of
// steel balls (R = 5 mm, Ms = 1.6e6 A/m, chi = 1000, one cell each): 10 x 10
// touching the face, 9 x 9 in the hollows below, 4 x 4 below those (197).
Crane make_crane() {
  Crane c;
  const double R = 0.005, gap = 1e-6;  // centre distances 2 R + 1 um: touching, outside the kernel's core
  c.model.add_body("magnet", Box{{0.12, 0.12, 0.03}}, PermanentMaterial{{0.0, 0.0, -1.2e6}, 0.0}, 0.012);
  c.poses.push_back({Mat3{}, {0.0, 0.0, 0.015}});
  SoftMaterial steel;
  steel.saturation = 1.6e6;
  steel.susceptibility = 1000.0;
  const double d = 2.0 * R + gap;              // neighbour distance in a layer
  const double dz = d / std::sqrt(2.0);        // layer spacing (square pyramid packing)
  auto layer = [&](int n, int first, int count, double z) {
    for (int i = first; i < first + count; ++i)
      for (int j = first; j < first + count; ++j) {
        c.model.add_body("ball" + std::to_string(c.poses.size()), Sphere{R}, steel, 0.0);
        c.poses.push_back({Mat3{}, {(i - 0.5 * (n - 1)) * d, (j - 0.5 * (n - 1)) * d, z}});
      }
  };
  const double z1 = -(R + gap);
  layer(10, 0, 10, z1);
  layer(9, 0, 9, z1 - dz);
  layer(8, 2, 4, z1 - 2.0 * dz);
  return c;
}

void set_poses(const Crane& c, MagneticState& s, double lift) {
  for (size_t b = 0; b < c.poses.size(); ++b) s.pose[b] = c.poses[b];
  s.pose[0].position.z += lift;
}

void force_errors(const std::vector<Vec3>& F, const std::vector<Vec3>& F_ref, double& emax, double& erms) {
  double fmax = 0.0, num = 0.0, den = 0.0, dmax = 0.0;
  for (size_t b = 0; b < F.size(); ++b) {
    fmax = std::max(fmax, norm(F_ref[b]));
    dmax = std::max(dmax, norm(F[b] - F_ref[b]));
    num += squared_norm(F[b] - F_ref[b]);
    den += squared_norm(F_ref[b]);
  }
  emax = dmax / fmax;
  erms = std::sqrt(num / den);
}

void crane_study(MagneticBackend& backend) {
  const Crane crane = make_crane();
  const MagneticModel& model = crane.model;
  const double lift = 2e-4;
  // References: cold at the initial poses; warm = from that state after the lift.
  RelaxOptions ro;
  ro.tolerance = 1e-10;
  ro.max_iterations = 2000;
  MagneticState cold_ref = make_state(model, 1);
  set_poses(crane, cold_ref, 0.0);
  RelaxReport rr = magnetic_step(model, cold_ref, ro, backend);
  std::fprintf(stderr, "crane: %d bodies, %d cells; cold reference %d iterations, converged %d, residual %.2e\n",
               model.body_count(), model.cell_count(), rr.iterations, rr.converged ? 1 : 0, rr.residual);
  MagneticState warm_ref = cold_ref;
  set_poses(crane, warm_ref, lift);
  rr = magnetic_step(model, warm_ref, ro, backend);
  std::fprintf(stderr, "crane: warm reference %d iterations, converged %d, residual %.2e\n", rr.iterations,
               rr.converged ? 1 : 0, rr.residual);
  double fmax = 0.0;
  for (const Vec3& f : cold_ref.force) fmax = std::max(fmax, norm(f));
  std::fprintf(stderr, "crane: largest force %.4g N, magnet force %.4g N\n", fmax, norm(cold_ref.force[0]));
  int saturated = 0;
  double m_min = 1e300;
  for (int c = 1; c < model.cell_count(); ++c) {
    if (model.body(model.cell_body(c)).kind != CellKind::soft) continue;
    const double m = norm(cold_ref.magnetization[c]) / 1.6e6;
    saturated += m > 0.95 ? 1 : 0;
    m_min = std::min(m_min, m);
  }
  std::fprintf(stderr, "crane: %d of %d balls at |M| > 0.95 Ms, smallest |M| / Ms = %.3f\n", saturated,
               model.body_count() - 1, m_min);

  for (const char* start : {"cold", "warm"}) {
    const bool warm = start[0] == 'w';
    const MagneticState& reference = warm ? warm_ref : cold_ref;
    for (double tol : {1e-2, 1e-3, 1e-4, 1e-5, 1e-6, 1e-7, 1e-8}) {
      char name[64];
      std::snprintf(name, sizeof name, "%s tol=%.0e", start, tol);
      for (int cap : {2, 5, 10, 20, 50, 100, 200}) {
        RelaxOptions o;
        o.tolerance = tol;
        o.max_iterations = cap;
        double best = 1e300;
        MagneticState s;
        RelaxReport r;
        for (int rep = 0; rep < 3; ++rep) {
          if (warm) {
            s = cold_ref;
          } else {
            s = make_state(model, 1);
            set_poses(crane, s, 0.0);
          }
          if (warm) set_poses(crane, s, lift);
          const auto t0 = std::chrono::steady_clock::now();
          r = magnetic_step(model, s, o, backend);
          best = std::min(best, seconds_since(t0));
        }
        double emax = 0.0, erms = 0.0;
        force_errors(s.force, reference.force, emax, erms);
        row("crane", name, "max_iterations", cap, 12.0, model.cell_count(), r.iterations, r.converged, best, emax,
            erms);
      }
    }
  }
}

}  // namespace

int main(int argc, char** argv) {
  int threads = 2;
  std::string only;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--threads" && i + 1 < argc) threads = std::stoi(argv[++i]);
    else if (a == "--study" && i + 1 < argc) only = argv[++i];
    else {
      std::fprintf(stderr, "usage: speed_vs_error [--threads N] [--study sphere|cuboid|crane]\n");
      return 2;
    }
  }
  auto backend = make_cpu_backend(threads);
  std::printf("study,case,param_name,param,h_mm,cells,iterations,converged,seconds,error_max,error_rms\n");
  if (only.empty() || only == "sphere") sphere_study(*backend);
  if (only.empty() || only == "cuboid") cuboid_study(*backend);
  if (only.empty() || only == "crane") crane_study(*backend);
  return 0;
}
