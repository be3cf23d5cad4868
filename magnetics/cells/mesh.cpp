#include "magnetics/cells/mesh.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <mutex>
#include <stdexcept>
#include <utility>

#include "odemag/constants.h"

namespace odemag {

Mesh::Mesh() : data_(std::make_shared<MeshData>()) {}

Mesh::Mesh(std::vector<Vec3> vertices, std::vector<std::array<int, 3>> triangles) {
  auto d = std::make_shared<MeshData>();
  d->vertices = std::move(vertices);
  d->triangles = std::move(triangles);
  data_ = std::move(d);
}

const std::vector<Vec3>& Mesh::vertices() const { return data_->vertices; }
const std::vector<std::array<int, 3>>& Mesh::triangles() const { return data_->triangles; }

Mat3 inertia_from_second_moments(const Mat3& c) {
  const double tr = c.m[0][0] + c.m[1][1] + c.m[2][2];
  Mat3 j;
  for (int a = 0; a < 3; ++a)
    for (int b = 0; b < 3; ++b) j.m[a][b] = (a == b ? tr : 0.0) - c.m[a][b];
  return j;
}

namespace {

double det3(const Vec3& a, const Vec3& b, const Vec3& c) { return dot(a, cross(b, c)); }

Vec3 min3(const Vec3& a, const Vec3& b) { return {std::min(a.x, b.x), std::min(a.y, b.y), std::min(a.z, b.z)}; }
Vec3 max3(const Vec3& a, const Vec3& b) { return {std::max(a.x, b.x), std::max(a.y, b.y), std::max(a.z, b.z)}; }

struct TriangleRef {
  Vec3 a, b, c;
  int ia, ib, ic;
};

TriangleRef triangle(const MeshData& d, int t) {
  const std::array<int, 3>& f = d.triangles[t];
  return {d.vertices[f[0]], d.vertices[f[1]], d.vertices[f[2]], f[0], f[1], f[2]};
}

// Bins of the box [lo, hi] on the grid, clamped to it; false when the box
// misses the grid.
bool bin_range(const MeshGrid& g, const Vec3& lo, const Vec3& hi, std::array<int, 3>& b0, std::array<int, 3>& b1) {
  for (int a = 0; a < 3; ++a) {
    const double top = g.origin[a] + g.bin * g.dims[a];
    if (hi[a] < g.origin[a] || lo[a] > top) return false;
    b0[a] = g.bin_of(a, lo[a]);
    b1[a] = g.bin_of(a, hi[a]);
  }
  return true;
}

// The triangles whose bounding boxes meet the box [lo, hi] (sorted, unique).
std::vector<int> triangles_near(const MeshData& d, const MeshData::Index& ix, const Vec3& lo, const Vec3& hi) {
  std::vector<int> out;
  std::array<int, 3> b0{}, b1{};
  if (!bin_range(ix.grid, lo, hi, b0, b1)) return out;
  const MeshGrid& g = ix.grid;
  for (int k = b0[2]; k <= b1[2]; ++k)
    for (int j = b0[1]; j <= b1[1]; ++j)
      for (int i = b0[0]; i <= b1[0]; ++i) {
        const int bin = (k * g.dims[1] + j) * g.dims[0] + i;
        out.insert(out.end(), g.items.begin() + g.start[bin], g.items.begin() + g.start[bin + 1]);
      }
  std::sort(out.begin(), out.end());
  out.erase(std::unique(out.begin(), out.end()), out.end());
  std::erase_if(out, [&](int t) {
    const TriangleRef r = triangle(d, t);
    const Vec3 tlo = min3(r.a, min3(r.b, r.c)), thi = max3(r.a, max3(r.b, r.c));
    return tlo.x > hi.x || tlo.y > hi.y || tlo.z > hi.z || thi.x < lo.x || thi.y < lo.y || thi.z < lo.z;
  });
  return out;
}

// Where the line through p along axis e crosses the triangle: the crossing's
// coordinate along e and the sign of the triangle's normal along e (+1: the
// line leaves the solid there). The triangle's projection on the other two
// axes (u, v) = (e + 1, e + 2) must contain (p_u, p_v); each edge's
// orientation test is evaluated from its lower-indexed vertex, with a fixed
// rule for ties, so that the two triangles sharing an edge decide a point on
// it the same way and a line through an edge crosses once (or both
// triangles, at a silhouette).
bool line_crossing(const TriangleRef& t, int e, const Vec3& p, double* at, int* sign) {
  const int u = (e + 1) % 3, v = (e + 2) % 3;
  auto edge = [&](const Vec3& a, int ia, const Vec3& b, int ib) {
    const bool swap = ia > ib;
    const Vec3& s = swap ? b : a;
    const Vec3& q = swap ? a : b;
    const double du = q[u] - s[u], dv = q[v] - s[v];
    double w = du * (p[v] - s[v]) - dv * (p[u] - s[u]);
    if (w == 0.0) w = (du > 0.0 || (du == 0.0 && dv > 0.0)) ? 1e-300 : -1e-300;
    return swap ? -w : w;
  };
  const double w0 = edge(t.b, t.ib, t.c, t.ic), w1 = edge(t.c, t.ic, t.a, t.ia), w2 = edge(t.a, t.ia, t.b, t.ib);
  const bool pos = w0 > 0.0 && w1 > 0.0 && w2 > 0.0, neg = w0 < 0.0 && w1 < 0.0 && w2 < 0.0;
  if (!pos && !neg) return false;
  const double s = w0 + w1 + w2;
  *at = (w0 * t.a[e] + w1 * t.b[e] + w2 * t.c[e]) / s;
  // Twice the projected area, positive for a counter-clockwise projection:
  // its sign is that of the normal's e component.
  *sign = pos ? 1 : -1;
  return true;
}

// Polygon clipping (Sutherland-Hodgman) against q[axis] >= 0 (keep_above)
// or q[axis] <= limit.
int clip_polygon(const Vec3* in, int n, Vec3* out, int axis, double limit, bool keep_above) {
  int m = 0;
  for (int i = 0; i < n; ++i) {
    const Vec3& a = in[i];
    const Vec3& b = in[(i + 1) % n];
    const double da = keep_above ? a[axis] - limit : limit - a[axis];
    const double db = keep_above ? b[axis] - limit : limit - b[axis];
    if (da >= 0.0) out[m++] = a;
    if ((da >= 0.0) != (db >= 0.0)) {
      const double s = da / (da - db);
      Vec3 x = a + s * (b - a);
      x[axis] = limit;
      out[m++] = x;
    }
  }
  return m;
}

// The triangle clipped to the box [0, size] (local coordinates): at most 9 vertices.
int clip_to_box(const Vec3 tri[3], const Vec3& size, Vec3* out) {
  Vec3 a[16], b[16];
  int n = 3;
  for (int k = 0; k < 3; ++k) a[k] = tri[k];
  for (int axis = 0; axis < 3 && n > 0; ++axis) {
    n = clip_polygon(a, n, b, axis, 0.0, true);
    n = clip_polygon(b, n, a, axis, size[axis], false);
  }
  for (int k = 0; k < n; ++k) out[k] = a[k];
  return n;
}

// Liang-Barsky: the segment p -> q clipped to [0, su] x [0, sv]; false when
// nothing is left.
bool clip_segment(double& pu, double& pv, double& qu, double& qv, double su, double sv) {
  double t0 = 0.0, t1 = 1.0;
  const double du = qu - pu, dv = qv - pv;
  const double p[4] = {-du, du, -dv, dv}, q[4] = {pu, su - pu, pv, sv - pv};
  for (int k = 0; k < 4; ++k) {
    if (p[k] == 0.0) {
      if (q[k] < 0.0) return false;
      continue;
    }
    const double r = q[k] / p[k];
    if (p[k] < 0.0) t0 = std::max(t0, r);
    else t1 = std::min(t1, r);
    if (t0 > t1) return false;
  }
  const double u0 = pu + t0 * du, v0 = pv + t0 * dv, u1 = pu + t1 * du, v1 = pv + t1 * dv;
  pu = u0, pv = v0, qu = u1, qv = v1;
  return true;
}

// Closest point of triangle abc to p (Ericson, Real-Time Collision Detection 5.1.5).
Vec3 closest_on_triangle(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c) {
  const Vec3 ab = b - a, ac = c - a, ap = p - a;
  const double d1 = dot(ab, ap), d2 = dot(ac, ap);
  if (d1 <= 0.0 && d2 <= 0.0) return a;
  const Vec3 bp = p - b;
  const double d3 = dot(ab, bp), d4 = dot(ac, bp);
  if (d3 >= 0.0 && d4 <= d3) return b;
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0) return a + (d1 / (d1 - d3)) * ab;
  const Vec3 cp = p - c;
  const double d5 = dot(ab, cp), d6 = dot(ac, cp);
  if (d6 >= 0.0 && d5 <= d6) return c;
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0) return a + (d2 / (d2 - d6)) * ac;
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0)
    return b + ((d4 - d3) / ((d4 - d3) + (d5 - d6))) * (c - b);
  const double den = 1.0 / (va + vb + vc);
  return a + (vb * den) * ab + (vc * den) * ac;
}

MeshGrid build_grid(const MeshData& d, const Vec3& lo, const Vec3& hi) {
  MeshGrid g;
  const Vec3 ext = hi - lo;
  const double big = std::max({ext.x, ext.y, ext.z});
  const double n = static_cast<double>(std::max<size_t>(1, d.triangles.size()));
  // About one triangle per bin on a closed surface: bins of the size of the
  // triangles, sqrt(area / n), from the box's surface.
  const double area = 2.0 * (ext.x * ext.y + ext.y * ext.z + ext.z * ext.x);
  g.bin = std::max({std::sqrt(area / n), big / 128.0, 1e-12 * big + 1e-300});
  g.origin = lo - Vec3{1e-9 * big, 1e-9 * big, 1e-9 * big};
  for (int a = 0; a < 3; ++a)
    g.dims[a] = std::max(1, static_cast<int>(std::ceil((ext[a] + 2e-9 * big) / g.bin)));
  const size_t bins = static_cast<size_t>(g.dims[0]) * g.dims[1] * g.dims[2];
  std::vector<int> count(bins + 1, 0);
  auto each_bin = [&](int t, auto&& f) {
    const TriangleRef r = triangle(d, t);
    const Vec3 tlo = min3(r.a, min3(r.b, r.c)), thi = max3(r.a, max3(r.b, r.c));
    std::array<int, 3> b0{}, b1{};
    for (int a = 0; a < 3; ++a) b0[a] = g.bin_of(a, tlo[a]), b1[a] = g.bin_of(a, thi[a]);
    for (int k = b0[2]; k <= b1[2]; ++k)
      for (int j = b0[1]; j <= b1[1]; ++j)
        for (int i = b0[0]; i <= b1[0]; ++i) f((k * g.dims[1] + j) * g.dims[0] + i);
  };
  const int nt = static_cast<int>(d.triangles.size());
  for (int t = 0; t < nt; ++t) each_bin(t, [&](int b) { ++count[b + 1]; });
  for (size_t b = 0; b < bins; ++b) count[b + 1] += count[b];
  g.start = count;
  g.items.resize(count[bins]);
  std::vector<int> fill(count.begin(), count.end() - 1);
  for (int t = 0; t < nt; ++t) each_bin(t, [&](int b) { g.items[fill[b]++] = t; });
  return g;
}

// Clusters of about 16 triangles (by centroid on a coarse grid) for the far
// field of mesh_demag_tensor.
std::vector<FaceCluster> build_clusters(const MeshData& d, const Vec3& lo, const Vec3& hi) {
  const Vec3 ext = hi - lo;
  const double big = std::max({ext.x, ext.y, ext.z, 1e-300});
  const int per_axis = std::clamp(static_cast<int>(std::cbrt(static_cast<double>(d.triangles.size()) / 16.0)) + 1, 1, 256);
  const double bin = big / per_axis;
  std::map<std::array<int, 3>, int> slot;
  std::vector<FaceCluster> clusters;
  for (int t = 0; t < static_cast<int>(d.triangles.size()); ++t) {
    const TriangleRef r = triangle(d, t);
    const Vec3 c = (r.a + r.b + r.c) / 3.0;
    std::array<int, 3> key{};
    for (int a = 0; a < 3; ++a) key[a] = std::min(per_axis - 1, static_cast<int>((c[a] - lo[a]) / bin));
    auto [it, added] = slot.try_emplace(key, static_cast<int>(clusters.size()));
    if (added) clusters.emplace_back();
    clusters[it->second].faces.push_back(t);
  }
  for (FaceCluster& fc : clusters) {
    double area = 0.0;
    Vec3 centre;
    for (int t : fc.faces) {
      const TriangleRef r = triangle(d, t);
      const double a = 0.5 * norm(cross(r.b - r.a, r.c - r.a));
      area += a;
      centre = centre + (a / 3.0) * (r.a + r.b + r.c);
    }
    fc.centre = area > 0.0 ? centre / area : triangle(d, fc.faces[0]).a;
    Mat3 m;
    m.m[0][0] = m.m[1][1] = m.m[2][2] = 0.0;
    for (int t : fc.faces) {
      const TriangleRef r = triangle(d, t);
      const Vec3 an = 0.5 * cross(r.b - r.a, r.c - r.a);  // A_f n_f
      const Vec3 off = (r.a + r.b + r.c) / 3.0 - fc.centre;
      fc.area_normal = fc.area_normal + an;
      for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) m.m[i][j] += off[i] * an[j];
      for (const Vec3* v : {&r.a, &r.b, &r.c}) fc.radius = std::max(fc.radius, norm(*v - fc.centre));
    }
    fc.moment = m;
  }
  return clusters;
}

}  // namespace

int MeshGrid::bin_of(int axis, double x) const {
  const int b = static_cast<int>(std::floor((x - origin[axis]) / bin));
  return std::clamp(b, 0, dims[axis] - 1);
}

const MeshData::Index& mesh_index(const Mesh& mesh) {
  const MeshData& d = mesh.data();
  std::call_once(d.index_once, [&] {
    auto ix = std::make_shared<MeshData::Index>();
    Vec3 lo{0, 0, 0}, hi{0, 0, 0};
    if (!d.vertices.empty()) lo = hi = d.vertices[0];
    for (const Vec3& v : d.vertices) lo = min3(lo, v), hi = max3(hi, v);
    ix->lo = lo, ix->hi = hi;
    const double big = std::max({hi.x - lo.x, hi.y - lo.y, hi.z - lo.z});
    ix->jitter = 1e-10 * big * Vec3{0.7548776662466927, 0.5698402909980532, 0.4301597090019468};
    ix->grid = build_grid(d, lo, hi);
    if (d.triangles.size() > kMeshExactFieldTriangles) ix->clusters = build_clusters(d, lo, hi);
    d.index = std::move(ix);
  });
  return *d.index;
}

namespace {

std::string check_mesh(const Mesh& mesh) {
  const auto& V = mesh.vertices();
  const auto& T = mesh.triangles();
  const long nv = static_cast<long>(V.size());
  if (T.size() < 4) return "a closed mesh needs at least 4 triangles (it has " + std::to_string(T.size()) + ")";
  for (size_t i = 0; i < V.size(); ++i)
    if (!is_finite(V[i])) return "vertex " + std::to_string(i) + " has a coordinate that is not finite";
  for (size_t t = 0; t < T.size(); ++t) {
    for (int k = 0; k < 3; ++k)
      if (T[t][k] < 0 || T[t][k] >= nv)
        return "triangle " + std::to_string(t) + " has vertex index " + std::to_string(T[t][k]) +
               " out of range (the mesh has " + std::to_string(nv) + " vertices)";
    if (T[t][0] == T[t][1] || T[t][1] == T[t][2] || T[t][2] == T[t][0])
      return "triangle " + std::to_string(t) + " repeats a vertex";
  }
  // Edges: each undirected edge must be used twice, once in each direction.
  std::vector<std::pair<std::pair<int, int>, int>> edges;  // (low, high), +1 low->high / -1
  edges.reserve(3 * T.size());
  for (const auto& f : T)
    for (int k = 0; k < 3; ++k) {
      const int a = f[k], b = f[(k + 1) % 3];
      edges.push_back({{std::min(a, b), std::max(a, b)}, a < b ? 1 : -1});
    }
  std::sort(edges.begin(), edges.end());
  long boundary = 0, shared_more = 0, same_direction = 0;
  for (size_t i = 0; i < edges.size();) {
    size_t j = i;
    int sum = 0;
    while (j < edges.size() && edges[j].first == edges[i].first) sum += edges[j++].second;
    const size_t uses = j - i;
    if (uses == 1) ++boundary;
    else if (uses > 2) ++shared_more;
    else if (sum != 0) ++same_direction;
    i = j;
  }
  if (boundary > 0)
    return "the mesh is not closed: " + std::to_string(boundary) + " boundary edges (edges of one triangle only)";
  if (shared_more > 0)
    return "the mesh is not manifold: " + std::to_string(shared_more) + " edges shared by more than two triangles";
  if (same_direction > 0)
    return "the triangles are not consistently oriented: " + std::to_string(same_direction) +
           " edges run the same way in both their triangles (a flipped face)";
  Vec3 lo = V[T[0][0]], hi = lo;
  for (const auto& f : T)
    for (int k = 0; k < 3; ++k) lo = min3(lo, V[f[k]]), hi = max3(hi, V[f[k]]);
  const Vec3 ext = hi - lo;
  const double big = std::max({ext.x, ext.y, ext.z});
  const double volume = mesh_mass_integrals(mesh).volume;
  if (!(std::fabs(volume) > 1e-9 * big * big * big)) return "the mesh encloses no volume";
  // Crossing triangles: a pair that shares no vertex and whose bounding
  // boxes meet, tested by its edges against the other triangle (strict
  // orientation signs, so touching is not crossing); each pair once, in the
  // bin that holds the lower corner of the meeting of their boxes.
  const MeshData::Index& ix = mesh_index(mesh);
  const MeshGrid& g = ix.grid;
  auto orient = [](const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& d) { return det3(b - a, c - a, d - a); };
  auto segment_crosses = [&](const Vec3& p, const Vec3& q, const TriangleRef& t) {
    const double sp = orient(t.a, t.b, t.c, p), sq = orient(t.a, t.b, t.c, q);
    if (!((sp > 0.0 && sq < 0.0) || (sp < 0.0 && sq > 0.0))) return false;
    const double e0 = orient(p, q, t.a, t.b), e1 = orient(p, q, t.b, t.c), e2 = orient(p, q, t.c, t.a);
    return (e0 > 0.0 && e1 > 0.0 && e2 > 0.0) || (e0 < 0.0 && e1 < 0.0 && e2 < 0.0);
  };
  // Every bin is searched, so that the pair reported (the lowest first
  // index, then the lowest second) does not depend on the threads.
  const long bins = static_cast<long>(g.start.size()) - 1;
  long crossing = -1, crossing_other = -1;
#pragma omp parallel for schedule(dynamic, 64)
  for (long bin = 0; bin < bins; ++bin) {
    const int i = static_cast<int>(bin % g.dims[0]), j = static_cast<int>((bin / g.dims[0]) % g.dims[1]),
              k = static_cast<int>(bin / (static_cast<long>(g.dims[0]) * g.dims[1]));
    for (int s = g.start[bin]; s < g.start[bin + 1]; ++s)
      for (int r = s + 1; r < g.start[bin + 1]; ++r) {
        const int ta = g.items[s], tb = g.items[r];
        const TriangleRef A = triangle(mesh.data(), ta), B = triangle(mesh.data(), tb);
        bool shares = false;
        for (int x : {A.ia, A.ib, A.ic}) shares = shares || x == B.ia || x == B.ib || x == B.ic;
        if (shares) continue;
        const Vec3 lo_ab = max3(min3(A.a, min3(A.b, A.c)), min3(B.a, min3(B.b, B.c)));
        const Vec3 hi_ab = min3(max3(A.a, max3(A.b, A.c)), max3(B.a, max3(B.b, B.c)));
        if (lo_ab.x > hi_ab.x || lo_ab.y > hi_ab.y || lo_ab.z > hi_ab.z) continue;
        if (g.bin_of(0, lo_ab.x) != i || g.bin_of(1, lo_ab.y) != j || g.bin_of(2, lo_ab.z) != k) continue;
        const bool cross = segment_crosses(A.a, A.b, B) || segment_crosses(A.b, A.c, B) ||
                           segment_crosses(A.c, A.a, B) || segment_crosses(B.a, B.b, A) ||
                           segment_crosses(B.b, B.c, A) || segment_crosses(B.c, B.a, A);
        if (cross) {
          const long first = std::min(ta, tb), second = std::max(ta, tb);
#pragma omp critical(odemag_mesh_crossing)
          if (crossing < 0 || first < crossing || (first == crossing && second < crossing_other))
            crossing = first, crossing_other = second;
        }
      }
  }
  if (crossing >= 0)
    return "the mesh intersects itself: triangles " + std::to_string(crossing) + " and " +
           std::to_string(crossing_other) + " cross";
  return "";
}

}  // namespace

std::string validate_mesh(const Mesh& mesh) {
  const MeshData& d = mesh.data();
  std::call_once(d.check_once, [&] { d.check = check_mesh(mesh); });
  return d.check;
}

Mesh mesh_outward(const Mesh& mesh, bool* flipped) {
  const bool inverted = mesh_mass_integrals(mesh).volume < 0.0;
  if (flipped) *flipped = inverted;
  if (!inverted) return mesh;
  std::vector<std::array<int, 3>> t = mesh.triangles();
  for (auto& f : t) std::swap(f[1], f[2]);
  return Mesh(mesh.vertices(), std::move(t));
}

MassIntegrals mesh_mass_integrals(const Mesh& mesh) {
  // Tetrahedra (0, a, b, c) of signed volume det / 6: first moment V (a + b
  // + c) / 4, second moments integral x_i x_j = det / 120 (a_i a_j + b_i b_j +
  // c_i c_j + s_i s_j), s = a + b + c.
  double volume = 0.0;
  Vec3 first;
  double c[3][3] = {};
  for (const auto& f : mesh.triangles()) {
    const Vec3& a = mesh.vertices()[f[0]];
    const Vec3& b = mesh.vertices()[f[1]];
    const Vec3& cc = mesh.vertices()[f[2]];
    const double det = det3(a, b, cc);
    const Vec3 s = a + b + cc;
    volume += det / 6.0;
    first = first + (det / 24.0) * s;
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) c[i][j] += det / 120.0 * (a[i] * a[j] + b[i] * b[j] + cc[i] * cc[j] + s[i] * s[j]);
  }
  MassIntegrals m;
  m.volume = volume;
  m.centroid = volume != 0.0 ? first / volume : Vec3{};
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) m.second.m[i][j] = c[i][j];
  return m;
}

Mesh mesh_centred(const Mesh& mesh, Vec3* offset) {
  const Vec3 c = mesh_mass_integrals(mesh).centroid;
  if (offset) *offset = c;
  std::vector<Vec3> v = mesh.vertices();
  for (Vec3& x : v) x = x - c;
  return Mesh(std::move(v), mesh.triangles());
}

int mesh_winding(const Mesh& mesh, const Vec3& p) {
  const MeshData& d = mesh.data();
  const MeshData::Index& ix = mesh_index(mesh);
  if (!(p.y >= ix.lo.y && p.y <= ix.hi.y && p.z >= ix.lo.z && p.z <= ix.hi.z && p.x <= ix.hi.x)) return 0;
  const std::vector<int> near = triangles_near(d, ix, {p.x, p.y, p.z}, {ix.hi.x, p.y, p.z});
  int w = 0;
  for (int t : near) {
    double at = 0.0;
    int sign = 0;
    if (line_crossing(triangle(d, t), 0, p, &at, &sign) && at > p.x) w += sign;
  }
  return w;
}

double mesh_surface_distance(const Mesh& mesh, const Vec3& p, double max_distance) {
  const MeshData& d = mesh.data();
  const MeshData::Index& ix = mesh_index(mesh);
  const Vec3 r{max_distance, max_distance, max_distance};
  double best = max_distance;
  for (int t : triangles_near(d, ix, p - r, p + r)) {
    const TriangleRef tr = triangle(d, t);
    best = std::min(best, norm(closest_on_triangle(p, tr.a, tr.b, tr.c) - p));
  }
  return best;
}

Vec3 mesh_closest_point(const Mesh& mesh, const Vec3& p) {
  const MeshData& d = mesh.data();
  const MeshData::Index& ix = mesh_index(mesh);
  // Boxes about p growing by the bin edge until one holds a triangle; then
  // every triangle within the distance found.
  double r = ix.grid.bin;
  const Vec3 ext = ix.hi - ix.lo;
  const double reach = norm(p - 0.5 * (ix.lo + ix.hi)) + norm(ext) + r;
  std::vector<int> near;
  while ((near = triangles_near(d, ix, p - Vec3{r, r, r}, p + Vec3{r, r, r})).empty() && r < reach) r *= 2.0;
  Vec3 best = p;
  double d2 = 1e300;
  auto consider = [&](const std::vector<int>& list) {
    for (int t : list) {
      const TriangleRef tr = triangle(d, t);
      const Vec3 c = closest_on_triangle(p, tr.a, tr.b, tr.c);
      if (squared_norm(c - p) < d2) d2 = squared_norm(c - p), best = c;
    }
  };
  consider(near);
  const double found = std::sqrt(d2);
  consider(triangles_near(d, ix, p - Vec3{found, found, found}, p + Vec3{found, found, found}));
  return best;
}

bool mesh_box_inside(const Mesh& mesh, const Vec3& lo0, const Vec3& hi0) {
  const MeshData& d = mesh.data();
  const MeshData::Index& ix = mesh_index(mesh);
  const Vec3 lo = lo0 + ix.jitter, hi = hi0 + ix.jitter, size = hi - lo;
  for (int t : triangles_near(d, ix, lo, hi)) {
    const TriangleRef r = triangle(d, t);
    const Vec3 tri[3] = {r.a - lo, r.b - lo, r.c - lo};
    Vec3 poly[16];
    if (clip_to_box(tri, size, poly) >= 3) return false;
  }
  return mesh_winding(mesh, 0.5 * (lo + hi)) != 0;
}

VolumeMoments mesh_box_moments(const Mesh& mesh, const Vec3& lo0, const Vec3& hi0) {
  const MeshData& d = mesh.data();
  const MeshData::Index& ix = mesh_index(mesh);
  VolumeMoments out;
  const Vec3 lo = lo0 + ix.jitter, hi = hi0 + ix.jitter, size = hi - lo;
  if (hi.x < ix.lo.x || hi.y < ix.lo.y || hi.z < ix.lo.z || lo.x > ix.hi.x || lo.y > ix.hi.y || lo.z > ix.hi.z)
    return out;
  const std::vector<int> near = triangles_near(d, ix, lo, hi);
  const double w_hi = near.empty() ? mesh_winding(mesh, 0.5 * (lo + hi)) : mesh_winding(mesh, hi);
  if (near.empty()) {  // no surface in the box: all or nothing
    if (w_hi == 0) return out;
    out.v = size.x * size.y * size.z;
    const Vec3 c = 0.5 * (lo0 + hi0);
    out.x = out.v * c.x, out.y = out.v * c.y, out.z = out.v * c.z;
    return out;
  }
  // In local coordinates q = x - lo (the box is [0, size]), by the divergence
  // theorem over the boundary of (mesh within box): the clipped triangles plus
  // the parts of the box's faces inside the mesh, of which only the far faces
  // q_c = size_c contribute to V = (1/3) oint q . n and to
  // int q_c dV = oint (q_c^2 / 2) n_c.
  double V = 0.0, M[3] = {0.0, 0.0, 0.0};
  std::vector<TriangleRef> tris;
  tris.reserve(near.size());
  for (int t : near) {
    TriangleRef r = triangle(d, t);
    r.a = r.a - lo, r.b = r.b - lo, r.c = r.c - lo;
    tris.push_back(r);
    const Vec3 tri[3] = {r.a, r.b, r.c};
    Vec3 poly[16];
    const int n = clip_to_box(tri, size, poly);
    for (int k = 1; k + 1 < n; ++k) {
      const Vec3 &q0 = poly[0], &q1 = poly[k], &q2 = poly[k + 1];
      V += det3(q0, q1, q2) / 6.0;
      const Vec3 S = 0.5 * cross(q1 - q0, q2 - q0);
      for (int c = 0; c < 3; ++c)
        M[c] += S[c] / 12.0 *
                (q0[c] * q0[c] + q1[c] * q1[c] + q2[c] * q2[c] + q0[c] * q1[c] + q0[c] * q2[c] + q1[c] * q2[c]);
    }
  }
  // Lengths inside the mesh of the three box edges through the far corner:
  // along axis e, L = size_e w(end) + sum over crossings t in (0, size_e) of
  // sign * t (the line is inside before an exit, sign +1).
  const Vec3 corner = size;
  double L[3];
  for (int e = 0; e < 3; ++e) {
    L[e] = size[e] * (w_hi != 0 ? 1.0 : 0.0);
    for (const TriangleRef& r : tris) {
      double at = 0.0;
      int sign = 0;
      if (line_crossing(r, e, corner, &at, &sign) && at > 0.0 && at < size[e]) L[e] += sign * at;
    }
  }
  // Area inside the mesh of each far face q_c = size_c, in its coordinates
  // (u, v) = (c + 1, c + 2): (1/2) oint (u, v) . m over its boundary, from the
  // mesh's section segments (oriented with the outward normal m) clipped to
  // the face, and the face's far edges (u = size_u: along v; v = size_v:
  // along u).
  for (int c = 0; c < 3; ++c) {
    const int u = (c + 1) % 3, v = (c + 2) % 3;
    double A = 0.5 * size[u] * L[v] + 0.5 * size[v] * L[u];
    for (const TriangleRef& r : tris) {
      const Vec3* p[3] = {&r.a, &r.b, &r.c};
      double s[3];
      for (int k = 0; k < 3; ++k) s[k] = (*p[k])[c] - size[c];
      double pts[2][2];
      int m = 0;
      for (int k = 0; k < 3 && m < 2; ++k) {
        const int k1 = (k + 1) % 3;
        if ((s[k] >= 0.0) != (s[k1] >= 0.0)) {
          const double f = s[k] / (s[k] - s[k1]);
          const Vec3 x = *p[k] + f * (*p[k1] - *p[k]);
          pts[m][0] = x[u], pts[m][1] = x[v];
          ++m;
        }
      }
      if (m < 2) continue;
      const Vec3 n = cross(r.b - r.a, r.c - r.a);
      double pu = pts[0][0], pv = pts[0][1], qu = pts[1][0], qv = pts[1][1];
      if ((qv - pv) * n[u] - (qu - pu) * n[v] < 0.0) std::swap(pu, qu), std::swap(pv, qv);
      if (!clip_segment(pu, pv, qu, qv, size[u], size[v])) continue;
      A += 0.5 * (pu * qv - pv * qu);
    }
    V += size[c] * A / 3.0;
    M[c] += 0.5 * size[c] * size[c] * A;
  }
  if (!(V > 0.0)) return out;
  out.v = V;
  // First moments in the caller's frame: int x = int q + (lo - jitter) V.
  out.x = M[0] + lo0.x * V, out.y = M[1] + lo0.y * V, out.z = M[2] + lo0.z * V;
  return out;
}

namespace {

// I_f(p) = int_f (p - x') / |p - x'|^3 dA' in closed form (mesh_demag_tensor).
Vec3 face_field(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& p) {
  const Vec3 nn = cross(b - a, c - a);
  const double twice_area = norm(nn);
  if (!(twice_area > 0.0)) return {};
  const Vec3 n = nn / twice_area;
  const Vec3 r1 = a - p, r2 = b - p, r3 = c - p;
  const double R1 = norm(r1), R2 = norm(r2), R3 = norm(r3);
  const double num = det3(r1, r2, r3);
  const double den = R1 * R2 * R3 + dot(r1, r2) * R3 + dot(r1, r3) * R2 + dot(r2, r3) * R1;
  const double omega = 2.0 * std::atan2(num, den);  // > 0 seen from the inner side
  Vec3 I = -omega * n;
  const Vec3* v[3] = {&a, &b, &c};
  const double R[3] = {R1, R2, R3};
  for (int k = 0; k < 3; ++k) {
    const Vec3 e = *v[(k + 1) % 3] - *v[k];
    const double len = norm(e);
    if (!(len > 0.0)) continue;
    const double s = R[k] + R[(k + 1) % 3];
    const double ln = std::log((s + len) / std::max(s - len, 1e-15 * len));
    I = I + ln * (cross(e, n) / len);
  }
  return I;
}

}  // namespace

void mesh_demag_tensor(const Mesh& mesh, const Vec3& p, double n[6]) {
  const MeshData& d = mesh.data();
  const MeshData::Index& ix = mesh_index(mesh);
  double s[3][3] = {};  // sum_f I_f n_f^T
  auto add_face = [&](int t) {
    const TriangleRef r = triangle(d, t);
    const Vec3 nn = cross(r.b - r.a, r.c - r.a);
    const double len = norm(nn);
    if (!(len > 0.0)) return;
    const Vec3 I = face_field(r.a, r.b, r.c, p), u = nn / len;
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) s[i][j] += I[i] * u[j];
  };
  if (ix.clusters.empty()) {
    for (int t = 0; t < static_cast<int>(d.triangles.size()); ++t) add_face(t);
  } else {
    for (const FaceCluster& fc : ix.clusters) {
      const Vec3 R = p - fc.centre;
      const double r = norm(R);
      if (r < kMeshClusterOpening * fc.radius) {
        for (int t : fc.faces) add_face(t);
        continue;
      }
      // g(R) S^T - J(R) D, g(R) = R / r^3, J = I / r^3 - 3 R R^T / r^5.
      const double r3 = r * r * r, r5 = r3 * r * r;
      for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) {
          double jd = 0.0;
          for (int k = 0; k < 3; ++k)
            jd += ((i == k ? 1.0 / r3 : 0.0) - 3.0 * R[i] * R[k] / r5) * fc.moment.m[k][j];
          s[i][j] += R[i] / r3 * fc.area_normal[j] - jd;
        }
    }
  }
  const double f = -1.0 / (4.0 * kPi);
  n[0] = f * s[0][0];
  n[1] = f * 0.5 * (s[0][1] + s[1][0]);
  n[2] = f * 0.5 * (s[0][2] + s[2][0]);
  n[3] = f * s[1][1];
  n[4] = f * 0.5 * (s[1][2] + s[2][1]);
  n[5] = f * s[2][2];
}

Mesh box_mesh(const Vec3& size) {
  const Vec3 e = 0.5 * size;
  std::vector<Vec3> v;
  for (int k = 0; k < 8; ++k) v.push_back({(k & 1) ? e.x : -e.x, (k & 2) ? e.y : -e.y, (k & 4) ? e.z : -e.z});
  // Two counter-clockwise triangles (seen from outside) per face.
  std::vector<std::array<int, 3>> t = {{0, 2, 1}, {1, 2, 3}, {4, 5, 6}, {5, 7, 6}, {0, 1, 4}, {1, 5, 4},
                                       {2, 6, 3}, {3, 6, 7}, {0, 4, 2}, {2, 4, 6}, {1, 3, 5}, {3, 7, 5}};
  return Mesh(std::move(v), std::move(t));
}

Mesh ball_mesh(double radius, int levels) {
  const double g = (1.0 + std::sqrt(5.0)) / 2.0;
  std::vector<Vec3> v = {{-1, g, 0}, {1, g, 0}, {-1, -g, 0}, {1, -g, 0}, {0, -1, g}, {0, 1, g},
                         {0, -1, -g}, {0, 1, -g}, {g, 0, -1}, {g, 0, 1}, {-g, 0, -1}, {-g, 0, 1}};
  std::vector<std::array<int, 3>> t = {{0, 11, 5}, {0, 5, 1}, {0, 1, 7}, {0, 7, 10}, {0, 10, 11},
                                       {1, 5, 9}, {5, 11, 4}, {11, 10, 2}, {10, 7, 6}, {7, 1, 8},
                                       {3, 9, 4}, {3, 4, 2}, {3, 2, 6}, {3, 6, 8}, {3, 8, 9},
                                       {4, 9, 5}, {2, 4, 11}, {6, 2, 10}, {8, 6, 7}, {9, 8, 1}};
  for (Vec3& x : v) x = normalized(x);
  for (int l = 0; l < levels; ++l) {
    std::map<std::pair<int, int>, int> middle;
    auto mid = [&](int a, int b) {
      auto [it, added] = middle.try_emplace(std::minmax(a, b), static_cast<int>(v.size()));
      if (added) v.push_back(normalized(v[a] + v[b]));
      return it->second;
    };
    std::vector<std::array<int, 3>> next;
    for (const auto& f : t) {
      const int ab = mid(f[0], f[1]), bc = mid(f[1], f[2]), ca = mid(f[2], f[0]);
      next.insert(next.end(), {{f[0], ab, ca}, {f[1], bc, ab}, {f[2], ca, bc}, {ab, bc, ca}});
    }
    t = std::move(next);
  }
  for (Vec3& x : v) x = radius * x;
  return Mesh(std::move(v), std::move(t));
}

}  // namespace odemag
