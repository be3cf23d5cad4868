// What a SavedMagneticState holds (include/odemag/magnetic_forces.h): a copy
// of the magnetic state and what it belongs to, the cell and moment counts of
// every body it was saved from.
#pragma once

#include <vector>

#include "magnetics/model/state.h"
#include "odemag/magnetic_forces.h"

namespace odemag {

struct SavedMagneticState::Data {
  MagneticState state;
  RelaxReport report;                 // last_report() when saved
  std::vector<int> body_cells;        // per body: cells
  std::vector<int> body_moments;      // per body: soft moments
  std::vector<int> body_refinements;  // per body: refine_body calls before the save
};

}  // namespace odemag
