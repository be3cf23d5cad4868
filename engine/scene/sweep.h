// Parameter sweeps (docs/sweeps.md): a spec file names a base scene and
// overrides by key path into its JSON ("materials.steel.susceptibility",
// "bodies[3].position[2]"), as a grid or a list of variants. This is the one
// place that reads specs and builds variant scenes; `odemag sweep`
// (cli/sweep.cpp) runs them, and the Dask runner (python/odemag/sweeps.py)
// gets them from it.
#pragma once

#include <cstddef>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "odemag/scene.h"

namespace odemag {

// One component of a key path: an object key, or an array index.
struct KeyPathStep {
  std::string key;       // object member ("" for an index)
  long long index = -1;  // >= 0: array element
};

// "a.b[2].c" -> {a, b, [2], c}. Throws std::invalid_argument with the reason
// (empty component, unclosed bracket, an index that is not a number).
std::vector<KeyPathStep> parse_key_path(const std::string& path);

struct SweepVariant {
  size_t index = 0;
  // Key path -> value as JSON text, in the order of the spec's columns; only
  // the keys this variant sets (a `variants` entry may leave some out).
  std::vector<std::pair<std::string, std::string>> overrides;
  std::string scene_json;  // the variant scene as JSON text, valid for parse_scene
  SceneDescription scene;  // and as the loader read it
};

class Sweep {
 public:
  // Reads and checks the spec and its base scene: unknown spec keys, values
  // of the wrong type, malformed key paths, and key paths that do not reach
  // into the base scene throw SceneError naming the spec and the key (an
  // error of the base scene itself names the scene file).
  static Sweep load(const std::string& spec_path);

  const std::string& spec_file() const;
  const std::string& scene_file() const;  // the base scene, as opened (relative to the spec's folder)
  const SceneDescription& base() const;
  size_t size() const;                                 // variant count
  const std::vector<std::string>& columns() const;     // override key paths, in spec order
  const std::vector<std::string>& collect() const;     // figures to collect (default: the base scene's outcomes)
  const std::vector<std::string>& run_arguments() const;  // spec "run": extra `odemag run` arguments

  // Variant i (0 <= i < size()): the base with `set`, then its overrides,
  // applied, and read by the scene loader. Throws SceneError naming the spec,
  // the variant and the key.
  SweepVariant variant(size_t i) const;

 private:
  struct Data;
  std::shared_ptr<const Data> data_;
};

}  // namespace odemag
