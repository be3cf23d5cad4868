// Per-body cell sets on a cubic lattice (docs/model.md "Cells").
#pragma once

#include <array>
#include <cstddef>
#include <vector>

#include "odemag/shape.h"
#include "odemag/vec3.h"

namespace odemag {

// The site of lattice point index on a lattice of extent points per axis,
// spacing h, centred on the body's origin.
inline Vec3 lattice_site(const std::array<int, 3>& extent, double h, const std::array<int, 3>& index) {
  return {(index[0] - 0.5 * (extent[0] - 1)) * h, (index[1] - 0.5 * (extent[1] - 1)) * h,
          (index[2] - 0.5 * (extent[2] - 1)) * h};
}

// The cells of one body, in the body frame (make_cells). A volume-share
// cell stands for the part of its cube (edge h, centred on its lattice site)
// inside the body: its volume is that part's volume (h^3 for a whole cube)
// and its position that part's centroid (the site for a whole cube). A
// centre-inside cell sits at its site and stands for volume / N. Either way
// the body's total moment is M times its volume. A one-cell body stands for
// the whole body.
struct CellSet {
  std::vector<Vec3> local_positions;              // body frame, m: centroid of the cell's part of the body
  std::vector<std::array<int, 3>> lattice_index;  // integer lattice coordinates, 0-based
  std::vector<double> volumes;                    // V_i, m^3: volume of the cell's part of the body
  // Per cell: the radius of the sphere about the cell point inscribed in the
  // cell's part of the body (h/2 for a whole cube), floored at h/4 (see
  // contact_radius below).
  std::vector<double> contact_radii;
  std::array<int, 3> lattice_extent{1, 1, 1};     // lattice points per axis of the bounding lattice
  double spacing = 0.0;                           // h, m; 0 for a single cell
  // The volume the intra-body tensors divide by (T = -N / cell_volume,
  // magnetics/model/model.cpp): h^3 for volume-share cells, volume / N for
  // centre-inside cells, the body's volume for a one-cell body.
  double cell_volume = 0.0;
  double cell_radius = 0.0;                       // radius of the sphere of volume cell_volume, m
  // Radius of the sphere inscribed in the solid a whole cell stands for: h/2
  // for a lattice cell (centre to the face of its cube), R for a one-cell
  // ball, the smallest half extent for another one-cell body; the largest of
  // contact_radii. Two cells of different bodies interact through the exact
  // dipole kernel while their points are farther apart than the sum of their
  // contact radii, so bodies that touch never reach the bounded core
  // (magnetics/kernels/kernels.h); a boundary cell, whose point lies closer to the
  // surface, has the smaller radius of its own part (not below h/4).
  double contact_radius = 0.0;
  // True when every cell stands for cell_volume (centre-inside cells, and
  // volume-share cells that are all whole cubes); false when some are partial
  // cubes: the body then gets the boundary correction (MagneticBody::
  // self_tensors).
  bool whole_cells = true;
  // Graded cells (make_graded_box_cells): the cells tile a box as cuboids
  // of different sizes, cell i of half extents half_extents[i] centred on its
  // point; whole_cells is false (the volumes differ) and the body's
  // intra-body tensors are per pair (MagneticBody::pair_tensors). spacing
  // then is the mean width edge / n of the first axis, for code that wants a
  // length scale. Empty half_extents for lattice cells (cubes of edge h).
  bool graded = false;
  std::vector<Vec3> half_extents;
  std::array<std::vector<double>, 3> faces;  // graded: the n_a + 1 face positions per axis, m
  // Refined zones (make_refined_cells): volume-share cells of a curved body
  // whose cubes have edges h / 2^l, finer near given points. Per cell the
  // centre of its cube (body frame; the centroid of its part of the body is
  // local_positions) and its half edges (half_extents); lattice_index is the
  // cube's index on the lattice at its own edge, nested in the one at h.
  // whole_cells is false; the body's intra-body tensors are per pair
  // (MagneticBody::pair_tensors).
  bool refined = false;
  std::vector<Vec3> cube_centres;
  // A box's cells: per cell the half extents of its part of the box, a
  // cuboid centred on the cell point (cube ∩ box about its centroid for
  // volume-share and refined cells; the layer of a thin box's centre-inside
  // cells), or the cube of edge h where its part is no cuboid about the
  // point. Empty for other bodies.
  std::vector<Vec3> part_halves;

  int size() const { return static_cast<int>(local_positions.size()); }
  // Cells of their own sizes (graded or refined): per-pair intra-body
  // tensors, and no lattice near field between bodies.
  bool mixed_sizes() const { return graded || refined; }
  // The cube (cuboid) cell i stands for: its centre in the body frame and its
  // half edges.
  Vec3 cube_centre(int i) const {
    if (refined) return cube_centres[i];
    if (graded) return local_positions[i];
    return lattice_site(lattice_extent, spacing, lattice_index[i]);
  }
  Vec3 cube_half(int i) const {
    return half_extents.empty() ? Vec3{0.5 * spacing, 0.5 * spacing, 0.5 * spacing} : half_extents[i];
  }
  // The uniformly magnetized solid cell i stands for in the fields between
  // bodies and at field points (the near fields, probes): a cuboid centred on
  // the cell point with these half extents, carrying the cell's moment over
  // solid_volume. A box's part of the body (part_halves), a graded cell's
  // cuboid, a refined cell's cube; otherwise the cube of edge h, with volume
  // cell_volume (a curved body's boundary cell: its cube at its centroid with
  // the reduced magnetization V_i M / h^3). For lattice cells (spacing > 0).
  Vec3 solid_half(int i) const {
    if (!part_halves.empty()) return part_halves[i];
    return cube_half(i);
  }
  double solid_volume(int i) const {
    if (!part_halves.empty() || graded) return volumes[i];
    if (refined) {
      const Vec3 a = cube_half(i);
      return 8.0 * a.x * a.y * a.z;
    }
    return cell_volume;
  }
  // True when cell i's solid is the cube of edge h (solid_half h/2).
  // True when every cell's solid is the part of the body it stands for (a
  // box's), so that fields between bodies can take the solids' exact tensors.
  bool exact_solids() const { return !part_halves.empty(); }
  bool solid_is_cube(int i) const {
    if (graded || refined) return false;
    if (part_halves.empty()) return true;
    const Vec3& p = part_halves[i];
    return p.x == 0.5 * spacing && p.y == 0.5 * spacing && p.z == 0.5 * spacing;
  }
};

// Cells of a shape on a lattice of spacing h = cell_size (docs/model.md
// "Cells"). With cell_size <= 0 the body is one cell at its centre, standing
// for the whole body. Bodies of fixed magnetization, and responsive bodies at
// least kMinVolumeShareExtent h across along every axis, get volume-share
// cells: per axis ceil(extent / h) points spaced h apart and centred on the
// body (so the cubes cover it), and every cube with a share of its volume
// inside the shape above kMinCellShare is a cell, standing for that part at
// its centroid (a box's parts are cuboids: CellSet::part_halves). Thinner
// responsive bodies keep centre-inside cells: per axis max(1, floor(extent /
// h)) points, those inside the shape are cells standing for volume / N each;
// a lattice coarser than the body gives one cell at the centre.
// responsive: the body's magnetization responds to fields (soft, recoil).
CellSet make_cells(const Shape& shape, double cell_size, bool responsive = true);

// Graded cells of a box (docs/model.md "Graded cells"): per axis n =
// floor(edge / h) cells (as make_cells) whose faces lie at the
// Chebyshev-Lobatto points x_k = -(edge / 2) cos(pi k / n), k = 0 .. n: a
// tensor-product grid with cells narrowing towards the faces (the face cells
// about pi^2 / (4 n) of the mean width), where a soft body's magnetization is
// singular (at its edges). Each cell is the cuboid between its faces,
// standing for its volume at its centre. For uses_graded_cells shapes only
// (std::invalid_argument otherwise).
CellSet make_graded_box_cells(const Shape& shape, double cell_size);

// A zone of a body's lattice refined towards a point (docs/model.md "Refined
// contact zones"): a cell whose cube (edge h / 2^l) comes within radii[l] of
// the point is replaced by the 8 cubes of edge h / 2^(l+1) that tile it, for
// l < radii.size() (at most kMaxRefinementLevels).
struct RefinedZone {
  Vec3 point;                 // body frame, m
  std::vector<double> radii;  // D_l, m
};

inline constexpr size_t kMaxRefinementLevels = 4;
// A body of refined zones may have at most this many cells: its per-pair
// tensors take 48 n^2 bytes (770 MB at 4000 cells).
inline constexpr int kMaxRefinedCells = 4000;
// A refined body of at most this many cells takes the exact boundary
// correction on its partial sub-cubes where its operator stays positive definite
// (checked by a Cholesky of its 3 n unknowns when it is built); a larger
// one caps every cell (docs/model.md "Refined contact zones").
inline constexpr int kMaxExactSubCubeCells = 2000;

// The radii chosen for two balls near contact (docs/model.md "Refined contact
// zones", measured in docs/validation.md section 5): 1.25 h, 0.75 h, h / 4,
// i.e. cubes of h / 8 at the point.
std::vector<double> default_refinement_radii(double cell_size);

// The volume-share cells of make_cells at cell_size, refined in the zones
// (CellSet::refined). For shapes that uses_volume_shares accepts (curved
// bodies at least kMinVolumeShareExtent cells across); std::invalid_argument
// otherwise, or for a non-finite point, negative or non-finite radii, more
// than kMaxRefinementLevels levels, or more than kMaxRefinedCells cells.
CellSet make_refined_cells(const Shape& shape, double cell_size, const std::vector<RefinedZone>& zones);

// True when a responsive body of this shape gets graded cells: a box at
// least kMinGradedExtent cells along every axis with at most kMaxGradedCells
// cells (their per-pair tensors take 48 n^2 bytes: 48 MB at 1000 cells).
bool uses_graded_cells(const Shape& shape, double cell_size);

inline constexpr int kMinGradedExtent = 4;
inline constexpr int kMaxGradedCells = 1000;

// True when make_cells gives the shape volume-share cells.
bool uses_volume_shares(const Shape& shape, double cell_size, bool responsive = true);

// Cubes with less than this share of their volume inside the shape are left
// out (their volume, at most this share of h^3 each, is lost).
inline constexpr double kMinCellShare = 1e-9;
// Extent (in cells, every axis) from which a responsive body has volume-share cells.
inline constexpr double kMinVolumeShareExtent = 2.0;

// Volume and first moments of the box [lo, hi] inside the shape (body frame):
// closed forms for balls, boxes and cylinders, magnetics/cells/mesh.h and
// compound.h for meshes and compounds.
struct VolumeMoments;
VolumeMoments shape_box_moments(const Shape& shape, const Vec3& lo, const Vec3& hi);
// Distance from a point inside the shape to its surface.
double shape_depth(const Shape& shape, const Vec3& p);

// The demagnetising tensor of the uniformly magnetized shape, averaged over
// cell i's part of it: H = -N M there for a body of uniform magnetization M
// (body frame, six components xx, xy, xz, yy, yz, zz; trace 1). Exactly I/3
// for a ball; for a cylinder the field of its charged end discs and side
// (one-dimensional quadratures) at 3 Gauss points along the axis through the
// centroid of the cell's cross-section; for a mesh or a compound the field of
// its face charges (magnetics/cells/mesh.h mesh_demag_tensor) at the cell's
// centroid. Boxes have no volume-share cells
// (uses_volume_shares): std::logic_error.
void uniform_demag_over_cell(const Shape& shape, const CellSet& cells, int i, double n[6]);

}  // namespace odemag
