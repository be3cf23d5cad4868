// The text of scene files and their key tables, as the loader reads them
// (engine/scene/scene.cpp): for the sweep specs, the tests and the fuzzers.
#pragma once

#include <string>
#include <vector>

#include "odemag/scene.h"

namespace odemag {

// One key of a scene object as the loader reads it (engine/scene/scene.cpp reads
// every object through a table with one rule per key) and as
// docs/scene-format.md documents it; tests/cli/scene_keys_test.cpp checks the
// docs' key tables against these.
struct SceneKeyDoc {
  std::string section;  // the object: "" (top level), "materials.soft", "bodies[]", "solver", "timeline[].add", ...
  std::string key;
  std::string type;           // the docs' type column ("vector", "number", ...); "" where undocumented
  std::string unit;           // the docs' unit column; "" where empty or the table has none
  std::string default_value;  // the docs' default column ("`0`", "**required**", ...)
  bool required = false;
  // A plain key's value before the file sets it, from the description
  // structs, as JSON text ("0", "[0.0,0.0,-9.81]", "\"\""); "" for keys read
  // by their own code and for unset optionals.
  std::string struct_default;
};

// Every key of every scene object, table by table, in the order the loader
// reads them and lists them in "unknown key" messages.
std::vector<SceneKeyDoc> scene_key_docs();

// The text of a scene (or sweep spec) file, read in pieces up to 256 MiB.
// Throws SceneError(path, "", ...) when it cannot be read.
std::string read_json_file(const std::string& path);
// The checks parse_scene makes on the text before it reads any key: valid,
// finite JSON without NUL bytes, duplicate keys or nesting beyond 64 levels.
// Throws SceneError naming `file` (and the key path where the text failed).
// Sweep specs (engine/scene/sweep.h) are read through it too.
void check_json_text(const std::string& json_text, const std::string& file);

}  // namespace odemag
