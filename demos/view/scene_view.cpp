#include "demos/view/scene_view.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <stdexcept>
#include <variant>

#include "demos/render/png_writer.h"
#include "magnetics/relax.h"
#include "magnetics/shape.h"

namespace odemag {

namespace {

RenderColor to_color(const std::array<double, 3>& c) {
  return {static_cast<float>(c[0]), static_cast<float>(c[1]), static_cast<float>(c[2])};
}

RenderPrimitive primitive_of(const Shape& shape, const BodyPose& pose) {
  return std::visit(
      Overloaded{[&](const Sphere& s) { return RenderPrimitive::sphere(pose.position, s.radius, palette::iron); },
                 [&](const Box& b) { return RenderPrimitive::box(pose.position, b.size, pose.rotation, palette::iron); },
                 [&](const Cylinder& c) {
                   return RenderPrimitive::cylinder(pose.position, c.radius, c.length, pose.rotation, palette::iron);
                 }},
      shape);
}

// The scene's length scale: the camera's distance to its target.
double scene_size(const SceneDescription& scene) {
  return std::max(1e-3, norm(scene.camera.position - scene.camera.target));
}

bool inside_a_magnet(const MagneticModel& model, const MagneticState& state, const Vec3& p) {
  for (int b = 0; b < model.body_count(); ++b) {
    const MagneticBody& body = model.body(b);
    if (body.inert() || body.kind == CellKind::soft || !state.active[b]) continue;
    const Vec3 local = state.pose[b].rotation.transpose_times(p - state.pose[b].position);
    if (shape_contains(body.shape, local)) return true;
  }
  return false;
}

}  // namespace

ViewOptions view_options(const SceneDescription& scene) {
  ViewOptions o;
  o.field_lines = scene.render.field_lines;
  o.field_line_count = scene.render.field_line_count;
  o.force_colors = scene.render.force_colors;
  return o;
}

std::vector<RenderLine> trace_field_lines(const MagneticModel& model, const MagneticState& state,
                                          MagneticBackend& backend, int count, double size) {
  // Seeds: rings on the north faces of the magnetized permanent magnets.
  std::vector<Vec3> heads;
  std::vector<int> magnets;
  for (int b = 0; b < model.body_count(); ++b) {
    const MagneticBody& body = model.body(b);
    if (body.inert() || body.kind == CellKind::soft || !state.active[b]) continue;
    if (norm(state.magnetization_scale[b] * body.remanence) == 0.0) continue;
    magnets.push_back(b);
  }
  if (magnets.empty() || count <= 0) return {};
  const int per_magnet = std::max(1, count / static_cast<int>(magnets.size()));
  for (int b : magnets) {
    const MagneticBody& body = model.body(b);
    const Vec3 axis = normalized(state.magnetization_scale[b] * body.remanence);  // body frame
    const Vec3 half = shape_half_extents(body.shape);
    const double reach = std::abs(axis.x) * half.x + std::abs(axis.y) * half.y + std::abs(axis.z) * half.z;
    Vec3 u = normalized(cross(axis, std::abs(axis.x) < 0.9 ? Vec3{1, 0, 0} : Vec3{0, 1, 0}));
    const Vec3 v = cross(axis, u);
    const double lateral = 0.6 * std::min({half.x, half.y, half.z});
    for (int k = 0; k < per_magnet; ++k) {
      const double phi = 2.0 * kPi * (k + 0.5) / per_magnet;
      const Vec3 local = (reach * 1.02) * axis + lateral * (std::cos(phi) * u + std::sin(phi) * v);
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
      if (far || (step > 3 && inside_a_magnet(model, state, next))) live[i] = 0;
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
      p.color = rainbow(norm(magnetics.force(b)) / strongest);
    view.primitives.push_back(p);
  }
  if (options.field_lines && field_backend)
    view.lines = trace_field_lines(model, magnetics.state(), *field_backend, options.field_line_count,
                                   scene_size(scene));
  if (options.caption) {
    char t[64];
    std::snprintf(t, sizeof t, "t = %.2f s", sim.time());
    view.text.push_back(t);
    // The title up to its first colon ("Ball chain (paper Fig. 12)").
    std::string title = scene.title.empty() ? std::filesystem::path(scene.file).stem().string() : scene.title;
    title = title.substr(0, title.find(':'));
    if (title.size() > 70) title = title.substr(0, 67) + "...";
    view.text.push_back(title);
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
