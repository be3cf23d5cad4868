// Held bodies (RelaxOptions::held_bodies, docs/simulation.md "Substeps"): a
// relaxation keeps their magnetization and converges on the other cells,
// which feel the held ones as sources. Checked against the closed form of a
// linear sphere in the field of two point dipoles, on the CPU backend (which
// skips the held cells) and on a backend that relaxes every cell (the
// interface's default: held cells under their last applied field).
#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <stdexcept>

#include "magnetics/model/backend.h"
#include "odemag/constants.h"
#include "magnetics/model/model.h"
#include "magnetics/relax/relax.h"

using namespace odemag;

namespace {

constexpr double kRadius = 0.005;  // m
constexpr double kChi = 10.0;

// Field (A/m) at r (from the dipole) of a point dipole mu (A m^2).
Vec3 dipole_field(const Vec3& r, const Vec3& mu) {
  const double d = norm(r);
  const Vec3 u = r / d;
  return (3.0 * dot(mu, u) * u - mu) / (4.0 * kPi * d * d * d);
}

// Three linear iron balls 12 radii apart (beyond every near-field pair:
// point dipoles, exactly) in a uniform field.
struct ThreeBalls {
  MagneticModel model;
  MagneticState state;
  RelaxOptions options;
  ThreeBalls() {
    SoftMaterial iron;
    iron.saturation = 1e8;  // far above the fields here: linear
    iron.susceptibility = kChi;
    for (const char* name : {"a", "b", "c"}) model.add_body(name, Sphere{kRadius}, iron, 0.0);
    state = make_state(model, 1);
    state.pose[1].position = {0.06, 0.0, 0.0};
    state.pose[2].position = {0.0, 0.0, 0.06};
    state.external_field = {2e3, 0.0, 1e4};
    options.tolerance = 1e-10;
  }
  Vec3 moment(int b) const { return model.body(b).cells.cell_volume * state.magnetization[b]; }
};

// The CPU backend with the interface's default set_held_bodies: it relaxes
// every cell.
class RelaxesEveryCell : public MagneticBackend {
 public:
  std::string name() const override { return "relaxes every cell"; }
  void begin_step(const MagneticModel& m, const MagneticState& s) override { cpu_->begin_step(m, s); }
  void set_near_field(bool on, bool mutual) override { cpu_->set_near_field(on, mutual); }
  void fixed_field(const MagneticModel& m, const MagneticState& s, std::vector<Vec3>& H) override {
    cpu_->fixed_field(m, s, H);
  }
  void responsive_field(const MagneticModel& m, const MagneticState& s, std::vector<Vec3>& H) override {
    cpu_->responsive_field(m, s, H);
  }
  LocalStats relax_cells(const MagneticModel& m, MagneticState& s, const std::vector<Vec3>& H_A,
                         const LocalRelaxOptions& o) override {
    return cpu_->relax_cells(m, s, H_A, o);
  }
  void forces(const MagneticModel& m, MagneticState& s) override { cpu_->forces(m, s); }
  void probe_field(const MagneticModel& m, const MagneticState& s, const std::vector<Vec3>& points,
                   std::vector<Vec3>& H) override {
    cpu_->probe_field(m, s, points, H);
  }

 private:
  std::unique_ptr<MagneticBackend> cpu_ = make_cpu_backend(1);
};

// Relaxes all three, moves b and c, relaxes again with b and c held; checks
// that they kept their moments and that a answers H_E plus their dipole
// fields at their new places: M_a = 3 chi / (3 + chi) H_applied.
void check_held_relaxation(MagneticBackend& backend, double held_tolerance) {
  ThreeBalls balls;
  ASSERT_TRUE(magnetic_step(balls.model, balls.state, balls.options, backend).converged);
  const Vec3 mu_b = balls.moment(1), mu_c = balls.moment(2);
  balls.state.pose[1].position = {0.05, 0.01, 0.0};
  balls.state.pose[2].position = {-0.01, 0.0, 0.05};
  balls.options.held_bodies = {0, 1, 1};
  const RelaxReport report = magnetic_step(balls.model, balls.state, balls.options, backend);
  ASSERT_TRUE(report.converged);
  EXPECT_LE(norm(balls.moment(1) - mu_b), held_tolerance * norm(mu_b));
  EXPECT_LE(norm(balls.moment(2) - mu_c), held_tolerance * norm(mu_c));
  const Vec3& x_a = balls.state.pose[0].position;
  const Vec3 H_applied = balls.state.external_field + dipole_field(x_a - balls.state.pose[1].position, mu_b) +
                         dipole_field(x_a - balls.state.pose[2].position, mu_c);
  const Vec3 expected = (3.0 * kChi / (3.0 + kChi)) * H_applied;
  EXPECT_LE(norm(balls.state.magnetization[0] - expected), 1e-8 * norm(expected))
      << "a: " << balls.state.magnetization[0].x << " " << balls.state.magnetization[0].z << " expected "
      << expected.x << " " << expected.z;
  // The backend holds them for that step only: its field sums then cover
  // every cell again (b's field is not zero).
  std::vector<Vec3> H(balls.model.cell_count());
  backend.responsive_field(balls.model, balls.state, H);
  EXPECT_GT(norm(H[1]), 0.0);
  // Without holding, b and c answer the moved field: their moments change.
  balls.options.held_bodies.clear();
  ASSERT_TRUE(magnetic_step(balls.model, balls.state, balls.options, backend).converged);
  EXPECT_GT(norm(balls.moment(1) - mu_b), 1e-4 * norm(mu_b));
}

}  // namespace

TEST(HeldBodies, HeldBallsKeepTheirMomentsAndTheOthersAnswerTheirField) {
  std::unique_ptr<MagneticBackend> cpu = make_cpu_backend(1);
  ASSERT_TRUE(cpu->set_held_bodies({0, 1, 1}));  // the CPU backend skips held cells
  cpu->set_held_bodies({});
  check_held_relaxation(*cpu, 1e-14);  // M recomputed from the same moments: rounding only
}

TEST(HeldBodies, ABackendThatRelaxesEveryCellRelaxesHeldOnesUnderTheirLastField) {
  RelaxesEveryCell backend;
  EXPECT_FALSE(backend.set_held_bodies({0, 1, 1}));
  check_held_relaxation(backend, 1e-9);
}

// Held moments turn with their bodies: an anisotropic ball turned by 90
// degrees about y carries its moment along, as place_cells does for
// magnetic_forces_at_held_magnetization.
TEST(HeldBodies, AHeldMomentTurnsWithItsBody) {
  MagneticModel model;
  SoftMaterial steel;
  steel.saturation = 8e5;
  steel.susceptibility = 1000;
  steel.anisotropy_field = 3.2e5;
  steel.moments_per_cell = 8;
  model.add_body("ball", Sphere{kRadius}, steel, 0.0);
  model.add_body("probe", Sphere{kRadius}, steel, 0.0);
  MagneticState state = make_state(model, 2);
  state.pose[1].position = {0.1, 0.0, 0.0};
  state.external_field = {0.0, 0.0, 3e5};
  RelaxOptions options;
  options.tolerance = 1e-8;
  std::unique_ptr<MagneticBackend> cpu = make_cpu_backend(1);
  ASSERT_TRUE(magnetic_step(model, state, options, *cpu).converged);
  const Vec3 before = state.magnetization[0];
  ASSERT_GT(before.z, 1e5);
  state.pose[0].rotation = Mat3{{{0.0, 0.0, 1.0}, {0.0, 1.0, 0.0}, {-1.0, 0.0, 0.0}}};
  options.held_bodies = {1, 0};
  ASSERT_TRUE(magnetic_step(model, state, options, *cpu).converged);
  const Vec3 turned = state.pose[0].rotation * before;
  EXPECT_LE(norm(state.magnetization[0] - turned), 1e-12 * norm(before));
}

// After a step that held bodies, the backend's field sums cover every cell
// again, the near-field pairs of two once-held touching balls included: the
// same field as a backend that never held anything.
TEST(HeldNearField, TheNearFieldOfHeldPairsReturnsAfterTheStep) {
  const uint8_t hold = RelaxOptions::kHeld;
  ThreeBalls balls;
  balls.state.pose[1].position = {0.0105, 0.0, 0.0};  // a, b and c in a touching row
  balls.state.pose[2].position = {0.021, 0.0, 0.0};
  std::unique_ptr<MagneticBackend> cpu = make_cpu_backend(1), fresh = make_cpu_backend(1);
  // Relaxed first: a saturated ball (as made) carries no near-field correction.
  ASSERT_TRUE(magnetic_step(balls.model, balls.state, balls.options, *cpu).converged);
  balls.state.pose[0].position.x -= 0.0002;
  balls.state.pose[2].position.x += 0.0002;  // b and c apart beyond the carry-over: a new evaluation
  balls.options.held_bodies = {0, hold, hold};
  ASSERT_TRUE(magnetic_step(balls.model, balls.state, balls.options, *cpu).converged);
  balls.options.held_bodies.clear();
  fresh->begin_step(balls.model, balls.state);
  std::vector<Vec3> H(balls.model.cell_count()), H_fresh(balls.model.cell_count());
  cpu->responsive_field(balls.model, balls.state, H);
  fresh->responsive_field(balls.model, balls.state, H_fresh);
  for (int c = 0; c < 3; ++c) EXPECT_EQ(norm(H[c] - H_fresh[c]), 0.0) << "cell " << c;
}

// A held list that does not have one entry per body is refused, naming it.
TEST(HeldBodies, AListOfTheWrongLengthThrows) {
  ThreeBalls balls;
  std::unique_ptr<MagneticBackend> cpu = make_cpu_backend(1);
  balls.options.held_bodies = {0, 1};
  try {
    magnetic_step(balls.model, balls.state, balls.options, *cpu);
    FAIL() << "no exception";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("held_bodies: 2 entries for 3 bodies"), std::string::npos) << e.what();
  }
  EXPECT_THROW(relax(balls.model, balls.state, balls.options, *cpu), std::invalid_argument);
  EXPECT_THROW(magnetic_forces_at_held_magnetization(balls.model, balls.state, balls.options, *cpu),
               std::invalid_argument);
}

TEST(HeldBodies, AnEntryOtherThanZeroOrOneThrows) {
  ThreeBalls balls;
  std::unique_ptr<MagneticBackend> cpu = make_cpu_backend(1);
  balls.options.held_bodies = {0, 2, 0};
  try {
    magnetic_step(balls.model, balls.state, balls.options, *cpu);
    FAIL() << "no exception";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("held_bodies: entry 1 is 2 (0 or 1)"), std::string::npos) << e.what();
  }
}
