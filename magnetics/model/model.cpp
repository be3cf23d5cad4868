#include "magnetics/model/model.h"

#include <Eigen/Dense>
#include <algorithm>
#include <array>
#include <atomic>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <sstream>
#include <stdexcept>
#include <string_view>
#include <unordered_map>
#include <utility>

#include "magnetics/kernels/eigen_tensors.h"
#include "magnetics/kernels/kernels.h"

namespace odemag {

namespace {

// Intra-body tensors act on moments mu = M V (H = T mu). The cube-cube tensor
// maps magnetization to field (H = -N M), so T = -N / h^3: a cell of volume
// V_j = w_j h^3 (w_j <= 1, its cube's share inside the body) acts as its cube
// carrying the reduced magnetization w_j M_j. The operator then stays that of
// a tiling by cubes of magnetization w M, whose energy is positive, so it
// keeps its stability. (Scaling up instead, T = -N / V with V = 1.13 h^3 the
// mean volume a cylinder's cells had, made them hold each other saturated: a
// spurious remanence.)
void build_offset_tensors(MagneticBody& body, IntraBodyTensor kind) {
  const auto& n = body.cells.lattice_extent;
  body.offset_extent = {2 * n[0] - 1, 2 * n[1] - 1, 2 * n[2] - 1};
  const double h = body.cells.spacing;
  body.offset_tensors.assign(6u * body.offset_extent[0] * body.offset_extent[1] * body.offset_extent[2],
                             0.0);
  for (int k = 0; k < body.offset_extent[2]; ++k)
    for (int j = 0; j < body.offset_extent[1]; ++j)
      for (int i = 0; i < body.offset_extent[0]; ++i) {
        const int di = i - (n[0] - 1), dj = j - (n[1] - 1), dk = k - (n[2] - 1);
        if (di == 0 && dj == 0 && dk == 0) continue;  // self term is H_endo
        const int idx = i + body.offset_extent[0] * (j + body.offset_extent[1] * k);
        double* t = &body.offset_tensors[6u * idx];
        if (kind == IntraBodyTensor::point_dipole) {
          dipole_tensor({di * h, dj * h, dk * h}, 0.0, t);
        } else {
          double n_tensor[6];
          cube_demag_tensor(di, dj, dk, h, n_tensor);
          for (int a = 0; a < 6; ++a) t[a] = -n_tensor[a] / body.cells.cell_volume;  // cell_volume = h^3
        }
      }
}

// Per-pair tensors of a body of graded cells (MagneticBody::pair_tensors):
// T_ij = -N_ij / V_j, symmetric in (i, j) because V_i N_ij = V_j N_ji (the
// Galerkin energy of the tiling), so each pair is computed once; the
// diagonal carries the cell's own tensor beyond I / 3.
void build_pair_tensors(MagneticBody& body) {
  const CellSet& cells = body.cells;
  const int count = cells.size();
  const GridDemagTable table(cells.faces);  // cuboid_demag_tensor from tabulated f and g
  body.pair_tensors.assign(6u * count * count, 0.0);
#pragma omp parallel for schedule(dynamic, 4)
  for (int i = 0; i < count; ++i) {
    for (int j = 0; j <= i; ++j) {
      double n[6];
      table.tensor(cells.lattice_index[i], cells.lattice_index[j], n);
      if (i == j) n[0] -= 1.0 / 3.0, n[3] -= 1.0 / 3.0, n[5] -= 1.0 / 3.0;
      double* tij = &body.pair_tensors[6u * (static_cast<size_t>(i) * count + j)];
      double* tji = &body.pair_tensors[6u * (static_cast<size_t>(j) * count + i)];
      for (int c = 0; c < 6; ++c) tij[c] = tji[c] = -n[c] / cells.volumes[j];
    }
  }
}

// Per-pair tensors of a body of refined zones (MagneticBody::pair_tensors):
// the cells' cubes, of edges h / 2^l, centred on their cube centres, T_ij =
// -N_ij / a_j^3 with N_ij the cuboid-cuboid tensor (cuboid_demag_tensor): a
// cell of volume V_j = w_j a_j^3 acts as its cube carrying w_j M_j, as on
// the uniform lattice (build_offset_tensors); symmetric, since a_i^3 N_ij =
// a_j^3 N_ji. The diagonal is zero: a cube's own tensor is I / 3, which the
// local relaxation holds. The cube centres lie on nested lattices, so N_ij
// depends only on the two levels and the offset in units of the finest
// lattice's half spacing: each distinct one is computed once (a 953-cell
// ball: 96071 of its 453628 pairs).
void build_refined_pair_tensors(MagneticBody& body) {
  const CellSet& cells = body.cells;
  const int count = cells.size();
  const double h = cells.spacing;
  std::vector<int> level(count);
  int finest = 0;
  for (int i = 0; i < count; ++i) {
    level[i] = static_cast<int>(std::lround(std::log2(h / (2.0 * cells.cube_half(i).x))));
    finest = std::max(finest, level[i]);
  }
  const double unit = h / std::ldexp(2.0, finest);  // offsets of cube centres are multiples of it
  auto key = [&](int i, int j) {
    const Vec3 d = (cells.cube_centre(i) - cells.cube_centre(j)) / unit;
    std::array<long, 3> q{std::lround(d.x), std::lround(d.y), std::lround(d.z)};
    if (std::abs(d.x - static_cast<double>(q[0])) + std::abs(d.y - static_cast<double>(q[1])) +
            std::abs(d.z - static_cast<double>(q[2])) >
        1e-6)
      throw std::logic_error("build_refined_pair_tensors: cube centres off their nested lattices");
    if (q < std::array<long, 3>{0, 0, 0}) q = {-q[0], -q[1], -q[2]};  // N(-d) = N(d)
    constexpr long kOffset = 1L << 17;
    return (static_cast<uint64_t>(level[i]) << 57) | (static_cast<uint64_t>(level[j]) << 54) |
           (static_cast<uint64_t>(q[0] + kOffset) << 36) | (static_cast<uint64_t>(q[1] + kOffset) << 18) |
           static_cast<uint64_t>(q[2] + kOffset);
  };
  // The distinct (level_i, level_j, offset) and a pair of each.
  std::unordered_map<uint64_t, int> slot;
  std::vector<std::pair<int, int>> representative;
  std::vector<int> pair_slot(static_cast<size_t>(count) * count, -1);
  for (int i = 0; i < count; ++i)
    for (int j = 0; j < i; ++j) {
      const auto [it, added] = slot.emplace(key(i, j), static_cast<int>(representative.size()));
      if (added) representative.emplace_back(i, j);
      pair_slot[static_cast<size_t>(i) * count + j] = it->second;
    }
  std::vector<std::array<double, 6>> tensor(representative.size());
#pragma omp parallel for schedule(dynamic, 64)
  for (size_t s = 0; s < representative.size(); ++s) {
    const auto [i, j] = representative[s];
    const Vec3 hi = cells.cube_half(i), hj = cells.cube_half(j);
    const Vec3 d = cells.cube_centre(i) - cells.cube_centre(j);
    const double half_i[3] = {hi.x, hi.y, hi.z}, half_j[3] = {hj.x, hj.y, hj.z}, dd[3] = {d.x, d.y, d.z};
    cuboid_demag_tensor(half_i, half_j, dd, tensor[s].data());
  }
  body.pair_tensors.assign(6u * count * count, 0.0);
  for (int i = 0; i < count; ++i)
    for (int j = 0; j < i; ++j) {
      const std::array<double, 6>& n_ij = tensor[pair_slot[static_cast<size_t>(i) * count + j]];
      const Vec3 hj = cells.cube_half(j);
      const double cube_j = 8.0 * hj.x * hj.y * hj.z;
      double* tij = &body.pair_tensors[6u * (static_cast<size_t>(i) * count + j)];
      double* tji = &body.pair_tensors[6u * (static_cast<size_t>(j) * count + i)];
      for (int c = 0; c < 6; ++c) tij[c] = tji[c] = -n_ij[c] / cube_j;
    }
}

// The local demagnetising factor of the body's cells: M = H / gamma in the
// linear range (soft: gamma_D; a recoil magnet: 1/3 + 1/chi_r).
double local_gamma(const MagneticBody& body) {
  return body.kind == CellKind::soft ? body.soft.gamma_D : 1.0 / 3.0 + 1.0 / body.recoil;
}

// Boundary correction (docs/model.md "Cells"). For a uniform magnetization M
// the cells' field is H_i = -(I/3 + sum_{j != i} w_j N_ij) M (self term and
// cube tensors of the cubes at the lattice sites, w_j = V_j / h^3), while the
// body's exact field averaged over cell i's part is -Nbar_i M
// (magnetics/cells/cells.h uniform_demag_over_cell). Adding
//   K_i = I/3 + sum_{j != i} w_j N_ij - Nbar_i
// as H_i += K_i M_i = (K_i / V_i) mu_i gives a uniformly magnetized body its
// exact field in every cell, but K_i softens boundary cells along the surface,
// and with it the divergence-free swirl modes, which the continuum leaves at
// zero energy, went below zero: the intra-body operator of a chi = infinity
// ball had a negative eigenvalue from R = 10 h on (-4.4e-4, -9.2e-4 at 10 h,
// 12 h), a spurious remanence. So the correction comes in two parts, each
// keeping the operator provably positive:
//
// 1. Local: K_i limited to K'_i. The cells' energy is that of the tiling by
//    cubes of magnetization w M (positive) plus, per cell, V_i M_i . ((gamma_D
//    - w_i / 3) I - K'_i) M_i / 2, so eigenvalues of K'_i up to (1 - w_i) / 3
//    are safe. Larger eigenvalues of K_i are cut to that bound, and what was
//    cut is added to the cell's other eigenvalues, up to the same bound.
// 2. Uniform modes: with the local part, the operator A (A M = W H_applied,
//    W = diag(V)) applied to a uniform M gives W Pi M per cell, Pi_i =
//    gamma_D I - K'_i + sum_{j != i} w_j N_ij, where the exact field needs W
//    beta M, beta_i = (gamma_D - 1/3) I + Nbar_i. The update
//      A' = A - (A U)(U^T A U)^-1 (A U)^T + B (U^T B)^-1 B^T
//    (U the uniform fields, A U = W Pi, B = W beta; the BFGS update) gives A' U
//    = B exactly and stays positive definite since U^T B = sum V beta (the
//    body's magnetometric demagnetising tensor plus 1/chi) is. It adds to
//    cell i's field Pi_i G_Pi sum_j Pi_j mu_j - beta_i G_beta sum_j beta_j mu_j.
// So a lattice ball in a uniform field takes the continuum sphere's moment (its
// solution is uniform), and the local part carries the boundary correction to
// non-uniform fields (a chi = 1000 ball next to a point dipole, docs/model.md).
// With exact_sub_cubes a refined body's partial sub-cubes take the exact
// local part, which the proof above does not cover (MagneticModel::add_body
// checks the operator and decides).
void build_boundary_correction(MagneticBody& body, bool exact_sub_cubes = false) {
  const CellSet& cells = body.cells;
  const int count = cells.size();
  const double gamma = local_gamma(body);
  const bool refined = cells.refined;  // per-pair tensors (else the lattice's offset tensors)
  body.self_tensors.assign(6u * count, 0.0);
  body.uniform_tensors.assign(12u * count, 0.0);
#pragma omp parallel for schedule(dynamic, 16)
  for (int i = 0; i < count; ++i) {
    double nbar[6], sum[6] = {0, 0, 0, 0, 0, 0};
    uniform_demag_over_cell(body.shape, cells, i, nbar);
    for (int j = 0; j < count; ++j) {
      if (j == i) continue;
      const double* t =
          refined ? &body.pair_tensors[6u * (static_cast<size_t>(i) * count + j)]
                  : &body.offset_tensors[6u * body.offset_index(cells.lattice_index[i], cells.lattice_index[j])];
      const double v = cells.volumes[j];  // w_j N = -T V_j
      for (int a = 0; a < 6; ++a) sum[a] -= v * t[a];
    }
    const Eigen::Matrix3d S = symmetric_matrix(sum), Nbar = symmetric_matrix(nbar), I = Eigen::Matrix3d::Identity();
    const Vec3 half = cells.cube_half(i);
    const double w = cells.volumes[i] / (8.0 * half.x * half.y * half.z);
    const double cap = (1.0 - w) / 3.0;
    // With exact_sub_cubes, a refined body's partial sub-cubes (edge h/2 and
    // smaller, w_i < 1) take the exact local part: the cap there biased the
    // contact force by +4% to +6% (docs/model.md "Refined contact zones").
    // The cells of edge h keep the cap, and so do whole sub-cubes, whose
    // bound is 0: their exact part took a swirl of magnetization about the
    // contact axis below zero energy.
    const bool sub_cube =
        exact_sub_cubes && refined && half.x < 0.375 * cells.spacing && cap > 1e-9;
    const Eigen::Matrix3d K = sub_cube ? Eigen::Matrix3d(I / 3.0 + S - Nbar)
                                       : capped_boundary_correction(I / 3.0 + S - Nbar, cap);
    const Eigen::Matrix3d Pi = gamma * I - K + S, beta = (gamma - 1.0 / 3.0) * I + Nbar;
    const double inv_v = 1.0 / cells.volumes[i];
    auto store = [](const Eigen::Matrix3d& m, double* out, double scale) {
      const double c[6] = {m(0, 0), m(0, 1), m(0, 2), m(1, 1), m(1, 2), m(2, 2)};
      for (int a = 0; a < 6; ++a) out[a] = scale * c[a];
    };
    store(K, &body.self_tensors[6u * i], inv_v);
    store(Pi, &body.uniform_tensors[12u * i], 1.0);
    store(beta, &body.uniform_tensors[12u * i + 6], 1.0);
  }
  for (int k = 0; k < 2; ++k) {
    Eigen::Matrix3d total = Eigen::Matrix3d::Zero();
    for (int i = 0; i < count; ++i) {
      total += cells.volumes[i] * symmetric_matrix(&body.uniform_tensors[12u * i + 6u * k]);
    }
    const Eigen::Matrix3d inv = total.inverse();
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 3; ++c) body.uniform_inverse[k].m[r][c] = inv(r, c);
  }
}

}  // namespace

uint64_t ModelGeneration::next() noexcept {
  static std::atomic<uint64_t> last{0};
  return last.fetch_add(1, std::memory_order_relaxed) + 1;
}

double body_lattice_points(const Shape& shape, double cell_size) {
  if (!(cell_size > 0.0)) return 1.0;
  const Vec3 half = shape_half_extents(shape);
  double points = 1.0;
  for (int a = 0; a < 3; ++a) points *= std::max(1.0, std::round(2.0 * half[a] / cell_size));
  return points;
}

std::string validate_body_lattice(const std::string& name, const Shape& shape, double cell_size) {
  const double points = body_lattice_points(shape, cell_size);
  if (!(points > kMaxBodyLatticePoints)) return {};
  char h[32];  // shortest round-trip form, as the scene loader writes numbers
  const auto end = std::to_chars(h, h + sizeof h, cell_size).ptr;
  std::ostringstream msg;
  msg.precision(3);
  msg << "cell size " << std::string_view(h, static_cast<size_t>(end - h)) << " gives body \"" << name << "\" a lattice of " << points
      << " points; at most " << static_cast<long long>(kMaxBodyLatticePoints) << " are allowed";
  return msg.str();
}

MagneticBody MagneticModel::make_body(const std::string& name, const Shape& shape,
                                      const Material& material, double cell_size,
                                      const std::vector<RefinedZone>& zones) const {
  if (std::string e = validate_shape(shape); !e.empty()) throw std::invalid_argument(e);
  if (std::string e = validate_material(material); !e.empty()) throw std::invalid_argument(e);
  if (!std::isfinite(cell_size)) throw std::invalid_argument("cell_size must be finite");
  if (!is_inert(material))
    if (std::string e = validate_body_lattice(name, shape, cell_size); !e.empty()) throw std::invalid_argument(e);

  MagneticBody body;
  body.name = name;
  body.shape = shape;
  body.material = material;
  body.cell_size = cell_size;
  const bool graded = graded_cells_ && intra_tensor_ == IntraBodyTensor::cell_average &&
                      has_positive_susceptibility(material) &&
                      uses_graded_cells(shape, cell_size);
  if (!zones.empty()) {
    if (is_inert(material))
      throw std::invalid_argument("body \"" + name + "\": an inert body has no cells to refine");
    if (intra_tensor_ != IntraBodyTensor::cell_average)
      throw std::invalid_argument("body \"" + name +
                                  "\": refined zones need the cell_average intra-body tensor");
    try {
      body.cells = make_refined_cells(shape, cell_size, zones);
    } catch (const std::invalid_argument& e) {
      throw std::invalid_argument("body \"" + name + "\": " + e.what());
    }
  } else if (!is_inert(material)) {
    body.cells = graded ? make_graded_box_cells(shape, cell_size)
                        : make_cells(shape, cell_size, has_positive_susceptibility(material));
  }

  if (const auto* pm = std::get_if<PermanentMaterial>(&material)) {
    body.remanence = pm->magnetization;
    body.recoil = pm->recoil_susceptibility;
    body.kind = pm->recoil_susceptibility != 0.0 ? CellKind::recoil_permanent : CellKind::fixed_permanent;
  } else if (const auto* sm = std::get_if<SoftMaterial>(&material)) {
    body.kind = CellKind::soft;
    body.soft.Ms = sm->saturation;
    if (!sm->bh_curve.empty()) {
      body.bh_curve = BhCurve(sm->bh_curve);
      body.soft.Ms = body.bh_curve.saturation();
    }
    body.soft.gamma_D = sm->demag_factor();
    body.soft.H_K = sm->anisotropy_field;
    body.soft.easy_axis = normalized(sm->easy_axis);
    body.soft.alpha = sm->damping;
    body.soft.n = sm->moments_per_cell;
    body.coil_field = sm->coil_field;
  }
  if (body.responsive() && body.cells.graded) {
    build_pair_tensors(body);
  } else if (body.responsive() && body.cells.refined) {
    build_refined_pair_tensors(body);
    if (body.recoil >= 0.0) {
      // The partial sub-cubes' exact local part is not bounded as the cap
      // is: keep it only where the body's operator stays positive definite
      // (checked up to kMaxExactSubCubeCells cells), else cap every cell
      // (docs/model.md "Refined contact zones").
      body.exact_sub_cubes = body.cell_count() <= kMaxExactSubCubeCells;
      build_boundary_correction(body, body.exact_sub_cubes);
      if (body.exact_sub_cubes && !body_operator_positive_definite(body, local_gamma(body))) {
        body.exact_sub_cubes = false;
        build_boundary_correction(body);
      }
    }
    body.response = build_body_response(body);
  } else if (body.responsive() && body.cell_count() > 1) {
    build_offset_tensors(body, intra_tensor_);
    // Diamagnets (recoil < 0) take none: its update needs N + 1/chi positive definite.
    if (!body.cells.whole_cells && intra_tensor_ == IntraBodyTensor::cell_average && body.recoil >= 0.0)
      build_boundary_correction(body);
    body.response = build_body_response(body);
  }

  return body;
}

void MagneticModel::append_cells(int b) {
  MagneticBody& body = bodies_[b];
  body.first_cell = cell_count();
  for (int c = 0; c < body.cell_count(); ++c) {
    cell_body_.push_back(b);
    if (body.kind == CellKind::soft) {
      moment_offset_.push_back(moment_count_);
      moment_count_ += body.soft.n;
      ++soft_cells_;
    } else {
      moment_offset_.push_back(-1);
    }
    if (body.responsive()) ++responsive_cells_;
  }
}

int MagneticModel::add_body(const std::string& name, const Shape& shape, const Material& material,
                            double cell_size, const std::vector<RefinedZone>& zones) {
  bodies_.push_back(make_body(name, shape, material, cell_size, zones));
  append_cells(body_count() - 1);
  generation_.bump();
  return body_count() - 1;
}

MagneticBody MagneticModel::refine_body(int b, const std::vector<RefinedZone>& zones) {
  if (b < 0 || b >= body_count())
    throw std::out_of_range("MagneticModel::refine_body: no body " + std::to_string(b) +
                            " (the model has " + std::to_string(body_count()) + ")");
  const MagneticBody& old = bodies_[b];
  MagneticBody body = make_body(old.name, old.shape, old.material, old.cell_size, zones);
  std::swap(bodies_[b], body);
  cell_body_.clear();
  moment_offset_.clear();
  moment_count_ = soft_cells_ = responsive_cells_ = 0;
  for (int i = 0; i < body_count(); ++i) append_cells(i);
  generation_.bump();
  return body;
}

void MagneticModel::add_coil(int body, const CoilSource& source) {
  if (body < 0 || body >= body_count())
    throw std::invalid_argument("MagneticModel::add_coil: no body " + std::to_string(body) + " (the model has " +
                                std::to_string(body_count()) + ")");
  if (const std::string e = coil_source_error(source); !e.empty())
    throw std::invalid_argument("MagneticModel::add_coil: body " + bodies_[body].name + ": " + e);
  coils_.push_back({body, source});
  generation_.bump();
}

int MagneticModel::find_body(const std::string& name) const {
  for (int b = 0; b < body_count(); ++b)
    if (bodies_[b].name == name) return b;
  return -1;
}

}  // namespace odemag
