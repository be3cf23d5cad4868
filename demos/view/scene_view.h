// The picture of a simulation: what the renderer draws for a scene's current
// state (bodies, poles, field lines, force colours), and the PNG frame writer
// that `odemag run` and the demo programs use.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "demos/render/renderer.h"
#include "engine/sim/frame_writer.h"
#include "engine/sim/simulation.h"

namespace odemag {

struct ViewOptions {
  bool field_lines = false;   // grey B-field lines traced from the solved field
  int field_line_count = 24;
  bool force_colors = false;  // magnetic bodies coloured by |F| (violet weakest, red strongest)
  bool caption = true;        // time and scene title, top left
};

// The scene file's `render` settings.
ViewOptions view_options(const SceneDescription& scene);

// Field lines of B (seeded in a ring on the north face of every magnetized
// permanent magnet, followed along B with midpoint steps until they re-enter
// a magnet, leave the region around the scene, or reach their length).
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
