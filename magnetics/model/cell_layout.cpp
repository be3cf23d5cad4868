#include "magnetics/model/cell_layout.h"

namespace odemag {

void CellList::clear() {
  cell.clear();
  body.clear();
  run.clear();
  runs.clear();
}

namespace {

void add_body(CellList& list, const MagneticBody& body, int b) {
  const int begin = list.size();
  const int run = static_cast<int>(list.runs.size());
  for (int i = 0; i < body.cell_count(); ++i) {
    list.cell.push_back(body.first_cell + i);
    list.body.push_back(b);
    list.run.push_back(run);
  }
  list.runs.push_back({b, begin, list.size()});
}

}  // namespace

void CellLayout::build(const MagneticModel& model, const MagneticState& state) {
  all.clear();
  responsive.clear();
  fixed.clear();
  for (int b = 0; b < model.body_count(); ++b) {
    const MagneticBody& body = model.body(b);
    if (body.inert() || !state.active[b]) continue;
    add_body(all, body, b);
    add_body(body.responsive() ? responsive : fixed, body, b);
  }
}

}  // namespace odemag
