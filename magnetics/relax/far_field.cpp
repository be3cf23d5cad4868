#include "magnetics/relax/far_field.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <numeric>

#include "odemag/constants.h"
#include "magnetics/kernels/pair_sums.h"

namespace odemag {

namespace {

// Cells per leaf: a leaf's near sums are SIMD runs of this length.
constexpr int kLeafCells = 16;

// Field at offset r from a group of dipoles with total moment mu and first
// moment Q (Q_ab = sum mu_a d_b, d the offsets from the group centre), to
// second order in |d| / |r|: the point dipole h(r, mu) minus
// sum_b d/dr_b h(r, Q_:b), i.e.
//   H = h(r, mu) - 3 / (4 pi r^5) [Q^T r + Q r + tr(Q) r - 5 (r^T Q r / r^2) r].
// gradient (symmetric, xx xy xz yy yz zz): dH_a/dr_b of h(r, mu) alone, which
// carries the field across a leaf to the same order.
void expansion_at(const Vec3& r, const Vec3& mu, const double* Q, Vec3& H, double* gradient) {
  const double k = 1.0 / (4.0 * kPi);
  const double r2 = dot(r, r), inv_r2 = 1.0 / r2, inv_r = std::sqrt(inv_r2);
  const double inv_r3 = inv_r * inv_r2, inv_r5 = inv_r3 * inv_r2;
  const double rm = dot(r, mu);
  H += (k * inv_r3) * ((3.0 * rm * inv_r2) * r - mu);
  const Vec3 Qr{Q[0] * r.x + Q[1] * r.y + Q[2] * r.z, Q[3] * r.x + Q[4] * r.y + Q[5] * r.z,
                Q[6] * r.x + Q[7] * r.y + Q[8] * r.z};
  const Vec3 QTr{Q[0] * r.x + Q[3] * r.y + Q[6] * r.z, Q[1] * r.x + Q[4] * r.y + Q[7] * r.z,
                 Q[2] * r.x + Q[5] * r.y + Q[8] * r.z};
  const double trace = Q[0] + Q[4] + Q[8], rQr = dot(r, Qr);
  H -= (3.0 * k * inv_r5) * (QTr + Qr + (trace - 5.0 * rQr * inv_r2) * r);
  // dh_a/dr_b = 3k/r^5 [delta_ab (r.mu) + r_a mu_b + mu_a r_b - 5 r_a r_b (r.mu) / r^2].
  const double c = 3.0 * k * inv_r5, radial = 5.0 * rm * inv_r2;
  const double v[3] = {r.x, r.y, r.z}, m[3] = {mu.x, mu.y, mu.z};
  int s = 0;
  for (int a = 0; a < 3; ++a)
    for (int b = a; b < 3; ++b, ++s)
      gradient[s] += c * ((a == b ? rm : 0.0) + v[a] * m[b] + m[a] * v[b] - radial * v[a] * v[b]);
}

}  // namespace

void FarFieldTree::build(const double* x, const double* y, const double* z, const double* radius,
                         const int* body, int n, double theta) {
  theta_ = theta;
  order_.resize(n);
  std::iota(order_.begin(), order_.end(), 0);
  x_.assign(x, x + n), y_.assign(y, y + n), z_.assign(z, z + n), radius_.assign(radius, radius + n);
  // Bodies with more than one cell get a bit each (modulo 64: a shared bit only
  // opens more nodes than needed).
  std::map<int, int> cells_of;
  for (int i = 0; i < n; ++i) ++cells_of[body[i]];
  std::map<int, int> slot;
  for (const auto& [b, count] : cells_of)
    if (count > 1) slot.emplace(b, static_cast<int>(slot.size()));
  std::vector<uint64_t> cell_mask(n, 0);
  for (int i = 0; i < n; ++i) {
    const auto it = slot.find(body[i]);
    if (it != slot.end()) cell_mask[i] = uint64_t{1} << (it->second % 64);
  }
  body_.assign(n, 0.0);
  for (int i = 0; i < n; ++i) body_[i] = body[i];  // input order until build_node permutes

  nodes_.clear();
  if (n > 0) build_node(0, n, cell_mask);

  // Tree order.
  auto permute = [&](std::vector<double>& v) {
    std::vector<double> sorted(n);
    for (int k = 0; k < n; ++k) sorted[k] = v[order_[k]];
    v.swap(sorted);
  };
  for (auto* v : {&x_, &y_, &z_, &radius_, &body_}) permute(*v);
  mx_.assign(n, 0.0), my_.assign(n, 0.0), mz_.assign(n, 0.0);
  node_moment_.assign(nodes_.size(), {});
  node_first_.assign(9 * nodes_.size(), 0.0);

  leaves_.clear();
  for (int i = 0; i < static_cast<int>(nodes_.size()); ++i)
    if (nodes_[i].child[0] < 0) leaves_.push_back({i, {}, {}});
  near_pairs_ = far_interactions_ = 0;
  for (LeafLists& leaf : leaves_) {
    collect(leaf);
    const long targets = nodes_[leaf.node].end - nodes_[leaf.node].begin;
    for (const auto& [b, e] : leaf.near) near_pairs_ += targets * (e - b);
    far_interactions_ += static_cast<long>(leaf.far.size());
  }
}

// Builds the node of tree positions [begin, end) (order_ indexes the input
// arrays, which stay in input order during the build) and returns its index.
// Splits at the median of the longest side of the bounding box.
int FarFieldTree::build_node(int begin, int end, const std::vector<uint64_t>& cell_mask) {
  const int index = static_cast<int>(nodes_.size());
  nodes_.emplace_back();
  Node node;
  node.begin = begin, node.end = end;
  Vec3 lo{1e300, 1e300, 1e300}, hi{-1e300, -1e300, -1e300};
  node.body = static_cast<int>(body_[order_[begin]]);
  for (int k = begin; k < end; ++k) {
    const int i = order_[k];
    lo = {std::min(lo.x, x_[i]), std::min(lo.y, y_[i]), std::min(lo.z, z_[i])};
    hi = {std::max(hi.x, x_[i]), std::max(hi.y, y_[i]), std::max(hi.z, z_[i])};
    node.max_contact = std::max(node.max_contact, radius_[i]);
    if (static_cast<int>(body_[i]) != node.body) node.body = -1;
    node.multi_cell_bodies |= cell_mask[i];
  }
  node.centre = 0.5 * (lo + hi);
  for (int k = begin; k < end; ++k) {
    const int i = order_[k];
    node.radius = std::max(node.radius, norm(Vec3{x_[i], y_[i], z_[i]} - node.centre));
  }
  if (end - begin > kLeafCells) {
    const Vec3 extent = hi - lo;
    const int axis = extent.x >= extent.y && extent.x >= extent.z ? 0 : (extent.y >= extent.z ? 1 : 2);
    const std::vector<double>& coordinate = axis == 0 ? x_ : (axis == 1 ? y_ : z_);
    const int mid = begin + (end - begin) / 2;
    // Ties broken by input index: the same cells always give the same tree.
    std::nth_element(order_.begin() + begin, order_.begin() + mid, order_.begin() + end, [&](int a, int b) {
      return coordinate[a] < coordinate[b] || (coordinate[a] == coordinate[b] && a < b);
    });
    node.child[0] = build_node(begin, mid, cell_mask);
    node.child[1] = build_node(mid, end, cell_mask);
  }
  nodes_[index] = node;
  return index;
}

// The far nodes and near cell ranges of one target leaf, by descent from the
// root.
void FarFieldTree::collect(LeafLists& leaf) const {
  const Node& T = nodes_[leaf.node];
  std::vector<int> stack{0};
  while (!stack.empty()) {
    const Node& S = nodes_[stack.back()];
    const int s = stack.back();
    stack.pop_back();
    if (T.body >= 0 && S.body == T.body) continue;  // one body: the intra-body tables
    const double d = norm(T.centre - S.centre), reach = T.radius + S.radius;
    const bool shares_body = (T.multi_cell_bodies & S.multi_cell_bodies) != 0;
    if (!shares_body && theta_ * d > reach && d > reach + T.max_contact + S.max_contact) {
      leaf.far.push_back(s);
    } else if (S.child[0] < 0) {
      if (!leaf.near.empty() && leaf.near.back().second == S.begin) {
        leaf.near.back().second = S.end;
      } else {
        leaf.near.push_back({S.begin, S.end});
      }
    } else {
      stack.push_back(S.child[1]);
      stack.push_back(S.child[0]);
    }
  }
}

void FarFieldTree::field(const double* mx, const double* my, const double* mz, Vec3* H, int threads) {
  const int n = size();
  for (int k = 0; k < n; ++k) mx_[k] = mx[order_[k]], my_[k] = my[order_[k]], mz_[k] = mz[order_[k]];
  // Node moments and first moments, children before parents (children have
  // larger indices).
  for (int s = static_cast<int>(nodes_.size()) - 1; s >= 0; --s) {
    const Node& S = nodes_[s];
    Vec3 mu;
    double* Q = &node_first_[9u * s];
    std::fill(Q, Q + 9, 0.0);
    if (S.child[0] < 0) {
      for (int k = S.begin; k < S.end; ++k) {
        const Vec3 m{mx_[k], my_[k], mz_[k]}, d = Vec3{x_[k], y_[k], z_[k]} - S.centre;
        mu += m;
        for (int a = 0; a < 3; ++a)
          for (int b = 0; b < 3; ++b) Q[3 * a + b] += m[a] * d[b];
      }
    } else {
      for (int c : S.child) {
        const Vec3& m = node_moment_[c];
        const Vec3 d = nodes_[c].centre - S.centre;
        mu += m;
        for (int a = 0; a < 9; ++a) Q[a] += node_first_[9u * c + a];
        for (int a = 0; a < 3; ++a)
          for (int b = 0; b < 3; ++b) Q[3 * a + b] += m[a] * d[b];
      }
    }
    node_moment_[s] = mu;
  }
  const int leaves = static_cast<int>(leaves_.size());
#pragma omp parallel num_threads(threads) if (near_pairs_ + 40 * far_interactions_ > 20000)
  {
    // The leaf's near cells gathered into one run: one SIMD sum per target
    // instead of one per range.
    std::vector<double> near[8];
#pragma omp for schedule(dynamic, 1)
    for (int l = 0; l < leaves; ++l) {
      const LeafLists& leaf = leaves_[l];
      const Node& T = nodes_[leaf.node];
      for (auto& v : near) v.clear();
      for (const auto& [b, e] : leaf.near)
        for (int j = b; j < e; ++j) {
          near[0].push_back(x_[j]), near[1].push_back(y_[j]), near[2].push_back(z_[j]);
          near[3].push_back(radius_[j]), near[4].push_back(mx_[j]), near[5].push_back(my_[j]);
          near[6].push_back(mz_[j]), near[7].push_back(body_[j]);
        }
      const SourceArrays sources{near[0].data(), near[1].data(), near[2].data(), near[3].data(),
                                 near[4].data(), near[5].data(), near[6].data(), near[7].data()};
      const int count = static_cast<int>(near[0].size());
      Vec3 Hc;
      double G[6] = {0, 0, 0, 0, 0, 0};
      for (int s : leaf.far) expansion_at(T.centre - nodes_[s].centre, node_moment_[s], &node_first_[9u * s], Hc, G);
      for (int k = T.begin; k < T.end; ++k) {
        const Vec3 d = Vec3{x_[k], y_[k], z_[k]} - T.centre;
        const Vec3 h = Hc + Vec3{G[0] * d.x + G[1] * d.y + G[2] * d.z, G[1] * d.x + G[3] * d.y + G[4] * d.z,
                                 G[2] * d.x + G[4] * d.y + G[5] * d.z};
        H[order_[k]] = h + sum_field<true>(sources, 0, count, x_[k], y_[k], z_[k], radius_[k], body_[k]);
      }
    }
  }
}

}  // namespace odemag
