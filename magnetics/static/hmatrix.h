// A symmetric matrix of cell-to-cell 3x3 blocks stored as a hierarchical
// matrix (docs/model.md "The compressed operator and stored forces"): the
// cells ordered by a cluster tree (boxes bisected along their longest axis),
// a block between two clusters far apart against their size stored as a
// product U V^T of low rank found by adaptive cross approximation, the rest
// dense.
//
// Two clusters A and B are far apart when
//   max(diam A, diam B) <= eta dist(A, P_s B)   for every image s          (1)
// (diam, dist: of the boxes that hold the clusters' cells; P_s the
// reflections in the problem's mirror planes, the identity included), so
// that the kernel summed over the images is smooth over the block.
//
// Adaptive cross approximation (partial pivoting): the block's rows and
// columns are read one at a time, each new rank-one term u v^T the residual's
// row and column through the largest remaining entry, until
//   |u| |v| <= tolerance |U V^T|_F                                         (2)
// A block whose factors would outweigh it (rank >= m n / (m + n)) is kept dense.
#pragma once

#include <Eigen/Dense>

#include <array>
#include <functional>
#include <vector>

#include "odemag/vec3.h"

namespace odemag {

struct HMatrixOptions {
  double tolerance = 1e-5;  // (2), per block
  double eta = 1.0;         // (1)
  int leaf_cells = 8;       // clusters of at most this many cells are not split
  // Store the blocks in single precision (docs/model.md "The compressed
  // operator and stored forces": a matvec about 1.6 times faster, but GMRES
  // then stalls near 1e-6 relative, so only for solves to 1e-3 or looser).
  bool single_precision = false;
};

class HMatrix {
 public:
  struct CellBox {
    Vec3 centre, half;  // m
  };
  // entry(r, c): the symmetric matrix's entry at scalar row r and column c
  // (3 cell + component), asked in either order, only while constructing.
  // images: the reflections of (1) (+-1 per axis), the identity first.
  HMatrix(const std::vector<CellBox>& cells, const std::vector<Vec3>& images,
          const std::function<double(int, int)>& entry, const HMatrixOptions& options = {});

  // y = A x (3 per cell, the cells' own order).
  void multiply(const Eigen::VectorXd& x, Eigen::VectorXd& y) const;

  // Numbers stored (the dense matrix: 9 N^2), and the blocks of each kind.
  long stored() const;
  int low_rank_blocks() const { return static_cast<int>(low_rank_.size()); }
  int dense_blocks() const { return static_cast<int>(dense_.size()); }

 private:
  struct Cluster {
    int begin, end;  // cells order_[begin, end)
    Vec3 lo, hi;     // the box holding the cells
    int first = -1, second = -1;
  };
  struct DenseBlock {
    int rows, cols;  // clusters; rows == cols: a diagonal block (stored whole)
  };
  struct LowRankBlock {
    int rows, cols;  // the block is u v^T
  };
  // The blocks' numbers in one precision, in the order of dense_ and low_rank_.
  template <class Scalar>
  struct Stored {
    using Matrix = Eigen::Matrix<Scalar, Eigen::Dynamic, Eigen::Dynamic>;
    std::vector<Matrix> dense, u, v;
  };

  int split(int begin, int end, const std::vector<CellBox>& cells);
  bool far_apart(const Cluster& a, const Cluster& b) const;
  // The matrix's scalar index (3 cell + component) of a cluster's local row k.
  int scalar_index(const Cluster& c, int k) const { return 3 * order_[c.begin + k / 3] + k % 3; }
  void partition(int a, int b, const std::function<double(int, int)>& entry);
  bool cross_approximation(const Cluster& a, const Cluster& b, const std::function<double(int, int)>& entry,
                           Eigen::MatrixXd& u, Eigen::MatrixXd& v) const;

  template <class Scalar>
  void multiply_stored(const Stored<Scalar>& stored, const Eigen::VectorXd& x, Eigen::VectorXd& y) const;

  static constexpr int kChunks = 4;  // of multiply's blocks, summed apart
  std::array<int, kChunks + 1> chunk_begin_{};
  HMatrixOptions options_;
  std::vector<Vec3> images_;
  std::vector<int> order_;  // cluster order -> cell
  std::vector<Cluster> clusters_;
  std::vector<DenseBlock> dense_;
  std::vector<LowRankBlock> low_rank_;
  Stored<double> double_;  // one of the two holds the numbers
  Stored<float> single_;
};

}  // namespace odemag
