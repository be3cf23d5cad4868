#include "magnetics/relax/relax.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>
#include <tuple>
#include <utility>

#include "magnetics/relax/anderson.h"
#include "magnetics/kernels/kernels.h"
#include "magnetics/near_field/near_field.h"

namespace odemag {

namespace {

// An Anderson step may move the applied field at most this many times the
// current (weighted) residual.
constexpr double kMaxStepPerResidual = 30.0;

// skip_unchanged: a magnetic body may move this fraction of its cell contact
// radius, and turn this many radians, from the pose last solved for.
constexpr double kUnchangedDistance = 1e-5, kUnchangedRotation = 1e-5;

// |H_A| + gamma_D |M| for soft cells, |H_A| + |M| / 3 for recoil magnets: the
// field scale against which a cell's applied-field change is measured.
double cell_field_scale(const MagneticModel& model, const MagneticState& state, int c,
                        const Vec3& H_A) {
  const MagneticBody& body = model.body(model.cell_body(c));
  const double gamma = body.kind == CellKind::soft ? body.soft.gamma_D : 1.0 / 3.0;
  return norm(H_A) + gamma * norm(state.magnetization[c]);
}

bool carries_coil(const MagneticModel& model, int b) {
  for (const AttachedCoil& k : model.coils())
    if (k.body == b) return true;
  return false;
}

bool unchanged_since_last_solve(const MagneticModel& model, const MagneticState& state, const RelaxOptions& o) {
  const SolvedInputs& last = state.last_solve;
  const size_t bodies = static_cast<size_t>(model.body_count());
  if (!last.valid || last.pose.size() != bodies || last.active != state.active ||
      last.magnetization_scale != state.magnetization_scale || last.mutual_induction != o.mutual_induction ||
      last.far_field_theta != o.far_field_theta || last.near_field != o.near_field || norm(last.external_field - state.external_field) != 0.0)
    return false;
  for (int b = 0; b < model.body_count(); ++b) {
    const MagneticBody& body = model.body(b);
    if ((body.inert() && !carries_coil(model, b)) || !state.active[b]) continue;
    const BodyPose &p = state.pose[b], &q = last.pose[b];
    if (norm(p.position - q.position) > kUnchangedDistance * body.cells.contact_radius) return false;
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j)
        if (std::fabs(p.rotation.m[i][j] - q.rotation.m[i][j]) > kUnchangedRotation) return false;
  }
  return true;
}

void record_solve(MagneticState& state, const RelaxOptions& o, bool converged) {
  SolvedInputs& last = state.last_solve;
  last.valid = converged;
  last.pose = state.pose;
  last.active = state.active;
  last.magnetization_scale = state.magnetization_scale;
  last.external_field = state.external_field;
  last.mutual_induction = o.mutual_induction;
  last.far_field_theta = o.far_field_theta;
  last.near_field = o.near_field;
}

// max(a, b) that keeps a NaN: once either is NaN the result is NaN (std::max
// drops a NaN second argument). Equal to std::max(a, b) otherwise.
double max_keeping_nan(double a, double b) { return b > a || std::isnan(b) ? b : a; }

// Whether coil k acts: its body active and its current not scaled to 0.
bool coil_acts(const MagneticState& state, const AttachedCoil& k) {
  return state.active[k.body] && state.magnetization_scale[k.body] != 0.0;
}

// H (A/m) of coil k at world point x, at its body's pose, its current times
// the body's magnetization_scale.
Vec3 coil_H(const MagneticState& state, const AttachedCoil& k, const Vec3& x) {
  const BodyPose& pose = state.pose[k.body];
  return state.magnetization_scale[k.body] * coil_field_H(k.source, pose.rotation, pose.position, x);
}

// H (A/m) at world point x of the model's acting coils (AttachedCoil) carried
// by bodies other than `skip_body`.
Vec3 attached_coil_field(const MagneticModel& model, const MagneticState& state, const Vec3& x, int skip_body) {
  Vec3 H;
  for (const AttachedCoil& k : model.coils())
    if (k.body != skip_body && coil_acts(state, k)) H += coil_H(state, k, x);
  return H;
}

// Electromagnets: the (scaled) coil field of a soft body's material acts on the
// cells of its own core; attached coils act on every responsive cell.
void add_coil_fields(const MagneticModel& model, const MagneticState& state, const std::vector<int>& cells,
                     std::vector<Vec3>& H) {
  const bool coils = !model.coils().empty();
  for (int c : cells) {
    const int b = model.cell_body(c);
    const Vec3& coil = model.body(b).coil_field;
    if (coil.x != 0.0 || coil.y != 0.0 || coil.z != 0.0)
      H[c] += state.pose[b].rotation * (state.magnetization_scale[b] * coil);
    if (coils) H[c] += attached_coil_field(model, state, state.cell_position[c], -1);
  }
}

// Forces of attached coils on the cells of other bodies, F = mu0 grad(mu . H)
// = mu0 (mu . grad) H (curl-free off the conductors, so grad H is symmetric),
// and torque mu0 mu x H; the carrying body takes minus both (about its own
// position), so momentum and angular momentum are conserved. (mu . grad) H by
// a central difference along mu, step 1e-4 of the cell's contact radius
// (truncation ~1e-8, round-off ~1e-12 relative), and H at the cell as the
// mean of the two points (the same ~1e-8): two field evaluations per cell
// and coil, where the gradient's three axes took seven (the coil field costs
// ~8 us a point for the TEAM 20 coil: it was most of an electromagnet
// crane's magnetic time).
void add_coil_forces(const MagneticModel& model, MagneticState& state) {
  if (model.coils().empty()) return;
  for (int c = 0; c < model.cell_count(); ++c) {
    const int b = model.cell_body(c);
    if (!state.active[b]) continue;
    const Vec3 mu = model.cell_volume(c) * state.magnetization[c];
    if (mu.x == 0.0 && mu.y == 0.0 && mu.z == 0.0) continue;
    const Vec3& x = state.cell_position[c];
    const double step = 1e-4 * std::max(model.cell_contact_radius(c), 1e-9), mu_norm = norm(mu);
    const Vec3 e = (step / mu_norm) * mu;
    for (const AttachedCoil& k : model.coils()) {
      if (k.body == b || !coil_acts(state, k)) continue;
      const Vec3 H_plus = coil_H(state, k, x + e), H_minus = coil_H(state, k, x - e);
      const Vec3 F = (kMu0 * mu_norm / (2.0 * step)) * (H_plus - H_minus);
      const Vec3 tau_mu = (0.5 * kMu0) * cross(mu, H_plus + H_minus);
      state.force[b] += F;
      state.torque[b] += cross(x - state.pose[b].position, F) + tau_mu;
      state.force[k.body] -= F;
      state.torque[k.body] -= cross(x - state.pose[k.body].position, F) + tau_mu;
    }
  }
}

RelaxReport relax_paper(const MagneticModel& model, MagneticState& state, const RelaxOptions& o,
                        MagneticBackend& backend, const std::vector<int>& cells,
                        const std::vector<Vec3>& H_fixed) {
  RelaxReport report;
  std::vector<Vec3> H(model.cell_count()), H_A(model.cell_count());
  LocalRelaxOptions local = o.local;
  local.single_step = true;
  local.tolerance = o.tolerance;
  // Every iteration re-evaluates the exo field, so the coupling between cells
  // (eigenvalues of the intra-body operator reach 2 gamma_D Ms) is integrated
  // explicitly too: its stiffness triples the bound S of the dt rule.
  local.time_step_factor /= 3.0;
  for (report.iterations = 0; report.iterations < o.max_iterations; ++report.iterations) {
    backend.responsive_field(model, state, H);
    ++report.field_evaluations;
    for (int c : cells) H_A[c] = H_fixed[c] + (o.mutual_induction ? H[c] : Vec3{});
    const LocalStats s = backend.relax_cells(model, state, H_A, local);
    report.llg_steps += s.llg_steps;
    report.residual = s.max_residual;
    report.residual_history.push_back(s.max_residual);
    if (o.progress) o.progress(report);
    // Non-finite cells (NaN fields or moments) take no LLG step either: a
    // failure, not convergence.
    if (!std::isfinite(s.max_residual)) break;
    if (s.llg_steps == 0) {
      report.converged = true;
      break;
    }
  }
  for (int c : cells) state.applied_field[c] = H_A[c];
  return report;
}

// Two-level scheme without mutual induction: one relaxation under the fixed field.
RelaxReport relax_one_pass(const MagneticModel& model, MagneticState& state, const RelaxOptions& o,
                           MagneticBackend& backend, const std::vector<int>& cells,
                           const std::vector<Vec3>& H_fixed) {
  RelaxReport report;
  LocalRelaxOptions local = o.local;
  local.single_step = false;
  std::vector<Vec3> H_A(model.cell_count());
  for (int c : cells) H_A[c] = H_fixed[c];
  const LocalStats s = backend.relax_cells(model, state, H_A, local);
  for (int c : cells) state.applied_field[c] = H_A[c];
  // Induced cells feel only H_E and fixed magnets: one pass is the solution.
  report.iterations = 1;
  report.residual = s.max_residual;
  report.converged = s.max_residual <= std::max(o.local.tolerance, o.tolerance);
  report.llg_steps = s.llg_steps;
  report.newton_steps = s.newton_steps;
  return report;
}

// The cells a relaxation solves for: every active responsive cell but those
// of held bodies (RelaxOptions::held_bodies); and those held.
bool held(const RelaxOptions& o, int b) { return !o.held_bodies.empty() && o.held_bodies[b]; }

std::vector<int> solved_cells(const MagneticModel& model, const MagneticState& state, const RelaxOptions& o) {
  std::vector<int> cells = active_responsive_cells(model, state);
  if (o.held_bodies.empty()) return cells;
  std::erase_if(cells, [&](int c) { return held(o, model.cell_body(c)); });
  return cells;
}

std::vector<int> held_cells(const MagneticModel& model, const MagneticState& state, const RelaxOptions& o) {
  std::vector<int> cells = active_responsive_cells(model, state);
  std::erase_if(cells, [&](int c) { return !held(o, model.cell_body(c)); });
  return cells;
}

// The outer loop of the two-level scheme. x: applied field at the responsive
// cells, flattened; G(x): the applied field after relaxing every cell under x.
struct OuterLoop {
  const MagneticModel& model;
  MagneticState& state;
  MagneticBackend& backend;
  const RelaxOptions& o;
  const std::vector<int>& cells;
  const std::vector<Vec3>& H_fixed;
  std::vector<int> held_cells;  // active responsive cells of held bodies (RelaxOptions::held_bodies)
  LocalRelaxOptions local;
  std::vector<Vec3> H_A, H_resp;  // by cell: the field x relaxed under; the responsive field after
  double local_residual = 0.0;    // the last relax_cells' largest residual (NaN: non-finite cells)
};

// Applied field at each responsive cell (in the order of cells): the fixed
// field plus the last responsive field.
std::vector<Vec3> fixed_plus_responsive(const OuterLoop& l) {
  const int n = static_cast<int>(l.cells.size());
  std::vector<Vec3> G(n);
  for (int i = 0; i < n; ++i) G[i] = l.H_fixed[l.cells[i]] + l.H_resp[l.cells[i]];
  return G;
}

// The largest cell field scale at the fields h (one per cell).
double largest_field_scale(const OuterLoop& l, const std::vector<Vec3>& h) {
  double largest = 0.0;
  for (size_t i = 0; i < h.size(); ++i)
    largest = std::max(largest, cell_field_scale(l.model, l.state, l.cells[i], h[i]));
  return largest;
}

// Floor of the field scales: 1e-9 of the largest at the fields h, plus
// kPeakScaleFloor of the largest any converged relaxation of the state
// reached. Without the second, fields that fall to zero (a coil switched
// off, no remanence) never converge: their solution is M = 0, and an
// iterate that shrinks every field by one factor keeps its relative
// residual (measured: an iron cube and two balls after H_E = 1e4 A/m is
// switched off ran to the 200-iteration cap, then 134 more).
constexpr double kPeakScaleFloor = 1e-6;
double field_scale_floor(const OuterLoop& l, const std::vector<Vec3>& h) {
  return 1e-9 * largest_field_scale(l, h) + kPeakScaleFloor * l.state.peak_field_scale + 1e-300;
}

// The initial iterate: the fixed field plus the responsive field of the
// warm-start magnetization, one per cell.
std::vector<Vec3> initial_iterate(OuterLoop& l, RelaxReport& report) {
  l.backend.responsive_field(l.model, l.state, l.H_resp);
  ++report.field_evaluations;
  return fixed_plus_responsive(l);
}

// Predicted warm start (docs/model.md): the first iterate h, the fixed field
// plus the field of the warm-start magnetization, lacks the magnetization's
// change over this relaxation. Where the last two relaxations changed a
// cell's applied field alike (to half the last change: a steady drift, as
// of a body moving smoothly), this one starts from h plus the last change.
// Elsewhere from h: at rest the changes are the solve's own error (added
// again, a cell would take more iterations and move within the tolerance),
// and a jump (a cold start, a coil switched, a ball snapping onto another)
// added again would push the cell's moments twice as far.
constexpr double kSteadyChange = 0.5;
std::vector<Vec3> predicted_start(const OuterLoop& l, const std::vector<Vec3>& h) {
  std::vector<Vec3> x = h;
  if (!l.o.predict_warm_start) return x;
  for (size_t i = 0; i < h.size(); ++i) {
    const Vec3& last = l.state.relaxation_change[l.cells[i]];
    const Vec3& before = l.state.previous_relaxation_change[l.cells[i]];
    if (norm(last - before) <= kSteadyChange * norm(last)) x[i] += last;
  }
  return x;
}

// What this relaxation added to its first iterate h, kept for the next ones'
// predicted start; zero at every other cell, and everywhere when it did not
// converge (a failed relaxation predicts nothing).
void remember_relaxation_change(const OuterLoop& l, const std::vector<Vec3>& h, bool converged) {
  MagneticState& s = l.state;
  std::vector<Vec3> last(s.relaxation_change.size());
  if (converged)
    for (size_t i = 0; i < h.size(); ++i) last[l.cells[i]] = l.H_A[l.cells[i]] - h[i];
  std::vector<Vec3> before = converged ? std::move(s.relaxation_change) : std::vector<Vec3>(last.size());
  // Held cells were not relaxed: they keep what their last relaxations found.
  for (int c : l.held_cells) {
    last[c] = converged ? before[c] : s.relaxation_change[c];
    before[c] = s.previous_relaxation_change[c];
  }
  s.previous_relaxation_change = std::move(before);
  s.relaxation_change = std::move(last);
}

std::vector<double> flatten(const std::vector<Vec3>& h) {
  std::vector<double> x(3 * h.size());
  for (size_t i = 0; i < h.size(); ++i)
    for (int a = 0; a < 3; ++a) x[3 * i + a] = h[i][a];
  return x;
}

// Per-component weights of the Anderson norm: one over each cell's field
// scale at the initial iterate h (plus the floor).
std::vector<double> cell_weights(const OuterLoop& l, const std::vector<Vec3>& h) {
  const double floor = field_scale_floor(l, h);
  std::vector<double> weights(3 * h.size());
  for (size_t i = 0; i < h.size(); ++i) {
    const double w = 1.0 / (cell_field_scale(l.model, l.state, l.cells[i], h[i]) + floor);
    weights[3 * i] = weights[3 * i + 1] = weights[3 * i + 2] = w;
  }
  return weights;
}

// G(x): relaxes every cell under the applied field x, then evaluates the
// responsive field.
std::vector<Vec3> apply_map(OuterLoop& l, const std::vector<double>& x, RelaxReport& report) {
  const int n = static_cast<int>(l.cells.size());
  for (int i = 0; i < n; ++i) l.H_A[l.cells[i]] = {x[3 * i], x[3 * i + 1], x[3 * i + 2]};
  // Inexact inner solves: each cell only as accurately as the outer loop
  // can use now (1% of its last residual), down to the inner tolerance.
  if (!report.residual_history.empty())
    l.local.tolerance =
        std::max(l.o.local.tolerance, std::min(1e-6, 1e-2 * report.residual_history.back()));
  const LocalStats s = l.backend.relax_cells(l.model, l.state, l.H_A, l.local);
  l.local_residual = s.max_residual;
  report.llg_steps += s.llg_steps;
  report.newton_steps += s.newton_steps;
  l.backend.responsive_field(l.model, l.state, l.H_resp);
  ++report.field_evaluations;
  return fixed_plus_responsive(l);
}

// Residual: change of each cell's applied field against its field scale.
// Sets f = G(x) - x (flattened) and returns the largest relative change;
// NaN when any cell's change or the local relaxation was not finite.
double iterate_residual(const OuterLoop& l, const std::vector<Vec3>& G, std::vector<double>& f) {
  double worst = 0.0;
  const double fl = field_scale_floor(l, G);
  for (size_t i = 0; i < G.size(); ++i) {
    const int c = l.cells[i];
    const Vec3 d = G[i] - l.H_A[c];
    for (int a = 0; a < 3; ++a) f[3 * i + a] = d[a];
    worst = max_keeping_nan(worst, norm(d) / (cell_field_scale(l.model, l.state, c, G[i]) + fl));
  }
  if (!std::isfinite(l.local_residual)) worst = std::numeric_limits<double>::quiet_NaN();
  return worst;
}

// Safeguarded Anderson step. Hysteretic cells make the map x -> G(x)
// path-dependent: an extrapolated field that overshoots can switch cells
// irreversibly (measured: a remanent nail demagnetized by one bad
// iterate). So a step is capped at 30 times the residual (ill-conditioned
// bodies such as needles need steps of ~1/(1 - lambda) = 100 times), and
// when the residual grows past 10 times the best seen, the history is
// dropped and a damped plain step taken instead.
struct SafeguardedAnderson {
  SafeguardedAnderson(int depth, double mixing, std::vector<double> w)
      : mixer(depth, mixing), weights(std::move(w)) {
    mixer.set_weights(weights);
  }
  AndersonMixer mixer;
  std::vector<double> weights;
  double best_residual = std::numeric_limits<double>::infinity();
  int last_progress = 0;  // iteration of the last halving of the best residual
};

// Norm of v under the per-component weights.
double weighted_norm(const std::vector<double>& weights, const std::vector<double>& v) {
  double sum = 0.0;
  for (size_t i = 0; i < v.size(); ++i) sum += weights[i] * weights[i] * v[i] * v[i];
  return std::sqrt(sum);
}

// Stagnation (cells switching across a hysteresis jump make x -> G(x)
// discontinuous, and the stored differences then describe the other
// branch): if the best residual has not halved in 20 iterations, the
// history is dropped.
void drop_stagnant_history(SafeguardedAnderson& a, int iteration, double fw) {
  if (fw < 0.5 * a.best_residual) {
    a.last_progress = iteration;
  } else if (iteration - a.last_progress >= 20) {
    a.mixer.reset();
    a.last_progress = iteration;
  }
}

// The step cap: x - x_old at most kMaxStepPerResidual times the weighted
// residual fw, in the weighted norm.
void cap_step(const std::vector<double>& weights, const std::vector<double>& x_old, double fw,
              std::vector<double>& x) {
  std::vector<double> step(x.size());
  for (size_t i = 0; i < x.size(); ++i) step[i] = x[i] - x_old[i];
  const double dw = weighted_norm(weights, step);
  if (dw > kMaxStepPerResidual * fw)
    for (size_t i = 0; i < x.size(); ++i)
      x[i] = x_old[i] + (kMaxStepPerResidual * fw / dw) * step[i];
}

// The next iterate x from the residual f at x (SafeguardedAnderson).
void anderson_step(SafeguardedAnderson& a, int iteration, std::vector<double>& x,
                   const std::vector<double>& f) {
  const double fw = weighted_norm(a.weights, f);
  if (fw > 10.0 * a.best_residual) {
    a.mixer.reset();
    for (size_t i = 0; i < x.size(); ++i) x[i] += 0.5 * f[i];
    return;
  }
  drop_stagnant_history(a, iteration, fw);
  a.best_residual = std::min(a.best_residual, fw);
  const std::vector<double> x_old = x;
  a.mixer.next(x, f);
  cap_step(a.weights, x_old, fw, x);
}

// A body whose block of the outer loop's residual is preconditioned by its
// linear self-response (magnetics/model/body_response.h): the body and the position
// of its first cell in the loop's cells.
struct ResponseBlock {
  int body;
  int first;
};

// Cells below this share of saturation count as linear (M = H_A / gamma_D).
constexpr double kLinearShare = 0.9;

// The bodies whose every cell is in the loop's cells, in order, and below
// kLinearShare of saturation at the initial iterate h: the response solve
// is a Newton step for them. Saturating bodies respond less than it assumes
// and go without.
std::vector<ResponseBlock> response_blocks(const OuterLoop& l, const std::vector<Vec3>& h) {
  std::vector<ResponseBlock> blocks;
  if (!l.o.precondition_bodies) return blocks;
  const int n = static_cast<int>(l.cells.size());
  for (int i = 0; i < n;) {
    const MagneticBody& body = l.model.body(l.model.cell_body(l.cells[i]));
    const int count = body.cell_count();
    bool take = body.response && l.cells[i] == body.first_cell && i + count <= n;
    for (int k = 0; take && k < count; ++k)
      take = l.cells[i + k] == body.first_cell + k &&
             norm(h[i + k]) < kLinearShare * body.soft.gamma_D * body.soft.Ms;
    if (take) blocks.push_back({l.model.cell_body(l.cells[i]), i});
    i += take ? count : 1;
  }
  return blocks;
}

// g = P^-1 f: each block's residual replaced by the Newton step of its body's
// linear response, (I - J)^-1 f, solved in the body frame.
void precondition(const OuterLoop& l, const std::vector<ResponseBlock>& blocks, std::vector<double>& g) {
  for (const ResponseBlock& k : blocks) {
    const MagneticBody& body = l.model.body(k.body);
    const Mat3& R = l.state.pose[k.body].rotation;
    double* r = &g[3 * static_cast<size_t>(k.first)];
    const int count = body.cell_count();
    for (int c = 0; c < count; ++c) {
      const Vec3 v = R.transpose_times({r[3 * c], r[3 * c + 1], r[3 * c + 2]});
      r[3 * c] = v.x, r[3 * c + 1] = v.y, r[3 * c + 2] = v.z;
    }
    solve_body_response(*body.response, r);
    for (int c = 0; c < count; ++c) {
      const Vec3 v = R * Vec3{r[3 * c], r[3 * c + 1], r[3 * c + 2]};
      r[3 * c] = v.x, r[3 * c + 1] = v.y, r[3 * c + 2] = v.z;
    }
  }
}

// The two-level scheme's outer loop, Anderson-accelerated: Anderson mixing
// of the map x -> x + P^-1 (G(x) - x), P the block preconditioner (identity
// outside the response blocks); convergence is judged on G(x) - x itself.
RelaxReport relax_two_level(const MagneticModel& model, MagneticState& state, const RelaxOptions& o,
                            MagneticBackend& backend, const std::vector<int>& cells,
                            const std::vector<Vec3>& H_fixed) {
  RelaxReport report;
  // A held cell's applied field stays its last (a backend that relaxes every
  // cell relaxes it under that: MagneticBackend::set_held_bodies).
  OuterLoop l{model, state, backend, o, cells, H_fixed, held_cells(model, state, o), o.local,
              state.applied_field, std::vector<Vec3>(model.cell_count())};
  l.local.single_step = false;
  const std::vector<Vec3> h = initial_iterate(l, report);
  std::vector<double> x = flatten(predicted_start(l, h)), f(x.size());
  SafeguardedAnderson anderson(o.anderson_depth, o.mixing, cell_weights(l, h));
  const std::vector<ResponseBlock> blocks = response_blocks(l, h);
  std::vector<double> g;
  for (report.iterations = 1; report.iterations <= o.max_iterations; ++report.iterations) {
    const std::vector<Vec3> G = apply_map(l, x, report);
    const double worst = iterate_residual(l, G, f);
    report.residual = worst;
    report.residual_history.push_back(worst);
    if (o.progress) o.progress(report);
    if (!std::isfinite(worst)) break;  // non-finite cells: not converged, and no iteration can mend them
    if (worst <= o.tolerance) {
      report.converged = true;
      for (size_t i = 0; i < cells.size(); ++i) l.H_A[cells[i]] = G[i];
      state.peak_field_scale = std::max(state.peak_field_scale, largest_field_scale(l, G));
      break;
    }
    if (blocks.empty()) {
      anderson_step(anderson, report.iterations, x, f);
    } else {
      g = f;
      precondition(l, blocks, g);
      anderson_step(anderson, report.iterations, x, g);
    }
  }
  report.iterations = std::min(report.iterations, o.max_iterations);
  for (int c : cells) state.applied_field[c] = l.H_A[c];
  remember_relaxation_change(l, h, report.converged);
  return report;
}

// The stages of a magnetic step, in order.

// docs/architecture.md "One magnetic step", 0: skip_unchanged, nothing changed since.
bool can_skip_step(const MagneticModel& model, const MagneticState& state, const RelaxOptions& o) {
  return o.skip_unchanged && unchanged_since_last_solve(model, state, o);
}

RelaxReport skipped_report() {
  RelaxReport skipped;
  skipped.converged = skipped.skipped = true;
  return skipped;
}

// docs/architecture.md "One magnetic step", 1: place the cells, begin the backend's step.
void place_cells_and_begin_step(const MagneticModel& model, MagneticState& state,
                                const RelaxOptions& o, MagneticBackend& backend) {
  if (!o.held_bodies.empty() && o.held_bodies.size() != static_cast<size_t>(model.body_count()))
    throw std::invalid_argument("RelaxOptions::held_bodies: " + std::to_string(o.held_bodies.size()) +
                                " entries for " + std::to_string(model.body_count()) + " bodies");
  for (size_t b = 0; b < o.held_bodies.size(); ++b)
    if (o.held_bodies[b] > RelaxOptions::kHeld)
      throw std::invalid_argument("RelaxOptions::held_bodies: entry " + std::to_string(b) + " is " +
                                  std::to_string(o.held_bodies[b]) + " (0 or 1)");
  place_cells(model, state);
  backend.set_far_field(o.far_field_theta);
  backend.set_near_field(o.near_field, o.mutual_induction);
  backend.set_held_bodies(o.held_bodies);
  backend.begin_step(model, state);
}

// docs/architecture.md "One magnetic step", 2: H_E, fixed magnets and coils, once.
std::vector<Vec3> fixed_field(const MagneticModel& model, const MagneticState& state,
                              MagneticBackend& backend, const std::vector<int>& cells) {
  if (cells.empty()) return {};
  std::vector<Vec3> H_fixed(model.cell_count());
  backend.fixed_field(model, state, H_fixed);
  add_coil_fields(model, state, cells, H_fixed);
  return H_fixed;
}

// docs/architecture.md "One magnetic step", 3: paper scheme, one pass or Anderson loop.
RelaxReport solve(const MagneticModel& model, MagneticState& state, const RelaxOptions& o,
                  MagneticBackend& backend, const std::vector<int>& cells,
                  const std::vector<Vec3>& H_fixed) {
  if (cells.empty()) {
    RelaxReport nothing;
    nothing.converged = true;
    return nothing;
  }
  if (o.scheme == RelaxScheme::two_level && o.mutual_induction)
    return relax_two_level(model, state, o, backend, cells, H_fixed);
  // The other schemes predict nothing for a later two-level relaxation.
  std::fill(state.relaxation_change.begin(), state.relaxation_change.end(), Vec3{});
  std::fill(state.previous_relaxation_change.begin(), state.previous_relaxation_change.end(),
            Vec3{});
  if (o.scheme == RelaxScheme::paper) return relax_paper(model, state, o, backend, cells, H_fixed);
  return relax_one_pass(model, state, o, backend, cells, H_fixed);
}

// docs/architecture.md "One magnetic step", 4: per-body forces and torques.
void compute_forces(const MagneticModel& model, MagneticState& state, MagneticBackend& backend) {
  backend.forces(model, state);
  add_coil_forces(model, state);
}

// docs/architecture.md "One magnetic step", 5: remember what was solved, for the skip check.
void record_step(MagneticState& state, const RelaxOptions& o, const RelaxReport& report) {
  // Only a run that skips pays for remembering what it solved; a relaxation
  // that held bodies did not solve for theirs.
  const bool held_any =
      std::any_of(o.held_bodies.begin(), o.held_bodies.end(), [](uint8_t h) { return h != 0; });
  if (o.skip_unchanged && !held_any) {
    record_solve(state, o, report.converged);
  } else {
    state.last_solve.valid = false;
  }
}

}  // namespace

RelaxReport relax(const MagneticModel& model, MagneticState& state, const RelaxOptions& o,
                  MagneticBackend& backend) {
  place_cells_and_begin_step(model, state, o, backend);
  const std::vector<int> cells = solved_cells(model, state, o);
  const std::vector<Vec3> H_fixed = fixed_field(model, state, backend, cells);
  RelaxReport report = solve(model, state, o, backend, cells, H_fixed);
  if (!o.held_bodies.empty()) backend.set_held_bodies({});  // held for this relaxation only
  return report;
}

RelaxReport magnetic_step(const MagneticModel& model, MagneticState& state,
                          const RelaxOptions& options, MagneticBackend& backend) {
  if (can_skip_step(model, state, options)) return skipped_report();
  place_cells_and_begin_step(model, state, options, backend);
  const std::vector<int> cells = solved_cells(model, state, options);
  const std::vector<Vec3> H_fixed = fixed_field(model, state, backend, cells);
  RelaxReport report = solve(model, state, options, backend, cells, H_fixed);
  compute_forces(model, state, backend);
  record_step(state, options, report);
  if (!options.held_bodies.empty()) backend.set_held_bodies({});  // held for this step only
  return report;
}

void magnetic_forces_at_held_magnetization(const MagneticModel& model, MagneticState& state,
                                           const RelaxOptions& options, MagneticBackend& backend) {
  place_cells_and_begin_step(model, state, options, backend);
  compute_forces(model, state, backend);
  state.last_solve.valid = false;  // the held magnetization is not the solution at these poses
}

void field_at_points(const MagneticModel& model, const MagneticState& state,
                     MagneticBackend& backend, const std::vector<Vec3>& points,
                     std::vector<Vec3>& B, std::vector<Vec3>& H) {
  backend.probe_field(model, state, points, H);
  if (!model.coils().empty())
    for (size_t p = 0; p < points.size(); ++p) H[p] += attached_coil_field(model, state, points[p], -1);
  B.resize(points.size());
  for (size_t p = 0; p < points.size(); ++p) {
    Vec3 M;
    for (int b = 0; b < model.body_count(); ++b) {
      const MagneticBody& body = model.body(b);
      if (body.inert() || !state.active[b]) continue;
      const BodyPose& pose = state.pose[b];
      const Vec3 local = pose.rotation.transpose_times(points[p] - pose.position);
      if (!shape_contains(body.shape, local)) continue;
      int nearest = 0;
      double best = 1e300;
      for (int i = 0; i < body.cell_count(); ++i) {
        const double d = squared_norm(body.cells.local_positions[i] - local);
        if (d < best) best = d, nearest = i;
      }
      M = state.magnetization[body.first_cell + nearest];
      break;
    }
    B[p] = kMu0 * (H[p] + M);
  }
}

double magnetic_energy(const MagneticModel& model, const MagneticState& state, bool near_field) {
  NearField near;
  near.build(model, state, near_field);
  double e = near.energy(model, state) + boundary_field_energy(model, state);
  const int n = model.cell_count();
  for (int a = 0; a < n; ++a) {
    const int ba = model.cell_body(a);
    if (!state.active[ba]) continue;
    const MagneticBody& body_a = model.body(ba);
    const Vec3 mu_a = model.cell_volume(a) * state.magnetization[a];
    e -= kMu0 * dot(mu_a, state.external_field);
    if (!model.coils().empty()) e -= kMu0 * dot(mu_a, attached_coil_field(model, state, state.cell_position[a], ba));
    for (int b = a + 1; b < n; ++b) {
      const int bb = model.cell_body(b);
      if (!state.active[bb]) continue;
      const Vec3 mu_b = model.cell_volume(b) * state.magnetization[b];
      const double s = ba == bb ? 0.0 : model.cell_contact_radius(a) + model.cell_contact_radius(b);
      e += dipole_energy(state.cell_position[b] - state.cell_position[a], mu_a, mu_b, s * s);
    }
    if (body_a.kind == CellKind::soft) {
      // Self energy mu0 V (gamma_D Ms^2 |mean m|^2 / 2 + anisotropy).
      SoftCellParams p = body_a.soft;
      e += kMu0 * model.cell_volume(a) * p.Ms *
           cell_free_energy(p, Vec3{}, &state.moments[model.moment_offset(a)]);
    }
  }
  return e;
}

}  // namespace odemag
