// CPU backend: OpenMP over target cells, one thread per target, sums in a fixed
// order, so results do not depend on the thread count (determinism).
#include <omp.h>

#include <algorithm>
#include <cmath>
#include <limits>

#include "magnetics/model/backend.h"
#include "magnetics/model/cell_layout.h"
#include "magnetics/relax/far_field.h"
#include "magnetics/relax/threads.h"
#include "magnetics/relax/field_probe.h"
#include "magnetics/kernels/kernels.h"
#include "magnetics/near_field/near_field.h"
#include "magnetics/kernels/pair_sums.h"
#include "magnetics/relax/relax.h"
#include "magnetics/kernels/simd.h"

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

// The cells of a CellList as structure of arrays, for the pair loops.
struct CellArrays {
  std::vector<double> x, y, z, radius, mx, my, mz;  // position, contact radius, moment mu = M V
  int size() const { return static_cast<int>(x.size()); }
  void assign(const MagneticModel& model, const MagneticState& state, const CellList& list) {
    const size_t n = static_cast<size_t>(list.size());
    for (auto* v : {&x, &y, &z, &radius}) v->resize(n);
    for (auto* v : {&mx, &my, &mz}) v->assign(n, 0.0);
    for (size_t i = 0; i < n; ++i) {
      const int c = list.cell[i];
      const Vec3& p = state.cell_position[c];
      x[i] = p.x, y[i] = p.y, z[i] = p.z;
      radius[i] = model.cell_contact_radius(c);
    }
  }
  SourceArrays sources() const {
    return {x.data(), y.data(), z.data(), radius.data(), mx.data(), my.data(), mz.data()};
  }
  void load_moments(const MagneticModel& model, const MagneticState& state, const CellList& list) {
    for (int i = 0; i < size(); ++i) {
      const int c = list.cell[i];
      const Vec3 mu = model.cell_volume(c) * state.magnetization[c];
      mx[i] = mu.x, my[i] = mu.y, mz[i] = mu.z;
    }
  }
};

class CpuBackend final : public MagneticBackend {
 public:
  explicit CpuBackend(int threads) : threads_(threads > 0 ? threads : default_thread_count()) {}

  std::string name() const override { return "cpu"; }

  void begin_step(const MagneticModel& model, const MagneticState& state) override {
    layout_.build(model, state);
    fixed_.assign(model, state, layout_.fixed);
    resp_.assign(model, state, layout_.responsive);
    all_.assign(model, state, layout_.all);
    fixed_.load_moments(model, state, layout_.fixed);
    use_tree_ = far_field_theta_ > 0.0 && resp_.size() >= kMinTreeCells;
    if (use_tree_)
      tree_.build(resp_.x.data(), resp_.y.data(), resp_.z.data(), resp_.radius.data(),
                  layout_.responsive.body.data(), resp_.size(), far_field_theta_);
    held_cell_.clear();
    if (!held_.empty()) {
      held_cell_.assign(model.cell_count(), 0);
      for (int b = 0; b < model.body_count(); ++b)
        std::fill_n(held_cell_.begin() + model.body(b).first_cell, model.body(b).cell_count(), held_[b]);
    }
    near_.set_held_cells(&held_cell_);
    near_.build(model, state, near_field_, near_mutual_induction_);
  }

  void set_far_field(double theta) override { far_field_theta_ = theta; }
  bool set_held_bodies(const std::vector<uint8_t>& held) override {
    held_ = held;
    if (held_.empty()) held_cell_.clear();  // a non-empty set is followed by begin_step, which builds it
    return true;
  }
  void set_near_field(bool on, bool mutual_induction) override {
    near_field_ = on;
    near_mutual_induction_ = mutual_induction;
  }

  void fixed_field(const MagneticModel& model, const MagneticState& state, std::vector<Vec3>& H) override {
    const int n = resp_.size();
#pragma omp parallel for schedule(static) num_threads(threads_) if (static_cast<long>(n) * fixed_.size() > kParallelPairs)
    for (int i = 0; i < n; ++i)
      H[layout_.responsive.cell[i]] = state.external_field +
                         sum_field(fixed_.sources(), 0, fixed_.size(), resp_.x[i], resp_.y[i], resp_.z[i],
                                   resp_.radius[i]);
    near_.add_field(model, state, NearFieldSources::fixed, H);
  }

  void responsive_field(const MagneticModel& model, const MagneticState& state,
                        std::vector<Vec3>& H) override {
    const CellList& resp = layout_.responsive;
    resp_.load_moments(model, state, resp);
    const int n = resp_.size();
    // Body-frame moments for the intra-body sums.
    body_moment_.resize(n);
    for (int i = 0; i < n; ++i)
      body_moment_[i] = state.pose[resp.body[i]].rotation.transpose_times(
          {resp_.mx[i], resp_.my[i], resp_.mz[i]});
    // Inter-body part from the far-field tree, when it is on.
    if (use_tree_) {
      tree_field_.resize(n);
      tree_.field(resp_.mx.data(), resp_.my.data(), resp_.mz.data(), tree_field_.data(), threads_);
    }
#pragma omp parallel for schedule(dynamic, 16) num_threads(threads_) if (static_cast<long>(n) * n > kParallelPairs)
    for (int i = 0; i < n; ++i) {
      const auto [b, begin, end] = resp.run_of(i);
      if (is_held(b)) {  // not relaxed: its field is not needed
        H[resp.cell[i]] = {};
        continue;
      }
      // Inter-body: every responsive cell of another body.
      Vec3 h = use_tree_ ? tree_field_[i]
                         : sum_field(resp_.sources(), 0, begin, resp_.x[i], resp_.y[i], resp_.z[i], resp_.radius[i]) +
                               sum_field(resp_.sources(), end, n, resp_.x[i], resp_.y[i], resp_.z[i], resp_.radius[i]);
      // Intra-body: cached tensors of the body, in the body frame.
      const MagneticBody& body = model.body(b);
      if (!body.pair_tensors.empty()) {
        // Graded cells or refined zones: per-pair tensors, the diagonal included (model.h).
        const size_t row = static_cast<size_t>(resp.cell[i] - body.first_cell) * body.cell_count();
        Vec3 hb;
        for (int j = begin; j < end; ++j)
          hb += symmetric_times(&body.pair_tensors[6u * (row + (resp.cell[j] - body.first_cell))], body_moment_[j]);
        h += state.pose[b].rotation * hb;
      } else if (end - begin > 1) {
        const auto& li = body.cells.lattice_index[resp.cell[i] - body.first_cell];
        Vec3 hb;
        for (int j = begin; j < end; ++j) {
          if (j == i) continue;
          const auto& lj = body.cells.lattice_index[resp.cell[j] - body.first_cell];
          hb += symmetric_times(&body.offset_tensors[6u * body.offset_index(li, lj)], body_moment_[j]);
        }
        h += state.pose[b].rotation * hb;
      }
      H[resp.cell[i]] = h;
    }
    add_boundary_field(model, state, H);
    near_.add_field(model, state, NearFieldSources::responsive, H);
  }

  LocalStats relax_cells(const MagneticModel& model, MagneticState& state,
                         const std::vector<Vec3>& H_A, const LocalRelaxOptions& options) override {
    const int n = resp_.size();
    long llg = 0, newton = 0, nonfinite = 0;
    double worst = 0.0;
    // A cell whose residual or magnetization is not finite (NaN moments or
    // fields) makes the largest residual NaN: max reductions drop NaN, and a
    // relaxation must not look converged with such cells.
#pragma omp parallel for schedule(dynamic, 8) num_threads(threads_) reduction(+ : llg, newton, nonfinite) \
    reduction(max : worst) if (n > 16)
    for (int i = 0; i < n; ++i) {
      const int c = layout_.responsive.cell[i], b = layout_.responsive.body[i];
      if (is_held(b)) continue;  // keeps its moments (place_cells turned them with the body)
      const MagneticBody& body = model.body(b);
      const Mat3& R = state.pose[b].rotation;
      if (body.kind == CellKind::recoil_permanent) {
        state.magnetization[c] = recoil_magnetization(
            R * (state.magnetization_scale[b] * body.remanence), body.recoil, H_A[c]);
        if (!is_finite(state.magnetization[c])) ++nonfinite;
        continue;
      }
      const int off = model.moment_offset(c);
      bool history = state.llg_history[c] != 0;
      // A B-H curve: the secant gamma_D puts the relaxed cell on the curve.
      SoftCellParams params = body.soft;
      if (!body.bh_curve.empty()) params.gamma_D = body.bh_curve.secant_demag_factor(norm(H_A[c]));
      const LocalRelaxResult r = relax_soft_cell(
          params, R.transpose_times(H_A[c]), &state.moments[off], &state.moment_hc_prev[off],
          history, state.noise_counter[c], noise_stream(state.seed, c), options);
      state.llg_history[c] = history ? 1 : 0;
      state.magnetization[c] = R * (body.soft.Ms * mean_moment(&state.moments[off], body.soft.n));
      llg += r.llg_steps;
      newton += r.newton_steps;
      if (!std::isfinite(r.residual) || !is_finite(state.magnetization[c])) ++nonfinite;
      worst = std::max(worst, r.residual);
    }
    if (nonfinite > 0) worst = std::numeric_limits<double>::quiet_NaN();
    return {llg, newton, worst};
  }

  void forces(const MagneticModel& model, MagneticState& state) override {
    const CellList& all = layout_.all;
    all_.load_moments(model, state, all);
    const int n = all_.size();
    cell_force_.assign(n, {});
    cell_field_.assign(n, {});
#pragma omp parallel for schedule(dynamic, 16) num_threads(threads_) if (static_cast<long>(n) * n > kParallelPairs)
    for (int i = 0; i < n; ++i) {
      const CellRun& body = all.run_of(i);
      // Every cell of another body (pairs inside a body cancel).
      const Vec3 xi{all_.x[i], all_.y[i], all_.z[i]}, mi{all_.mx[i], all_.my[i], all_.mz[i]};
      const FieldAndForce before = sum_field_and_force(all_.sources(), 0, body.begin, xi, mi, all_.radius[i]);
      const FieldAndForce after = sum_field_and_force(all_.sources(), body.end, n, xi, mi, all_.radius[i]);
      cell_force_[i] = before.force + after.force;
      cell_field_[i] = before.field + after.field;
    }
    if (near_.pair_count() > 0) {
      near_force_.assign(model.cell_count(), {});
      near_field_at_.assign(model.cell_count(), {});
      near_.add_forces(model, state, near_force_, near_field_at_);
      for (int i = 0; i < n; ++i) {
        cell_force_[i] += near_force_[all.cell[i]];
        cell_field_[i] += near_field_at_[all.cell[i]];
      }
    }
    std::fill(state.force.begin(), state.force.end(), Vec3{});
    std::fill(state.torque.begin(), state.torque.end(), Vec3{});
    for (int i = 0; i < n; ++i) {
      const int b = all.body[i];
      const Vec3 xi{all_.x[i], all_.y[i], all_.z[i]}, mi{all_.mx[i], all_.my[i], all_.mz[i]};
      state.force[b] += cell_force_[i];
      state.torque[b] += cell_torque(xi - state.pose[b].position, cell_force_[i], mi,
                                     cell_field_[i] + state.external_field);
    }
  }

  void probe_field(const MagneticModel& model, const MagneticState& state,
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
  CellLayout layout_;
  CellArrays fixed_, resp_, all_;  // positions, radii and moments of layout_'s lists
  std::vector<Vec3> body_moment_, cell_force_, cell_field_, near_force_, near_field_at_;
  bool near_field_ = true, near_mutual_induction_ = true;
  NearField near_;
  double far_field_theta_ = 0.0;  // 0: every pair summed exactly
  std::vector<uint8_t> held_;      // by body: magnetization kept (set_held_bodies); empty: none
  std::vector<uint8_t> held_cell_;  // the same by cell, for the near field
  bool is_held(int b) const { return !held_.empty() && held_[b]; }
  bool use_tree_ = false;
  FarFieldTree tree_;
  std::vector<Vec3> tree_field_;
};

}  // namespace

std::unique_ptr<MagneticBackend> make_cpu_backend(int threads) {
  return std::make_unique<CpuBackend>(threads);
}

}  // namespace odemag
