#include "engine/simulation/magnetic_system.h"

#include <algorithm>
#include <cstdio>
#include <stdexcept>

#include "engine/simulation/timeline.h"
#include "gpu/cuda_backend.h"
#include "magnetics/cells/cells.h"

namespace odemag {

BodyPose scene_pose(const BodyDescription& body) {
  BodyPose pose;
  pose.position = body.position;
  pose.rotation = rotation_from_quaternion(body.orientation.w, body.orientation.x,
                                           body.orientation.y, body.orientation.z);
  return pose;
}

bool takes_contact_zones(const SceneDescription& scene, int b) {
  const BodyDescription& body = scene.bodies[b];
  const auto material = scene.materials.find(body.material);
  return (std::holds_alternative<Sphere>(body.shape) || std::holds_alternative<Box>(body.shape)) &&
         material != scene.materials.end() && has_positive_susceptibility(material->second) &&
         uses_volume_shares(body.shape, scene.body_cell_size(b));
}

namespace {

// Whether body o's material is magnetized or soft (a body a zone can face).
bool zone_partner_material(const SceneDescription& scene, size_t o) {
  const auto material = scene.materials.find(scene.bodies[o].material);
  return material != scene.materials.end() && !is_inert(material->second);
}

// Whether another body of the scene could give body b zones: a magnetized or
// soft body for a ball, another such box for a box (contact_zones).
bool has_zone_partner(const SceneDescription& scene, int b) {
  const bool box = std::holds_alternative<Box>(scene.bodies[b].shape);
  for (size_t o = 0; o < scene.bodies.size(); ++o) {
    if (static_cast<int>(o) == b) continue;
    if (!zone_partner_material(scene, o)) continue;
    if (!box || std::holds_alternative<Box>(scene.bodies[o].shape)) return true;
  }
  return false;
}

// The zone of box b facing box o across a gap of at most kBoxContactGap h
// (none where they touch, overlap, meet only at an edge, or lie farther
// apart): the patch of b's face that o's box covers, refined to h/2 within
// its half diagonal of the patch's centre (docs/model.md "Refined contact
// zones").
bool box_facing_zone(const Box& box, const BodyPose& pose, const Box& other, const BodyPose& other_pose, double h,
                     RefinedZone& zone) {
  const Vec3 e = 0.5 * box.size, f = 0.5 * other.size;
  Vec3 lo{1e300, 1e300, 1e300}, hi{-1e300, -1e300, -1e300};  // o's box in b's frame
  for (int c = 0; c < 8; ++c) {
    const Vec3 corner{(c & 1 ? 1 : -1) * f.x, (c & 2 ? 1 : -1) * f.y, (c & 4 ? 1 : -1) * f.z};
    const Vec3 p = pose.rotation.transpose_times(other_pose.position + other_pose.rotation * corner - pose.position);
    for (int k = 0; k < 3; ++k) lo[k] = std::min(lo[k], p[k]), hi[k] = std::max(hi[k], p[k]);
  }
  int axis = -1;
  double gap = 0.0;
  for (int k = 0; k < 3; ++k) {
    const double s = std::max({lo[k] - e[k], -e[k] - hi[k], 0.0});
    if (s > 0.0) {
      if (axis >= 0) return false;  // apart along two axes: an edge or a corner
      axis = k, gap = s;
    }
  }
  if (axis < 0 || gap > kBoxContactGap * h) return false;
  Vec3 point;
  double half_diagonal2 = 0.0;
  for (int k = 0; k < 3; ++k) {
    if (k == axis) {
      point[k] = lo[k] > e[k] ? e[k] : -e[k];
      continue;
    }
    const double a = std::max(lo[k], -e[k]), c = std::min(hi[k], e[k]);
    if (!(c > a)) return false;  // the faces do not overlap
    point[k] = 0.5 * (a + c);
    half_diagonal2 += 0.25 * (c - a) * (c - a);
  }
  zone = {point, {std::sqrt(half_diagonal2)}};
  return true;
}

}  // namespace

std::vector<Vec3> contact_points(const SceneDescription& scene, const std::vector<BodyPose>& poses,
                                 const std::vector<uint8_t>& active, int b) {
  if (!takes_contact_zones(scene, b)) return {};
  const BodyDescription& body = scene.bodies[b];
  const auto* ball = std::get_if<Sphere>(&body.shape);
  const BodyPose& pose = poses[b];
  std::vector<Vec3> points;
  for (size_t o = 0; o < scene.bodies.size(); ++o) {
    const BodyDescription& other = scene.bodies[o];
    if (static_cast<int>(o) == b || !zone_partner_material(scene, o) || (!active.empty() && !active[o]))
      continue;
    // The other body's point nearest this ball's centre, and this ball's
    // surface point towards it.
    const BodyPose& other_pose = poses[o];
    const Vec3 nearest =
        other_pose.position +
        other_pose.rotation * closest_point_in_shape(other.shape, other_pose.rotation.transpose_times(
                                                                      pose.position - other_pose.position));
    const Vec3 towards = nearest - pose.position;
    const double distance = norm(towards);
    if (!(distance > 0.0) || distance - ball->radius > kContactRefinementGap * ball->radius) continue;
    points.push_back(pose.rotation.transpose_times((ball->radius / distance) * towards));
  }
  return points;
}

std::vector<RefinedZone> contact_zones(const SceneDescription& scene,
                                       const std::vector<BodyPose>& poses,
                                       const std::vector<uint8_t>& active, int b) {
  const double h = scene.body_cell_size(b);
  std::vector<RefinedZone> zones;
  if (const auto* box = std::get_if<Box>(&scene.bodies[b].shape)) {
    if (!takes_contact_zones(scene, b)) return zones;
    for (size_t o = 0; o < scene.bodies.size(); ++o) {
      const auto* other = std::get_if<Box>(&scene.bodies[o].shape);
      if (static_cast<int>(o) == b || !other || !zone_partner_material(scene, o) || (!active.empty() && !active[o]))
        continue;
      RefinedZone zone;
      if (box_facing_zone(*box, poses[b], *other, poses[o], h, zone)) zones.push_back(zone);
    }
    return zones;
  }
  for (const Vec3& point : contact_points(scene, poses, active, b))
    zones.push_back({point, default_refinement_radii(h)});
  return zones;
}

namespace {

// Whether the zones give the body at most kMaxRefinedCells cells.
bool zones_fit(const Shape& shape, double h, const std::vector<RefinedZone>& zones) {
  try {
    make_refined_cells(shape, h, zones);
    return true;
  } catch (const std::invalid_argument&) {
    return false;
  }
}

}  // namespace

std::vector<std::vector<RefinedZone>> scene_contact_zones(const SceneDescription& scene) {
  std::vector<std::vector<RefinedZone>> zones(scene.bodies.size());
  if (!scene.solver.contact_refinement) return zones;
  std::vector<BodyPose> poses;
  for (const BodyDescription& body : scene.bodies) poses.push_back(scene_pose(body));
  for (size_t b = 0; b < scene.bodies.size(); ++b) {
    zones[b] = contact_zones(scene, poses, {}, static_cast<int>(b));
    // Beyond the cap the ball keeps its plain cells (scene_notices says so).
    if (!zones[b].empty() && !zones_fit(scene.bodies[b].shape, scene.body_cell_size(static_cast<int>(b)), zones[b]))
      zones[b].clear();
  }
  return zones;
}

MagneticSystem build_magnetic_system(const SceneDescription& scene) {
  MagneticSystem ms;
  ms.contact_zones = scene_contact_zones(scene);
  ms.model.set_graded_cells(scene.solver.graded_cells);
  for (size_t b = 0; b < scene.bodies.size(); ++b) {
    const BodyDescription& body = scene.bodies[b];
    const auto material = scene.materials.find(body.material);
    if (material == scene.materials.end())
      throw SceneError(scene.file, "bodies[" + std::to_string(b) + "].material",
                       "unknown material \"" + body.material + "\"");
    try {
      const int index = ms.model.add_body(body.name, body.shape, material->second,
                                          scene.body_cell_size(static_cast<int>(b)),
                                          ms.contact_zones[b]);
      for (const CoilSource& coil : body.coils) ms.model.add_coil(index, coil);
    } catch (const std::invalid_argument& e) {
      throw SceneError(scene.file, "bodies[" + std::to_string(b) + "]", e.what());
    }
  }
  ms.state = make_state(ms.model, scene.seed);
  ms.state.external_field = scene.external_field;
  for (size_t b = 0; b < scene.bodies.size(); ++b) {
    ms.state.pose[b] = scene_pose(scene.bodies[b]);
    ms.state.active[b] = scene.bodies[b].present ? 1 : 0;
  }
  place_cells(ms.model, ms.state);
  return ms;
}

namespace {

// The time line's target at t = 0 when nothing moves: the system's state and
// the relaxation options.
class TimelineOnSystem : public TimelineTarget {
 public:
  TimelineOnSystem(MagneticSystem& system, RelaxOptions& options) : state_(system.state), options_(options) {}
  void set_present(int body, bool present) override { state_.active[body] = present ? 1 : 0; }
  double magnetization_scale(int body) const override { return state_.magnetization_scale[body]; }
  void set_magnetization_scale(int body, double scale) override { state_.magnetization_scale[body] = scale; }
  Vec3 external_field() const override { return state_.external_field; }
  void set_external_field(const Vec3& H) override { state_.external_field = H; }
  void set_mutual_induction(bool enabled) override { options_.mutual_induction = enabled; }
  void follow_track(int body, bool on_track, const BodyPose& pose, const Vec3&, const Vec3&) override {
    if (on_track) state_.pose[body] = pose;
  }

 private:
  MagneticState& state_;
  RelaxOptions& options_;
};

}  // namespace

void apply_events_at_start(const SceneDescription& scene, MagneticSystem& system, RelaxOptions& options) {
  Timeline timeline(scene);
  TimelineOnSystem target(system, options);
  timeline.apply(0.0, scene.simulation.time_step, target);
  place_cells(system.model, system.state);
}

std::vector<std::string> scene_notices(const SceneDescription& scene) {
  std::vector<std::string> notices;
  for (size_t b = 0; b < scene.bodies.size(); ++b) {
    const BodyDescription& body = scene.bodies[b];
    const Material& material = scene.materials.at(body.material);
    const double h = scene.body_cell_size(static_cast<int>(b));
    if (scene.solver.contact_refinement && takes_contact_zones(scene, static_cast<int>(b))) {
      std::vector<BodyPose> poses;
      for (const BodyDescription& d : scene.bodies) poses.push_back(scene_pose(d));
      const std::vector<RefinedZone> zones = contact_zones(scene, poses, {}, static_cast<int>(b));
      if (!zones.empty() && !zones_fit(body.shape, h, zones))
        notices.push_back(scene.file + ": body '" + body.name + "' (bodies[" + std::to_string(b) +
                          "]) keeps its plain cells near its contacts: refined zones there would give it more "
                          "than " + std::to_string(kMaxRefinedCells) +
                          " cells (force at the contact up to 20% low); a larger cell_size allows them");
    }
    if (!(h > 0.0) || !has_positive_susceptibility(material) || uses_volume_shares(body.shape, h)) continue;
    const Vec3 half = shape_half_extents(body.shape);
    const double thinnest = 2.0 * std::min({half.x, half.y, half.z});
    char text[320];
    std::snprintf(text, sizeof text,
                  "is %.3g mm thin at a cell size of %.3g mm: its cells keep its moment but not where its "
                  "material is (forces and fields near it poor); a cell_size of at most %.3g mm fixes that",
                  thinnest * 1e3, h * 1e3, 0.5 * thinnest * 1e3);
    notices.push_back(scene.file + ": body '" + body.name + "' (bodies[" + std::to_string(b) + "]) " + text);
  }
  return notices;
}

SceneCellCounts count_scene_cells(const SceneDescription& scene) {
  SceneCellCounts counts;
  const std::vector<std::vector<RefinedZone>> scene_zones = scene_contact_zones(scene);
  for (size_t b = 0; b < scene.bodies.size(); ++b) {
    const BodyDescription& body = scene.bodies[b];
    const Material& material = scene.materials.at(body.material);
    if (is_inert(material)) continue;
    const double h = scene.body_cell_size(static_cast<int>(b));
    const std::vector<RefinedZone>& zones = scene_zones[b];
    double cells = 1.0;
    try {
      if (h > 0.0)
        cells = static_cast<double>(
            (zones.empty() ? make_cells(body.shape, h, has_positive_susceptibility(material))
                           : make_refined_cells(body.shape, h, zones))
                .size());
    } catch (const std::invalid_argument& e) {  // refined zones beyond kMaxRefinedCells
      throw SceneError(scene.file, "bodies[" + std::to_string(b) + "]", e.what());
    }
    counts.magnetized += cells;
    if (has_positive_susceptibility(material)) counts.responsive += cells;
  }
  return counts;
}

std::string cpu_only_feature(const SceneDescription& scene) {
  if (scene.solver.graded_cells) return "graded cells (solver.graded_cells)";
  // A lattice body that may get zones, now or when a run moves them.
  for (size_t b = 0; scene.solver.contact_refinement && b < scene.bodies.size(); ++b)
    if (takes_contact_zones(scene, static_cast<int>(b)) && has_zone_partner(scene, static_cast<int>(b)))
      return "refined contact zones (solver.contact_refinement)";
  for (const auto& [name, material] : scene.materials)
    if (const auto* soft = std::get_if<SoftMaterial>(&material); soft && !soft->bh_curve.empty())
      return "a B-H curve (materials." + name + ".bh_curve)";
  return "";
}

}  // namespace odemag
