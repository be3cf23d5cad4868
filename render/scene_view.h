// The picture of a simulation: what the renderer draws for a scene's current
// state (bodies, poles, field lines, force colours), and the PNG frame writer
// that `odemag run` and the demo programs use.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "render/renderer.h"
#include "engine/simulation/frame_writer.h"
#include "odemag/simulation.h"

namespace odemag {

struct ViewOptions {
  bool field_lines = false;   // grey B-field lines traced from the solved field
  int field_line_count = 24;
  bool force_colors = false;  // magnetic bodies coloured by |F| (force_color: teal weakest, yellow strongest)
  bool caption = true;        // time and the whole scene title, in a band at the top
  bool legend = true;         // pole colours, force colour bar, scale bar, in a band at the bottom
};

// Opacity of inert bodies of a glass material (a material name containing
// "glass", any case): translucent, so that the balls in a glass tube show.
inline constexpr float kGlassOpacity = 0.3f;

// A body field lines start from. Permanent magnets (non-zero remanence) and
// electromagnets (soft bodies whose coil is on) always count; other soft
// bodies when their moment is at least kInducedSourceFraction of the
// strongest body's.
struct FieldSource {
  enum class Kind { permanent, electromagnet, induced };
  int body = -1;
  Kind kind = Kind::permanent;
  Vec3 axis;            // unit, world: the body's moment (north) direction
  double moment = 0.0;  // |moment|, A m^2
};
inline constexpr double kInducedSourceFraction = 0.1;

// The field sources of a state: magnets and electromagnets first, then
// induced bodies, each group strongest first.
std::vector<FieldSource> field_sources(const MagneticModel& model, const MagneticState& state);

// The scene file's `render` settings.
ViewOptions view_options(const SceneDescription& scene);

// Field lines of B (seeded in a ring on the north face of every magnet and
// electromagnet and of the strongest induced bodies while there are at most
// count / 4 sources; followed along B with midpoint steps until they enter a
// source, leave the region around the scene, or reach their length).
// `size` is the scene's length scale (m).
std::vector<RenderLine> trace_field_lines(const MagneticModel& model, const MagneticState& state,
                                          MagneticBackend& backend, int count, double size);

// What to draw for the simulation's current state, seen by the scene camera.
// field_backend is used for field lines (may be null when they are off).
RenderFrame render_scene_of(const Simulation& sim, const ViewOptions& options,
                            MagneticBackend* field_backend);

// Frames for `odemag run`: renders with OSMesa and writes PNGs atomically.
std::unique_ptr<FrameWriter> make_png_frame_writer(const SceneDescription& scene);

}  // namespace odemag
