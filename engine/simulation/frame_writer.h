// Draws frames of a running simulation. The simulation layer only knows this
// interface; the OSMesa renderer (render/scene_view.h) implements it, and
// the odemag program (cli) hands one to `run` when it is built with the
// renderer.
#pragma once

#include <string>

#include "odemag/simulation.h"

namespace odemag {

class FrameWriter {
 public:
  virtual ~FrameWriter() = default;
  // Writes the current state as a PNG at path (atomically).
  virtual void write(const Simulation& simulation, const std::string& path) = 0;
};

}  // namespace odemag
