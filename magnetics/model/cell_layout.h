// The active cells of one rigid step as both backends (magnetics/relax/cpu_backend.cpp,
// gpu/cuda_backend.cu) lay them out for the pair sums: body order, then cell
// order, in three lists: every active cell (forces), the responsive cells
// (fields and relaxation) and the fixed permanent cells (the fixed field).
// Sums over a list run in this order, so the two backends add the same terms
// in the same order.
#pragma once

#include <vector>

#include "magnetics/model/model.h"
#include "magnetics/model/state.h"

namespace odemag {

// Entries [begin, end) of a list: the cells of one body.
struct CellRun {
  int body = 0;
  int begin = 0, end = 0;
};

struct CellList {
  std::vector<int> cell;      // per entry: the model's cell index
  std::vector<int> body;      // per entry: its body
  std::vector<int> run;       // per entry: index of its body's run in `runs`
  std::vector<CellRun> runs;  // one per body with cells in the list

  int size() const { return static_cast<int>(cell.size()); }
  const CellRun& run_of(int entry) const { return runs[static_cast<size_t>(run[entry])]; }
  void clear();
};

struct CellLayout {
  CellList all, responsive, fixed;

  // Lays out the cells of every active body with cells (inert bodies have
  // none). Reuses the lists' memory from step to step.
  void build(const MagneticModel& model, const MagneticState& state);
};

}  // namespace odemag
