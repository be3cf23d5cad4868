// Parity of the CUDA backend with the CPU backend (docs/gpu.md "Parity
// tests"): the same scenes and states go through both backends and the
// results are compared. Where this machine has no usable CUDA device, every
// parity test skips with the reason make_cuda_backend gives; with
// ODEMAG_REQUIRE_CUDA=1 in the environment each of them fails instead (a GPU
// machine whose driver or device is unusable must not pass by skipping).
//
// Tolerances are normwise and relative: max over items of |cpu - cuda|
// against max over items of |cpu|. Both backends evaluate the same formulas
// (the ODEMAG_HD functions of magnetics/) in double precision; they differ
// only by round-off (summation order, fused multiply-adds, the device's
// sin/cos/log/atan within an ulp or two), which a sum of N terms grows to
// about N * 1e-16 of its largest term. A non-finite value on either side
// fails the comparison, however many finite items follow it.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <iostream>
#include <limits>
#include <sstream>
#include <string>
#include <vector>

#include "engine/simulation/magnetic_system.h"
#include "gpu/cuda_backend.h"
#include "magnetics/model/backend.h"
#include "magnetics/near_field/near_field.h"
#include "magnetics/relax/relax.h"
#include "magnetics/kernels/rng.h"
#include "tests/support/magnetic_setup.h"
#include "tests/support/test_math.h"

namespace odemag {
namespace {

// One evaluation of the field sums (at most a few thousand terms each).
constexpr double kSumTolerance = 1e-11;
// Per-body sums of cell forces and torques: the cells' forces partly cancel,
// so the body totals keep less of their relative precision.
constexpr double kForceTolerance = 1e-10;
// Probe fields: the cuboid formulas subtract logarithms and arctangents that
// the device's math library rounds a little differently.
constexpr double kProbeTolerance = 1e-10;
// One local relaxation of every cell: the Newton polish stops at a relative
// torque of 1e-12, so cells converge onto the same equilibrium to about that.
constexpr double kRelaxTolerance = 1e-9;
// Whole magnetic steps: the outer loop (Anderson mixing) stops at 1e-6 after
// the same iterations on both, each carrying the round-off above forward.
constexpr double kStepTolerance = 1e-8;

// ODEMAG_REQUIRE_CUDA set to anything but "" or "0": a missing CUDA backend
// fails the test instead of skipping it (scripts/gpu-check.sh --run sets it).
bool require_cuda() {
  const char* v = std::getenv("ODEMAG_REQUIRE_CUDA");
  return v != nullptr && *v != '\0' && std::string(v) != "0";
}

// A CUDA backend for the test, or a skip (a failure under
// ODEMAG_REQUIRE_CUDA=1) with the reason it is unavailable.
#define CUDA_BACKEND_OR_SKIP(name)                                                    \
  std::string name##_why;                                                             \
  std::unique_ptr<MagneticBackend> name = make_cuda_backend(&name##_why);              \
  if (!name) {                                                                        \
    if (require_cuda()) FAIL() << "no CUDA backend (ODEMAG_REQUIRE_CUDA): " << name##_why; \
    GTEST_SKIP() << "no CUDA backend: " << name##_why;                                \
  }                                                                                   \
  static_assert(true, "")

std::string str(const Vec3& v) {
  std::ostringstream s;
  s.precision(17);
  s << "(" << v.x << ", " << v.y << ", " << v.z << ")";
  return s.str();
}

// The comparison behind close(). A non-finite item (any component NaN or
// infinite, on either side) is counted and makes worst NaN for good: later
// finite differences cannot overwrite it.
struct Comparison {
  int items = 0;
  double scale = 0.0;         // max |cpu| over the finite items
  double worst = 0.0;         // max |cpu - cuda|; NaN once any item is non-finite
  int at = -1;                // the item of worst; with non-finite items, the first of them
  int nonfinite = 0;          // items with a non-finite component
  double worst_finite = 0.0;  // max |cpu - cuda| over the finite items
  int at_finite = -1;
};

Comparison compare(const std::vector<Vec3>& cpu, const std::vector<Vec3>& cuda, const std::vector<int>& items) {
  Comparison c;
  for (int i : items) {
    ++c.items;
    if (!is_finite(cpu[i]) || !is_finite(cuda[i])) {
      if (c.nonfinite++ == 0) c.at = i;
      c.worst = std::numeric_limits<double>::quiet_NaN();
      continue;
    }
    c.scale = std::max(c.scale, norm(cpu[i]));
    const double d = norm(cpu[i] - cuda[i]);
    if (c.at_finite < 0 || d > c.worst_finite) c.worst_finite = d, c.at_finite = i;
    if (c.nonfinite == 0) c.worst = c.worst_finite, c.at = c.at_finite;
  }
  return c;
}

// max_i |a_i - b_i| <= tolerance * max_i |a_i| over the items, every value finite.
::testing::AssertionResult close(const std::vector<Vec3>& cpu, const std::vector<Vec3>& cuda,
                                 const std::vector<int>& items, double tolerance) {
  const Comparison c = compare(cpu, cuda, items);
  if (c.nonfinite == 0 && c.worst <= tolerance * c.scale && std::isfinite(c.scale))
    return ::testing::AssertionSuccess();
  ::testing::AssertionResult failure = ::testing::AssertionFailure();
  if (c.nonfinite > 0)
    failure << c.nonfinite << " of " << c.items << " items non-finite (first at item " << c.at << ": cpu "
            << str(cpu[c.at]) << ", cuda " << str(cuda[c.at]) << "); ";
  if (c.at_finite >= 0)
    failure << "largest finite difference " << c.worst_finite << " at item " << c.at_finite << ": cpu "
            << str(cpu[c.at_finite]) << ", cuda " << str(cuda[c.at_finite]);
  return failure << "; allowed " << tolerance << " x " << c.scale;
}

using test_support::axis_rotation;

SoftMaterial iron(double chi = 5000.0) { return test_support::soft_material(1.7e6, chi); }

struct Scene {
  MagneticModel model;
  MagneticState state;
  explicit Scene(IntraBodyTensor tensor = IntraBodyTensor::cell_average) : model(tensor) {}
  std::vector<int> responsive_cells() const { return active_responsive_cells(model, state); }
  std::vector<int> bodies() const {
    std::vector<int> b(model.body_count());
    for (int i = 0; i < model.body_count(); ++i) b[i] = i;
    return b;
  }
};

// Every kind of body the backends handle: lattice and one-cell permanent
// magnets, a recoil magnet, soft balls (two moment counts, finite and
// "infinite" chi), a soft lattice plate, an anisotropic nail, bodies that
// overlap (ball in the plate, two balls in each other), an inert body, a
// removed body, rotations and an external field.
void build_workshop(Scene& s) {
  MagneticModel& m = s.model;
  m.add_body("bar", Box{{0.03, 0.01, 0.01}}, PermanentMaterial{{8e5, 0, 1e5}, 0.0}, 0.005);  // 0
  m.add_body("recoil", Box{{0.01, 0.01, 0.01}}, PermanentMaterial{{0, 0, 9e5}, 0.3}, 0.005);  // 1
  m.add_body("plate", Box{{0.02, 0.02, 0.004}}, iron(), 0.004);                              // 2
  m.add_body("ball_a", Sphere{0.003}, iron(), 0.0);                                          // 3
  m.add_body("ball_b", Sphere{0.003}, iron(), 0.0);                                          // 4
  m.add_body("ball_c", Sphere{0.003}, iron(), 0.0);                                          // 5
  m.add_body("ball_in_plate", Sphere{0.003}, iron(), 0.0);                                   // 6
  SoftMaterial nail = iron();
  nail.anisotropy_field = 8e5;
  nail.easy_axis = {0, 0, 1};
  m.add_body("nail", Cylinder{0.0015, 0.02}, nail, 0.002);                                    // 7
  m.add_body("wood", Box{{0.05, 0.05, 0.01}}, InertMaterial{}, 0.0);                         // 8
  m.add_body("removed", Sphere{0.003}, iron(), 0.0);                                         // 9
  m.add_body("ball_magnet", Sphere{0.004}, PermanentMaterial{{0, 5e5, 5e5}, 0.0}, 0.0);      // 10
  SoftMaterial nickel = iron(200.0);
  nickel.saturation = 4.8e5;
  nickel.damping = 0.5;
  nickel.moments_per_cell = 4;
  m.add_body("nickel", Sphere{0.0025}, nickel, 0.0);                                          // 11
  s.state = make_state(m, 11);
  MagneticState& st = s.state;
  st.external_field = {2e3, -1e3, 5e3};
  st.pose[0].position = {0.0, 0.0, 0.03};
  st.pose[0].rotation = axis_rotation({1, 2, 3}, 0.3);
  st.pose[1].position = {-0.03, 0.01, 0.02};
  st.pose[2].position = {0.004, 0.002, 0.012};
  st.pose[2].rotation = axis_rotation({1, 1, 0}, 0.25);
  st.pose[3].position = {-0.012, 0.003, 0.0};
  st.pose[4].position = {-0.0125, 0.0075, 0.001};  // overlaps ball_a
  st.pose[5].position = {0.02, -0.015, 0.005};
  st.pose[6].position = {0.006, 0.001, 0.0125};  // inside the plate
  st.pose[7].position = {0.025, 0.012, 0.02};
  st.pose[7].rotation = axis_rotation({0, 1, 0}, 0.7);
  st.pose[8].position = {0.0, 0.0, -0.02};
  st.pose[9].position = {0.0, 0.0, 0.0};
  st.active[9] = 0;
  st.pose[10].position = {0.015, 0.02, -0.004};
  st.pose[11].position = {-0.004, -0.016, 0.008};
  st.pose[11].rotation = axis_rotation({3, -1, 1}, 1.2);
  place_cells(m, st);
}

// Soft moments in deterministic random directions (magnetized cells), recoil
// magnets with a made-up applied field, so that every source is non-zero.
void randomize_moments(Scene& s, uint64_t seed) {
  for (int c = 0; c < s.model.cell_count(); ++c) {
    const int off = s.model.moment_offset(c);
    const MagneticBody& body = s.model.body(s.model.cell_body(c));
    if (off >= 0)
      for (int k = 0; k < body.soft.n; ++k)
        s.state.moments[off + k] = random_unit_vector(hash_key(seed, 0x5445535453ULL, c, k));
    s.state.applied_field[c] = 3e4 * random_unit_vector(hash_key(seed, 0x4150504cULL, c, 0));
  }
  place_cells(s.model, s.state);
}

// A heap of one-cell balls and a soft lattice block larger than one tile of
// the kernels (partial last tiles, intra-body sums across tiles).
void build_heap(Scene& s, int balls) {
  MagneticModel& m = s.model;
  m.add_body("crane", Cylinder{0.03, 0.02}, PermanentMaterial{{0, 0, 1e6}, 0.0}, 0.006);
  m.add_body("block", Box{{0.05, 0.05, 0.02}}, iron(), 0.005);  // 10 x 10 x 4
  for (int i = 0; i < balls; ++i) m.add_body("ball" + std::to_string(i), Sphere{0.002}, iron(), 0.0);
  s.state = make_state(m, 5);
  s.state.pose[0].position = {0.0, 0.0, 0.06};
  s.state.pose[1].position = {0.0, 0.0, 0.03};
  s.state.pose[1].rotation = axis_rotation({0, 0, 1}, 0.1);
  const int side = static_cast<int>(std::ceil(std::sqrt(balls / 4.0)));
  for (int i = 0; i < balls; ++i) {
    const int ix = i % side, iy = (i / side) % side, iz = i / (side * side);
    const double jitter = 1e-4 * (unit_interval(hash_key(3, 1, i, 0)) - 0.5);
    s.state.pose[2 + i].position = {(ix - side / 2) * 0.0041 + jitter, (iy - side / 2) * 0.0041,
                                    -iz * 0.0041 + jitter};
  }
  place_cells(m, s.state);
}

TEST(CudaBackend, IsAvailableOrSaysWhy) {
  std::string why;
  const std::unique_ptr<MagneticBackend> cuda = make_cuda_backend(&why);
  if (cuda) {
    EXPECT_TRUE(cuda_backend_compiled());
    EXPECT_EQ(cuda->name(), "cuda");
  } else {
    EXPECT_FALSE(why.empty());
    std::cout << "no CUDA backend: " << why << "\n";
    EXPECT_FALSE(require_cuda()) << "ODEMAG_REQUIRE_CUDA is set and there is no CUDA backend: " << why;
  }
}

// The comparison itself, without a device: a NaN stays the worst difference
// however many finite items follow it, and non-finite items are counted.
TEST(ParityComparison, NonFiniteItemsAreStickyAndCounted) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();
  const std::vector<Vec3> cpu = {{1, 0, 0}, {0, 2, 0}, {0, 0, 3}, {1, 1, 1}, {-2, 0, 1}};
  const std::vector<int> all = {0, 1, 2, 3, 4};
  std::vector<Vec3> cuda = cpu;
  EXPECT_TRUE(close(cpu, cuda, all, 1e-12));
  cuda[3].y += 1e-3;  // a finite difference, beyond the tolerance
  EXPECT_FALSE(close(cpu, cuda, all, 1e-12));
  EXPECT_TRUE(close(cpu, cuda, all, 1e-3));

  // NaN first, then a larger finite difference: the old `!(d <= worst)`
  // stored the NaN and let the next finite difference overwrite it.
  cuda = cpu;
  cuda[1].x = nan;
  cuda[2].z += 0.5;
  Comparison c = compare(cpu, cuda, all);
  EXPECT_EQ(c.items, 5);
  EXPECT_EQ(c.nonfinite, 1);
  EXPECT_EQ(c.at, 1);
  EXPECT_TRUE(std::isnan(c.worst));
  EXPECT_EQ(c.at_finite, 2);
  EXPECT_DOUBLE_EQ(c.worst_finite, 0.5);
  const ::testing::AssertionResult r = close(cpu, cuda, all, 1.0);  // the finite part would pass
  EXPECT_FALSE(r);
  EXPECT_NE(std::string(r.message()).find("1 of 5 items non-finite (first at item 1"), std::string::npos)
      << r.message();

  // A NaN as the last item, an infinity on the CPU side, a NaN on both.
  cuda = cpu;
  cuda[4].z = nan;
  c = compare(cpu, cuda, all);
  EXPECT_EQ(c.nonfinite, 1);
  EXPECT_EQ(c.at, 4);
  EXPECT_FALSE(close(cpu, cuda, all, 1.0));
  std::vector<Vec3> cpu_inf = cpu;
  cpu_inf[0].x = inf;
  cuda = cpu_inf;
  cuda[2].y = nan;
  c = compare(cpu_inf, cuda, all);
  EXPECT_EQ(c.nonfinite, 2);
  EXPECT_EQ(c.at, 0);
  EXPECT_TRUE(std::isnan(c.worst));
  EXPECT_FALSE(close(cpu_inf, cuda, all, 1.0));

  // Only the listed items count.
  EXPECT_TRUE(close(cpu_inf, cuda, {1, 3, 4}, 1e-15));
  EXPECT_TRUE(close(cpu, cpu, {}, 0.0));
}

TEST(ParityComparison, RequireCudaReadsTheEnvironment) {
  const char* saved = std::getenv("ODEMAG_REQUIRE_CUDA");
  const std::string before = saved ? saved : "";
  ::setenv("ODEMAG_REQUIRE_CUDA", "1", 1);
  EXPECT_TRUE(require_cuda());
  ::setenv("ODEMAG_REQUIRE_CUDA", "0", 1);
  EXPECT_FALSE(require_cuda());
  ::setenv("ODEMAG_REQUIRE_CUDA", "", 1);
  EXPECT_FALSE(require_cuda());
  ::unsetenv("ODEMAG_REQUIRE_CUDA");
  EXPECT_FALSE(require_cuda());
  if (saved) ::setenv("ODEMAG_REQUIRE_CUDA", before.c_str(), 1);
}

// The backend the relaxation runs on really is the device's: its name, the
// engine's choice for "auto" and "cuda" (what `odemag run --backend cuda`
// gets), and the device's counters after a magnetic step.
TEST(CudaBackend, BackendInUseIsCuda) {
  CUDA_BACKEND_OR_SKIP(cuda);
  EXPECT_TRUE(cuda_backend_compiled());
  EXPECT_EQ(cuda->name(), "cuda");
  for (const char* choice : {"auto", "cuda"}) {
    std::string notice;
    const std::unique_ptr<MagneticBackend> chosen = make_backend(backend_kind(choice), 2, &notice);
    ASSERT_TRUE(chosen) << choice;
    EXPECT_EQ(chosen->name(), "cuda") << choice << ": " << notice;
    EXPECT_TRUE(notice.empty()) << choice << ": " << notice;
  }
  Scene s;
  build_workshop(s);
  reset_cuda_backend_stats(*cuda);
  const RelaxReport r = magnetic_step(s.model, s.state, RelaxOptions{}, *cuda);
  EXPECT_TRUE(r.converged);
  const CudaBackendStats stats = cuda_backend_stats(*cuda);
  EXPECT_EQ(stats.begin_step.calls, 1);
  EXPECT_EQ(stats.fixed_field.calls, 1);
  EXPECT_EQ(stats.relax_cells.calls, r.iterations);
  EXPECT_EQ(stats.responsive_field.calls, r.field_evaluations);
  EXPECT_EQ(stats.forces.calls, 1);
  EXPECT_GT(stats.relax_cells.kernel_ms, 0.0);
  EXPECT_GT(stats.responsive_field.kernel_ms, 0.0);
  EXPECT_GT(stats.begin_step.upload_bytes, 0.0);
  // A CPU backend has no device counters.
  EXPECT_EQ(cuda_backend_stats(*make_cpu_backend(1)).begin_step.calls, 0);
}

TEST(CudaParity, FixedField) {
  CUDA_BACKEND_OR_SKIP(cuda);
  Scene s;
  build_workshop(s);
  randomize_moments(s, 1);
  auto cpu = make_cpu_backend(2);
  std::vector<Vec3> a(s.model.cell_count()), b(s.model.cell_count());
  cpu->begin_step(s.model, s.state);
  cpu->fixed_field(s.model, s.state, a);
  cuda->begin_step(s.model, s.state);
  cuda->fixed_field(s.model, s.state, b);
  EXPECT_TRUE(close(a, b, s.responsive_cells(), kSumTolerance));
}

TEST(CudaParity, ResponsiveField) {
  CUDA_BACKEND_OR_SKIP(cuda);
  for (IntraBodyTensor tensor : {IntraBodyTensor::cell_average, IntraBodyTensor::point_dipole}) {
    Scene s(tensor);
    build_workshop(s);
    randomize_moments(s, 2);
    auto cpu = make_cpu_backend(2);
    std::vector<Vec3> a(s.model.cell_count()), b(s.model.cell_count());
    cpu->begin_step(s.model, s.state);
    cpu->responsive_field(s.model, s.state, a);
    cuda->begin_step(s.model, s.state);
    cuda->responsive_field(s.model, s.state, b);
    EXPECT_TRUE(close(a, b, s.responsive_cells(), kSumTolerance))
        << "intra-body tensor " << static_cast<int>(tensor);
  }
}

TEST(CudaParity, RelaxCellsTwice) {
  CUDA_BACKEND_OR_SKIP(cuda);
  Scene s;
  build_workshop(s);
  randomize_moments(s, 3);
  auto cpu = make_cpu_backend(2);
  const int n = s.model.cell_count();
  std::vector<Vec3> H_fixed(n), H_resp(n), H_A(n);
  cpu->begin_step(s.model, s.state);
  cpu->fixed_field(s.model, s.state, H_fixed);
  cpu->responsive_field(s.model, s.state, H_resp);
  const std::vector<int> cells = s.responsive_cells();
  for (int c : cells) H_A[c] = H_fixed[c] + H_resp[c];
  MagneticState on_cpu = s.state, on_cuda = s.state;
  cuda->begin_step(s.model, on_cuda);
  const LocalRelaxOptions options;
  // The second call starts from the moments the first left on the device.
  for (int call = 0; call < 2; ++call) {
    if (call == 1)
      for (int c : cells) H_A[c] = 0.5 * H_A[c];
    const LocalStats a = cpu->relax_cells(s.model, on_cpu, H_A, options);
    const LocalStats b = cuda->relax_cells(s.model, on_cuda, H_A, options);
    EXPECT_TRUE(close(on_cpu.magnetization, on_cuda.magnetization, cells, kRelaxTolerance)) << "call " << call;
    // The same LLG steps draw the same noise (counter-based RNG).
    EXPECT_EQ(a.llg_steps, b.llg_steps) << "call " << call;
    EXPECT_NEAR(static_cast<double>(a.newton_steps), static_cast<double>(b.newton_steps),
                0.02 * static_cast<double>(a.newton_steps) + 2.0)
        << "call " << call;
    if (a.max_residual <= options.tolerance) {
      EXPECT_LE(b.max_residual, options.tolerance) << "call " << call;
    }
    for (int c : cells) {
      EXPECT_EQ(on_cpu.noise_counter[c], on_cuda.noise_counter[c]) << "cell " << c;
      EXPECT_EQ(on_cpu.llg_history[c], on_cuda.llg_history[c]) << "cell " << c;
    }
  }
}

TEST(CudaParity, Forces) {
  CUDA_BACKEND_OR_SKIP(cuda);
  Scene s;
  build_workshop(s);
  randomize_moments(s, 4);
  auto cpu = make_cpu_backend(2);
  MagneticState on_cpu = s.state, on_cuda = s.state;
  cpu->begin_step(s.model, on_cpu);
  cpu->forces(s.model, on_cpu);
  cuda->begin_step(s.model, on_cuda);
  cuda->forces(s.model, on_cuda);
  EXPECT_TRUE(close(on_cpu.force, on_cuda.force, s.bodies(), kForceTolerance));
  EXPECT_TRUE(close(on_cpu.torque, on_cuda.torque, s.bodies(), kForceTolerance));
  EXPECT_EQ(norm(on_cuda.force[8]), 0.0);  // inert
  EXPECT_EQ(norm(on_cuda.force[9]), 0.0);  // removed
}

TEST(CudaParity, FieldAtPoints) {
  CUDA_BACKEND_OR_SKIP(cuda);
  Scene s;
  build_workshop(s);
  randomize_moments(s, 5);
  std::vector<Vec3> points;
  for (int i = 0; i < 9; ++i)
    for (int j = 0; j < 9; ++j)
      for (int k = 0; k < 9; ++k)  // a jittered grid through and around the bodies
        points.push_back({-0.04 + 0.01 * i + 3.7e-4, -0.04 + 0.01 * j - 2.3e-4, -0.03 + 0.0075 * k + 1.1e-4});
  points.push_back({1.0, -2.0, 0.5});  // far away
  auto cpu = make_cpu_backend(2);
  std::vector<Vec3> a, b;
  cpu->probe_field(s.model, s.state, points, a);
  cuda->probe_field(s.model, s.state, points, b);
  ASSERT_EQ(a.size(), points.size());
  ASSERT_EQ(b.size(), points.size());
  std::vector<int> all(points.size());
  for (size_t p = 0; p < points.size(); ++p) all[p] = static_cast<int>(p);
  EXPECT_TRUE(close(a, b, all, kProbeTolerance));
  std::vector<Vec3> none;
  cuda->probe_field(s.model, s.state, {}, none);
  EXPECT_TRUE(none.empty());
}

// Whole rigid steps (relax + forces) with warm starts, bodies moving between
// steps; one removed and brought back.
void check_steps(const RelaxOptions& options, int steps, double tolerance) {
  CUDA_BACKEND_OR_SKIP(cuda);
  Scene s;
  build_workshop(s);
  auto cpu = make_cpu_backend(2);
  MagneticState on_cpu = s.state, on_cuda = s.state;
  for (int step = 0; step < steps; ++step) {
    for (MagneticState* st : {&on_cpu, &on_cuda}) {
      for (int b : {2, 3, 5, 7}) st->pose[b].position.z -= 3e-4 * step;
      st->pose[7].rotation = axis_rotation({1, 0, 0}, 0.05 * step) * st->pose[7].rotation;
      st->active[5] = step == 1 ? 0 : 1;
    }
    const RelaxReport a = magnetic_step(s.model, on_cpu, options, *cpu);
    const RelaxReport b = magnetic_step(s.model, on_cuda, options, *cuda);
    const std::vector<int> cells = s.responsive_cells();
    SCOPED_TRACE("step " + std::to_string(step));
    EXPECT_EQ(a.converged, b.converged);
    EXPECT_LE(std::abs(a.iterations - b.iterations), 1);
    EXPECT_TRUE(close(on_cpu.magnetization, on_cuda.magnetization, cells, tolerance));
    EXPECT_TRUE(close(on_cpu.applied_field, on_cuda.applied_field, cells, tolerance));
    EXPECT_TRUE(close(on_cpu.force, on_cuda.force, s.bodies(), tolerance));
    EXPECT_TRUE(close(on_cpu.torque, on_cuda.torque, s.bodies(), tolerance));
  }
}

TEST(CudaParity, MagneticStepsTwoLevel) { check_steps(RelaxOptions{}, 3, kStepTolerance); }

TEST(CudaParity, MagneticStepsWithoutMutualInduction) {
  RelaxOptions o;
  o.mutual_induction = false;
  check_steps(o, 2, kStepTolerance);
}

// The near-field corrections (magnetics/near_field/near_field.h) run on the host with
// the same code for both backends; the workshop has close sphere pairs
// (ball_a and ball_b overlap, the nickel ball and the ball magnet), so the
// steps above compare them. Here: that it does, and the point-dipole model
// without them.
TEST(CudaParity, WorkshopHasNearFieldPairs) {
  Scene s;
  build_workshop(s);
  NearField near;
  near.build(s.model, s.state, true);
  EXPECT_GT(near.pair_count(), 0);
}

TEST(CudaParity, MagneticStepsWithoutNearField) {
  RelaxOptions o;
  o.near_field = false;
  check_steps(o, 2, kStepTolerance);
}

TEST(CudaParity, PaperScheme) {
  // Algorithm 1: one LLG step per field evaluation, with the noise field;
  // capped so that the test stays short (the paths are compared, not the end).
  RelaxOptions o;
  o.scheme = RelaxScheme::paper;
  o.max_iterations = 40;
  check_steps(o, 2, kRelaxTolerance);
}

TEST(CudaParity, HeapAndLatticeSpanManyTiles) {
  CUDA_BACKEND_OR_SKIP(cuda);
  Scene s;
  build_heap(s, 700);
  randomize_moments(s, 6);
  auto cpu = make_cpu_backend(0);
  const int n = s.model.cell_count();
  std::vector<Vec3> a(n), b(n), c(n), d(n);
  MagneticState on_cpu = s.state, on_cuda = s.state;
  cpu->begin_step(s.model, on_cpu);
  cuda->begin_step(s.model, on_cuda);
  cpu->fixed_field(s.model, on_cpu, a);
  cuda->fixed_field(s.model, on_cuda, b);
  cpu->responsive_field(s.model, on_cpu, c);
  cuda->responsive_field(s.model, on_cuda, d);
  const std::vector<int> cells = s.responsive_cells();
  ASSERT_GT(cells.size(), 1000u);
  EXPECT_TRUE(close(a, b, cells, kSumTolerance));
  EXPECT_TRUE(close(c, d, cells, kSumTolerance));
  cpu->forces(s.model, on_cpu);
  cuda->forces(s.model, on_cuda);
  EXPECT_TRUE(close(on_cpu.force, on_cuda.force, s.bodies(), kForceTolerance));
  EXPECT_TRUE(close(on_cpu.torque, on_cuda.torque, s.bodies(), kForceTolerance));
}

// After relax() the host state is complete: the moments and counters the
// device computed are in state.moments, and they give state.magnetization.
TEST(CudaCoherence, HostStateIsCompleteAfterRelax) {
  CUDA_BACKEND_OR_SKIP(cuda);
  Scene s;
  build_workshop(s);
  reset_cuda_backend_stats(*cuda);
  const RelaxReport r = relax(s.model, s.state, RelaxOptions{}, *cuda);
  EXPECT_TRUE(r.converged);
  long draws = 0;
  for (int c : s.responsive_cells()) {
    const MagneticBody& body = s.model.body(s.model.cell_body(c));
    if (body.kind != CellKind::soft) continue;
    const Vec3 M = soft_cell_magnetization(s.model, s.state, c);
    EXPECT_LT(norm(M - s.state.magnetization[c]), 1e-12 * body.soft.Ms) << "cell " << c;
    for (int k = 0; k < body.soft.n; ++k)
      EXPECT_NEAR(norm(s.state.moments[s.model.moment_offset(c) + k]), 1.0, 1e-12);
    draws += static_cast<long>(s.state.noise_counter[c]);
  }
  EXPECT_EQ(draws, r.llg_steps);
  const CudaBackendStats stats = cuda_backend_stats(*cuda);
  EXPECT_EQ(stats.begin_step.calls, 1);
  EXPECT_EQ(stats.relax_cells.calls, r.iterations);
  EXPECT_EQ(stats.responsive_field.calls, r.field_evaluations);
}

// Host edits of the moments between steps (a body demagnetized, reset) reach
// the device at the next begin_step.
TEST(CudaCoherence, HostEditsTakeEffectAtTheNextStep) {
  CUDA_BACKEND_OR_SKIP(cuda);
  Scene s;
  build_workshop(s);
  auto cpu = make_cpu_backend(2);
  MagneticState on_cpu = s.state, on_cuda = s.state;
  magnetic_step(s.model, on_cpu, RelaxOptions{}, *cpu);
  magnetic_step(s.model, on_cuda, RelaxOptions{}, *cuda);
  for (MagneticState* st : {&on_cpu, &on_cuda}) {
    reset_moments(s.model, *st, 2);
    reset_moments(s.model, *st, 7);
    st->external_field = {-4e3, 0, 1e3};
  }
  magnetic_step(s.model, on_cpu, RelaxOptions{}, *cpu);
  magnetic_step(s.model, on_cuda, RelaxOptions{}, *cuda);
  const std::vector<int> cells = s.responsive_cells();
  EXPECT_TRUE(close(on_cpu.magnetization, on_cuda.magnetization, cells, kStepTolerance));
  EXPECT_TRUE(close(on_cpu.force, on_cuda.force, s.bodies(), kStepTolerance));
}

// One backend for several models in turn, and a model that grows (the
// embedding API adds bodies): the offset tensor tables follow the model.
TEST(CudaCoherence, BackendFollowsModelChanges) {
  CUDA_BACKEND_OR_SKIP(cuda);
  auto cpu = make_cpu_backend(2);
  auto compare = [&](Scene& s, const char* what) {
    std::vector<Vec3> a(s.model.cell_count()), b(s.model.cell_count());
    cpu->begin_step(s.model, s.state);
    cpu->responsive_field(s.model, s.state, a);
    cuda->begin_step(s.model, s.state);
    cuda->responsive_field(s.model, s.state, b);
    EXPECT_TRUE(close(a, b, s.responsive_cells(), kSumTolerance)) << what;
  };
  Scene workshop, heap;
  build_workshop(workshop);
  randomize_moments(workshop, 7);
  build_heap(heap, 50);
  randomize_moments(heap, 8);
  compare(workshop, "workshop");
  compare(heap, "heap");
  compare(workshop, "workshop again");
  // Bodies added to a model the backend has seen.
  SoftMaterial steel = iron(1000.0);
  heap.model.add_body("late_plate", Box{{0.012, 0.012, 0.006}}, steel, 0.003);
  heap.model.add_body("late_ball", Sphere{0.002}, steel, 0.0);
  extend_state(heap.model, heap.state);
  heap.state.pose[heap.model.body_count() - 2].position = {0.05, 0.05, 0.02};
  heap.state.pose[heap.model.body_count() - 1].position = {-0.05, 0.04, 0.03};
  randomize_moments(heap, 9);
  compare(heap, "heap with added bodies");
}

// Like the crane scene (demos/scenes/crane.json): a soft lattice core with a
// coil field above a heap of one-cell steel balls with 8 moments per cell and
// uniaxial anisotropy (its easy axis turning with each ball's random
// orientation), the balls close under the core where the field is strong.
void build_crane(Scene& s, int balls) {
  MagneticModel& m = s.model;
  SoftMaterial core = iron(1000.0);
  core.coil_field = {0, 0, -5e5};
  m.add_body("crane", Box{{0.12, 0.12, 0.03}}, core, 0.012);  // 10 x 10 x 2 lattice
  const SoftMaterial steel = test_support::anisotropic_steel(8e5, 1000.0, 3.2e5, 8);
  for (int i = 0; i < balls; ++i) m.add_body("ball_" + std::to_string(i), Sphere{0.005}, steel, 0.0);
  s.state = make_state(m, 17);
  s.state.pose[0].position = {0.0, 0.0, 0.04955};
  const int side = 8;
  for (int i = 0; i < balls; ++i) {
    const int ix = i % side, iy = (i / side) % side, iz = i / (side * side);
    const double jitter = 2e-4 * (unit_interval(hash_key(17, 2, i, 0)) - 0.5);
    s.state.pose[1 + i].position = {(ix - 3.5) * 0.0102 + jitter, (iy - 3.5) * 0.0102 - jitter,
                                    0.0296 - 0.0102 * iz};
    s.state.pose[1 + i].rotation =
        axis_rotation(random_unit_vector(hash_key(17, 3, i, 0)), 3.0 * unit_interval(hash_key(17, 4, i, 0)));
  }
  place_cells(m, s.state);
}

TEST(CudaParity, EightMomentAnisotropicCellsRelaxCells) {
  CUDA_BACKEND_OR_SKIP(cuda);
  Scene s;
  build_crane(s, 96);
  randomize_moments(s, 12);
  auto cpu = make_cpu_backend(0);
  const int n = s.model.cell_count();
  std::vector<Vec3> H_fixed(n), H_resp(n), H_A(n), b(n);
  cpu->begin_step(s.model, s.state);
  cpu->fixed_field(s.model, s.state, H_fixed);
  cpu->responsive_field(s.model, s.state, H_resp);
  const std::vector<int> cells = s.responsive_cells();
  ASSERT_EQ(static_cast<int>(cells.size()), s.model.body(0).cell_count() + 96);
  ASSERT_EQ(s.model.body(0).cell_count(), 200);
  EXPECT_EQ(s.model.body(1).soft.n, 8);
  MagneticState on_cpu = s.state, on_cuda = s.state;
  cuda->begin_step(s.model, on_cuda);
  cuda->responsive_field(s.model, on_cuda, b);
  EXPECT_TRUE(close(H_resp, b, cells, kSumTolerance)) << "responsive field";
  for (int c : cells) H_A[c] = H_fixed[c] + H_resp[c];
  const LocalRelaxOptions options;
  for (int call = 0; call < 2; ++call) {
    if (call == 1)
      for (int c : cells) H_A[c] = -0.3 * H_A[c];  // reversed: the anisotropic balls switch
    const LocalStats a = cpu->relax_cells(s.model, on_cpu, H_A, options);
    const LocalStats d = cuda->relax_cells(s.model, on_cuda, H_A, options);
    EXPECT_TRUE(close(on_cpu.magnetization, on_cuda.magnetization, cells, kRelaxTolerance)) << "call " << call;
    EXPECT_EQ(a.llg_steps, d.llg_steps) << "call " << call;
    EXPECT_TRUE(std::isfinite(d.max_residual)) << "call " << call;
    if (a.max_residual <= options.tolerance) {
      EXPECT_LE(d.max_residual, options.tolerance) << "call " << call;
    }
    for (int c : cells) {
      EXPECT_EQ(on_cpu.noise_counter[c], on_cuda.noise_counter[c]) << "cell " << c;
      EXPECT_EQ(on_cpu.llg_history[c], on_cuda.llg_history[c]) << "cell " << c;
    }
  }
}

// Whole steps of the crane-like scene: the core coming down onto the balls,
// with and without mutual induction.
void check_crane_steps(const RelaxOptions& options, int steps) {
  CUDA_BACKEND_OR_SKIP(cuda);
  Scene s;
  build_crane(s, 96);
  auto cpu = make_cpu_backend(0);
  MagneticState on_cpu = s.state, on_cuda = s.state;
  for (int step = 0; step < steps; ++step) {
    for (MagneticState* st : {&on_cpu, &on_cuda}) {
      st->pose[0].position.z -= 1e-3 * step;
      st->magnetization_scale[0] = 1.0 - 0.2 * step;
    }
    const RelaxReport a = magnetic_step(s.model, on_cpu, options, *cpu);
    const RelaxReport b = magnetic_step(s.model, on_cuda, options, *cuda);
    const std::vector<int> cells = s.responsive_cells();
    SCOPED_TRACE("step " + std::to_string(step) + ": cpu " + std::to_string(a.iterations) + " iterations, cuda " +
                 std::to_string(b.iterations));
    EXPECT_TRUE(a.converged);
    EXPECT_EQ(a.converged, b.converged);
    EXPECT_LE(std::abs(a.iterations - b.iterations), 1);
    EXPECT_TRUE(std::isfinite(b.residual));
    EXPECT_TRUE(close(on_cpu.magnetization, on_cuda.magnetization, cells, kStepTolerance));
    EXPECT_TRUE(close(on_cpu.applied_field, on_cuda.applied_field, cells, kStepTolerance));
    EXPECT_TRUE(close(on_cpu.force, on_cuda.force, s.bodies(), kStepTolerance));
    EXPECT_TRUE(close(on_cpu.torque, on_cuda.torque, s.bodies(), kStepTolerance));
  }
}

TEST(CudaParity, EightMomentAnisotropicCellsSteps) { check_crane_steps(RelaxOptions{}, 3); }

TEST(CudaParity, EightMomentAnisotropicCellsWithoutMutualInduction) {
  RelaxOptions o;
  o.mutual_induction = false;
  check_crane_steps(o, 2);
}

// A relaxation of 2000 responsive cells (a 400-cell lattice block and 1600
// one-cell balls): many tiles in every kernel and an outer loop long enough
// to carry the round-off of every iteration forward.
TEST(CudaParity, HeapOf2000CellsRelaxes) {
  CUDA_BACKEND_OR_SKIP(cuda);
  Scene s;
  build_heap(s, 1600);
  auto cpu = make_cpu_backend(0);
  const std::vector<int> cells = s.responsive_cells();
  ASSERT_EQ(cells.size(), 2000u);
  MagneticState on_cpu = s.state, on_cuda = s.state;
  for (int step = 0; step < 2; ++step) {
    for (MagneticState* st : {&on_cpu, &on_cuda}) st->pose[0].position.z -= 5e-3 * step;
    const RelaxReport a = magnetic_step(s.model, on_cpu, RelaxOptions{}, *cpu);
    const RelaxReport b = magnetic_step(s.model, on_cuda, RelaxOptions{}, *cuda);
    SCOPED_TRACE("step " + std::to_string(step) + ": cpu " + std::to_string(a.iterations) +
                 " iterations, cuda " + std::to_string(b.iterations));
    EXPECT_TRUE(a.converged);
    EXPECT_EQ(a.converged, b.converged);
    EXPECT_LE(std::abs(a.iterations - b.iterations), 1);
    EXPECT_TRUE(close(on_cpu.magnetization, on_cuda.magnetization, cells, kStepTolerance));
    EXPECT_TRUE(close(on_cpu.applied_field, on_cuda.applied_field, cells, kStepTolerance));
    EXPECT_TRUE(close(on_cpu.force, on_cuda.force, s.bodies(), kStepTolerance));
    EXPECT_TRUE(close(on_cpu.torque, on_cuda.torque, s.bodies(), kStepTolerance));
  }
}

// Lattice bodies of every responsive kind: a soft lattice ball (partial
// cells: the boundary correction of magnetics/model/model.cpp), a rotated soft
// lattice box with two moments per cell and anisotropy, a recoil lattice
// magnet, beside a fixed lattice magnet.
void build_lattices(Scene& s) {
  MagneticModel& m = s.model;
  m.add_body("magnet", Box{{0.02, 0.02, 0.01}}, PermanentMaterial{{0, 0, 9e5}, 0.0}, 0.005);  // 0
  m.add_body("ball", Sphere{0.008}, iron(1000.0), 0.002);                                    // 1
  SoftMaterial plate = iron(300.0);
  plate.anisotropy_field = 2e5;
  plate.easy_axis = {1, 0, 0};
  plate.moments_per_cell = 2;
  m.add_body("plate", Box{{0.03, 0.015, 0.003}}, plate, 0.003);                                  // 2
  m.add_body("recoil", Cylinder{0.006, 0.012}, PermanentMaterial{{0, 6e5, 0}, 0.05}, 0.003);    // 3
  s.state = make_state(m, 23);
  s.state.external_field = {0, 1e3, -2e3};
  s.state.pose[0].position = {0, 0, 0.02};
  s.state.pose[1].position = {0.001, -0.002, 0.0};
  s.state.pose[2].position = {0.0, 0.0, -0.012};
  s.state.pose[2].rotation = axis_rotation({1, 2, 0}, 0.4);
  s.state.pose[3].position = {0.022, 0.003, 0.004};
  s.state.pose[3].rotation = axis_rotation({0, 1, 1}, 0.8);
  place_cells(m, s.state);
}

TEST(CudaParity, LatticeBodies) {
  CUDA_BACKEND_OR_SKIP(cuda);
  auto cpu = make_cpu_backend(0);
  // One evaluation of each field with either intra-body tensor.
  for (IntraBodyTensor tensor : {IntraBodyTensor::cell_average, IntraBodyTensor::point_dipole}) {
    SCOPED_TRACE("intra-body tensor " + std::to_string(static_cast<int>(tensor)));
    Scene s(tensor);
    build_lattices(s);
    randomize_moments(s, 24);
    ASSERT_GT(s.model.body(1).cell_count(), 400);
    EXPECT_EQ(s.model.body(1).self_tensors.empty(), tensor == IntraBodyTensor::point_dipole);
    std::vector<Vec3> a(s.model.cell_count()), b(s.model.cell_count());
    cpu->begin_step(s.model, s.state);
    cuda->begin_step(s.model, s.state);
    cpu->fixed_field(s.model, s.state, a);
    cuda->fixed_field(s.model, s.state, b);
    EXPECT_TRUE(close(a, b, s.responsive_cells(), kSumTolerance)) << "fixed field";
    cpu->responsive_field(s.model, s.state, a);
    cuda->responsive_field(s.model, s.state, b);
    EXPECT_TRUE(close(a, b, s.responsive_cells(), kSumTolerance)) << "responsive field";
  }
  // Whole steps with the cube-cube tensor (about 40 outer iterations each;
  // with point dipoles the lattice ball does not converge in 200).
  Scene s;
  build_lattices(s);
  MagneticState on_cpu = s.state, on_cuda = s.state;
  for (int step = 0; step < 2; ++step) {
    for (MagneticState* st : {&on_cpu, &on_cuda}) st->pose[0].position.z -= 2e-3 * step;
    const RelaxReport a = magnetic_step(s.model, on_cpu, RelaxOptions{}, *cpu);
    const RelaxReport b = magnetic_step(s.model, on_cuda, RelaxOptions{}, *cuda);
    const std::vector<int> cells = s.responsive_cells();
    SCOPED_TRACE("step " + std::to_string(step) + ": cpu " + std::to_string(a.iterations) + " iterations, cuda " +
                 std::to_string(b.iterations));
    EXPECT_TRUE(a.converged);
    EXPECT_EQ(a.converged, b.converged);
    EXPECT_LE(std::abs(a.iterations - b.iterations), 1);
    EXPECT_TRUE(close(on_cpu.magnetization, on_cuda.magnetization, cells, kStepTolerance));
    EXPECT_TRUE(close(on_cpu.applied_field, on_cuda.applied_field, cells, kStepTolerance));
    EXPECT_TRUE(close(on_cpu.force, on_cuda.force, s.bodies(), kStepTolerance));
    EXPECT_TRUE(close(on_cpu.torque, on_cuda.torque, s.bodies(), kStepTolerance));
  }
}

// Non-finite cells fail the relaxation on the device as on the CPU: a NaN
// external field reaches every cell, a NaN moment one cell.
TEST(CudaParity, NonFiniteCellsFailTheRelaxation) {
  CUDA_BACKEND_OR_SKIP(cuda);
  auto cpu = make_cpu_backend(2);
  for (int kind = 0; kind < 2; ++kind) {
    for (RelaxScheme scheme : {RelaxScheme::two_level, RelaxScheme::paper}) {
      Scene s;
      build_workshop(s);
      if (kind == 0) {
        s.state.external_field.y = std::numeric_limits<double>::quiet_NaN();
      } else {
        s.state.moments[s.model.moment_offset(s.model.body(3).first_cell)].x =
            std::numeric_limits<double>::quiet_NaN();
      }
      RelaxOptions o;
      o.scheme = scheme;
      o.max_iterations = 20;
      MagneticState on_cpu = s.state, on_cuda = s.state;
      const RelaxReport a = relax(s.model, on_cpu, o, *cpu);
      const RelaxReport b = relax(s.model, on_cuda, o, *cuda);
      SCOPED_TRACE("kind " + std::to_string(kind) + ", scheme " + std::to_string(static_cast<int>(scheme)));
      EXPECT_FALSE(a.converged);
      EXPECT_FALSE(b.converged);
      EXPECT_FALSE(std::isfinite(a.residual));
      EXPECT_FALSE(std::isfinite(b.residual));
    }
  }
}

// The CUDA backend has no far-field approximation: a theta > 0 is reported
// once on stderr and every pair is still summed exactly.
TEST(CudaBackend, IgnoredFarFieldIsReportedOnce) {
  CUDA_BACKEND_OR_SKIP(cuda);
  ::testing::internal::CaptureStderr();
  cuda->set_far_field(0.0);
  const std::string none = ::testing::internal::GetCapturedStderr();
  EXPECT_EQ(none, "");
  ::testing::internal::CaptureStderr();
  cuda->set_far_field(0.5);
  cuda->set_far_field(0.7);
  const std::string once = ::testing::internal::GetCapturedStderr();
  const std::string line = "odemag: the CUDA backend ignores solver.far_field_theta";
  ASSERT_NE(once.find(line), std::string::npos) << once;
  EXPECT_EQ(once.find(line, once.find(line) + 1), std::string::npos) << once;
  // Exact sums all the same.
  Scene s;
  build_heap(s, 700);
  randomize_moments(s, 25);
  auto cpu = make_cpu_backend(0);
  std::vector<Vec3> a(s.model.cell_count()), b(s.model.cell_count());
  cpu->begin_step(s.model, s.state);
  cpu->responsive_field(s.model, s.state, a);
  cuda->begin_step(s.model, s.state);
  cuda->responsive_field(s.model, s.state, b);
  EXPECT_TRUE(close(a, b, s.responsive_cells(), kSumTolerance));
}

// Models that are copies of one another, or a model replaced by a new one at
// the same address, are told apart by their generation (magnetics/model/model.h):
// the offset tensor tables follow.
TEST(CudaCoherence, CopiedAndReplacedModels) {
  CUDA_BACKEND_OR_SKIP(cuda);
  auto cpu = make_cpu_backend(2);
  auto compare_fields = [&](const MagneticModel& model, MagneticState& state, const char* what) {
    std::vector<Vec3> a(model.cell_count()), b(model.cell_count());
    cpu->begin_step(model, state);
    cpu->responsive_field(model, state, a);
    cuda->begin_step(model, state);
    cuda->responsive_field(model, state, b);
    EXPECT_TRUE(close(a, b, active_responsive_cells(model, state), kSumTolerance)) << what;
  };
  Scene s(IntraBodyTensor::cell_average);
  build_lattices(s);
  randomize_moments(s, 26);
  compare_fields(s.model, s.state, "original");
  // The same address, other tables (point dipole), same layout.
  {
    Scene t(IntraBodyTensor::point_dipole);
    build_lattices(t);
    s.model = t.model;
  }
  compare_fields(s.model, s.state, "replaced in place");
  const MagneticModel copy = s.model;
  EXPECT_NE(copy.generation(), s.model.generation());
  compare_fields(copy, s.state, "copy");
}

}  // namespace
}  // namespace odemag
