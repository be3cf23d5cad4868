// Sweep specs -> variant scenes (engine/scene/sweep.h, docs/sweeps.md).
#include "engine/scene/sweep.h"

#include <filesystem>
#include <set>
#include <stdexcept>

#include <nlohmann/json.hpp>

#include "engine/scene/scene_text.h"

namespace odemag {

namespace {

// A variant's scene is written to its own folder (odemag sweep): mesh files
// named relative to the base scene's folder become absolute paths, so that
// the variant reads the same files (docs/scene-format.md "Meshes").
void absolute_mesh_files(nlohmann::ordered_json& scene, const std::string& scene_file) {
  const std::filesystem::path folder = std::filesystem::absolute(scene_file).parent_path();
  auto fix_shape = [&](nlohmann::ordered_json& shape) {
    if (!shape.is_object()) return;
    const auto mesh = shape.find("mesh");
    if (mesh == shape.end() || !mesh->is_object()) return;
    const auto file = mesh->find("file");
    if (file == mesh->end() || !file->is_string()) return;
    const std::filesystem::path path = file->get<std::string>();
    if (path.is_relative()) *file = (folder / path).lexically_normal().string();
  };
  const auto bodies = scene.find("bodies");
  if (bodies == scene.end() || !bodies->is_array()) return;
  for (nlohmann::ordered_json& body : *bodies) {
    if (!body.is_object() || !body.contains("shape")) continue;
    nlohmann::ordered_json& shape = body["shape"];
    fix_shape(shape);
    if (shape.is_object() && shape.contains("compound") && shape["compound"].is_array())
      for (nlohmann::ordered_json& part : shape["compound"])
        if (part.is_object() && part.contains("shape")) fix_shape(part["shape"]);
  }
}

}  // namespace

namespace {

using json = nlohmann::ordered_json;  // keeps the scene's and the spec's key order

// More variants than this is a mistake in the spec, not a sweep.
constexpr double kMaxVariants = 1e6;

struct Override {
  std::string path;
  std::vector<KeyPathStep> steps;
  json value;
};

std::string json_string(const std::string& s) { return json(s).dump(); }

std::string step_text(const std::vector<KeyPathStep>& steps, size_t n) {
  std::string p;
  for (size_t i = 0; i < n; ++i) {
    if (steps[i].index >= 0) {
      p += '[';
      p += std::to_string(steps[i].index);
      p += ']';
    } else {
      if (i) p += '.';
      p += steps[i].key;
    }
  }
  return p;
}

// The value at the path, for writing; "" and the value's address, or the
// reason it cannot be reached. The last step may name a new key of an
// existing object (the scene loader then rejects it unless the scene format
// knows it); everything else must exist in the scene.
std::pair<std::string, json*> reach(json& root, const std::vector<KeyPathStep>& steps) {
  json* at = &root;
  for (size_t i = 0; i < steps.size(); ++i) {
    const KeyPathStep& s = steps[i];
    const std::string where = i ? step_text(steps, i) : "the scene";
    const bool last = i + 1 == steps.size();
    if (s.index >= 0) {
      if (!at->is_array()) return {where + " is not an array", nullptr};
      if (static_cast<size_t>(s.index) >= at->size())
        return {where + " has " + std::to_string(at->size()) + " elements, no [" + std::to_string(s.index) + "]",
                nullptr};
      at = &(*at)[static_cast<size_t>(s.index)];
    } else {
      if (!at->is_object()) return {where + " is not an object", nullptr};
      if (!at->contains(s.key) && !last) return {where + " has no key " + json_string(s.key), nullptr};
      at = &(*at)[s.key];
    }
  }
  return {"", at};
}

}  // namespace

std::vector<KeyPathStep> parse_key_path(const std::string& path) {
  std::vector<KeyPathStep> steps;
  size_t i = 0;
  while (i < path.size()) {
    if (path[i] == '[') {
      const size_t close = path.find(']', i);
      if (close == std::string::npos) throw std::invalid_argument("'[' at offset " + std::to_string(i) + " is not closed");
      const std::string digits = path.substr(i + 1, close - i - 1);
      if (digits.empty() || digits.size() > 9 || digits.find_first_not_of("0123456789") != std::string::npos)
        throw std::invalid_argument("[" + digits + "] is not an array index (a number from 0)");
      if (steps.empty()) throw std::invalid_argument("a key path starts with a key, not an index");
      steps.push_back({"", std::stoll(digits)});
      i = close + 1;
      if (i < path.size() && path[i] != '[' && path[i] != '.')
        throw std::invalid_argument("expected '.' or '[' after [" + digits + "]");
      if (i < path.size() && path[i] == '.') {
        ++i;
        if (i == path.size()) throw std::invalid_argument("ends with '.'");
      }
      continue;
    }
    const size_t end = path.find_first_of(".[]", i);
    const std::string key = path.substr(i, end == std::string::npos ? std::string::npos : end - i);
    if (key.empty()) throw std::invalid_argument("empty key at offset " + std::to_string(i));
    steps.push_back({key, -1});
    i = end == std::string::npos ? path.size() : end;
    if (i < path.size() && path[i] == ']') throw std::invalid_argument("']' without '['");
    if (i < path.size() && path[i] == '.') {
      ++i;
      if (i == path.size()) throw std::invalid_argument("ends with '.'");
    }
  }
  if (steps.empty()) throw std::invalid_argument("empty key path");
  return steps;
}

struct Sweep::Data {
  std::string spec_file, scene_file;
  json base;
  SceneDescription base_scene;
  std::vector<Override> set;
  std::vector<std::string> columns, collect, run_arguments;
  // A grid: one axis per column, the first varying slowest; or a list.
  std::vector<std::vector<json>> axes;
  std::vector<std::vector<Override>> variants;
  size_t size = 0;

  [[noreturn]] void fail(const std::string& key, const std::string& message) const {
    throw SceneError(spec_file, key, message);
  }

  // One override of the spec at `key` ("grid[\"a.b\"]"): parsed, and checked
  // against the base scene.
  Override make_override(const std::string& key, const std::string& path, const json& value) const {
    Override o{path, {}, value};
    try {
      o.steps = parse_key_path(path);
    } catch (const std::invalid_argument& e) {
      fail(key, "malformed key path " + json_string(path) + ": " + e.what());
    }
    json probe = base;
    if (const std::string why = reach(probe, o.steps).first; !why.empty())
      fail(key, "key path " + json_string(path) + " is not in the base scene " + scene_file + ": " + why);
    return o;
  }

  std::vector<std::string> string_list(const json& spec, const char* key) const {
    std::vector<std::string> out;
    if (!spec.contains(key)) return out;
    const json& v = spec[key];
    if (!v.is_array()) fail(key, "expected an array of strings");
    for (size_t i = 0; i < v.size(); ++i) {
      if (!v[i].is_string()) fail(std::string(key) + "[" + std::to_string(i) + "]", "expected a string");
      out.push_back(v[i].get<std::string>());
    }
    return out;
  }
};

Sweep Sweep::load(const std::string& spec_path) {
  auto d = std::make_shared<Data>();
  d->spec_file = spec_path;
  const std::string text = read_json_file(spec_path);
  check_json_text(text, spec_path);
  const json spec = json::parse(text);
  if (!spec.is_object()) d->fail("", "a sweep spec must be a JSON object {...}");
  static const std::set<std::string> kKeys = {"scene", "set", "grid", "variants", "collect", "run"};
  for (const auto& [key, value] : spec.items())
    if (!kKeys.count(key)) d->fail(key, "unknown key (keys: scene, set, grid, variants, collect, run)");

  if (!spec.contains("scene") || !spec["scene"].is_string() || spec["scene"].get<std::string>().empty())
    d->fail("scene", "required: the base scene file, relative to the spec's folder");
  const std::filesystem::path scene = spec["scene"].get<std::string>();
  d->scene_file = scene.is_absolute() ? scene.string()
                                      : (std::filesystem::path(spec_path).parent_path() / scene).string();
  const std::string scene_text = read_json_file(d->scene_file);
  d->base_scene = parse_scene(scene_text, d->scene_file);  // a bad base scene names its own file
  d->base = json::parse(scene_text);

  std::set<std::string> paths;  // each key path once, in `set` or in the columns
  if (spec.contains("set")) {
    if (!spec["set"].is_object()) d->fail("set", "expected an object {key path: value}");
    for (const auto& [path, value] : spec["set"].items()) {
      d->set.push_back(d->make_override("set[" + json_string(path) + "]", path, value));
      paths.insert(path);
    }
  }
  const bool grid = spec.contains("grid"), list = spec.contains("variants");
  if (grid == list) d->fail(grid ? "variants" : "grid", "give either grid or variants, not both and not neither");
  if (grid) {
    const json& g = spec["grid"];
    if (!g.is_object() || g.empty()) d->fail("grid", "expected an object {key path: [values...]} with a key");
    double count = 1;
    for (const auto& [path, values] : g.items()) {
      const std::string key = "grid[" + json_string(path) + "]";
      if (!values.is_array() || values.empty()) d->fail(key, "expected a non-empty array of values");
      if (!paths.insert(path).second) d->fail(key, "the key path is also in set");
      d->make_override(key, path, values[0]);
      d->columns.push_back(path);
      d->axes.emplace_back(values.begin(), values.end());
      count *= static_cast<double>(values.size());
    }
    if (count > kMaxVariants) d->fail("grid", "the grid has more than 1e6 variants");
    d->size = static_cast<size_t>(count);
  } else {
    const json& v = spec["variants"];
    if (!v.is_array() || v.empty()) d->fail("variants", "expected a non-empty array of {key path: value} objects");
    if (static_cast<double>(v.size()) > kMaxVariants) d->fail("variants", "more than 1e6 variants");
    std::set<std::string> column_set;
    for (size_t i = 0; i < v.size(); ++i) {
      const std::string at = "variants[" + std::to_string(i) + "]";
      if (!v[i].is_object()) d->fail(at, "expected an object {key path: value}");
      std::vector<Override> overrides;
      for (const auto& [path, value] : v[i].items()) {
        const std::string key = at + "[" + json_string(path) + "]";
        if (paths.count(path)) d->fail(key, "the key path is also in set");
        overrides.push_back(d->make_override(key, path, value));
        if (column_set.insert(path).second) d->columns.push_back(path);
      }
      d->variants.push_back(std::move(overrides));
    }
    d->size = v.size();
  }

  d->collect = d->string_list(spec, "collect");
  if (!spec.contains("collect"))
    for (const OutcomeDescription& o : d->base_scene.outcomes) d->collect.push_back(o.name);
  std::set<std::string> seen;
  for (size_t i = 0; i < d->collect.size(); ++i)
    if (d->collect[i].empty() || !seen.insert(d->collect[i]).second)
      d->fail("collect[" + std::to_string(i) + "]", "empty or repeated name " + json_string(d->collect[i]));
  d->run_arguments = d->string_list(spec, "run");

  Sweep s;
  s.data_ = std::move(d);
  return s;
}

const std::string& Sweep::spec_file() const { return data_->spec_file; }
const std::string& Sweep::scene_file() const { return data_->scene_file; }
const SceneDescription& Sweep::base() const { return data_->base_scene; }
size_t Sweep::size() const { return data_->size; }
const std::vector<std::string>& Sweep::columns() const { return data_->columns; }
const std::vector<std::string>& Sweep::collect() const { return data_->collect; }
const std::vector<std::string>& Sweep::run_arguments() const { return data_->run_arguments; }

SweepVariant Sweep::variant(size_t i) const {
  const Data& d = *data_;
  if (i >= d.size) throw std::out_of_range("variant " + std::to_string(i) + " of " + std::to_string(d.size));
  std::vector<Override> overrides;
  if (!d.axes.empty()) {
    size_t rest = i;
    overrides.resize(d.axes.size());
    for (size_t k = d.axes.size(); k-- > 0;) {
      const std::vector<json>& axis = d.axes[k];
      overrides[k] = {d.columns[k], parse_key_path(d.columns[k]), axis[rest % axis.size()]};
      rest /= axis.size();
    }
  } else {
    overrides = d.variants[i];
  }
  SweepVariant v;
  v.index = i;
  json scene = d.base;
  std::string described;
  for (const std::vector<Override>* list : {&d.set, static_cast<const std::vector<Override>*>(&overrides)})
    for (const Override& o : *list) {
      *reach(scene, o.steps).second = o.value;  // reachable: checked by make_override
      if (list == &overrides) {
        v.overrides.emplace_back(o.path, o.value.dump());
        described += (described.empty() ? "" : ", ") + o.path + " = " + o.value.dump();
      }
    }
  absolute_mesh_files(scene, d.scene_file);
  v.scene_json = scene.dump(1) + "\n";
  try {
    v.scene = parse_scene(v.scene_json, d.scene_file);
  } catch (const SceneError& e) {
    throw SceneError(d.spec_file, e.key(),
                     "variant " + std::to_string(i) + " (" + described + ") of " + d.scene_file + ": " + e.message());
  }
  return v;
}

}  // namespace odemag
