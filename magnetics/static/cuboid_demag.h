// The demagnetizing field of axis-aligned cuboid cells of any sizes and
// places by a dense sum, reduced by mirror planes (docs/model.md "Graded
// cells with mirror planes").
//
// The cells are those of one symmetric sector: x >= 0 with the mirror plane
// x = 0, y >= 0 with y = 0 (either, both or none). The rest of the bodies is
// their mirror images. A problem symmetric under the reflection P = diag(-1,
// 1, 1) in x = 0 whose sources are currents around the z axis or magnets
// along z has H and M that transform as polar vectors, M(P r) = S M(r) with S
// = diag(-1, 1, 1): the image of cell j sits at P c_j with magnetization S M_j
// (likewise for y = 0). The mean field over cell i is
//   H_i = -sum_j K_ij M_j,   K_ij = sum_s N_ij(c_i - P_s c_j) S_s          (1)
// over the images s (the identity included), N_ij the cell-averaged tensor
// of cuboid i and cuboid j (cuboid_demag_tensor). V_j K_ji = V_i K_ij^T, so
// S = V K is symmetric: half of it is computed, stored dense (3N x 3N, lower
// triangle) and read per field, or compressed (compress(): a hierarchical
// matrix, docs/model.md "The compressed operator and stored forces").
//
// The force on all images of a set T of cells from all images of a set S:
//   F_q = -mu0 sum_{i in T} V_i sum_{j in S} sum_s M_i^T dN_ij/dd (c_i - P_s c_j) S_s M_j   (2)
// is the force on T's own cells; T's image P_s T feels S_s F_q, so the total
// is sum_s S_s F_q (along z alone with both planes).
#pragma once

#include <Eigen/Dense>

#include <array>
#include <memory>
#include <vector>

#include "magnetics/static/demag_operator.h"
#include "magnetics/static/hmatrix.h"
#include "odemag/vec3.h"

namespace odemag {

struct CuboidCell {
  Vec3 centre;  // m
  Vec3 half;    // half edges, m
};

// The cells of the tensor-product grid with these faces per axis (m), x
// fastest.
std::vector<CuboidCell> grid_cells(const std::vector<double>& fx, const std::vector<double>& fy,
                                   const std::vector<double>& fz);

class CuboidDemag : public DemagOperator {
 public:
  // mirror_x, mirror_y: the planes x = 0, y = 0; the cells must lie on
  // their non-negative side (a face may lie on the plane).
  CuboidDemag(std::vector<CuboidCell> cell_list, bool mirror_x, bool mirror_y);

  int cells() const override { return static_cast<int>(cells_.size()); }
  const CuboidCell& cell(int i) const { return cells_[i]; }
  double volume(int i) const { return 8.0 * cells_[i].half.x * cells_[i].half.y * cells_[i].half.z; }
  // (1), from the stored K.
  void field(const std::vector<Vec3>& M, std::vector<Vec3>& H) const override;
  void self_block(int cell, double n[6]) const override;
  // (2): the force (N) on all images of cells [t0, t1) from all images of
  // cells [s0, s1) (disjoint ranges), by force_operator.
  Vec3 force(int t0, int t1, int s0, int s1, const std::vector<Vec3>& M) const;
  // (2) as a bilinear form of M, for many M on one geometry: the gradients
  // summed over the images, stored per cell pair for each component of the
  // total that the images do not cancel.
  class ForceOperator {
   public:
    Vec3 operator()(const std::vector<Vec3>& M) const;

   private:
    friend class CuboidDemag;
    int t0_ = 0, s0_ = 0;
    std::array<Eigen::MatrixXd, 3> G_;  // per component k: -mu0 V_i sum_s dN/dd_k S_s; empty when cancelled
    Vec3 image_sum_;                    // sum of the images' signs per axis
  };
  ForceOperator force_operator(int t0, int t1, int s0, int s1) const;
  // H (A/m) at a point outside the cells: every cell and its images.
  Vec3 field_at(const Vec3& point, const std::vector<Vec3>& M) const;
  // The images: their reflections (+-1 per axis), the identity first.
  const std::vector<Vec3>& images() const { return images_; }
  // Stores S as a hierarchical matrix (magnetics/static/hmatrix.h) and frees the
  // dense one; field() reads it from then on.
  void compress(const HMatrixOptions& options = {});
  const HMatrix* compressed() const { return compressed_.get(); }

 private:
  // N of cell i and the image s of cell j (1); with dn, also its gradient (2).
  void pair_tensor(int i, int j, int s, double n[6], double (*dn)[6] = nullptr) const;

  std::vector<CuboidCell> cells_;
  std::vector<Vec3> images_;
  Eigen::MatrixXd S_;  // V_i K_ij (1), symmetric: only its lower triangle is set
  std::shared_ptr<const HMatrix> compressed_;  // S, when compressed
  std::vector<Eigen::Matrix3d> self_;          // K_ii, when compressed
};

}  // namespace odemag
