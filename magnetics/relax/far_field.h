// Far-field approximation of the responsive field (docs/model.md "Far
// field"). A binary space-partition tree over the cells, each node holding the
// total moment of its cells and its first moment about the node centre. For a
// leaf of targets T and a node S with
//   theta * |c_T - c_S| > R_T + R_S      (R: radius of the node about c)
// and no overlap of contact distances, the field of S's cells at T's cells is
// replaced by the dipole-plus-first-moment expansion of S evaluated at c_T and
// carried to each target to first order (the field and its gradient at c_T);
// every other pair is summed exactly through the kernel. The error of a
// replaced pair group falls as theta^2. Pairs of cells of one body are left
// out (the intra-body tables carry them).
#pragma once

#include <cstdint>
#include <vector>

#include "odemag/vec3.h"

namespace odemag {

class FarFieldTree {
 public:
  // Cells that are both the sources and the targets: positions (m), contact
  // radii (m) and bodies, n of each. 0 < theta < 1.
  void build(const double* x, const double* y, const double* z, const double* radius, const int* body,
             int n, double theta);

  // H[i] (A/m): the field at cell i of every cell of another body, from the
  // moments mu = M V (A m^2) in the order given to build. Sums run in a fixed
  // order, so the result does not depend on the number of threads.
  void field(const double* mx, const double* my, const double* mz, Vec3* H, int threads);

  int size() const { return static_cast<int>(order_.size()); }
  // Work of one field evaluation: pairs summed exactly, node expansions used.
  long near_pairs() const { return near_pairs_; }
  long far_interactions() const { return far_interactions_; }

 private:
  struct Node {
    Vec3 centre;              // centre of the cells' bounding box
    double radius = 0.0;      // largest distance of a cell from centre
    double max_contact = 0.0; // largest contact radius of a cell
    int begin = 0, end = 0;   // cells in tree order
    int child[2] = {-1, -1};  // -1: a leaf
    int body = -1;            // the body of all its cells, -1 when several
    uint64_t multi_cell_bodies = 0;  // bit (slot % 64) of each body with more than one cell
  };
  struct LeafLists {
    int node = 0;
    std::vector<int> far;                       // nodes replaced by their expansion
    std::vector<std::pair<int, int>> near;      // cell ranges summed exactly
  };

  int build_node(int begin, int end, const std::vector<uint64_t>& cell_mask);
  void collect(LeafLists& leaf) const;

  double theta_ = 0.5;
  std::vector<int> order_;  // tree position -> input index
  std::vector<double> x_, y_, z_, radius_, body_, mx_, my_, mz_;  // in tree order
  std::vector<Node> nodes_;
  std::vector<LeafLists> leaves_;
  std::vector<Vec3> node_moment_;     // sum of mu over the node
  std::vector<double> node_first_;    // 9 per node: Q_ab = sum mu_a (x_b - c_b)
  long near_pairs_ = 0, far_interactions_ = 0;
};

}  // namespace odemag
