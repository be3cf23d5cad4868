#include "magnetics/near_field/near_field.h"

namespace odemag {

NearField::NearField() {
  terms_.push_back(make_sphere_near_field());
  terms_.push_back(make_lattice_near_field());
  terms_.push_back(make_ball_lattice_near_field());
}

void NearField::build(const MagneticModel& model, const MagneticState& state, bool enabled,
                      bool mutual_induction) {
  enabled_ = enabled;
  if (!enabled_) return;
  for (auto& t : terms_) {
    t->set_mutual_induction(mutual_induction);
    t->build(model, state);
  }
}

void NearField::set_held_cells(const std::vector<uint8_t>* held) {
  for (const auto& t : terms_) t->set_held_cells(held);
}

void NearField::add_field(const MagneticModel& model, const MagneticState& state, NearFieldSources sources,
                          std::vector<Vec3>& H) const {
  if (!enabled_) return;
  for (const auto& t : terms_) t->add_field(model, state, sources, H);
}

void NearField::add_forces(const MagneticModel& model, const MagneticState& state, std::vector<Vec3>& force,
                           std::vector<Vec3>& field) const {
  if (!enabled_) return;
  for (const auto& t : terms_) t->add_forces(model, state, force, field);
}

double NearField::energy(const MagneticModel& model, const MagneticState& state) const {
  double e = 0.0;
  if (!enabled_) return e;
  for (const auto& t : terms_) e += t->energy(model, state);
  return e;
}

int NearField::pair_count() const {
  int n = 0;
  if (!enabled_) return n;
  for (const auto& t : terms_) n += t->pair_count();
  return n;
}

}  // namespace odemag
