// Hierarchical matrix by adaptive cross approximation (magnetics/static/hmatrix.h).
#include "magnetics/static/hmatrix.h"

#include <algorithm>
#include <cmath>
#include <numeric>

namespace odemag {

namespace {

// Distance between two axis-aligned boxes (0 when they overlap or touch).
double box_distance(const Vec3& lo_a, const Vec3& hi_a, const Vec3& lo_b, const Vec3& hi_b) {
  double d2 = 0.0;
  for (int k = 0; k < 3; ++k) {
    const double gap = std::max({0.0, lo_a[k] - hi_b[k], lo_b[k] - hi_a[k]});
    d2 += gap * gap;
  }
  return std::sqrt(d2);
}

double diameter(const Vec3& lo, const Vec3& hi) { return norm(hi - lo); }

}  // namespace

HMatrix::HMatrix(const std::vector<CellBox>& cells, const std::vector<Vec3>& images,
                 const std::function<double(int, int)>& entry, const HMatrixOptions& options)
    : options_(options), images_(images) {
  order_.resize(cells.size());
  std::iota(order_.begin(), order_.end(), 0);
  if (cells.empty()) return;
  split(0, static_cast<int>(cells.size()), cells);
  partition(0, 0, entry);
  for (const DenseBlock& d : dense_) {
    const Cluster& r = clusters_[d.rows];
    const Cluster& c = clusters_[d.cols];
    Eigen::MatrixXd a(3 * (r.end - r.begin), 3 * (c.end - c.begin));
    for (int i = 0; i < a.rows(); ++i)
      for (int j = 0; j < a.cols(); ++j)
        a(i, j) = entry(scalar_index(r, i), scalar_index(c, j));
    double_.dense.push_back(std::move(a));
  }
  // The chunks of multiply: blocks (dense first, then low-rank) in runs of
  // about equal stored numbers.
  const long total = stored();
  long sum = 0;
  int chunk = 1;
  const int blocks = static_cast<int>(dense_.size() + low_rank_.size());
  chunk_begin_.fill(blocks);
  chunk_begin_[0] = 0;
  for (int k = 0; k < blocks && chunk < kChunks; ++k) {
    const int d = static_cast<int>(dense_.size());
    sum += k < d ? static_cast<long>(double_.dense[k].size())
                 : static_cast<long>(double_.u[k - d].size() + double_.v[k - d].size());
    if (sum * kChunks >= chunk * total) chunk_begin_[chunk++] = k + 1;
  }
  if (options_.single_precision) {
    auto to_single = [](std::vector<Eigen::MatrixXd>& from, std::vector<Eigen::MatrixXf>& to) {
      for (const Eigen::MatrixXd& m : from) to.push_back(m.cast<float>());
      from = {};
    };
    to_single(double_.dense, single_.dense);
    to_single(double_.u, single_.u);
    to_single(double_.v, single_.v);
  }
}

int HMatrix::split(int begin, int end, const std::vector<CellBox>& cells) {
  Cluster c{begin, end, cells[order_[begin]].centre, cells[order_[begin]].centre};
  Vec3 centre_lo = c.lo, centre_hi = c.hi;
  for (int k = begin; k < end; ++k) {
    const CellBox& b = cells[order_[k]];
    for (int a = 0; a < 3; ++a) {
      c.lo[a] = std::min(c.lo[a], b.centre[a] - b.half[a]);
      c.hi[a] = std::max(c.hi[a], b.centre[a] + b.half[a]);
      centre_lo[a] = std::min(centre_lo[a], b.centre[a]);
      centre_hi[a] = std::max(centre_hi[a], b.centre[a]);
    }
  }
  const int index = static_cast<int>(clusters_.size());
  clusters_.push_back(c);
  if (end - begin <= options_.leaf_cells) return index;
  // Bisect at the median along the axis the centres spread most.
  const Vec3 spread = centre_hi - centre_lo;
  const int axis = spread.x >= spread.y && spread.x >= spread.z ? 0 : (spread.y >= spread.z ? 1 : 2);
  if (spread[axis] == 0.0) return index;
  const int middle = begin + (end - begin) / 2;
  std::nth_element(order_.begin() + begin, order_.begin() + middle, order_.begin() + end, [&](int i, int j) {
    return cells[i].centre[axis] < cells[j].centre[axis] || (cells[i].centre[axis] == cells[j].centre[axis] && i < j);
  });
  const int first = split(begin, middle, cells);
  const int second = split(middle, end, cells);
  clusters_[index].first = first;
  clusters_[index].second = second;
  return index;
}

bool HMatrix::far_apart(const Cluster& a, const Cluster& b) const {
  const double size = std::max(diameter(a.lo, a.hi), diameter(b.lo, b.hi));
  for (const Vec3& s : images_) {
    // The image of b's box: reflected corners, reordered.
    Vec3 lo, hi;
    for (int k = 0; k < 3; ++k) {
      lo[k] = std::min(s[k] * b.lo[k], s[k] * b.hi[k]);
      hi[k] = std::max(s[k] * b.lo[k], s[k] * b.hi[k]);
    }
    if (size > options_.eta * box_distance(a.lo, a.hi, lo, hi)) return false;
  }
  return true;
}

// The blocks of rows a, columns b with a's cells after b's or a == b (the
// lower triangle in cluster order).
void HMatrix::partition(int a, int b, const std::function<double(int, int)>& entry) {
  const Cluster& ca = clusters_[a];
  const Cluster& cb = clusters_[b];
  const bool leaf_a = ca.first < 0, leaf_b = cb.first < 0;
  if (a == b) {
    if (leaf_a) {
      dense_.push_back({a, b});
    } else {
      partition(ca.first, ca.first, entry);
      partition(ca.second, ca.first, entry);
      partition(ca.second, ca.second, entry);
    }
  } else if (far_apart(ca, cb)) {
    Eigen::MatrixXd u, v;
    if (cross_approximation(ca, cb, entry, u, v)) {
      low_rank_.push_back({a, b});
      double_.u.push_back(std::move(u));
      double_.v.push_back(std::move(v));
    } else {
      dense_.push_back({a, b});
    }
  } else if (leaf_a && leaf_b) {
    dense_.push_back({a, b});
  } else if (leaf_b || (!leaf_a && ca.end - ca.begin >= cb.end - cb.begin)) {
    const int first = ca.first, second = ca.second;
    partition(first, b, entry);
    partition(second, b, entry);
  } else {
    const int first = cb.first, second = cb.second;
    partition(a, first, entry);
    partition(a, second, entry);
  }
}

bool HMatrix::cross_approximation(const Cluster& a, const Cluster& b, const std::function<double(int, int)>& entry,
                                  Eigen::MatrixXd& u, Eigen::MatrixXd& v) const {
  const int m = 3 * (a.end - a.begin), n = 3 * (b.end - b.begin);
  const int max_rank = m * n / (m + n);  // past it the factors outweigh the block
  std::vector<Eigen::VectorXd> us, vs;
  std::vector<bool> row_used(m, false);
  double approximation2 = 0.0;  // |U V^T|_F^2
  int pivot_row = 0;
  for (int attempts = 0; attempts < m && static_cast<int>(us.size()) < max_rank; ++attempts) {
    row_used[pivot_row] = true;
    Eigen::VectorXd row(n);
    for (int j = 0; j < n; ++j) row(j) = entry(scalar_index(a, pivot_row), scalar_index(b, j));
    for (size_t k = 0; k < us.size(); ++k) row -= us[k](pivot_row) * vs[k];
    Eigen::Index pivot_col;
    const double largest = row.cwiseAbs().maxCoeff(&pivot_col);
    if (largest > 0.0) {
      const Eigen::VectorXd vk = row / row(pivot_col);
      Eigen::VectorXd uk(m);
      for (int i = 0; i < m; ++i) uk(i) = entry(scalar_index(a, i), scalar_index(b, static_cast<int>(pivot_col)));
      for (size_t k = 0; k < us.size(); ++k) uk -= vs[k](pivot_col) * us[k];
      // |S_k|^2 = |S_{k-1}|^2 + 2 sum_l (u_l . u)(v_l . v) + |u|^2 |v|^2
      double cross = 0.0;
      for (size_t k = 0; k < us.size(); ++k) cross += us[k].dot(uk) * vs[k].dot(vk);
      const double term2 = uk.squaredNorm() * vk.squaredNorm();
      approximation2 += 2.0 * cross + term2;
      us.push_back(uk);
      vs.push_back(vk);
      if (term2 <= options_.tolerance * options_.tolerance * approximation2) {
        u.resize(m, static_cast<Eigen::Index>(us.size()));
        v.resize(n, static_cast<Eigen::Index>(vs.size()));
        for (size_t k = 0; k < us.size(); ++k) {
          u.col(static_cast<Eigen::Index>(k)) = us[k];
          v.col(static_cast<Eigen::Index>(k)) = vs[k];
        }
        return static_cast<int>(us.size()) < max_rank;
      }
      // Next pivot row: the largest entry of the new column among unused rows.
      double best = -1.0;
      for (int i = 0; i < m; ++i)
        if (!row_used[i] && std::abs(uk(i)) > best) best = std::abs(uk(i)), pivot_row = i;
    } else {
      // A zero residual row: try the next unused one.
      pivot_row = -1;
      for (int i = 0; i < m; ++i)
        if (!row_used[i]) {
          pivot_row = i;
          break;
        }
    }
    if (pivot_row < 0) break;
  }
  if (us.empty() || approximation2 == 0.0) {  // the block is zero
    u.resize(m, 0);
    v.resize(n, 0);
    return true;
  }
  return false;
}

void HMatrix::multiply(const Eigen::VectorXd& x, Eigen::VectorXd& y) const {
  if (options_.single_precision)
    multiply_stored(single_, x, y);
  else
    multiply_stored(double_, x, y);
}

template <class Scalar>
void HMatrix::multiply_stored(const Stored<Scalar>& stored, const Eigen::VectorXd& x, Eigen::VectorXd& y) const {
  using Vector = Eigen::Matrix<Scalar, Eigen::Dynamic, 1>;
  const int N = static_cast<int>(order_.size());
  Vector xp(3 * N);
  for (int k = 0; k < N; ++k) xp.template segment<3>(3 * k) = x.segment<3>(3 * order_[k]).template cast<Scalar>();
  // The blocks in kChunks fixed shares of the stored numbers, each summed
  // into its own vector, the vectors added in order: the same result for any
  // number of threads.
  std::array<Vector, kChunks> part;
  const int dense_count = static_cast<int>(dense_.size());
#pragma omp parallel for schedule(static, 1)
  for (int c = 0; c < kChunks; ++c) {
    Vector& yp = part[c];
    yp.setZero(3 * N);
    Vector t;
    for (int k = chunk_begin_[c]; k < chunk_begin_[c + 1]; ++k) {
      if (k < dense_count) {
        const auto& a = stored.dense[k];
        const int r0 = 3 * clusters_[dense_[k].rows].begin, c0 = 3 * clusters_[dense_[k].cols].begin;
        yp.segment(r0, a.rows()).noalias() += a * xp.segment(c0, a.cols());
        if (dense_[k].rows != dense_[k].cols) yp.segment(c0, a.cols()).noalias() += a.transpose() * xp.segment(r0, a.rows());
      } else {
        const auto& u = stored.u[k - dense_count];
        const auto& v = stored.v[k - dense_count];
        const LowRankBlock& b = low_rank_[k - dense_count];
        const int r0 = 3 * clusters_[b.rows].begin, c0 = 3 * clusters_[b.cols].begin;
        t.noalias() = v.transpose() * xp.segment(c0, v.rows());
        yp.segment(r0, u.rows()).noalias() += u * t;
        t.noalias() = u.transpose() * xp.segment(r0, u.rows());
        yp.segment(c0, v.rows()).noalias() += v * t;
      }
    }
  }
  for (int c = 1; c < kChunks; ++c) part[0] += part[c];
  y.resize(3 * N);
  for (int k = 0; k < N; ++k) y.segment<3>(3 * order_[k]) = part[0].template segment<3>(3 * k).template cast<double>();
}

long HMatrix::stored() const {
  long numbers = 0;
  auto count = [&](const auto& set) {
    for (const auto* list : {&set.dense, &set.u, &set.v})
      for (const auto& m : *list) numbers += static_cast<long>(m.size());
  };
  count(double_);
  count(single_);
  return numbers;
}

}  // namespace odemag
