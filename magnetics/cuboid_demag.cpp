// Dense cuboid-cell demagnetizing field with mirror planes (magnetics/cuboid_demag.h).
#include "magnetics/cuboid_demag.h"

#include <stdexcept>

#include "magnetics/cell_field.h"
#include "magnetics/constants.h"
#include "magnetics/demag_tensor.h"
#include "magnetics/eigen_tensors.h"

namespace odemag {

namespace {

Vec3 reflect(const Vec3& s, const Vec3& v) { return {s.x * v.x, s.y * v.y, s.z * v.z}; }

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
  K_.resize(3 * N, 3 * N);
  // K_ij for j >= i from the tensors; K_ji = (V_i / V_j) K_ij^T (1).
#pragma omp parallel for schedule(dynamic, 4)
  for (int i = 0; i < N; ++i) {
    const double ha[3] = {cells_[i].half.x, cells_[i].half.y, cells_[i].half.z};
    for (int j = i; j < N; ++j) {
      const double hb[3] = {cells_[j].half.x, cells_[j].half.y, cells_[j].half.z};
      Eigen::Matrix3d k = Eigen::Matrix3d::Zero();
      for (const Vec3& s : images_) {
        const Vec3 d = cells_[i].centre - reflect(s, cells_[j].centre);
        const double dd[3] = {d.x, d.y, d.z};
        double n[6];
        cuboid_demag_tensor(ha, hb, dd, n);
        k += symmetric_matrix(n) * Eigen::Vector3d(s.x, s.y, s.z).asDiagonal();
      }
      K_.block<3, 3>(3 * i, 3 * j) = k;
      if (j != i) K_.block<3, 3>(3 * j, 3 * i) = (volume(i) / volume(j)) * k.transpose();
    }
  }
}

void CuboidDemag::field(const std::vector<Vec3>& M, std::vector<Vec3>& H) const {
  const int N = cells();
  H.resize(N);
  Eigen::Map<const Eigen::VectorXd> m(&M[0].x, 3 * N);
  Eigen::Map<Eigen::VectorXd> h(&H[0].x, 3 * N);
  h.noalias() = -K_ * m;
}

void CuboidDemag::self_block(int cell, double n[6]) const {
  const auto k = K_.block<3, 3>(3 * cell, 3 * cell);
  n[0] = k(0, 0), n[1] = k(0, 1), n[2] = k(0, 2), n[3] = k(1, 1), n[4] = k(1, 2), n[5] = k(2, 2);
}

Vec3 CuboidDemag::force(int t0, int t1, int s0, int s1, const std::vector<Vec3>& M) const {
  Vec3 F{};
  for (int i = t0; i < t1; ++i) {
    const double ha[3] = {cells_[i].half.x, cells_[i].half.y, cells_[i].half.z};
    Vec3 Fi{};
    for (int j = s0; j < s1; ++j) {
      const double hb[3] = {cells_[j].half.x, cells_[j].half.y, cells_[j].half.z};
      for (const Vec3& s : images_) {
        const Vec3 d = cells_[i].centre - reflect(s, cells_[j].centre);
        const double dd[3] = {d.x, d.y, d.z};
        double n[6], dn[3][6];
        cuboid_demag_tensor(ha, hb, dd, n, dn);
        const Vec3 Mj = reflect(s, M[j]);
        for (int k = 0; k < 3; ++k) Fi[k] -= dot(M[i], symmetric_times(dn[k], Mj));
      }
    }
    F += (kMu0 * volume(i)) * Fi;
  }
  Vec3 total{};
  for (const Vec3& s : images_) total += reflect(s, F);
  return total;
}

Vec3 CuboidDemag::field_at(const Vec3& point, const std::vector<Vec3>& M) const {
  Vec3 H{};
  for (int j = 0; j < cells(); ++j)
    for (const Vec3& s : images_) H += uniform_cuboid_field(point - reflect(s, cells_[j].centre), cells_[j].half, reflect(s, M[j]));
  return H;
}

}  // namespace odemag
