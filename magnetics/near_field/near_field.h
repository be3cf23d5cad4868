// Near-field corrections between cells of different bodies (docs/model.md
// "The near field"). The dense sums (magnetics/kernels/pair_sums.h) couple every pair
// of cells of different bodies as point dipoles (with the bounded overlap
// core, magnetics/kernels/kernels.h). Where bodies touch that is wrong in two ways:
//
// - A one-cell sphere carries only a dipole. A linear sphere answers each
//   multipole order l of the applied potential with its own factor gamma_l =
//   l (mu - 1) / (l mu + l + 1); the missing orders l >= 2 carry most of the
//   force near contact. SphereNearField adds them for close pairs of one-cell
//   spheres, as an energy -mu0/2 p^T K(r) p of the pair's two dipoles p
//   (the higher multipoles eliminated exactly by a two-centre solve).
// - Lattice cells of two bodies couple as point dipoles, while inside a body
//   they use the cell-averaged (Newell) tensor: face neighbours across a
//   contact couple 18% too strongly. LatticeNearField replaces the point
//   dipole by the cell-averaged tensor for close pairs of aligned lattices.
// - A one-cell ball next to a lattice body couples with each close cell as
//   with a point dipole, while the cell is a cube (in a box body: its cuboid
//   part of the box) whose field at the ball's centre, the field the ball's
//   dipole answers, is far from a dipole's within a few h (3.9 times the
//   force for a ball touching the ball chain's magnet). BallLatticeNearField
//   replaces the point dipole by the cuboid's exact field (dipole level: the
//   ball's induced higher orders are not included).
//
// Each correction is a short list of close pairs rebuilt once per rigid step
// (build); the backends add its field to the dense sums at every outer
// iteration and its forces once per step. The pair lists are in a fixed order
// and summed on one thread, so results do not depend on the thread count.
#pragma once

#include <memory>
#include <vector>

#include "magnetics/model/model.h"
#include "odemag/settings.h"
#include "magnetics/model/state.h"
#include "odemag/vec3.h"

namespace odemag {

// Which cells act as sources in add_field.
enum class NearFieldSources { fixed, responsive };

// One correction, behind a common interface. Vectors are indexed by cell.
class NearFieldTerm {
 public:
  virtual ~NearFieldTerm() = default;
  // Close pairs at the current cell positions (after place_cells); inactive
  // and inert bodies take no part.
  virtual void build(const MagneticModel& model, const MagneticState& state) = 0;
  // Adds, at every active responsive cell, the correction field (A/m) of the
  // given sources (their state.magnetization).
  virtual void add_field(const MagneticModel& model, const MagneticState& state, NearFieldSources sources,
                         std::vector<Vec3>& H) const = 0;
  // Adds to every active cell the correction force (N) on it and the
  // correction field (A/m) at it (for the torque mu0 mu x H), from all cells.
  virtual void add_forces(const MagneticModel& model, const MagneticState& state, std::vector<Vec3>& force,
                          std::vector<Vec3>& field) const = 0;
  // The correction's share of the magnetic energy (J) at the current
  // magnetizations (F = -grad U holds for it as for the dipole sums).
  virtual double energy(const MagneticModel& model, const MagneticState& state) const = 0;
  virtual int pair_count() const = 0;

  // false: induced cells feel only H_E and fixed magnets (RelaxOptions::
  // mutual_induction); a correction that is itself induction between
  // responsive cells (a sphere's higher orders excited by an induced
  // neighbour) is then left out. Takes effect at the next build.
  void set_mutual_induction(bool on) { mutual_induction_ = on; }

  // By cell, 1 where the relaxation keeps the magnetization
  // (RelaxOptions::held_bodies); nullptr or empty: none. add_field skips the
  // pairs of two held cells, whose fields nothing reads. Set before build;
  // until the next build the cells may only be cleared (an empty vector),
  // not changed.
  void set_held_cells(const std::vector<uint8_t>* held) { held_cells_ = held; }

 protected:
  bool both_held(int a, int b) const {
    return held_cells_ && !held_cells_->empty() && (*held_cells_)[a] && (*held_cells_)[b];
  }
  bool mutual_induction_ = true;
  const std::vector<uint8_t>* held_cells_ = nullptr;
};

std::unique_ptr<NearFieldTerm> make_sphere_near_field();
std::unique_ptr<NearFieldTerm> make_lattice_near_field();
std::unique_ptr<NearFieldTerm> make_ball_lattice_near_field();

// All near-field terms of a model; what the backends hold.
class NearField {
 public:
  NearField();
  // enabled = false: no pairs (the paper's point-dipole model);
  // mutual_induction: NearFieldTerm::set_mutual_induction.
  void build(const MagneticModel& model, const MagneticState& state, bool enabled, bool mutual_induction = true);
  // NearFieldTerm::set_held_cells for every term; the vector must outlive its use.
  void set_held_cells(const std::vector<uint8_t>* held);
  void add_field(const MagneticModel& model, const MagneticState& state, NearFieldSources sources,
                 std::vector<Vec3>& H) const;
  void add_forces(const MagneticModel& model, const MagneticState& state, std::vector<Vec3>& force,
                  std::vector<Vec3>& field) const;
  double energy(const MagneticModel& model, const MagneticState& state) const;
  int pair_count() const;

 private:
  std::vector<std::unique_ptr<NearFieldTerm>> terms_;
  bool enabled_ = false;
};

}  // namespace odemag
