#include "engine/simulation/outcomes.h"

#include <algorithm>

namespace odemag {

using Statistic = OutcomeDescription::Statistic;

namespace {

// A component (0, 1, 2) of v, or its length (-1).
double component_of(const Vec3& v, int component) {
  return component < 0 ? norm(v) : component == 0 ? v.x : component == 1 ? v.y : v.z;
}

}  // namespace

double outcome_value(const OutcomeDescription& o, const SceneDescription& scene, const RigidWorld& world,
                     const MagneticForces& magnetics) {
  using Quantity = OutcomeDescription::Quantity;
  if (o.quantity == Quantity::count_above) {
    int count = 0;
    for (int b = 0; b < world.body_count(); ++b)
      if (world.enabled(b) && scene.bodies[b].name.rfind(o.prefix, 0) == 0 && world.pose(b).position.z > o.height)
        ++count;
    return count;
  }
  const int b = scene.find_body(o.bodies.at(0));
  switch (o.quantity) {
    case Quantity::distance:
      return norm(world.pose(b).position - world.pose(scene.find_body(o.bodies.at(1))).position);
    case Quantity::height: return world.pose(b).position.z;
    case Quantity::speed: return norm(world.velocity(b));
    case Quantity::contact_count: return world.contact_count(b);
    case Quantity::force: return component_of(magnetics.force(b), o.component);
    case Quantity::moment: return component_of(magnetics.moment(b), o.component);
    case Quantity::count_above: break;
  }
  return 0.0;
}

void OutcomeRecorder::sample(const SceneDescription& scene, double time, double dt, const RigidWorld& world,
                             const MagneticForces& magnetics) {
  for (size_t i = 0; i < scene.outcomes.size(); ++i) {
    const OutcomeDescription& o = scene.outcomes[i];
    if (o.statistic != Statistic::none) {
      if (time + 0.5 * dt < o.from) continue;
      const double v = outcome_value(o, scene, world, magnetics);
      if (!seen_[i]) running_[i] = v;
      else if (o.statistic == Statistic::max) running_[i] = std::max(running_[i], v);
      else if (o.statistic == Statistic::min) running_[i] = std::min(running_[i], v);
      else running_[i] += v;  // mean: the sum, divided at the end
      ++seen_[i];
    } else if (o.time >= 0.0 && !values_.count(o.name) && time + 0.5 * dt >= o.time) {
      values_[o.name] = outcome_value(o, scene, world, magnetics);
    }
  }
}

void OutcomeRecorder::finish(const SceneDescription& scene, const RigidWorld& world, const MagneticForces& magnetics) {
  for (size_t i = 0; i < scene.outcomes.size(); ++i) {
    const OutcomeDescription& o = scene.outcomes[i];
    if (values_.count(o.name)) continue;
    if (o.statistic != Statistic::none) {
      if (seen_[i]) {
        values_[o.name] = o.statistic == Statistic::mean ? running_[i] / static_cast<double>(seen_[i]) : running_[i];
      } else if (o.from <= 0.0) {  // no step taken: the state now
        values_[o.name] = outcome_value(o, scene, world, magnetics);
      }  // a start time the run did not reach: left out
    } else if (o.time < 0.0) {
      values_[o.name] = outcome_value(o, scene, world, magnetics);
    }  // a time the run did not reach: left out
  }
}

}  // namespace odemag
