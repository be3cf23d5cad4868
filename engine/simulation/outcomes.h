// Scene outcomes (docs/scene-format.md "outcomes"): the numbers a run reports
// in its summary, taken from the rigid world and the magnetics at a time, at
// the end, or as the largest, smallest or mean value over the rigid steps.
#pragma once

#include <map>
#include <string>
#include <vector>

#include "odemag/magnetic_forces.h"
#include "odemag/scene.h"
#include "engine/simulation/rigid_world.h"

namespace odemag {

// The outcome's quantity in the current state.
double outcome_value(const OutcomeDescription& o, const SceneDescription& scene, const RigidWorld& world,
                     const MagneticForces& magnetics);

class OutcomeRecorder {
 public:
  explicit OutcomeRecorder(const SceneDescription& scene)
      : running_(scene.outcomes.size()), seen_(scene.outcomes.size(), 0) {}
  // After every rigid step, and at t = 0: the statistics' running values and
  // the outcomes due at `time` (within half a step dt).
  void sample(const SceneDescription& scene, double time, double dt, const RigidWorld& world,
              const MagneticForces& magnetics);
  // The end of the run: outcomes without a time, and the statistics' values.
  void finish(const SceneDescription& scene, const RigidWorld& world, const MagneticForces& magnetics);
  const std::map<std::string, double>& values() const { return values_; }

 private:
  std::map<std::string, double> values_;
  std::vector<double> running_;  // per outcome: max, min or sum so far (statistics)
  std::vector<long> seen_;       // per outcome: the samples in running_
};

}  // namespace odemag
