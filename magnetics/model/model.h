// The magnetic model: what does not change during a simulation (bodies,
// materials, cells, cached intra-body tensors). The changing part lives in
// MagneticState; solvers take both (docs/architecture.md).
#pragma once

#include <array>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "magnetics/materials/bh_curve.h"
#include "magnetics/model/body_response.h"
#include "magnetics/cells/cells.h"
#include "magnetics/sources/coil.h"
#include "magnetics/cells/demag_tensor.h"
#include "magnetics/kernels/llg.h"
#include "odemag/material.h"
#include "odemag/shape.h"

namespace odemag {

// How a cell's magnetization is determined.
enum class CellKind : uint8_t {
  fixed_permanent,   // M = M_r (rotating with the body); a source only
  recoil_permanent,  // M = (M_r + chi_r H_A) / (1 + chi_r / 3)
  soft,              // n unit moments relaxed by LLG
};

struct MagneticBody {
  std::string name;
  Shape shape;
  Material material;
  CellSet cells;         // empty for inert bodies
  double cell_size = 0.0;  // h as given to MagneticModel::add_body, m (<= 0: one cell)
  int first_cell = 0;    // index of the first cell in the model's cell arrays
  CellKind kind = CellKind::fixed_permanent;
  SoftCellParams soft;   // for soft bodies (easy axis normalised, body frame)
  Vec3 remanence;        // M_r for permanent bodies, body frame
  Vec3 coil_field;       // coil field of an electromagnet's core (soft bodies), body frame
  double recoil = 0.0;   // chi_r for permanent bodies
  BhCurve bh_curve;      // soft bodies with a B-H curve (empty: linear to saturation)

  // Intra-body interaction tensors, computed once per body: H = T(d) mu for
  // every lattice offset d (six components, body frame). T = -N(d) / h^3 with N
  // the cube-cube tensor, or the point dipole (magnetics/cells/demag_tensor.h).
  std::vector<double> offset_tensors;
  std::array<int, 3> offset_extent{0, 0, 0};  // 2 n - 1 per axis
  // Bodies of graded cells (CellSet::graded) instead: per pair (i, j), at
  // 6 (i n + j), H_i += T_ij mu_j with T_ij = -N_ij / V_j, N_ij the
  // cuboid-cuboid tensor (cuboid_demag_tensor; T_ij = T_ji since V_i N_ij =
  // V_j N_ji), and on the diagonal T_ii = -(N_ii - I / 3) / V_i: the
  // cell's own demagnetising tensor beyond the cube's I / 3 that the local
  // relaxation (gamma_D) already holds. offset_tensors is empty then.
  // Bodies of refined zones (CellSet::refined) too, with their cubes: T_ij =
  // -N_ij / a_j^3 (a_j the edge of cell j's cube, N_ij of the two cubes at
  // their cube centres) and T_ii = 0 (magnetics/model/model.cpp
  // build_refined_pair_tensors).
  std::vector<double> pair_tensors;
  // Boundary correction of the intra-body field of a responsive body with
  // partial cells (docs/model.md "Cells"; magnetics/model/state.h add_boundary_field),
  // body frame, six components per symmetric tensor. Empty when not needed
  // (bodies of whole cells, one cell, point-dipole tensors).
  //  - self_tensors: per cell S_i, adding S_i mu_i to the cell's field (the
  //    local correction, limited so that the operator stays positive);
  //  - uniform_tensors: per cell Pi_i then beta_i (twelve numbers), with
  //    uniform_inverse = ((sum_j V_j Pi_j)^-1, (sum_j V_j beta_j)^-1): the
  //    correction of the uniform modes, adding
  //      Pi_i G_Pi sum_j Pi_j mu_j - beta_i G_beta sum_j beta_j mu_j,
  //    so that a uniform magnetization gets the exact field of the shape.
  std::vector<double> self_tensors;
  std::vector<double> uniform_tensors;
  Mat3 uniform_inverse[2];
  // Bodies of refined zones: whether their partial sub-cubes took the exact
  // local part (add_body's positivity check passed), else every cell is
  // capped (docs/model.md "Refined contact zones").
  bool exact_sub_cubes = false;
  // The factor of the body's linear self-response (magnetics/model/body_response.h),
  // the outer loop's block preconditioner; null for bodies that take none.
  std::shared_ptr<const BodyResponseFactor> response;

  int cell_count() const { return cells.size(); }
  bool inert() const { return cells.size() == 0; }
  bool responsive() const { return !inert() && kind != CellKind::fixed_permanent; }
  // Index into offset_tensors (times 6) of the offset a - b.
  int offset_index(const std::array<int, 3>& a, const std::array<int, 3>& b) const {
    const int nx = cells.lattice_extent[0], ny = cells.lattice_extent[1], nz = cells.lattice_extent[2];
    return (a[0] - b[0] + nx - 1) +
           offset_extent[0] * ((a[1] - b[1] + ny - 1) + offset_extent[1] * (a[2] - b[2] + nz - 1));
  }
};

// A body's lattice may have at most this many points: beyond it the per-body
// tensors alone take gigabytes. MagneticModel::add_body and the scene loader
// apply it (validate_body_lattice).
inline constexpr double kMaxBodyLatticePoints = 4194304.0;  // 2^22

// Points of the lattice a shape gets at cell_size: its bounding box over h^3,
// per axis max(1, round(extent / h)); 1 for cell_size <= 0 (one cell). A
// double, so that absurd lattices (1 m at 1 um: 1e18) count without overflow.
double body_lattice_points(const Shape& shape, double cell_size);

// Empty when a body of this shape at cell_size has at most
// kMaxBodyLatticePoints lattice points; otherwise the message, naming the body
// and giving the count and the limit. Shapes only: inert bodies, which get no
// cells, are the caller's to skip.
std::string validate_body_lattice(const std::string& name, const Shape& shape, double cell_size);

// A number that identifies one model's contents within the process: a new
// one for every model made, copied or moved (both the source and the target
// of a move get one) and after every change. Backends that cache what they
// derive from a model (the CUDA backend's offset tensor tables) key the cache
// on it instead of the model's address, which a copy or a new model can share.
class ModelGeneration {
 public:
  ModelGeneration() : value_(next()) {}
  ModelGeneration(const ModelGeneration&) : value_(next()) {}
  ModelGeneration(ModelGeneration&& other) noexcept : value_(next()) { other.value_ = next(); }
  ModelGeneration& operator=(const ModelGeneration&) {
    value_ = next();
    return *this;
  }
  ModelGeneration& operator=(ModelGeneration&& other) noexcept {
    value_ = next();
    other.value_ = next();
    return *this;
  }
  ~ModelGeneration() = default;
  void bump() { value_ = next(); }
  uint64_t value() const { return value_; }

 private:
  static uint64_t next() noexcept;  // process-wide, thread-safe, never 0
  uint64_t value_;
};

// A current source carried by a body (magnetics/sources/coil.h), given in the body
// frame: it moves with the body, its current is multiplied by the body's
// MagneticState::magnetization_scale, its field acts on every active
// responsive cell (its own body's too: a coil around a core) and its force on
// the cells of other bodies returns to the carrying body (docs/model.md
// "Coils in a scene").
struct AttachedCoil {
  int body = -1;
  CoilSource source;
};

class MagneticModel {
 public:
  MagneticModel() = default;
  explicit MagneticModel(IntraBodyTensor intra_tensor) : intra_tensor_(intra_tensor) {}
  IntraBodyTensor intra_body_tensor() const { return intra_tensor_; }
  // Graded cells (docs/model.md "Graded cells") for the responsive boxes
  // added from now on that uses_graded_cells accepts, with the cell_average
  // tensor. Off by default (the uniform lattice of cubes): the lattice near
  // field between touching bodies (magnetics/near_field/lattice_near_field.cpp) and
  // field probes treat cells as cubes of edge h, and the CUDA backend
  // refuses graded bodies.
  void set_graded_cells(bool on) { graded_cells_ = on; }
  bool graded_cells() const { return graded_cells_; }

  // This model's contents (ModelGeneration): unique to the model object and
  // new after every add_body.
  uint64_t generation() const { return generation_.value(); }

  // Adds a body and returns its index. cell_size <= 0: one cell (spheres) or
  // one cell at the centre. Throws std::invalid_argument on a bad shape or
  // material, or a lattice beyond kMaxBodyLatticePoints (validate_body_lattice,
  // checked before any cell is made).
  // zones: refined zones of the body's lattice (make_refined_cells, docs/model.md
  // "Refined contact zones"), in the body frame; for curved bodies of
  // volume-share cells with the cell_average tensor (std::invalid_argument
  // otherwise, naming the body). Such a body takes no lattice or ball-lattice
  // near field and no block preconditioner, and only the CPU backend runs it.
  int add_body(const std::string& name, const Shape& shape, const Material& material, double cell_size,
               const std::vector<RefinedZone>& zones = {});

  // Gives body b new refined zones (docs/model.md "Refined contact zones";
  // none: its plain cells again): its cells, tensors, boundary correction
  // and response are built anew, as add_body builds them with its shape,
  // material and cell size; the other bodies keep theirs, their cells
  // renumbered. Returns the body as it was (transfer_refined_state carries
  // the state over). Throws std::out_of_range on a bad index, and
  // std::invalid_argument, leaving the model unchanged, for zones add_body
  // refuses.
  MagneticBody refine_body(int b, const std::vector<RefinedZone>& zones);

  // Attaches a current source to body `body` (body frame). Throws
  // std::invalid_argument on a bad index or geometry (coil_source_error).
  void add_coil(int body, const CoilSource& source);
  const std::vector<AttachedCoil>& coils() const { return coils_; }

  const std::vector<MagneticBody>& bodies() const { return bodies_; }
  const MagneticBody& body(int b) const { return bodies_[b]; }
  int body_count() const { return static_cast<int>(bodies_.size()); }
  int find_body(const std::string& name) const;  // -1 when absent

  int cell_count() const { return static_cast<int>(cell_body_.size()); }
  int cell_body(int c) const { return cell_body_[c]; }
  // Volume (m^3) of cell c's part of its body: mu = M V (CellSet::volumes).
  double cell_volume(int c) const {
    const MagneticBody& b = bodies_[cell_body_[c]];
    return b.cells.volumes[c - b.first_cell];
  }
  // Contact radius (m) of cell c (CellSet::contact_radii).
  double cell_contact_radius(int c) const {
    const MagneticBody& b = bodies_[cell_body_[c]];
    return b.cells.contact_radii[c - b.first_cell];
  }
  // Index of the cell's first moment in the state's moment array, -1 if not soft.
  int moment_offset(int c) const { return moment_offset_[c]; }
  int moment_count() const { return moment_count_; }
  int soft_cell_count() const { return soft_cells_; }
  int responsive_cell_count() const { return responsive_cells_; }

 private:
  // The body add_body would add (first_cell unset); throws as add_body does.
  MagneticBody make_body(const std::string& name, const Shape& shape, const Material& material,
                         double cell_size, const std::vector<RefinedZone>& zones) const;
  // Numbers body b's cells after the cells of the bodies before it.
  void append_cells(int b);

  IntraBodyTensor intra_tensor_ = IntraBodyTensor::cell_average;
  bool graded_cells_ = false;
  std::vector<MagneticBody> bodies_;
  std::vector<AttachedCoil> coils_;
  std::vector<int> cell_body_;
  std::vector<int> moment_offset_;
  int moment_count_ = 0;
  int soft_cells_ = 0;
  int responsive_cells_ = 0;
  ModelGeneration generation_;
};

}  // namespace odemag
