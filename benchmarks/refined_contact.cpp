// Two lattice balls near contact in the engine, with and without refined
// contact zones (docs/model.md "Refined contact zones", docs/validation.md
// section 5): the force on the upper ball against the exact two-centre
// series of two linear spheres in a uniform field
// (tests/support/contact_references.h), the cells per ball, the outer
// iterations and the time of one magnetic step (the model built once per
// row: its tensors are not timed).
//
// Each row: R/h, the line of centres (along z, or along (1, 2, 2) / 3,
// oblique to the lattice axes; its contact point R (1, 2, 2) / 3 lies on
// lattice planes at R/h = 4.5, not at 4 or 5), chi,
// the field along or across the line, and per gap the error of the plain
// lattice and of the refined one (zones at the balls' nearest points, radii
// default_refinement_radii).
//
// Usage: refined_contact [--quick] [--contact] [--rolling] [--radii D0,D1,...]
//   --quick: R/h 4.5 only, gaps 0.05 R and 0.1 R (the default takes about
//   10 minutes on one core); --contact: every row at 0.05 R and 0.1 R, the
//   refined balls only (the plain columns zero); --radii: the zone radii in
//   units of h instead of default_refinement_radii; --rolling: the upper
//   ball moved around the lower one at 0.05 R (the line of centres turned
//   from z towards x), the zones either left where they were placed for the
//   line along z or moved to the new contact points
//   (MagneticModel::refine_body, transfer_refined_state), as
//   solver.contact_refinement does in a run.
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "magnetics/model/backend.h"
#include "magnetics/cells/cells.h"
#include "magnetics/model/model.h"
#include "magnetics/relax/relax.h"
#include "magnetics/model/state.h"
#include "tests/support/contact_references.h"

using namespace odemag;

namespace {

constexpr double kR = 0.005;

struct Row {
  double R_over_h;
  Vec3 line;  // unit vector from the lower ball to the upper one
  double chi;
  bool across;
};

struct Solve {
  double error;  // |F - F_exact| / |F_exact|
  double along;  // F . F_exact / |F_exact|^2 - 1: the signed error of the exact force's component
  int cells, iterations;
  double seconds;
};

// The zone radii / h (empty: default_refinement_radii).
std::vector<double> zone_radii;

Solve solve(const Row& row, double gap, bool refine) {
  const double h = kR / row.R_over_h;
  std::vector<double> radii = default_refinement_radii(h);
  if (!zone_radii.empty()) {
    radii.clear();
    for (double d : zone_radii) radii.push_back(d * h);
  }
  SoftMaterial mat;
  mat.saturation = 1e12;  // linear at these fields
  mat.susceptibility = row.chi;
  MagneticModel model;
  std::vector<RefinedZone> lower, upper;
  if (refine) {
    lower = {{kR * row.line, radii}};
    upper = {{-kR * row.line, radii}};
  }
  model.add_body("lower", Sphere{kR}, mat, h, lower);
  model.add_body("upper", Sphere{kR}, mat, h, upper);
  MagneticState state = make_state(model, 7);
  const Vec3 centre = (2.0 + gap) * kR * row.line;
  state.pose[1] = {Mat3{}, centre};
  Vec3 H0 = 1e3 * row.line;
  if (row.across) {
    Vec3 t = cross(row.line, Vec3{0, 0, 1});
    if (norm(t) < 0.1) t = {1, 0, 0};
    H0 = 1e3 / norm(t) * t;
  }
  state.external_field = H0;
  auto backend = make_cpu_backend(1);
  const auto t0 = std::chrono::steady_clock::now();
  const RelaxReport report = magnetic_step(model, state, RelaxOptions{}, *backend);
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  const auto ref = reference::two_linear_spheres_in_uniform_field(kR, row.chi, kR, row.chi,
                                                                  {0, 0, 0}, centre, H0);
  const Vec3& F = ref.force_on_2;
  return {norm(state.force[1] - F) / norm(F), dot(state.force[1], F) / dot(F, F) - 1.0,
          model.body(0).cell_count(), report.converged ? report.iterations : -1, seconds};
}

// --rolling: the zones placed for the line along z, the upper ball then at
// angle theta from z in the xz plane, 0.05 R apart, chi = 1000, the field
// along the line. Stationary zones: the model of theta = 0 relaxed there;
// moved: refine_body on both balls (from the state relaxed at theta = 0,
// as a run carries it) and relaxed.
void rolling() {
  const double R_over_h = 4.5, h = kR / R_over_h, gap = 0.05, chi = 1000.0;
  const std::vector<double> radii = default_refinement_radii(h);
  SoftMaterial mat;
  mat.saturation = 1e12;
  mat.susceptibility = chi;
  auto backend = make_cpu_backend(1);
  auto seconds_since = [](std::chrono::steady_clock::time_point t0) {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  };
  std::printf(
      "Two linear balls (R = 5 mm, R/h = 4.5, chi = 1000), 0.05 R apart, the field along the line "
      "of centres, the line turned by theta from z towards x; zones placed for theta = 0. The "
      "engine, one thread; error of the force against the exact series (signed: of the exact "
      "force's component).\n\n");
  std::printf(
      "| theta (deg) | contact moved (h) | stationary zones: error | iterations |"
      " moved zones: error | iterations | cells per ball | refine_body, both balls (s) |\n");
  std::printf("|---|---|---|---|---|---|---|---|\n");
  for (const double degrees : {0.0, 5.0, 10.0, 20.0, 30.0, 45.0}) {
    const double theta = degrees * 3.14159265358979323846 / 180.0;
    const Vec3 line{std::sin(theta), 0.0, std::cos(theta)}, H0 = 1e3 * line;
    const auto ref = reference::two_linear_spheres_in_uniform_field(kR, chi, kR, chi, {0, 0, 0},
                                                                    (2.0 + gap) * kR * line, H0);
    const Vec3& F = ref.force_on_2;
    MagneticModel model;
    model.add_body("lower", Sphere{kR}, mat, h, {{{0, 0, kR}, radii}});
    model.add_body("upper", Sphere{kR}, mat, h, {{{0, 0, -kR}, radii}});
    MagneticState state = make_state(model, 7);
    state.pose[1] = {Mat3{}, {0, 0, (2.0 + gap) * kR}};
    state.external_field = {0, 0, 1e3};
    // Relaxed at theta = 0, as before the move.
    magnetic_step(model, state, RelaxOptions{}, *backend);
    state.pose[1] = {Mat3{}, (2.0 + gap) * kR * line};
    state.external_field = H0;
    MagneticState stationary = state;
    const RelaxReport still = magnetic_step(model, stationary, RelaxOptions{}, *backend);
    const auto t0 = std::chrono::steady_clock::now();
    const MagneticBody lower = model.refine_body(0, {{kR * line, radii}});
    transfer_refined_state(model, 0, lower, state);
    const MagneticBody upper = model.refine_body(1, {{-kR * line, radii}});
    transfer_refined_state(model, 1, upper, state);
    const double refine_seconds = seconds_since(t0);
    const RelaxReport moved = magnetic_step(model, state, RelaxOptions{}, *backend);
    auto signed_error = [&](const Vec3& f) { return 100.0 * (dot(f, F) / dot(F, F) - 1.0); };
    std::printf("| %g | %.2f | %+.2f%% | %d | %+.2f%% | %d | %d | %.2f |\n", degrees,
                kR * theta / h, signed_error(stationary.force[1]),
                still.converged ? still.iterations : -1, signed_error(state.force[1]),
                moved.converged ? moved.iterations : -1, model.body(0).cell_count(),
                refine_seconds);
    std::fflush(stdout);
  }
}

}  // namespace

int main(int argc, char** argv) {
  bool quick = false, contact = false, roll = false;
  for (int a = 1; a < argc; ++a) {
    const std::string arg = argv[a];
    if (arg == "--quick") {
      quick = true;
    } else if (arg == "--contact") {
      contact = true;
    } else if (arg == "--rolling") {
      roll = true;
    } else if (arg == "--radii" && a + 1 < argc) {
      const char* list = argv[++a];
      for (const char* p = list;;) {
        char* end = nullptr;
        const double d = std::strtod(p, &end);
        if (end == p || !(d > 0.0) || !std::isfinite(d) || (*end != ',' && *end != '\0')) {
          std::fprintf(stderr,
                       "refined_contact: --radii '%s': positive numbers separated by commas\n",
                       list);
          return 2;
        }
        zone_radii.push_back(d);
        if (*end == '\0') break;
        p = end + 1;
      }
    } else {
      std::fprintf(stderr,
                   "refined_contact: unknown argument '%s' (usage: refined_contact [--quick]"
                   " [--contact] [--rolling] [--radii D0,D1,...])\n",
                   argv[a]);
      return 2;
    }
  }
  if (roll) {
    rolling();
    return 0;
  }
  const Vec3 axial{0, 0, 1}, tilted = Vec3{1, 2, 2} / 3.0;
  std::vector<Row> rows;
  for (double k : quick ? std::vector<double>{4.5} : std::vector<double>{4.0, 4.5, 5.0})
    for (const Vec3& line : {axial, tilted}) rows.push_back({k, line, 1000, false});
  rows.push_back({4.5, tilted, 1000, true});
  rows.push_back({4.5, tilted, 10, false});
  rows.push_back({4.5, tilted, 1e4, false});
  const std::vector<double> gaps = quick || contact ? std::vector<double>{0.05, 0.1}
                                                    : std::vector<double>{0.05, 0.1, 0.5, 1.0, 2.0, 4.0};
  std::printf(
      "Two linear balls (R = 5 mm) near contact, the engine (one thread), against the exact "
      "series.\n"
      "Error |F - F_exact| / |F_exact| (in brackets the signed error of the exact force's "
      "component);"
      " iterations of the relaxation (-1: not converged); time of one magnetic step.\n\n");
  std::printf(
      "| R/h | line | chi | field | gap | plain: cells | error | iterations | s |"
      " refined: cells | error | iterations | s |\n");
  std::printf("|---|---|---|---|---|---|---|---|---|---|---|---|---|\n");
  for (const Row& row : rows)
    for (double g : gaps) {
      const Solve plain = contact ? Solve{} : solve(row, g, false), refined = solve(row, g, true);
      std::printf(
          "| %g | %s | %g | %s | %g R | %d | %.2f%% (%+.2f%%) | %d | %.2f | %d | %.2f%% (%+.2f%%) "
          "| %d | %.2f |\n",
          row.R_over_h, row.line.z == 1.0 ? "z" : "(1,2,2)/3", row.chi,
          row.across ? "across" : "along", g, plain.cells, 100.0 * plain.error, 100.0 * plain.along,
          plain.iterations, plain.seconds, refined.cells, 100.0 * refined.error,
          100.0 * refined.along, refined.iterations, refined.seconds);
      std::fflush(stdout);
    }
  return 0;
}
