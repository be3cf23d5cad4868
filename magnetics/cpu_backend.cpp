// CPU backend: OpenMP over target cells, one thread per target, sums in a fixed
// order, so results do not depend on the thread count (determinism).
#include <omp.h>

#include <algorithm>

#include "magnetics/backend.h"
#include "magnetics/far_field.h"
#include "magnetics/field_probe.h"
#include "magnetics/kernels.h"
#include "magnetics/near_field.h"
#include "magnetics/pair_sums.h"
#include "magnetics/simd.h"

namespace odemag {

namespace {

// Below this many pair interactions a loop runs on one thread: waking the
// team costs more than it saves.
constexpr long kParallelPairs = 20000;

// Fewer responsive cells than this are summed exactly even when the far-field
// approximation is on: in the plate scenes (140-190 cells, one lattice body
// whose nodes are always opened) the tree was 1.2x slower than the exact sum
// (docs/benchmarks.md section 2b).
constexpr int kMinTreeCells = 512;

// Cells as structure of arrays, for the pair loops.
struct CellArrays {
  std::vector<double> x, y, z, radius, mx, my, mz;  // position, contact radius, moment mu = M V
  std::vector<int> cell, body;
  void clear() {
    for (auto* v : {&x, &y, &z, &radius, &mx, &my, &mz}) v->clear();
    cell.clear();
    body.clear();
  }
  int size() const { return static_cast<int>(x.size()); }
  void push(const MagneticModel& model, const MagneticState& state, int c) {
    const Vec3& p = state.cell_position[c];
    x.push_back(p.x), y.push_back(p.y), z.push_back(p.z);
    radius.push_back(model.cell_contact_radius(c));
    mx.push_back(0), my.push_back(0), mz.push_back(0);
    cell.push_back(c);
    body.push_back(model.cell_body(c));
  }
  SourceArrays sources() const {
    return {x.data(), y.data(), z.data(), radius.data(), mx.data(), my.data(), mz.data()};
  }
  void load_moments(const MagneticModel& model, const MagneticState& state) {
    for (int i = 0; i < size(); ++i) {
      const Vec3 mu = model.cell_volume(cell[i]) * state.magnetization[cell[i]];
      mx[i] = mu.x, my[i] = mu.y, mz[i] = mu.z;
    }
  }
};

// Force (N) on, and field (A/m) at, a target cell (position t, moment mt,
// contact radius rt) from sources [j0, j1), through the kernel with contact
// distance rt + source radius.
struct ForceAndField {
  Vec3 force, field;
};
inline ForceAndField sum_force_and_field(const CellArrays& s, int j0, int j1, const Vec3& t, const Vec3& mt,
                                        double rt) {
  const double* __restrict x = s.x.data();
  const double* __restrict y = s.y.data();
  const double* __restrict z = s.z.data();
  const double* __restrict r = s.radius.data();
  const double* __restrict mx = s.mx.data();
  const double* __restrict my = s.my.data();
  const double* __restrict mz = s.mz.data();
  // F = mu0 [B ((r.mu_a) mu_b + (r.mu_b) mu_a + (mu_a.mu_b) r) + C (r.mu_a)(r.mu_b) r]
  // (magnetics/kernels.h), mu_a the source, mu_b the target.
#if ODEMAG_HAVE_SIMD
  SimdD fx, fy, fz, hx, hy, hz;
  const SimdD bx(mt.x), by(mt.y), bz(mt.z);
  for (int j = j0; j < j1; j += kSimdWidth) {
    const int count = j1 - j < kSimdWidth ? j1 - j : kSimdWidth;
    const SimdD dx = SimdD(t.x) - SimdD::load(x + j, count), dy = SimdD(t.y) - SimdD::load(y + j, count),
                dz = SimdD(t.z) - SimdD::load(z + j, count);
    const SimdD contact = SimdD(rt) + SimdD::load(r + j, count);
    const SimdD r2 = dx * dx + dy * dy + dz * dz;
    const DipoleCoefficientsT<SimdD> c = dipole_coefficients_from(r2, inverse_sqrt(max(r2, contact * contact)));
    const SimdD ax = SimdD::load(mx + j, count), ay = SimdD::load(my + j, count), az = SimdD::load(mz + j, count);
    const SimdD ra = dx * ax + dy * ay + dz * az, rb = dx * bx + dy * by + dz * bz;
    const SimdD radial = c.B * (ax * bx + ay * by + az * bz) + c.C * ra * rb;
    fx += c.B * (ra * bx + rb * ax) + radial * dx;
    fy += c.B * (ra * by + rb * ay) + radial * dy;
    fz += c.B * (ra * bz + rb * az) + radial * dz;
    const SimdD rm = c.B * ra;
    hx += c.A * ax + rm * dx;
    hy += c.A * ay + rm * dy;
    hz += c.A * az + rm * dz;
  }
  return {kMu0 * Vec3{fx.sum(), fy.sum(), fz.sum()}, {hx.sum(), hy.sum(), hz.sum()}};
#else
  double fx = 0, fy = 0, fz = 0, hx = 0, hy = 0, hz = 0;
#pragma omp simd reduction(+ : fx, fy, fz, hx, hy, hz)
  for (int j = j0; j < j1; ++j) {
    const double dx = t.x - x[j], dy = t.y - y[j], dz = t.z - z[j];
    const double contact = rt + r[j];
    const DipoleCoefficients c = dipole_coefficients(dx * dx + dy * dy + dz * dz, contact * contact);
    const double ra = dx * mx[j] + dy * my[j] + dz * mz[j];
    const double rb = dx * mt.x + dy * mt.y + dz * mt.z;
    const double radial = c.B * (mx[j] * mt.x + my[j] * mt.y + mz[j] * mt.z) + c.C * ra * rb;
    fx += c.B * (ra * mt.x + rb * mx[j]) + radial * dx;
    fy += c.B * (ra * mt.y + rb * my[j]) + radial * dy;
    fz += c.B * (ra * mt.z + rb * mz[j]) + radial * dz;
    hx += c.A * mx[j] + c.B * ra * dx;
    hy += c.A * my[j] + c.B * ra * dy;
    hz += c.A * mz[j] + c.B * ra * dz;
  }
  return {kMu0 * Vec3{fx, fy, fz}, {hx, hy, hz}};
#endif
}

class CpuBackend final : public MagneticBackend {
 public:
  explicit CpuBackend(int threads) : threads_(threads > 0 ? threads : omp_get_max_threads()) {}

  std::string name() const override { return "cpu"; }

  void begin_step(const MagneticModel& model, const MagneticState& state) override {
    fixed_.clear();
    resp_.clear();
    all_.clear();
    resp_range_.clear();
    all_range_.clear();
    for (int b = 0; b < model.body_count(); ++b) {
      const MagneticBody& body = model.body(b);
      if (body.inert() || !state.active[b]) continue;
      const int begin = resp_.size(), all_begin = all_.size();
      for (int i = 0; i < body.cell_count(); ++i) {
        const int c = body.first_cell + i;
        all_.push(model, state, c);
        if (body.responsive()) {
          resp_.push(model, state, c);
        } else {
          fixed_.push(model, state, c);
        }
      }
      for (int i = begin; i < resp_.size(); ++i) resp_range_.push_back({begin, resp_.size()});
      for (int i = all_begin; i < all_.size(); ++i) all_range_.push_back({all_begin, all_.size()});
    }
    fixed_.load_moments(model, state);
    use_tree_ = far_field_theta_ > 0.0 && resp_.size() >= kMinTreeCells;
    if (use_tree_)
      tree_.build(resp_.x.data(), resp_.y.data(), resp_.z.data(), resp_.radius.data(), resp_.body.data(),
                  resp_.size(), far_field_theta_);
    near_.build(model, state, near_field_, near_mutual_induction_);
  }

  void set_far_field(double theta) override { far_field_theta_ = theta; }
  void set_near_field(bool on, bool mutual_induction) override {
    near_field_ = on;
    near_mutual_induction_ = mutual_induction;
  }

  void fixed_field(const MagneticModel& model, const MagneticState& state, std::vector<Vec3>& H) override {
    const int n = resp_.size();
#pragma omp parallel for schedule(static) num_threads(threads_) if (static_cast<long>(n) * fixed_.size() > kParallelPairs)
    for (int i = 0; i < n; ++i)
      H[resp_.cell[i]] = state.external_field +
                         sum_field(fixed_.sources(), 0, fixed_.size(), resp_.x[i], resp_.y[i], resp_.z[i],
                                   resp_.radius[i]);
    near_.add_field(model, state, NearFieldSources::fixed, H);
  }

  void responsive_field(const MagneticModel& model, const MagneticState& state,
                        std::vector<Vec3>& H) override {
    resp_.load_moments(model, state);
    const int n = resp_.size();
    // Body-frame moments for the intra-body sums.
    body_moment_.resize(n);
    for (int i = 0; i < n; ++i)
      body_moment_[i] = state.pose[resp_.body[i]].rotation.transpose_times(
          {resp_.mx[i], resp_.my[i], resp_.mz[i]});
    // Inter-body part from the far-field tree, when it is on.
    if (use_tree_) {
      tree_field_.resize(n);
      tree_.field(resp_.mx.data(), resp_.my.data(), resp_.mz.data(), tree_field_.data(), threads_);
    }
#pragma omp parallel for schedule(dynamic, 16) num_threads(threads_) if (static_cast<long>(n) * n > kParallelPairs)
    for (int i = 0; i < n; ++i) {
      const auto [begin, end] = resp_range_[i];
      // Inter-body: every responsive cell of another body.
      Vec3 h = use_tree_ ? tree_field_[i]
                         : sum_field(resp_.sources(), 0, begin, resp_.x[i], resp_.y[i], resp_.z[i], resp_.radius[i]) +
                               sum_field(resp_.sources(), end, n, resp_.x[i], resp_.y[i], resp_.z[i], resp_.radius[i]);
      // Intra-body: cached tensors of the body, in the body frame.
      const MagneticBody& body = model.body(resp_.body[i]);
      if (end - begin > 1) {
        const auto& li = body.cells.lattice_index[resp_.cell[i] - body.first_cell];
        Vec3 hb;
        for (int j = begin; j < end; ++j) {
          if (j == i) continue;
          const auto& lj = body.cells.lattice_index[resp_.cell[j] - body.first_cell];
          hb += symmetric_times(&body.offset_tensors[6u * body.offset_index(li, lj)], body_moment_[j]);
        }
        h += state.pose[resp_.body[i]].rotation * hb;
      }
      H[resp_.cell[i]] = h;
    }
    add_boundary_field(model, state, H);
    near_.add_field(model, state, NearFieldSources::responsive, H);
  }

  LocalStats relax_cells(const MagneticModel& model, MagneticState& state,
                         const std::vector<Vec3>& H_A, const LocalRelaxOptions& options) override {
    const int n = resp_.size();
    long llg = 0, newton = 0;
    double worst = 0.0;
#pragma omp parallel for schedule(dynamic, 8) num_threads(threads_) reduction(+ : llg, newton) \
    reduction(max : worst) if (n > 16)
    for (int i = 0; i < n; ++i) {
      const int c = resp_.cell[i], b = resp_.body[i];
      const MagneticBody& body = model.body(b);
      const Mat3& R = state.pose[b].rotation;
      if (body.kind == CellKind::recoil_permanent) {
        state.magnetization[c] = recoil_magnetization(
            R * (state.magnetization_scale[b] * body.remanence), body.recoil, H_A[c]);
        continue;
      }
      const int off = model.moment_offset(c);
      bool history = state.llg_history[c] != 0;
      const LocalRelaxResult r = relax_soft_cell(
          body.soft, R.transpose_times(H_A[c]), &state.moments[off], &state.moment_hc_prev[off],
          history, state.noise_counter[c], noise_stream(state.seed, c), options);
      state.llg_history[c] = history ? 1 : 0;
      state.magnetization[c] = R * (body.soft.Ms * mean_moment(&state.moments[off], body.soft.n));
      llg += r.llg_steps;
      newton += r.newton_steps;
      worst = std::max(worst, r.residual);
    }
    return {llg, newton, worst};
  }

  void forces(const MagneticModel& model, MagneticState& state) override {
    all_.load_moments(model, state);
    const int n = all_.size();
    cell_force_.assign(n, {});
    cell_field_.assign(n, {});
#pragma omp parallel for schedule(dynamic, 16) num_threads(threads_) if (static_cast<long>(n) * n > kParallelPairs)
    for (int i = 0; i < n; ++i) {
      // Every cell of another body (pairs inside a body cancel).
      const Vec3 xi{all_.x[i], all_.y[i], all_.z[i]}, mi{all_.mx[i], all_.my[i], all_.mz[i]};
      const auto [begin, end] = all_range_[i];
      const ForceAndField a = sum_force_and_field(all_, 0, begin, xi, mi, all_.radius[i]);
      const ForceAndField b = sum_force_and_field(all_, end, n, xi, mi, all_.radius[i]);
      cell_force_[i] = a.force + b.force;
      cell_field_[i] = a.field + b.field;
    }
    if (near_.pair_count() > 0) {
      near_force_.assign(model.cell_count(), {});
      near_field_at_.assign(model.cell_count(), {});
      near_.add_forces(model, state, near_force_, near_field_at_);
      for (int i = 0; i < n; ++i) {
        cell_force_[i] += near_force_[all_.cell[i]];
        cell_field_[i] += near_field_at_[all_.cell[i]];
      }
    }
    std::fill(state.force.begin(), state.force.end(), Vec3{});
    std::fill(state.torque.begin(), state.torque.end(), Vec3{});
    for (int i = 0; i < n; ++i) {
      const int b = all_.body[i];
      const Vec3 xi{all_.x[i], all_.y[i], all_.z[i]}, mi{all_.mx[i], all_.my[i], all_.mz[i]};
      state.force[b] += cell_force_[i];
      state.torque[b] += cell_torque(xi - state.pose[b].position, cell_force_[i], mi,
                                     cell_field_[i] + state.external_field);
    }
  }

  void field_at_points(const MagneticModel& model, const MagneticState& state,
                       const std::vector<Vec3>& points, std::vector<Vec3>& H) override {
    const std::vector<ProbeCell> cells = probe_cells(model, state);
    const int n = static_cast<int>(points.size()), m = static_cast<int>(cells.size());
    H.resize(n);
#pragma omp parallel for schedule(dynamic, 64) num_threads(threads_) if (static_cast<long>(n) * m > kParallelPairs)
    for (int p = 0; p < n; ++p) {
      Vec3 h = state.external_field;
      for (int c = 0; c < m; ++c) h += probe_cell_field(cells[c], points[p]);
      H[p] = h;
    }
  }

 private:
  int threads_;
  CellArrays fixed_, resp_, all_;
  std::vector<std::pair<int, int>> resp_range_;  // per responsive cell: its body's range in resp_
  std::vector<std::pair<int, int>> all_range_;   // per cell: its body's range in all_
  std::vector<Vec3> body_moment_, cell_force_, cell_field_, near_force_, near_field_at_;
  bool near_field_ = true, near_mutual_induction_ = true;
  NearField near_;
  double far_field_theta_ = 0.0;  // 0: every pair summed exactly
  bool use_tree_ = false;
  FarFieldTree tree_;
  std::vector<Vec3> tree_field_;
};

}  // namespace

std::unique_ptr<MagneticBackend> make_cpu_backend(int threads) {
  return std::make_unique<CpuBackend>(threads);
}

}  // namespace odemag
