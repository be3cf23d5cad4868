// Contact forces against the exact linear solutions (docs/validation.md
// "Contact"): for each case, gap and susceptibility, the force error of the
// point-dipole model (near_field off) and of the near-field model (on), and
// the time of one magnetic step (relaxation and forces, best of 20).
//   ball_magnet:  a one-cell soft ball next to a permanent ball (the exact
//                 series of a linear sphere next to a point dipole), magnet
//                 magnetized along the line of centres;
//   balls_axial / balls_transverse: two equal one-cell soft balls in a
//                 uniform field along / across the line of centres (the
//                 two-centre re-expansion of the reference, converged).
// CSV on stdout: case,chi,gap_over_R,near_field,force_error,seconds
// Usage: contact_accuracy
#include <chrono>
#include <cstdio>

#include "magnetics/model/backend.h"
#include "magnetics/relax/relax.h"
#include "tests/support/contact_references.h"

using namespace odemag;

namespace {

constexpr double kR = 0.01;

struct Result {
  Vec3 force;
  double seconds;
};

Result run(const MagneticModel& model, const MagneticState& initial, bool near_field) {
  RelaxOptions o;
  o.tolerance = 1e-10;
  o.near_field = near_field;
  auto backend = make_cpu_backend(1);
  Result r{{}, 1e300};
  for (int rep = 0; rep < 20; ++rep) {
    MagneticState s = initial;
    const auto t0 = std::chrono::steady_clock::now();
    magnetic_step(model, s, o, *backend);
    r.seconds = std::min(r.seconds, std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
    r.force = s.force[1];
  }
  return r;
}

void row(const char* name, double chi, double gap, const MagneticModel& model, const MagneticState& state,
         const Vec3& exact) {
  for (bool near : {false, true}) {
    const Result r = run(model, state, near);
    std::printf("%s,%g,%g,%d,%.4e,%.3e\n", name, chi, gap, near ? 1 : 0, norm(r.force - exact) / norm(exact),
                r.seconds);
  }
}

}  // namespace

int main() {
  std::printf("case,chi,gap_over_R,near_field,force_error,seconds\n");
  SoftMaterial iron;
  iron.saturation = 1e12;  // linear
  for (double chi : {10.0, 1000.0, 1e4})
    for (double gap : {0.05, 0.1, 0.5, 1.0, 2.0, 4.0}) {
      iron.susceptibility = chi;
      const Vec3 xb{0, 0, 2 * kR + gap * kR};
      {
        MagneticModel model;
        const Vec3 M{0, 0, 8e5};
        model.add_body("magnet", Sphere{kR}, PermanentMaterial{M, 0.0}, 0.0);
        model.add_body("ball", Sphere{kR}, iron, 0.0);
        MagneticState s = make_state(model);
        s.pose[1].position = xb;
        const Vec3 m = (4.0 / 3.0 * kPi * kR * kR * kR) * M;
        row("ball_magnet", chi, gap, model, s, reference::linear_sphere_force_from_dipole(kR, chi, xb, {}, m));
      }
      for (int axial = 1; axial >= 0; --axial) {
        MagneticModel model;
        model.add_body("a", Sphere{kR}, iron, 0.0);
        model.add_body("b", Sphere{kR}, iron, 0.0);
        MagneticState s = make_state(model);
        s.pose[1].position = xb;
        s.external_field = axial ? Vec3{0, 0, 1e3} : Vec3{1e3, 0, 0};
        const Vec3 exact =
            reference::two_linear_spheres_in_uniform_field(kR, chi, kR, chi, {}, xb, s.external_field).force_on_2;
        row(axial ? "balls_axial" : "balls_transverse", chi, gap, model, s, exact);
      }
    }
}
