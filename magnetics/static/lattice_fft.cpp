// FFT convolution of the cell-averaged demagnetizing tensor on lattices
// (magnetics/static/lattice_fft.h, docs/model.md "FFT convolution on lattices").
#include "magnetics/static/lattice_fft.h"

#include <unsupported/Eigen/FFT>

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "odemag/constants.h"
#include "magnetics/cells/demag_tensor.h"
#include "magnetics/kernels/kernels.h"

namespace odemag {

namespace {

using Complex = std::complex<double>;

// Smallest even 2-3-5-smooth integer >= n (kissfft's fast radices).
int padded_size(int n) {
  for (int m = std::max(2, n + (n & 1));; m += 2) {
    int r = m;
    for (int p : {2, 3, 5})
      while (r % p == 0) r /= p;
    if (r == 1) return m;
  }
}

// The ten components of the fully symmetric dN_ij / dd_k, as (i, j, k) with i <= j <= k.
constexpr int kGradientIndex[10][3] = {{0, 0, 0}, {0, 0, 1}, {0, 0, 2}, {0, 1, 1}, {0, 1, 2},
                                       {0, 2, 2}, {1, 1, 1}, {1, 1, 2}, {1, 2, 2}, {2, 2, 2}};
// Six-component index of the symmetric pair (i, j).
constexpr int kPair[3][3] = {{0, 1, 2}, {1, 3, 4}, {2, 4, 5}};
// Ten-component index of the symmetric triple (i, j, k).
int triple(int i, int j, int k) {
  int a[3] = {i, j, k};
  std::sort(a, a + 3);
  for (int c = 0; c < 10; ++c)
    if (kGradientIndex[c][0] == a[0] && kGradientIndex[c][1] == a[1] && kGradientIndex[c][2] == a[2]) return c;
  return -1;
}

// a0 b0 + a1 b1 + a2 b2 in plain real arithmetic (std::complex's operator*
// checks for infinities through a library call).
Complex multiply_add3(const Complex& a0, const Complex& b0, const Complex& a1, const Complex& b1, const Complex& a2,
                      const Complex& b2) {
  return {a0.real() * b0.real() - a0.imag() * b0.imag() + a1.real() * b1.real() - a1.imag() * b1.imag() +
              a2.real() * b2.real() - a2.imag() * b2.imag(),
          a0.real() * b0.imag() + a0.imag() * b0.real() + a1.real() * b1.imag() + a1.imag() * b1.real() +
              a2.real() * b2.imag() + a2.imag() * b2.real()};
}

// Transforms `count` complex lines of `length` points in place, line l at
// data[base(l) + stride e]; an orphaned work-shared loop of the caller's
// parallel region (a, b: the thread's scratch lines).
template <class Base>
void transform_lines(Eigen::FFT<double>& fft, bool inverse, std::vector<Complex>& data, int count, Base base,
                     size_t stride, int length, std::vector<Complex>& a, std::vector<Complex>& b) {
#pragma omp for
  for (int l = 0; l < count; ++l) {
    const size_t o = base(l);
    for (int e = 0; e < length; ++e) a[e] = data[o + stride * e];
    if (inverse)
      fft.inv(b.data(), a.data(), length);
    else
      fft.fwd(b.data(), a.data(), length);
    for (int e = 0; e < length; ++e) data[o + stride * e] = b[e];
  }
}

// The pair tensor at real offset d (target centre - source centre) of cells
// of half extents ht (target) and hs (source): N (six components) and, when g
// is not null, its gradient g[k][c] = dN_c / dd_k.
void pair_tensor(const Vec3& ht, const Vec3& hs, const Vec3& d, double n[6], double (*g)[6]) {
  const double dd[3] = {d.x, d.y, d.z};
  const double a[3] = {ht.x, ht.y, ht.z}, b[3] = {hs.x, hs.y, hs.z};
  if (g && ht.x == hs.x && ht.y == hs.y && ht.z == hs.z && ht.x == ht.y && ht.y == ht.z) {
    cube_demag_tensor_at(dd, 2.0 * ht.x, n, g);  // equal cubes
    return;
  }
  cuboid_demag_tensor(a, b, dd, n, g);
}

}  // namespace

LatticeDemag::LatticeDemag(const Vec3& cell, std::vector<LatticeGrid> lattices,
                           const std::vector<std::array<int, 2>>& force_pairs)
    : cell_(cell), lattices_(std::move(lattices)), force_pairs_(force_pairs) {
  if (!(cell.x > 0.0 && cell.y > 0.0 && cell.z > 0.0)) throw std::invalid_argument("LatticeDemag: cell size must be positive");
  const int L = static_cast<int>(lattices_.size());
  std::array<int, 3> largest{1, 1, 1};
  first_.push_back(0);
  for (int l = 0; l < L; ++l) {
    const auto& g = lattices_[l];
    if (g.mask.size() != static_cast<size_t>(g.n[0]) * g.n[1] * g.n[2])
      throw std::invalid_argument("LatticeDemag: mask size differs from the lattice's cell count");
    const Vec3 e = g.extent.x == 0.0 && g.extent.y == 0.0 && g.extent.z == 0.0 ? cell_ : g.extent;
    for (int a = 0; a < 3; ++a)
      if (!(e[a] > 0.0) || (g.n[a] > 1 && e[a] > cell_[a]))
        throw std::invalid_argument("LatticeDemag: a cell's extent must be positive and, along an axis with more than one cell, at most the spacing");
    half_.push_back(0.5 * e);
    volume_.push_back(e.x * e.y * e.z);
    self_of_.emplace_back();
    pair_tensor(half_.back(), half_.back(), Vec3{}, self_of_.back().data(), nullptr);
    for (int k = 0; k < g.n[2]; ++k)
      for (int j = 0; j < g.n[1]; ++j)
        for (int i = 0; i < g.n[0]; ++i)
          if (g.mask[i + g.n[0] * (j + g.n[1] * k)]) cell_index_.push_back({l, i, j, k});
    first_.push_back(static_cast<int>(cell_index_.size()));
    for (int a = 0; a < 3; ++a) largest[a] = std::max(largest[a], g.n[a]);
  }
  for (int a = 0; a < 3; ++a) pad_[a] = padded_size(2 * largest[a] - 1);  // no wrap-around: P >= n_t + n_s - 1
  half_x_ = pad_[0] / 2 + 1;
  const Vec3 zero{0.0, 0.0, 0.0};
  pair_tensor(0.5 * cell_, 0.5 * cell_, zero, self_.data(), nullptr);

  // Kernel grids: entry d mod P holds the tensor at offset (origin_t - origin_s) + d h,
  // d_a from -(n_s - 1) to n_t - 1.
  const size_t P = static_cast<size_t>(pad_[0]) * pad_[1] * pad_[2];
  auto fill = [&](int t, int s, bool gradient, int components, std::vector<std::vector<double>>& grids) {
    grids.assign(components, std::vector<double>(P, 0.0));
    const auto &nt = lattices_[t].n, &ns = lattices_[s].n;
    const int lo[3] = {-(ns[0] - 1), -(ns[1] - 1), -(ns[2] - 1)};
    const int span[3] = {nt[0] + ns[0] - 1, nt[1] + ns[1] - 1, nt[2] + ns[2] - 1};
    const long total = static_cast<long>(span[0]) * span[1] * span[2];
#pragma omp parallel for schedule(dynamic, 256)
    for (long e = 0; e < total; ++e) {
      const std::array<int, 3> d{lo[0] + static_cast<int>(e % span[0]), lo[1] + static_cast<int>((e / span[0]) % span[1]),
                                 lo[2] + static_cast<int>(e / (static_cast<long>(span[0]) * span[1]))};
      const size_t at = static_cast<size_t>((d[0] + pad_[0]) % pad_[0]) +
                        pad_[0] * (static_cast<size_t>((d[1] + pad_[1]) % pad_[1]) +
                                   pad_[1] * static_cast<size_t>((d[2] + pad_[2]) % pad_[2]));
      double n[6], g[3][6];
      pair_tensor(half_[t], half_[s], offset(t, s, d), n, gradient ? g : nullptr);
      if (!gradient) {
        for (int c = 0; c < 6; ++c) grids[c][at] = n[c];
      } else {
        for (int c = 0; c < 10; ++c)
          grids[c][at] = g[kGradientIndex[c][2]][kPair[kGradientIndex[c][0]][kGradientIndex[c][1]]];
      }
    }
  };
  const std::array<int, 3> full = pad_;
  // Pairs t <= s only: the kernel of (s, t) is that of (t, s) at -d times
  // V_t / V_s (N_st(-d) = N_ts(d) V_t / V_s, N even in d), whose spectrum is
  // the complex conjugate.
  kernel_.resize(static_cast<size_t>(L) * L);
  std::vector<std::vector<double>> grids;
  for (int t = 0; t < L; ++t)
    for (int s = t; s < L; ++s) {
      fill(t, s, false, 6, grids);
      for (int c = 0; c < 6; ++c) forward(grids[c], full, kernel_[t * L + s][c]);
    }
  gradient_.resize(force_pairs_.size());
  for (size_t p = 0; p < force_pairs_.size(); ++p) {
    const int t = force_pairs_[p][0], s = force_pairs_[p][1];
    if (t < 0 || s < 0 || t >= L || s >= L) throw std::invalid_argument("LatticeDemag: force pair out of range");
    fill(t, s, true, 10, grids);
    for (int c = 0; c < 10; ++c) forward(grids[c], full, gradient_[p][c]);
  }
}

Vec3 LatticeDemag::offset(int target, int source, const std::array<int, 3>& d) const {
  const Vec3 o = lattices_[target].origin - lattices_[source].origin;
  return {o.x + d[0] * cell_.x, o.y + d[1] * cell_.y, o.z + d[2] * cell_.z};
}

int LatticeDemag::lattice_of(int cell) const { return cell_index_[cell][0]; }

Vec3 LatticeDemag::centre(int cell) const {
  const auto& c = cell_index_[cell];
  const Vec3& o = lattices_[c[0]].origin;
  return {o.x + c[1] * cell_.x, o.y + c[2] * cell_.y, o.z + c[3] * cell_.z};
}

// Real-to-complex along x, then complex along y and z, each only over the
// lines that can hold data: the input is zero outside [0, used).
void LatticeDemag::forward(const std::vector<double>& in, const std::array<int, 3>& used, Spectrum& out) const {
  const int px = pad_[0], py = pad_[1], pz = pad_[2], hx = half_x_;
  out.assign(static_cast<size_t>(hx) * py * pz, Complex(0.0, 0.0));
#pragma omp parallel if (parallel())
  {
    Eigen::FFT<double> fft;
    fft.SetFlag(Eigen::FFT<double>::HalfSpectrum);
    std::vector<Complex> a(std::max(py, pz)), b(std::max({py, pz, hx}));
#pragma omp for
    for (int yz = 0; yz < used[1] * used[2]; ++yz) {
      const int y = yz % used[1], z = yz / used[1];
      fft.fwd(b.data(), &in[static_cast<size_t>(px) * (y + py * z)], px);
      std::copy(b.begin(), b.begin() + hx, out.begin() + static_cast<size_t>(hx) * (y + py * z));
    }
    const size_t row = hx, plane = static_cast<size_t>(hx) * py;
    transform_lines(fft, false, out, hx * used[2], [&](int l) { return l % hx + plane * (l / hx); }, row, py, a, b);
    transform_lines(fft, false, out, hx * py, [](int l) { return static_cast<size_t>(l); }, plane, pz, a, b);
  }
}

// The inverse, computing only the lines that reach the output [0, used).
// Consumes `in`.
void LatticeDemag::inverse(Spectrum& in, const std::array<int, 3>& used, std::vector<double>& out) const {
  const int px = pad_[0], py = pad_[1], pz = pad_[2], hx = half_x_;
  out.assign(static_cast<size_t>(px) * py * pz, 0.0);
#pragma omp parallel if (parallel())
  {
    Eigen::FFT<double> fft;
    fft.SetFlag(Eigen::FFT<double>::HalfSpectrum);
    std::vector<Complex> a(std::max(py, pz)), b(std::max(py, pz));
    const size_t row = hx, plane = static_cast<size_t>(hx) * py;
    transform_lines(fft, true, in, hx * py, [](int l) { return static_cast<size_t>(l); }, plane, pz, a, b);
    transform_lines(fft, true, in, hx * used[2], [&](int l) { return l % hx + plane * (l / hx); }, row, py, a, b);
#pragma omp for
    for (int yz = 0; yz < used[1] * used[2]; ++yz) {
      const int y = yz % used[1], z = yz / used[1];
      fft.inv(&out[static_cast<size_t>(px) * (y + py * z)], &in[static_cast<size_t>(hx) * (y + py * z)], px);
    }
  }
}

// One component of a lattice's M on the padded grid (zero elsewhere).
void LatticeDemag::scatter(int lattice, const std::vector<Vec3>& M, int component, std::vector<double>& grid) const {
  grid.assign(static_cast<size_t>(pad_[0]) * pad_[1] * pad_[2], 0.0);
  for (int c = first_[lattice]; c < first_[lattice + 1]; ++c) {
    const auto& ix = cell_index_[c];
    grid[ix[1] + static_cast<size_t>(pad_[0]) * (ix[2] + static_cast<size_t>(pad_[1]) * ix[3])] = M[c][component];
  }
}

void LatticeDemag::source_spectra(const std::vector<Vec3>& M, std::vector<std::array<Spectrum, 3>>& out) const {
  const int L = lattice_count();
  out.resize(L);
  std::vector<double> grid;
  for (int s = 0; s < L; ++s)
    for (int b = 0; b < 3; ++b) {
      scatter(s, M, b, grid);
      forward(grid, lattices_[s].n, out[s][b]);
    }
}

void LatticeDemag::field(const std::vector<Vec3>& M, std::vector<Vec3>& H) const {
  const int L = lattice_count();
  std::vector<std::array<Spectrum, 3>> m;
  source_spectra(M, m);
  H.assign(cells(), Vec3{});
  const size_t S = static_cast<size_t>(half_x_) * pad_[1] * pad_[2];
  std::vector<double> grid;
  std::array<Spectrum, 3> h;
  for (int t = 0; t < L; ++t) {
    // (1): H_k = -sum_s sum_b N_kb^(ts) * M_b^(s), summed in the frequency domain.
    for (auto& c : h) c.assign(S, Complex(0.0, 0.0));
    for (int s = 0; s < L; ++s) {
      const bool mirrored = s < t;
      const auto& K = kernel_[mirrored ? s * L + t : t * L + s];
      const auto &m0 = m[s][0], &m1 = m[s][1], &m2 = m[s][2];
      const double ratio = volume_[s] / volume_[t];  // reciprocity V_t N_ts = V_s N_st
      const bool scaled = mirrored && ratio != 1.0;
#pragma omp parallel for if (parallel())
      for (long q = 0; q < static_cast<long>(S); ++q) {
        Complex n[6];
        for (int c = 0; c < 6; ++c) n[c] = mirrored ? std::conj(K[c][q]) : K[c][q];
        if (scaled)
          for (auto& v : n) v *= ratio;
        h[0][q] -= multiply_add3(n[0], m0[q], n[1], m1[q], n[2], m2[q]);
        h[1][q] -= multiply_add3(n[1], m0[q], n[3], m1[q], n[4], m2[q]);
        h[2][q] -= multiply_add3(n[2], m0[q], n[4], m1[q], n[5], m2[q]);
      }
    }
    for (int k = 0; k < 3; ++k) {
      inverse(h[k], lattices_[t].n, grid);
      for (int c = first_[t]; c < first_[t + 1]; ++c) {
        const auto& ix = cell_index_[c];
        H[c][k] = grid[ix[1] + static_cast<size_t>(pad_[0]) * (ix[2] + static_cast<size_t>(pad_[1]) * ix[3])];
      }
    }
  }
}

Vec3 LatticeDemag::force(int target, int source, const std::vector<Vec3>& M) const {
  size_t p = 0;
  while (p < force_pairs_.size() && !(force_pairs_[p][0] == target && force_pairs_[p][1] == source)) ++p;
  if (p == force_pairs_.size()) throw std::invalid_argument("LatticeDemag::force: not a force pair");
  std::vector<std::array<Spectrum, 3>> m;
  source_spectra(M, m);
  const auto& ms = m[source];
  const size_t S = static_cast<size_t>(half_x_) * pad_[1] * pad_[2];
  const auto& G = gradient_[p];
  Spectrum q;
  std::vector<double> grid;
  Vec3 F{};
  const double V = volume_[target];
  // (2): Q_ka = sum_j dN_kb/dd_a M_jb (symmetric in k, a), F_a = -mu0 V sum_i M_ik Q_ka.
  for (int k = 0; k < 3; ++k)
    for (int a = k; a < 3; ++a) {
      q.assign(S, Complex(0.0, 0.0));
      const int c0 = triple(k, a, 0), c1 = triple(k, a, 1), c2 = triple(k, a, 2);
#pragma omp parallel for if (parallel())
      for (long e = 0; e < static_cast<long>(S); ++e)
        q[e] = multiply_add3(G[c0][e], ms[0][e], G[c1][e], ms[1][e], G[c2][e], ms[2][e]);
      inverse(q, lattices_[target].n, grid);
      for (int c = first_[target]; c < first_[target + 1]; ++c) {
        const auto& ix = cell_index_[c];
        const double Q = grid[ix[1] + static_cast<size_t>(pad_[0]) * (ix[2] + static_cast<size_t>(pad_[1]) * ix[3])];
        F[a] -= kMu0 * V * M[c][k] * Q;
        if (a != k) F[k] -= kMu0 * V * M[c][a] * Q;
      }
    }
  return F;
}

void LatticeDemag::dense_field(const std::vector<Vec3>& M, std::vector<Vec3>& H) const {
  H.assign(cells(), Vec3{});
#pragma omp parallel for schedule(dynamic, 16)
  for (int i = 0; i < cells(); ++i) {
    const Vec3 ri = centre(i);
    for (int j = 0; j < cells(); ++j) {
      double n[6];
      pair_tensor(half_[lattice_of(i)], half_[lattice_of(j)], ri - centre(j), n, nullptr);
      H[i] -= symmetric_times(n, M[j]);  // (1)
    }
  }
}

Vec3 LatticeDemag::dense_force(int target, int source, const std::vector<Vec3>& M) const {
  Vec3 F{};
  const double V = volume_[target];
  for (int i = first_[target]; i < first_[target + 1]; ++i)
    for (int j = first_[source]; j < first_[source + 1]; ++j) {
      double n[6], g[3][6];
      pair_tensor(half_[target], half_[source], centre(i) - centre(j), n, g);
      for (int a = 0; a < 3; ++a) F[a] -= kMu0 * V * dot(M[i], symmetric_times(g[a], M[j]));  // (2)
    }
  return F;
}

}  // namespace odemag
