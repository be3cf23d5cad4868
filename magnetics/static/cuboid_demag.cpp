// Dense cuboid-cell demagnetizing field with mirror planes (magnetics/static/cuboid_demag.h).
#include "magnetics/static/cuboid_demag.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <map>
#include <stdexcept>
#include <unordered_map>

#include "magnetics/kernels/cell_field.h"
#include "odemag/constants.h"
#include "magnetics/cells/demag_tensor.h"
#include "magnetics/kernels/eigen_tensors.h"

namespace odemag {

namespace {

Vec3 reflect(const Vec3& s, const Vec3& v) { return {s.x * v.x, s.y * v.y, s.z * v.z}; }

// Repeated pairs. N_ij (1) and its gradient (2) depend only on the two
// cells' half edges and the offset c_i - P_s c_j, and on grids whose cells
// repeat sizes and spacings most pairs repeat another's (on a uniform grid
// every pair at one lattice offset). Per axis each cell is one of a few
// columns (its centre and half edge); a pair's column pair and image sign
// along the axis give its half edges and offset there, numbered once per
// distinct triple, and the three numbers are the pair's key. The tensors are
// evaluated once per key, at its first pair. Values equal to within
// kSameValue of the smallest half edge count as equal (cell centres of one
// lattice offset differ by rounding), which moves a tensor by about that
// share of itself at most.
constexpr double kSameValue = 1e-9;
constexpr int kAxisBits = 21;      // per axis, at most 2^21 distinct triples
constexpr int kMaxColumns = 1024;  // per axis; more: no table (cells that share few planes)

class PairKeys {
 public:
  PairKeys(const std::vector<CuboidCell>& cells, const std::vector<Vec3>& images)
      : images_(static_cast<int>(images.size())) {
    double smallest = std::numeric_limits<double>::infinity();
    for (const CuboidCell& c : cells) smallest = std::min({smallest, c.half.x, c.half.y, c.half.z});
    const double q = kSameValue * smallest;
    auto quantum = [q](double v) { return std::llround(v / q); };
    for (int a = 0; a < 3; ++a) {
      std::map<std::pair<long long, long long>, int> columns;
      std::vector<std::pair<double, double>> column_values;  // centre, half
      column_[a].resize(cells.size());
      for (size_t i = 0; i < cells.size(); ++i) {
        const double centre = cells[i].centre[a], half = cells[i].half[a];
        const auto inserted =
            columns.emplace(std::make_pair(quantum(centre), quantum(half)), static_cast<int>(columns.size()));
        if (inserted.second) column_values.emplace_back(centre, half);
        column_[a][i] = inserted.first->second;
      }
      const int n = static_cast<int>(column_values.size());
      columns_[a] = n;
      if (n > kMaxColumns) {
        usable_ = false;
        return;
      }
      std::map<std::array<long long, 3>, int> triples;
      triple_[a].resize(static_cast<size_t>(n) * n * images_);
      for (int ca = 0; ca < n; ++ca)
        for (int cb = 0; cb < n; ++cb)
          for (int s = 0; s < images_; ++s) {
            const double d = column_values[ca].first - images[s][a] * column_values[cb].first;
            const std::array<long long, 3> t{quantum(column_values[ca].second),
                                             quantum(column_values[cb].second), quantum(d)};
            triple_[a][(static_cast<size_t>(ca) * n + cb) * images_ + s] =
                triples.emplace(t, static_cast<int>(triples.size())).first->second;
          }
      if (triples.size() >= (1u << kAxisBits)) usable_ = false;
    }
  }
  // false: too many columns or distinct triples along an axis for the table.
  bool usable() const { return usable_; }
  uint64_t key(int i, int j, int s) const {
    uint64_t k = 0;
    for (int a = 0; a < 3; ++a) {
      const size_t slot = (static_cast<size_t>(column_[a][i]) * columns_[a] + column_[a][j]) * images_ + s;
      k = (k << kAxisBits) | static_cast<uint64_t>(triple_[a][slot]);
    }
    return k;
  }

 private:
  int images_;
  bool usable_ = true;
  std::array<std::vector<int>, 3> column_;  // per axis, per cell
  std::array<int, 3> columns_{0, 0, 0};
  std::array<std::vector<int>, 3> triple_;  // per axis: (column a, column b, image) -> triple
};

// The pairs (i, j) with i in [i0, i1) and j in [j0, j1), only those with
// j >= i where `from_i`, each with every image.
struct PairRange {
  int i0, i1, j0, j1;
  bool from_i;
  int first_j(int i) const { return from_i ? std::max(i, j0) : j0; }
};

// The distinct pairs (i, j, image) of a range, numbered in the order first
// met, with one representative each. Given up (valid false, nothing kept)
// once more than half of the range's pairs are distinct: evaluating every
// pair then costs less than the table (the 5 mm TEAM 20 grid's force:
// 152,400 distinct of 158,400).
struct DistinctPairs {
  bool valid = false;
  std::unordered_map<uint64_t, int> index;
  std::vector<std::array<int, 3>> first;  // i, j, image
};

DistinctPairs distinct_pairs(const PairKeys& keys, const PairRange& r, int image_count) {
  long total = 0;
  for (int i = r.i0; i < r.i1; ++i) total += std::max(0, r.j1 - r.first_j(i));
  const size_t limit = static_cast<size_t>(total * image_count / 2);
  DistinctPairs d;
  if (!keys.usable()) return d;
  for (int i = r.i0; i < r.i1; ++i)
    for (int j = r.first_j(i); j < r.j1; ++j)
      for (int s = 0; s < image_count; ++s) {
        const int next = static_cast<int>(d.first.size());
        if (d.index.emplace(keys.key(i, j, s), next).second) d.first.push_back({i, j, s});
        if (d.first.size() > limit) return {};
      }
  d.valid = true;
  return d;
}

}  // namespace

std::vector<CuboidCell> grid_cells(const std::vector<double>& fx, const std::vector<double>& fy,
                                   const std::vector<double>& fz) {
  std::vector<CuboidCell> cells;
  for (size_t k = 0; k + 1 < fz.size(); ++k)
    for (size_t j = 0; j + 1 < fy.size(); ++j)
      for (size_t i = 0; i + 1 < fx.size(); ++i)
        cells.push_back({{0.5 * (fx[i] + fx[i + 1]), 0.5 * (fy[j] + fy[j + 1]), 0.5 * (fz[k] + fz[k + 1])},
                         {0.5 * (fx[i + 1] - fx[i]), 0.5 * (fy[j + 1] - fy[j]), 0.5 * (fz[k + 1] - fz[k])}});
  return cells;
}

CuboidDemag::CuboidDemag(std::vector<CuboidCell> cell_list, bool mirror_x, bool mirror_y) : cells_(std::move(cell_list)) {
  images_.push_back({1.0, 1.0, 1.0});
  if (mirror_x) images_.push_back({-1.0, 1.0, 1.0});
  if (mirror_y) images_.push_back({1.0, -1.0, 1.0});
  if (mirror_x && mirror_y) images_.push_back({-1.0, -1.0, 1.0});
  for (const CuboidCell& c : cells_) {
    if (!(c.half.x > 0.0 && c.half.y > 0.0 && c.half.z > 0.0))
      throw std::invalid_argument("CuboidDemag: a cell's half edges must be positive");
    const double tolerance = 1e-12 * (c.half.x + c.half.y + c.half.z);
    if ((mirror_x && c.centre.x - c.half.x < -tolerance) || (mirror_y && c.centre.y - c.half.y < -tolerance))
      throw std::invalid_argument("CuboidDemag: a cell crosses a mirror plane");
  }
  const int N = cells();
  const int image_count = static_cast<int>(images_.size());
  // The distinct pairs of j >= i (repeated pairs, above), their tensors once each.
  const PairKeys keys(cells_, images_);
  const DistinctPairs distinct = distinct_pairs(keys, {0, N, 0, N, true}, image_count);
  std::vector<std::array<double, 6>> tensor(distinct.first.size());
#pragma omp parallel for schedule(dynamic, 64)
  for (long p = 0; p < static_cast<long>(tensor.size()); ++p) {
    const auto [i, j, s] = distinct.first[p];
    pair_tensor(i, j, s, tensor[p].data());
  }
  S_.resize(3 * N, 3 * N);
  // K_ij for j >= i from the tensors; K_ji = (V_i / V_j) K_ij^T (1).
#pragma omp parallel for schedule(dynamic, 4)
  for (int i = 0; i < N; ++i) {
    for (int j = i; j < N; ++j) {
      Eigen::Matrix3d k = Eigen::Matrix3d::Zero();
      for (int s = 0; s < image_count; ++s) {
        double own[6];
        const double* n = own;
        if (distinct.valid)
          n = tensor[distinct.index.at(keys.key(i, j, s))].data();
        else
          pair_tensor(i, j, s, own);
        k += symmetric_matrix(n) * Eigen::Vector3d(images_[s].x, images_[s].y, images_[s].z).asDiagonal();
      }
      // S = V K is symmetric (S_ji = V_j K_ji = V_i K_ij^T): its lower triangle.
      S_.block<3, 3>(3 * j, 3 * i) = volume(i) * k.transpose();
    }
  }
}

void CuboidDemag::pair_tensor(int i, int j, int s, double n[6], double (*dn)[6]) const {
  const double ha[3] = {cells_[i].half.x, cells_[i].half.y, cells_[i].half.z};
  const double hb[3] = {cells_[j].half.x, cells_[j].half.y, cells_[j].half.z};
  const Vec3 d = cells_[i].centre - reflect(images_[s], cells_[j].centre);
  const double dd[3] = {d.x, d.y, d.z};
  cuboid_demag_tensor(ha, hb, dd, n, dn);
}

void CuboidDemag::field(const std::vector<Vec3>& M, std::vector<Vec3>& H) const {
  const int N = cells();
  H.resize(N);
  Eigen::Map<const Eigen::VectorXd> m(&M[0].x, 3 * N);
  Eigen::Map<Eigen::VectorXd> h(&H[0].x, 3 * N);
  // H = -K M = -V^-1 S M, S read from its lower triangle (half the bytes of K).
  if (compressed_) {
    Eigen::VectorXd y;
    compressed_->multiply(m, y);
    h = y;
  } else {
    h.noalias() = S_.selfadjointView<Eigen::Lower>() * m;
  }
  for (int i = 0; i < N; ++i) H[i] = (-1.0 / volume(i)) * H[i];
}

void CuboidDemag::compress(const HMatrixOptions& options) {
  if (compressed_) return;
  const int N = cells();
  std::vector<HMatrix::CellBox> boxes(N);
  self_.resize(N);
  for (int i = 0; i < N; ++i) {
    boxes[i] = {cells_[i].centre, cells_[i].half};
    self_[i] = S_.block<3, 3>(3 * i, 3 * i) / volume(i);
  }
  compressed_ = std::make_shared<const HMatrix>(
      boxes, images_, [this](int r, int c) { return r >= c ? S_(r, c) : S_(c, r); }, options);
  S_ = Eigen::MatrixXd();
}

void CuboidDemag::self_block(int cell, double n[6]) const {
  const Eigen::Matrix3d k = compressed_ ? self_[cell] : Eigen::Matrix3d(S_.block<3, 3>(3 * cell, 3 * cell) / volume(cell));
  n[0] = k(0, 0), n[1] = k(1, 0), n[2] = k(2, 0), n[3] = k(1, 1), n[4] = k(2, 1), n[5] = k(2, 2);
}

Vec3 CuboidDemag::force(int t0, int t1, int s0, int s1, const std::vector<Vec3>& M) const {
  return force_operator(t0, t1, s0, s1)(M);
}

CuboidDemag::ForceOperator CuboidDemag::force_operator(int t0, int t1, int s0, int s1) const {
  const int image_count = static_cast<int>(images_.size());
  ForceOperator op;
  op.t0_ = t0;
  op.s0_ = s0;
  for (const Vec3& s : images_) op.image_sum_ += s;
  for (int k = 0; k < 3; ++k)
    if (op.image_sum_[k] != 0.0) op.G_[k] = Eigen::MatrixXd::Zero(3 * (t1 - t0), 3 * (s1 - s0));
  const PairKeys keys(cells_, images_);
  const DistinctPairs distinct = distinct_pairs(keys, {t0, t1, s0, s1, false}, image_count);
  std::vector<std::array<double, 18>> gradient(distinct.first.size());
#pragma omp parallel for schedule(dynamic, 64)
  for (long p = 0; p < static_cast<long>(gradient.size()); ++p) {
    const auto [i, j, s] = distinct.first[p];
    double n[6];
    pair_tensor(i, j, s, n, reinterpret_cast<double(*)[6]>(gradient[p].data()));
  }
#pragma omp parallel for schedule(dynamic, 4)
  for (int i = t0; i < t1; ++i) {
    for (int j = s0; j < s1; ++j) {
      for (int s = 0; s < image_count; ++s) {
        double n[6], own[3][6];
        const double(*dn)[6] = own;
        if (distinct.valid)
          dn = reinterpret_cast<const double(*)[6]>(gradient[distinct.index.at(keys.key(i, j, s))].data());
        else
          pair_tensor(i, j, s, n, own);
        const Eigen::Vector3d reflection(images_[s].x, images_[s].y, images_[s].z);
        for (int k = 0; k < 3; ++k)
          if (op.G_[k].size() > 0)
            op.G_[k].block<3, 3>(3 * (i - t0), 3 * (j - s0)) -=
                (kMu0 * volume(i)) * symmetric_matrix(dn[k]) * reflection.asDiagonal();
      }
    }
  }
  return op;
}

Vec3 CuboidDemag::ForceOperator::operator()(const std::vector<Vec3>& M) const {
  Vec3 F{};
  for (int k = 0; k < 3; ++k) {
    if (G_[k].size() == 0) continue;
    const Eigen::Map<const Eigen::VectorXd> target(&M[t0_].x, G_[k].rows());
    const Eigen::Map<const Eigen::VectorXd> source(&M[s0_].x, G_[k].cols());
    F[k] = image_sum_[k] * target.dot(G_[k] * source);  // (2), summed over the images' reflections
  }
  return F;
}

Vec3 CuboidDemag::field_at(const Vec3& point, const std::vector<Vec3>& M) const {
  Vec3 H{};
  for (int j = 0; j < cells(); ++j)
    for (const Vec3& s : images_) H += uniform_cuboid_field(point - reflect(s, cells_[j].centre), cells_[j].half, reflect(s, M[j]));
  return H;
}

}  // namespace odemag
