#include "magnetics/cells/compound.h"

#include <algorithm>
#include <cmath>
#include <string>

#include "magnetics/cells/cells.h"
#include "odemag/constants.h"

namespace odemag {

Compound::Compound() : data_(std::make_shared<CompoundData>()) {}

Compound::Compound(std::vector<CompoundPart> parts) {
  auto d = std::make_shared<CompoundData>();
  d->parts = std::move(parts);
  data_ = std::move(d);
}

const std::vector<CompoundPart>& Compound::parts() const { return data_->parts; }

namespace {

Shape as_shape(const PartShape& p) {
  return std::visit([](const auto& s) -> Shape { return s; }, p);
}

// True when the rotation maps each axis onto an axis (entries 0 or +-1).
bool signed_permutation(const Mat3& r) {
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) {
      const double a = std::fabs(r.m[i][j]);
      if (a > 1e-12 && std::fabs(a - 1.0) > 1e-12) return false;
    }
  return true;
}

Mat3 snapped(const Mat3& r) {
  Mat3 s;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) s.m[i][j] = std::round(r.m[i][j]);
  return s;
}

Mesh placed(const Mesh& m, const Vec3& position, const Mat3& orientation) {
  std::vector<Vec3> v = m.vertices();
  for (Vec3& x : v) x = position + orientation * x;
  return Mesh(std::move(v), m.triangles());
}

// The body-frame box of the part-frame box [lo, hi] turned by a signed permutation.
void turned_box(const Mat3& r, const Vec3& pos, const Vec3& lo, const Vec3& hi, Vec3& blo, Vec3& bhi) {
  const Vec3 a = pos + r * lo, b = pos + r * hi;
  blo = {std::min(a.x, b.x), std::min(a.y, b.y), std::min(a.z, b.z)};
  bhi = {std::max(a.x, b.x), std::max(a.y, b.y), std::max(a.z, b.z)};
}

// The first moments of a part-frame region mapped to the body frame.
VolumeMoments to_body(const VolumeMoments& m, const Vec3& pos, const Mat3& r) {
  const Vec3 f = r * Vec3{m.x, m.y, m.z} + m.v * pos;
  return {m.v, f.x, f.y, f.z};
}

MassIntegrals part_mass(const BodyFramePart& p) {
  if (const Mesh* m = std::get_if<Mesh>(&p.primitive)) return mesh_mass_integrals(*m);
  // A primitive centred on its origin: volume, centroid at the origin, second
  // moments diag from its inertia (C = tr(J)/2 I - J), then placed.
  const double v = shape_volume(p.primitive);
  const Mat3 j = shape_unit_inertia(p.primitive);
  const double half_trace = 0.5 * (j.m[0][0] + j.m[1][1] + j.m[2][2]);
  Mat3 c;
  for (int a = 0; a < 3; ++a)
    for (int b = 0; b < 3; ++b) c.m[a][b] = (a == b ? half_trace : 0.0) - j.m[a][b];
  const Mat3 rc = p.orientation * c * p.orientation.transposed();
  MassIntegrals out;
  out.volume = v;
  out.centroid = p.position;
  for (int a = 0; a < 3; ++a)
    for (int b = 0; b < 3; ++b) out.second.m[a][b] = rc.m[a][b] + v * p.position[a] * p.position[b];
  return out;
}

bool part_contains(const BodyFramePart& p, const Vec3& x, double tol) {
  if (const Mesh* m = std::get_if<Mesh>(&p.primitive)) return shape_contains(*m, x, tol);
  return shape_contains(p.primitive, p.orientation.transpose_times(x - p.position), tol);
}

}  // namespace

Mesh cylinder_prism_mesh(double radius, double length, int sides) {
  // The polygon's area n r'^2 sin(2 pi / n) / 2 equals pi r^2.
  const double r = radius * std::sqrt(2.0 * kPi / (sides * std::sin(2.0 * kPi / sides)));
  std::vector<Vec3> v;
  for (int k = 0; k < sides; ++k) {
    const double t = 2.0 * kPi * k / sides;
    v.push_back({r * std::cos(t), r * std::sin(t), -0.5 * length});
    v.push_back({r * std::cos(t), r * std::sin(t), 0.5 * length});
  }
  const int bottom = 2 * sides, top = bottom + 1;
  v.push_back({0, 0, -0.5 * length});
  v.push_back({0, 0, 0.5 * length});
  std::vector<std::array<int, 3>> t;
  for (int k = 0; k < sides; ++k) {
    const int a = 2 * k, b = 2 * ((k + 1) % sides);
    t.push_back({a, b, a + 1});
    t.push_back({b, b + 1, a + 1});
    t.push_back({bottom, b, a});
    t.push_back({top, a + 1, b + 1});
  }
  return Mesh(std::move(v), std::move(t));
}

const std::vector<BodyFramePart>& compound_parts(const Compound& compound) {
  const CompoundData& d = compound.data();
  std::call_once(d.once, [&] {
    std::vector<BodyFramePart> out;
    for (const CompoundPart& part : d.parts) {
      BodyFramePart b;
      const Mat3& r = part.orientation;
      const bool aligned = signed_permutation(r);
      std::visit(Overloaded{
                     [&](const Sphere& s) {
                       b.primitive = s, b.position = part.position, b.sphere_radius = s.radius;
                       const Vec3 e{s.radius, s.radius, s.radius};
                       b.lo = part.position - e, b.hi = part.position + e;
                     },
                     [&](const Box& x) {
                       b.field_mesh = placed(box_mesh(x.size), part.position, r);
                       if (aligned) {
                         b.primitive = x, b.position = part.position, b.orientation = snapped(r);
                       } else {
                         b.primitive = b.field_mesh;
                       }
                     },
                     [&](const Cylinder& c) {
                       b.field_mesh = placed(cylinder_prism_mesh(c.radius, c.length, kCompoundCylinderSides),
                                             part.position, r);
                       if (aligned) {
                         b.primitive = c, b.position = part.position, b.orientation = snapped(r);
                       } else {
                         b.primitive = b.field_mesh;
                       }
                     },
                     [&](const Mesh& m) {
                       b.field_mesh = placed(m, part.position, r);
                       b.primitive = b.field_mesh;
                     },
                 },
                 part.shape);
      if (!std::holds_alternative<Sphere>(b.primitive)) {
        if (const Mesh* m = std::get_if<Mesh>(&b.primitive)) {
          const MeshData::Index& ix = mesh_index(*m);
          b.lo = ix.lo, b.hi = ix.hi;
        } else {
          const Vec3 e = shape_half_extents(b.primitive);
          turned_box(b.orientation, b.position, -1.0 * e, e, b.lo, b.hi);
        }
      }
      out.push_back(std::move(b));
    }
    d.body_parts = std::move(out);
  });
  return d.body_parts;
}

namespace {

// The overlap of two boxes, with positive volume (touching boxes do not overlap).
bool boxes_overlap(const Vec3& alo, const Vec3& ahi, const Vec3& blo, const Vec3& bhi, Vec3& lo, Vec3& hi) {
  for (int a = 0; a < 3; ++a) {
    lo[a] = std::max(alo[a], blo[a]);
    hi[a] = std::min(ahi[a], bhi[a]);
    const double scale = std::max({ahi[a] - alo[a], bhi[a] - blo[a]});
    if (!(hi[a] - lo[a] > 1e-9 * scale)) return false;
  }
  return true;
}

}  // namespace

MassIntegrals compound_mass_integrals(const Compound& compound) {
  const auto& parts = compound_parts(compound);
  double v = 0.0;
  Vec3 first;
  Mat3 second;
  for (int a = 0; a < 3; ++a) second.m[a][a] = 0.0;
  for (const BodyFramePart& p : parts) {
    const MassIntegrals m = part_mass(p);
    v += m.volume;
    first = first + m.volume * m.centroid;
    for (int a = 0; a < 3; ++a)
      for (int b = 0; b < 3; ++b) second.m[a][b] += m.second.m[a][b];
  }
  // Overlaps: the points of the box holding every pair's overlap, each inside
  // c > 1 parts, counted c - 1 times too often.
  bool any = false;
  Vec3 olo, ohi;
  for (size_t i = 0; i < parts.size(); ++i)
    for (size_t j = i + 1; j < parts.size(); ++j) {
      Vec3 lo, hi;
      if (!boxes_overlap(parts[i].lo, parts[i].hi, parts[j].lo, parts[j].hi, lo, hi)) continue;
      if (!any) olo = lo, ohi = hi, any = true;
      for (int a = 0; a < 3; ++a) olo[a] = std::min(olo[a], lo[a]), ohi[a] = std::max(ohi[a], hi[a]);
    }
  if (any) {
    const int n = kCompoundOverlapSamples;
    const Vec3 step = (ohi - olo) / static_cast<double>(n);
    const double dv = step.x * step.y * step.z;
    for (int k = 0; k < n; ++k)
      for (int j = 0; j < n; ++j)
        for (int i = 0; i < n; ++i) {
          const Vec3 x = olo + Vec3{(i + 0.5) * step.x, (j + 0.5) * step.y, (k + 0.5) * step.z};
          int c = 0;
          for (const BodyFramePart& p : parts) c += part_contains(p, x, 0.0) ? 1 : 0;
          if (c < 2) continue;
          const double w = (c - 1) * dv;
          v -= w;
          first = first - w * x;
          for (int a = 0; a < 3; ++a)
            for (int b = 0; b < 3; ++b) second.m[a][b] -= w * x[a] * x[b];
        }
  }
  MassIntegrals out;
  out.volume = v;
  out.centroid = v > 0.0 ? first / v : Vec3{};
  out.second = second;
  return out;
}

Vec3 compound_half_extents(const Compound& compound) {
  Vec3 h;
  for (const BodyFramePart& p : compound_parts(compound))
    for (int a = 0; a < 3; ++a) h[a] = std::max({h[a], std::fabs(p.lo[a]), std::fabs(p.hi[a])});
  return h;
}

bool compound_contains(const Compound& compound, const Vec3& x, double tol) {
  for (const BodyFramePart& p : compound_parts(compound))
    if (part_contains(p, x, tol)) return true;
  return false;
}

Vec3 compound_closest_point(const Compound& compound, const Vec3& x) {
  Vec3 best = x;
  double d2 = 1e300;
  for (const BodyFramePart& p : compound_parts(compound)) {
    Vec3 c;
    if (const Mesh* m = std::get_if<Mesh>(&p.primitive)) c = closest_point_in_shape(*m, x);
    else c = p.position + p.orientation * closest_point_in_shape(p.primitive, p.orientation.transpose_times(x - p.position));
    const double e = squared_norm(c - x);
    if (e < d2) d2 = e, best = c;
  }
  return best;
}

double compound_depth(const Compound& compound, const Vec3& x) {
  double depth = 0.0;
  for (const BodyFramePart& p : compound_parts(compound)) {
    if (!part_contains(p, x, 0.0)) continue;
    if (const Mesh* m = std::get_if<Mesh>(&p.primitive)) {
      depth = std::max(depth, norm(mesh_closest_point(*m, x) - x));
    } else {
      depth = std::max(depth, shape_depth(p.primitive, p.orientation.transpose_times(x - p.position)));
    }
  }
  return depth;
}

namespace {

VolumeMoments part_box_moments(const BodyFramePart& p, const Vec3& lo, const Vec3& hi) {
  if (const Mesh* m = std::get_if<Mesh>(&p.primitive)) return mesh_box_moments(*m, lo, hi);
  // Axis-aligned in the part frame too: the box turned back.
  Vec3 plo, phi;
  turned_box(p.orientation.transposed(), p.orientation.transpose_times(-1.0 * p.position), lo, hi, plo, phi);
  return to_body(shape_box_moments(p.primitive, plo, phi), p.position, p.orientation);
}

}  // namespace

VolumeMoments compound_box_moments(const Compound& compound, const Vec3& lo, const Vec3& hi) {
  const auto& parts = compound_parts(compound);
  const Vec3 size = hi - lo;
  const double cube = size.x * size.y * size.z;
  std::vector<int> meeting;
  std::vector<VolumeMoments> m;
  VolumeMoments sum;
  for (int i = 0; i < static_cast<int>(parts.size()); ++i) {
    const BodyFramePart& p = parts[i];
    if (p.hi.x < lo.x || p.hi.y < lo.y || p.hi.z < lo.z || p.lo.x > hi.x || p.lo.y > hi.y || p.lo.z > hi.z) continue;
    const VolumeMoments pm = part_box_moments(p, lo, hi);
    if (!(pm.v > 0.0)) continue;
    if (pm.v >= cube * (1.0 - 1e-9)) return pm;  // one part fills the box
    meeting.push_back(i);
    m.push_back(pm);
    sum.v += pm.v, sum.x += pm.x, sum.y += pm.y, sum.z += pm.z;
  }
  if (meeting.size() < 2) return sum;
  bool overlap = false;
  for (size_t a = 0; a < meeting.size() && !overlap; ++a)
    for (size_t b = a + 1; b < meeting.size() && !overlap; ++b) {
      Vec3 olo, ohi;
      const BodyFramePart &pa = parts[meeting[a]], &pb = parts[meeting[b]];
      if (boxes_overlap(pa.lo, pa.hi, pb.lo, pb.hi, olo, ohi) &&
          boxes_overlap(olo, ohi, lo, hi, olo, ohi))
        overlap = true;
    }
  if (!overlap) return sum;
  const int n = 6;
  const Vec3 step = size / static_cast<double>(n);
  const double dv = step.x * step.y * step.z;
  for (int k = 0; k < n; ++k)
    for (int j = 0; j < n; ++j)
      for (int i = 0; i < n; ++i) {
        const Vec3 x = lo + Vec3{(i + 0.5) * step.x, (j + 0.5) * step.y, (k + 0.5) * step.z};
        int c = 0;
        for (int q : meeting) c += part_contains(parts[q], x, 0.0) ? 1 : 0;
        if (c < 2) continue;
        const double w = (c - 1) * dv;
        sum.v -= w, sum.x -= w * x.x, sum.y -= w * x.y, sum.z -= w * x.z;
      }
  if (!(sum.v > 0.0)) return {};
  return sum;
}

bool compound_box_inside(const Compound& compound, const Vec3& lo, const Vec3& hi) {
  const Vec3 s = hi - lo;
  // Mesh parts' shares are exact up to the cubes' shift by 1e-10 of their size.
  return compound_box_moments(compound, lo, hi).v >= s.x * s.y * s.z * (1.0 - 1e-9);
}

void compound_demag_tensor(const Compound& compound, const Vec3& x, double n[6]) {
  for (int a = 0; a < 6; ++a) n[a] = 0.0;
  for (const BodyFramePart& p : compound_parts(compound)) {
    double t[6];
    if (p.sphere_radius > 0.0) {
      // A ball: I/3 inside; outside the dipole's N = (R^3/3) (I/r^3 - 3 r r^T / r^5).
      const Vec3 r = x - p.position;
      const double d = norm(r), R = p.sphere_radius;
      if (d <= R) {
        t[0] = t[3] = t[5] = 1.0 / 3.0, t[1] = t[2] = t[4] = 0.0;
      } else {
        const double k = R * R * R / 3.0, d3 = d * d * d, d5 = d3 * d * d;
        const int ij[6][2] = {{0, 0}, {0, 1}, {0, 2}, {1, 1}, {1, 2}, {2, 2}};
        for (int a = 0; a < 6; ++a)
          t[a] = k * ((ij[a][0] == ij[a][1] ? 1.0 / d3 : 0.0) - 3.0 * r[ij[a][0]] * r[ij[a][1]] / d5);
      }
    } else {
      mesh_demag_tensor(p.field_mesh, x, t);
    }
    for (int a = 0; a < 6; ++a) n[a] += t[a];
  }
}

std::string validate_compound(const Compound& compound) {
  if (compound.parts().empty()) return "a compound needs at least one part";
  for (size_t i = 0; i < compound.parts().size(); ++i) {
    const CompoundPart& p = compound.parts()[i];
    const std::string at = "part " + std::to_string(i) + ": ";
    if (std::string e = validate_shape(as_shape(p.shape)); !e.empty()) return at + e;
    if (!is_finite(p.position)) return at + "the position must be finite";
    const Mat3& r = p.orientation;
    const Mat3 rtr = r.transposed() * r;
    for (int a = 0; a < 3; ++a)
      for (int b = 0; b < 3; ++b)
        if (!(std::fabs(rtr.m[a][b] - (a == b ? 1.0 : 0.0)) < 1e-9)) return at + "the orientation must be a rotation";
  }
  return "";
}

Compound compound_centred(const Compound& compound, Vec3* offset) {
  const Vec3 c = compound_mass_integrals(compound).centroid;
  if (offset) *offset = c;
  std::vector<CompoundPart> parts = compound.parts();
  for (CompoundPart& p : parts) p.position = p.position - c;
  return Compound(std::move(parts));
}

}  // namespace odemag
