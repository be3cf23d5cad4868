#include "render/scene_view.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <mutex>
#include <stdexcept>
#include <utility>
#include <variant>

#include "magnetics/cells/compound.h"
#include "magnetics/cells/mesh.h"
#include "render/png_writer.h"
#include "magnetics/relax/relax.h"
#include "odemag/shape.h"
#include "engine/simulation/rigid_world.h"

namespace odemag {

namespace {

RenderColor to_color(const std::array<double, 3>& c) {
  return {static_cast<float>(c[0]), static_cast<float>(c[1]), static_cast<float>(c[2])};
}

// The triangles of a mesh or a compound (every part as triangles, a ball as
// a subdivided icosahedron, a cylinder as a prism of 64 sides) in the body
// frame, each corner with the mean normal of the triangles at its vertex
// within 35 degrees of its own (sharp edges stay sharp).
std::shared_ptr<const RenderSurface> surface_of(const Shape& shape) {
  std::vector<Vec3> v;
  std::vector<std::array<int, 3>> t;
  auto add = [&](const Mesh& m, const Vec3& position, const Mat3& orientation) {
    const int first = static_cast<int>(v.size());
    for (const Vec3& x : m.vertices()) v.push_back(position + orientation * x);
    for (const auto& f : m.triangles()) t.push_back({f[0] + first, f[1] + first, f[2] + first});
  };
  auto part_mesh = [](const PartShape& p) {
    return std::visit(Overloaded{[](const Sphere& s) { return ball_mesh(s.radius, 3); },
                                 [](const Box& b) { return box_mesh(b.size); },
                                 [](const Cylinder& c) { return cylinder_prism_mesh(c.radius, c.length, 64); },
                                 [](const Mesh& m) { return m; }},
                      p);
  };
  if (const Mesh* m = std::get_if<Mesh>(&shape)) add(*m, {}, Mat3{});
  if (const Compound* c = std::get_if<Compound>(&shape))
    for (const CompoundPart& p : c->parts()) add(part_mesh(p.shape), p.position, p.orientation);
  std::vector<Vec3> face(t.size());
  std::vector<std::vector<int>> at(v.size());
  for (size_t f = 0; f < t.size(); ++f) {
    face[f] = cross(v[t[f][1]] - v[t[f][0]], v[t[f][2]] - v[t[f][0]]);  // area-weighted
    for (int k = 0; k < 3; ++k) at[t[f][k]].push_back(static_cast<int>(f));
  }
  auto surface = std::make_shared<RenderSurface>();
  const double crease = std::cos(35.0 * kPi / 180.0);
  for (size_t f = 0; f < t.size(); ++f) {
    const Vec3 own = normalized(face[f]);
    for (int k = 0; k < 3; ++k) {
      Vec3 n;
      for (int g : at[t[f][k]])
        if (dot(normalized(face[g]), own) >= crease) n = n + face[g];
      n = is_finite(normalized(n)) ? normalized(n) : own;
      const Vec3& x = v[t[f][k]];
      surface->positions.insert(surface->positions.end(),
                                {static_cast<float>(x.x), static_cast<float>(x.y), static_cast<float>(x.z)});
      surface->normals.insert(surface->normals.end(),
                              {static_cast<float>(n.x), static_cast<float>(n.y), static_cast<float>(n.z)});
      surface->radius = std::max(surface->radius, norm(x));
    }
  }
  return surface;
}

// Surfaces are built once per mesh or compound: the cache holds the shape
// (so its data, whose address is the key, stays alive).
std::shared_ptr<const RenderSurface> cached_surface(const Shape& shape) {
  static std::mutex mutex;
  static std::vector<std::pair<Shape, std::shared_ptr<const RenderSurface>>> cache;
  auto key = [](const Shape& s) -> const void* {
    if (const Mesh* m = std::get_if<Mesh>(&s)) return &m->data();
    if (const Compound* c = std::get_if<Compound>(&s)) return &c->data();
    return nullptr;
  };
  std::lock_guard<std::mutex> lock(mutex);
  for (const auto& [s, surface] : cache)
    if (key(s) == key(shape)) return surface;
  if (cache.size() >= 64) cache.clear();
  cache.emplace_back(shape, surface_of(shape));
  return cache.back().second;
}

RenderPrimitive primitive_of(const Shape& shape, const BodyPose& pose) {
  return std::visit(
      Overloaded{[&](const Sphere& s) { return RenderPrimitive::sphere(pose.position, s.radius, palette::iron); },
                 [&](const Box& b) { return RenderPrimitive::box(pose.position, b.size, pose.rotation, palette::iron); },
                 [&](const Cylinder& c) {
                   return RenderPrimitive::cylinder(pose.position, c.radius, c.length, pose.rotation, palette::iron);
                 },
                 [&](const auto&) {
                   return RenderPrimitive::of_surface(pose.position, cached_surface(shape), pose.rotation,
                                                      palette::iron);
                 }},
      shape);
}

// The scene's length scale: the camera's distance to its target.
double scene_size(const SceneDescription& scene) {
  return std::max(1e-3, norm(scene.camera.position - scene.camera.target));
}

bool inside_a_source(const MagneticModel& model, const MagneticState& state, const std::vector<FieldSource>& sources,
                     const Vec3& p) {
  for (const FieldSource& s : sources) {
    const Vec3 local = state.pose[s.body].rotation.transpose_times(p - state.pose[s.body].position);
    if (shape_contains(model.body(s.body).shape, local)) return true;
  }
  return false;
}

// Inert bodies of a material named like glass ("glass", "Glass_tube") are
// drawn translucent, so that what they hold stays visible.
bool glass_material(const std::string& material) {
  std::string lower = material;
  for (char& c : lower) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return lower.find("glass") != std::string::npos;
}

}  // namespace

std::vector<FieldSource> field_sources(const MagneticModel& model, const MagneticState& state) {
  std::vector<FieldSource> all;
  double strongest = 0.0;
  for (int b = 0; b < model.body_count(); ++b) {
    const MagneticBody& body = model.body(b);
    if (body.inert() || !state.active[b]) continue;
    FieldSource s;
    s.body = b;
    const Vec3 moment = body_moment(model, state, b);
    s.moment = norm(moment);
    if (body.kind != CellKind::soft) {
      const Vec3 m = state.magnetization_scale[b] * body.remanence;
      if (norm(m) == 0.0) continue;
      s.kind = FieldSource::Kind::permanent;
      s.axis = state.pose[b].rotation * normalized(m);
      // Before the cells are placed the state's moment is zero.
      if (s.moment == 0.0) s.moment = norm(m) * shape_volume(body.shape);
    } else {
      if (!(s.moment > 0.0) || !std::isfinite(s.moment)) continue;
      const bool coil_on = norm(state.magnetization_scale[b] * body.coil_field) > 0.0;
      s.kind = coil_on ? FieldSource::Kind::electromagnet : FieldSource::Kind::induced;
      s.axis = moment / s.moment;
    }
    if (!is_finite(s.axis) || squared_norm(s.axis) == 0.0) continue;
    strongest = std::max(strongest, s.moment);
    all.push_back(s);
  }
  std::vector<FieldSource> sources;
  for (const FieldSource& s : all)
    if (s.kind != FieldSource::Kind::induced || s.moment >= kInducedSourceFraction * strongest)
      sources.push_back(s);
  // Magnets and electromagnets first, then by moment.
  std::stable_sort(sources.begin(), sources.end(), [](const FieldSource& a, const FieldSource& b) {
    const bool ai = a.kind == FieldSource::Kind::induced, bi = b.kind == FieldSource::Kind::induced;
    if (ai != bi) return bi;
    return a.moment > b.moment;
  });
  return sources;
}

ViewOptions view_options(const SceneDescription& scene) {
  ViewOptions o;
  o.field_lines = scene.render.field_lines;
  o.field_line_count = scene.render.field_line_count;
  o.force_colors = scene.render.force_colors;
  return o;
}

namespace {

// The conductors of a coil (magnetics/sources/coil.h) as polylines in its frame, for
// drawing: a loop's circle, a solenoid's end rings and eight turns between,
// a finite-section winding's inner and outer rings at both ends, a
// rounded-rectangle winding's inner and outer outlines at both ends, a
// segment, an arc. Orientation: the source's axis (and width direction).
std::vector<std::vector<Vec3>> coil_outlines(const CoilSource& source) {
  constexpr int kSides = 48;
  auto frame = [](const Vec3& axis, Vec3 width, Vec3& u, Vec3& v, Vec3& w) {
    w = normalized(axis);
    width = width - dot(width, w) * w;
    if (norm(width) < 1e-12) width = std::fabs(w.x) < 0.9 ? Vec3{1.0, 0.0, 0.0} : Vec3{0.0, 1.0, 0.0};
    width = width - dot(width, w) * w;
    u = normalized(width);
    v = cross(w, u);
  };
  // An arc of `angle` about `axis` from the direction `start`, `height` along the axis off `centre`.
  auto ring = [&](const Vec3& centre, const Vec3& axis, const Vec3& start, double radius, double height,
                  double angle) {
    Vec3 u, v, w;
    frame(axis, start, u, v, w);
    std::vector<Vec3> pts;
    const int n = std::max(2, static_cast<int>(std::ceil(kSides * std::fabs(angle) / (2.0 * kPi))));
    for (int i = 0; i <= n; ++i) {
      const double t = angle * i / n;
      pts.push_back(centre + height * w + radius * (std::cos(t) * u + std::sin(t) * v));
    }
    return pts;
  };
  const Vec3 x_axis{1.0, 0.0, 0.0};
  std::vector<std::vector<Vec3>> out;
  std::visit(
      Overloaded{
          [&](const CircularLoop& l) { out.push_back(ring(l.centre, l.axis, x_axis, l.radius, 0.0, 2.0 * kPi)); },
          [&](const StraightSegment& s) { out.push_back({s.a, s.b}); },
          [&](const Arc& a) { out.push_back(ring(a.centre, a.axis, a.start, a.radius, 0.0, a.angle)); },
          [&](const Solenoid& s) {
            for (int i = 0; i <= 8; ++i)
              out.push_back(ring(s.centre, s.axis, x_axis, s.radius, s.length * (i / 8.0 - 0.5), 2.0 * kPi));
          },
          [&](const CircularCoil& c) {
            for (double z : {-0.5 * c.length, 0.5 * c.length})
              for (double r : {c.inner_radius, c.outer_radius})
                if (r > 0.0) out.push_back(ring(c.centre, c.axis, x_axis, r, z, 2.0 * kPi));
          },
          [&](const RoundedRectangleCoil& c) {
            Vec3 u, v, w;
            frame(c.axis, c.width_direction, u, v, w);
            for (double z : {-0.5 * c.height, 0.5 * c.height})
              for (double r : {c.inner_corner_radius, c.outer_corner_radius}) {
                // The core rectangle's outline pushed out by r: four quarter arcs about its corners.
                std::vector<Vec3> pts;
                const double cu[4] = {1, -1, -1, 1}, cv[4] = {1, 1, -1, -1};
                for (int k = 0; k < 4; ++k) {
                  const Vec3 corner = c.centre + z * w + (cu[k] * c.core_half_width) * u + (cv[k] * c.core_half_depth) * v;
                  for (int i = 0; i <= 12; ++i) {
                    const double t = 0.5 * kPi * (k + i / 12.0);
                    pts.push_back(corner + r * (std::cos(t) * u + std::sin(t) * v));
                  }
                }
                pts.push_back(pts.front());
                out.push_back(pts);
              }
          }},
      source);
  return out;
}
}  // namespace

std::vector<RenderLine> trace_field_lines(const MagneticModel& model, const MagneticState& state,
                                          MagneticBackend& backend, int count, double size) {
  // Seeds: rings on the north faces of the magnetized bodies: every magnet
  // and electromagnet, and induced bodies, strongest first, while they get
  // four lines each.
  const std::vector<FieldSource> all_sources = field_sources(model, state);
  if (all_sources.empty() || count <= 0) return {};
  std::vector<FieldSource> sources;
  const auto most = static_cast<std::size_t>(std::max(1, count / 4));
  for (const FieldSource& s : all_sources)
    if (s.kind != FieldSource::Kind::induced || sources.size() < most) sources.push_back(s);
  const int per_magnet = std::max(1, count / static_cast<int>(sources.size()));
  std::vector<Vec3> heads;
  for (const FieldSource& source : sources) {
    const int b = source.body;
    const MagneticBody& body = model.body(b);
    const Vec3 axis = normalized(state.pose[b].rotation.transpose_times(source.axis));  // body frame
    const Vec3 half = shape_half_extents(body.shape);
    // How far the body's bounding box reaches along a body-frame direction.
    auto reach_along = [&](const Vec3& d) {
      return std::abs(d.x) * half.x + std::abs(d.y) * half.y + std::abs(d.z) * half.z;
    };
    const double reach = reach_along(axis);
    const Vec3 u = normalized(cross(axis, std::abs(axis.x) < 0.9 ? Vec3{1, 0, 0} : Vec3{0, 1, 0}));
    const Vec3 v = cross(axis, u);
    // A ring over the north face, 0.6 of the way out across it (a flat core
    // magnetized through its thickness gets a wide one).
    const double lateral_u = 0.6 * reach_along(u), lateral_v = 0.6 * reach_along(v);
    for (int k = 0; k < per_magnet; ++k) {
      const double phi = 2.0 * kPi * (k + 0.5) / per_magnet;
      const Vec3 local = (reach * 1.02) * axis + (lateral_u * std::cos(phi)) * u + (lateral_v * std::sin(phi)) * v;
      heads.push_back(state.pose[b].position + state.pose[b].rotation * local);
    }
  }
  std::vector<RenderLine> lines(heads.size());
  for (size_t i = 0; i < heads.size(); ++i) {
    lines[i].points.push_back(heads[i]);
    lines[i].color = palette::field_line;
    lines[i].width = 1.2f;
  }
  // March all live lines together along B (midpoint rule), steps of size / 60.
  const double ds = size / 60.0;
  std::vector<char> live(heads.size(), 1);
  std::vector<Vec3> B, H, points;
  std::vector<size_t> index;
  for (int step = 0; step < 400; ++step) {
    points.clear();
    index.clear();
    for (size_t i = 0; i < heads.size(); ++i)
      if (live[i]) points.push_back(heads[i]), index.push_back(i);
    if (points.empty()) break;
    field_at_points(model, state, backend, points, B, H);
    std::vector<Vec3> mid(points.size());
    for (size_t j = 0; j < points.size(); ++j) mid[j] = points[j] + (0.5 * ds) * normalized(B[j]);
    field_at_points(model, state, backend, mid, B, H);
    for (size_t j = 0; j < points.size(); ++j) {
      const size_t i = index[j];
      const Vec3 next = points[j] + ds * normalized(B[j]);
      if (!is_finite(next) || norm(B[j]) == 0.0) {
        live[i] = 0;
        continue;
      }
      heads[i] = next;
      lines[i].points.push_back(next);
      const bool far = norm(next - lines[i].points.front()) > 3.0 * size;
      if (far || (step > 3 && inside_a_source(model, state, all_sources, next))) live[i] = 0;
    }
  }
  return lines;
}

RenderFrame render_scene_of(const Simulation& sim, const ViewOptions& options, MagneticBackend* field_backend) {
  const SceneDescription& scene = sim.scene();
  const MagneticForces& magnetics = sim.magnetics();
  const MagneticModel& model = magnetics.model();
  RenderFrame view;
  view.camera.position = scene.camera.position;
  view.camera.target = scene.camera.target;
  view.camera.up = scene.camera.up;
  view.camera.fov_degrees = scene.camera.fov_degrees;
  view.camera.width = scene.camera.width;
  view.camera.height = scene.camera.height;
  view.ground = scene.simulation.ground;
  view.ground_height = scene.simulation.ground_height;
  view.ground_extent = 2.0 * scene_size(scene) + 0.05;

  double strongest = 0.0;
  for (int b = 0; b < sim.world().body_count(); ++b)
    if (sim.world().enabled(b)) strongest = std::max(strongest, norm(magnetics.force(b)));

  for (int b = 0; b < sim.world().body_count(); ++b) {
    if (!sim.world().enabled(b)) continue;
    const BodyDescription& d = scene.bodies[b];
    const MagneticBody& body = model.body(b);
    RenderPrimitive p = primitive_of(d.shape, sim.world().pose(b));
    const auto material_color = scene.material_colors.find(d.material);
    if (d.color) {
      p.color = to_color(*d.color);
    } else if (material_color != scene.material_colors.end()) {
      p.color = to_color(material_color->second);
    } else if (body.inert()) {
      p.color = palette::wood;
    }
    const bool magnet = !body.inert() && body.kind != CellKind::soft;
    if (magnet && norm(magnetics.magnetization_scale(b) * body.remanence) > 0.0)
      p.pole_axis = normalized(body.remanence);  // two colours: north along +M
    if (options.force_colors && !body.inert() && !magnet && strongest > 0.0)
      p.color = force_color(norm(magnetics.force(b)) / strongest);
    if (body.inert() && glass_material(d.material)) p.opacity = kGlassOpacity;
    if (squared_norm(p.pole_axis) > 0.0) {
      view.legend.poles = true;
      view.legend.north = p.north_color;
      view.legend.south = p.south_color;
    }
    view.primitives.push_back(p);
  }
  if (options.legend) {
    view.legend.scale_bar = true;
    if (options.force_colors && strongest > 0.0) {
      for (int i = 0; i <= 8; ++i) view.legend.colorbar.push_back(force_color(i / 8.0));
      view.legend.colorbar_low = 0.0;
      view.legend.colorbar_high = strongest;
    }
  } else {
    view.legend.poles = false;
  }
  if (options.field_lines && field_backend)
    view.lines = trace_field_lines(model, magnetics.state(), *field_backend, options.field_line_count,
                                   scene_size(scene));
  // Coils carried by bodies: their conductors in copper, at the body's pose.
  for (const AttachedCoil& k : model.coils()) {
    if (!sim.world().enabled(k.body)) continue;
    const BodyPose pose = sim.world().pose(k.body);
    for (const std::vector<Vec3>& outline : coil_outlines(k.source)) {
      RenderLine line;
      for (const Vec3& x : outline) line.points.push_back(pose.position + pose.rotation * x);
      line.color = palette::copper;
      line.width = 2.5f;
      view.lines.push_back(line);
    }
  }
  if (options.caption) {
    char t[64];
    std::snprintf(t, sizeof t, "t = %.2f s", sim.time());
    view.text.push_back(t);
    // The whole title; the renderer wraps it to the image width.
    view.text.push_back(scene.title.empty() ? std::filesystem::path(scene.file).stem().string() : scene.title);
  }
  return view;
}

namespace {

class PngFrameWriter final : public FrameWriter {
 public:
  explicit PngFrameWriter(const SceneDescription& scene)
      : options_(view_options(scene)),
        renderer_(scene.camera.width, scene.camera.height, 2),
        field_backend_(options_.field_lines ? make_cpu_backend(1) : nullptr) {}

  void write(const Simulation& simulation, const std::string& path) override {
    const RenderFrame view = render_scene_of(simulation, options_, field_backend_.get());
    const std::vector<std::uint8_t> rgb = renderer_.render(view);
    std::string error;
    if (!write_png(path, renderer_.width(), renderer_.height(), rgb, &error))
      throw std::runtime_error("cannot write frame " + path + ": " + error);
  }

 private:
  ViewOptions options_;
  OffscreenRenderer renderer_;
  std::unique_ptr<MagneticBackend> field_backend_;
};

}  // namespace

std::unique_ptr<FrameWriter> make_png_frame_writer(const SceneDescription& scene) {
  return std::make_unique<PngFrameWriter>(scene);
}

}  // namespace odemag
