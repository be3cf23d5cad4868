// Scene files: JSON text -> validated SceneDescription (docs/scene-format.md).
//
// Every value is checked where it is read, and every failure names the file
// and the JSON key path of the offending value ("bodies[2].shape.sphere").
#include "odemag/scene.h"
#include "engine/scene/scene_text.h"

#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <initializer_list>
#include <type_traits>
#include <limits>
#include <set>
#include <sstream>
#include <string_view>
#include <utility>
#include <variant>
#include <vector>

#include <nlohmann/json.hpp>

#include "engine/scene/mesh_file.h"
#include "magnetics/cells/compound.h"
#include "magnetics/cells/mesh.h"
#include "magnetics/materials/bh_curve.h"
#include "magnetics/model/model.h"
#include "odemag/constants.h"

namespace odemag {

SceneError::SceneError(std::string file, std::string key, std::string message)
    : std::runtime_error(key.empty() ? file + ": " + message : file + ": " + key + ": " + message),
      file_(std::move(file)), key_(std::move(key)), message_(std::move(message)) {}

int SceneDescription::find_body(const std::string& name) const {
  for (size_t b = 0; b < bodies.size(); ++b)
    if (bodies[b].name == name) return static_cast<int>(b);
  return -1;
}

double lattice_spacing(const BodyDescription& body, double scene_cell_size) {
  if (body.cell_size) return *body.cell_size;
  return std::holds_alternative<Sphere>(body.shape) ? 0.0 : scene_cell_size;
}

double SceneDescription::body_cell_size(int b) const { return lattice_spacing(bodies[b], cell_size); }

namespace {

using json = nlohmann::json;

// The deepest scene value is 5 levels down (timeline[0].keys[0].position[0]);
// deeper nesting is rejected while parsing, so that a file of a million '['
// fails at once instead of building a million-level tree (docs/testing.md, fuzzing findings).
constexpr size_t kMaxNesting = 64;

// The largest magnitude a scene value of a kind may have: odemag/constants.h
// (docs/scene-format.md "Ranges"), shared with the controls of the APIs. A
// magnetization of 1e160 A/m made moments whose squares overflow: the
// relaxation failed instead of the loader naming the key.
using namespace ranges;
// A shape's radius, side or length is at least this (its volume must not
// underflow to a zero moment), m.
constexpr double kMinSize = 1e-9;

std::string member(const std::string& path, std::string_view key) {
  return path.empty() ? std::string(key) : path + "." + std::string(key);
}

std::string element(const std::string& path, size_t index) {
  return path + "[" + std::to_string(index) + "]";
}

// A string as a JSON literal, for messages (escapes quotes and control characters).
std::string as_literal(const std::string& s) {
  return json(s).dump(-1, ' ', false, json::error_handler_t::replace);
}

std::string format_number(double x) { return json(x).dump(); }

// Three significant digits: 1e+09, 1.5e+160.
std::string short_number(double x) {
  char text[32];
  std::snprintf(text, sizeof text, "%.3g", x);
  return text;
}

// A first pass over the text (SAX: no tree is built) that checks what the
// parser itself does not -- nesting depth, duplicate keys -- and, when the
// parser fails, knows the key path where it failed ("bodies[2].shape"). The
// tree is then built by a plain json::parse. (nlohmann's parse with a
// callback, which this pass replaces, takes time quadratic in the length of
// an array of objects; docs/testing.md, fuzzing findings.)
class PathTracker : public nlohmann::json_sax<json> {
 public:
  explicit PathTracker(const std::string& file) : file_(file) {}

  // The parser's error, when it failed (json::sax_parse returned false).
  const std::optional<std::string>& error() const { return error_; }
  int error_id() const { return error_id_; }

  bool null() override { return value(); }
  bool boolean(bool) override { return value(); }
  bool number_integer(number_integer_t) override { return value(); }
  bool number_unsigned(number_unsigned_t) override { return value(); }
  bool number_float(number_float_t, const string_t&) override { return value(); }
  bool string(string_t&) override { return value(); }
  bool binary(binary_t&) override { return value(); }
  bool start_object(std::size_t) override { return start(false); }
  bool start_array(std::size_t) override { return start(true); }
  bool end_object() override { return end(); }
  bool end_array() override { return end(); }
  bool key(string_t& name) override {
    Frame& top = frames_.back();
    top.key = name;
    if (!top.keys.insert(top.key).second) throw SceneError(file_, path(), "key appears twice in the same object");
    return true;
  }
  bool parse_error(std::size_t, const std::string&, const nlohmann::detail::exception& e) override {
    error_ = e.what();
    error_id_ = e.id;
    return false;
  }

  // Key path of the value being read.
  std::string path() const {
    std::string p;  // appended in place: linear in the length of the path
    for (const Frame& f : frames_) {
      if (f.array) {
        p += '[';
        p += std::to_string(f.index);
        p += ']';
      } else {
        if (!p.empty()) p += '.';
        p += f.key;
      }
    }
    return p;
  }

 private:
  struct Frame {
    bool array;
    size_t index;                // array: the element being read
    std::string key;             // object: the member being read
    std::set<std::string> keys;  // object: the keys seen so far
  };
  bool start(bool array) {
    if (frames_.size() >= kMaxNesting)
      throw SceneError(file_, path(), "nested more than " + std::to_string(kMaxNesting) + " levels deep");
    frames_.push_back({array, 0, {}, {}});
    return true;
  }
  bool end() {
    frames_.pop_back();
    return value();
  }
  bool value() {
    if (!frames_.empty() && frames_.back().array) ++frames_.back().index;
    return true;
  }

  const std::string& file_;
  std::vector<Frame> frames_;
  std::optional<std::string> error_;
  int error_id_ = 0;
};

// nlohmann's what() starts with "[json.exception.NAME.ID] "; drop that.
std::string without_exception_tag(const std::string& what) {
  if (what.rfind("[json.exception.", 0) == 0) {
    const size_t end = what.find("] ");
    if (end != std::string::npos) return what.substr(end + 2);
  }
  return what;
}

// Reads typed values out of the JSON tree; every failure names its key path.
class SceneReader {
 public:
  explicit SceneReader(const std::string& file) : file_(file) {}

  [[noreturn]] void fail(const std::string& path, const std::string& message) const {
    throw SceneError(file_, path, message);
  }

  void require_object(const json& v, const std::string& path) const {
    if (!v.is_object()) fail(path, "must be an object {...}, got " + describe(v));
  }

  const json& required(const json& obj, std::string_view key, const std::string& path) const {
    const auto it = obj.find(key);
    if (it == obj.end()) fail(member(path, key), "required key is missing");
    return *it;
  }

  double number(const json& v, const std::string& path) const {
    if (!v.is_number()) fail(path, "must be a number, got " + describe(v));
    const double x = v.get<double>();
    if (!std::isfinite(x)) fail(path, "must be a finite number");
    return x;
  }
  double positive(const json& v, const std::string& path) const {
    const double x = number(v, path);
    if (!(x > 0.0)) fail(path, "must be > 0, got " + format_number(x));
    return x;
  }
  double non_negative(const json& v, const std::string& path) const {
    const double x = number(v, path);
    if (!(x >= 0.0)) fail(path, "must be >= 0, got " + format_number(x));
    return x;
  }
  double in_range(const json& v, const std::string& path, double lo, double hi) const {
    const double x = number(v, path);
    if (!(x >= lo && x <= hi))
      fail(path, "must be in " + format_number(lo) + ".." + format_number(hi) + ", got " +
                     format_number(x));
    return x;
  }

  // x, or a failure when |x| exceeds the bound.
  double bounded(double x, const std::string& path, const Magnitude& bound) const {
    if (bound.max > 0.0 && std::abs(x) > bound.max)
      fail(path, "magnitude " + short_number(std::abs(x)) + " " + bound.unit + " exceeds the largest accepted, " +
                     short_number(bound.max) + " " + bound.unit + " (docs/scene-format.md \"Ranges\")");
    return x;
  }
  // v, or a failure when its length exceeds the bound.
  Vec3 bounded(const Vec3& v, const std::string& path, const Magnitude& bound) const {
    if (bound.max <= 0.0) return v;
    const double largest = std::max({std::abs(v.x), std::abs(v.y), std::abs(v.z)});
    bounded(largest > bound.max ? largest : norm(v), path, bound);  // norm(v) cannot overflow here
    return v;
  }
  // A shape's radius, side or length: kMinSize .. kLength.max, m.
  double size(const json& v, const std::string& path) const {
    const double x = bounded(positive(v, path), path, kLength);
    if (x < kMinSize) fail(path, "must be at least " + format_number(kMinSize) + " m, got " + format_number(x));
    return x;
  }

  // An integer in lo..hi; a JSON number with a fractional part is rejected.
  long long integer(const json& v, const std::string& path, long long lo, long long hi) const {
    const std::string range = "an integer in " + std::to_string(lo) + ".." + std::to_string(hi);
    if (v.is_number_unsigned()) {
      const auto u = v.get<unsigned long long>();
      if (u > static_cast<unsigned long long>(hi) || static_cast<long long>(u) < lo)
        fail(path, "must be " + range + ", got " + std::to_string(u));
      return static_cast<long long>(u);
    }
    if (v.is_number_integer()) {
      const auto i = v.get<long long>();
      if (i < lo || i > hi) fail(path, "must be " + range + ", got " + std::to_string(i));
      return i;
    }
    const double x = number(v, path);
    if (x != std::floor(x)) fail(path, "must be an integer, got " + format_number(x));
    if (x < static_cast<double>(lo) || x > static_cast<double>(hi))
      fail(path, "must be " + range + ", got " + format_number(x));
    return static_cast<long long>(x);
  }
  int int_value(const json& v, const std::string& path, int lo, int hi) const {
    return static_cast<int>(integer(v, path, lo, hi));
  }

  bool boolean(const json& v, const std::string& path) const {
    if (!v.is_boolean()) fail(path, "must be true or false, got " + describe(v));
    return v.get<bool>();
  }

  std::string string(const json& v, const std::string& path) const {
    if (!v.is_string()) fail(path, "must be a string, got " + describe(v));
    return v.get<std::string>();
  }
  std::string non_empty_string(const json& v, const std::string& path) const {
    std::string s = string(v, path);
    if (s.empty()) fail(path, "must not be empty");
    return s;
  }
  // One of the given words.
  std::string choice(const json& v, const std::string& path,
                     const std::vector<std::string_view>& words) const {
    const std::string s = string(v, path);
    std::string list;
    for (std::string_view w : words) {
      if (s == w) return s;
      list += (list.empty() ? "" : ", ") + std::string(w);
    }
    fail(path, as_literal(s) + " is not one of: " + list);
  }

  void require_array(const json& v, const std::string& path, size_t size) const {
    if (!v.is_array() || v.size() != size)
      fail(path, "must be an array of " + std::to_string(size) + " numbers, got " + describe(v));
  }
  Vec3 vec3(const json& v, const std::string& path) const {
    require_array(v, path, 3);
    return {number(v[0], element(path, 0)), number(v[1], element(path, 1)),
            number(v[2], element(path, 2))};
  }
  Vec3 non_zero_vec3(const json& v, const std::string& path) const {
    const Vec3 a = vec3(v, path);
    if (a.x == 0.0 && a.y == 0.0 && a.z == 0.0) fail(path, "must not be the zero vector");
    // Its length is computed as sqrt(x^2 + y^2 + z^2): [1e-200, 0, 0] would
    // have length 0 and [1e200, 0, 0] length infinity (docs/testing.md, fuzzing findings).
    const double n = norm(a);
    if (!(n > 0.0) || !std::isfinite(n))
      fail(path, "components too small or too large (the length must be between about 1e-150 and 1e150)");
    return a;
  }
  std::array<double, 3> color(const json& v, const std::string& path) const {
    require_array(v, path, 3);
    std::array<double, 3> rgb{};
    for (size_t i = 0; i < 3; ++i) rgb[i] = in_range(v[i], element(path, i), 0.0, 1.0);
    return rgb;
  }
  // [w, x, y, z], normalised.
  Quaternion quaternion(const json& v, const std::string& path) const {
    require_array(v, path, 4);
    double q[4], largest = 0.0;
    for (size_t i = 0; i < 4; ++i) {
      q[i] = number(v[i], element(path, i));
      largest = std::max(largest, std::abs(q[i]));
    }
    if (!(largest > 0.0)) fail(path, "must be a non-zero quaternion [w, x, y, z]");
    // Scaled by the largest component first: [1e300, 0, 0, 0] and
    // [1e-300, 0, 0, 0] are the identity, not an overflow or a zero.
    for (double& c : q) c /= largest;
    const double n = std::sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]);
    return {q[0] / n, q[1] / n, q[2] / n, q[3] / n};
  }

  const std::string& file() const { return file_; }
  // A line for SceneDescription::notices: "KEY: message".
  void notice(const std::string& path, const std::string& message) const { notices_.push_back(path + ": " + message); }
  const std::vector<std::string>& notices() const { return notices_; }

 private:
  mutable std::vector<std::string> notices_;
  static std::string describe(const json& v) {
    if (v.is_array()) return "an array of " + std::to_string(v.size());
    if (v.is_object()) return "an object";
    if (v.is_string()) return "the string " + as_literal(v.get<std::string>());
    if (v.is_boolean()) return v.get<bool>() ? "true" : "false";
    if (v.is_null()) return "null";
    return "the number " + v.dump();
  }

  const std::string& file_;
};

// ---- the key tables -----------------------------------------------------------
//
// Every JSON object of a scene is read through a table with one KeyRule per
// key: the table is the list of allowed keys (an unknown key is rejected with
// the table's names, in table order), says how each present key is checked and
// where its value goes, and carries the key's row of docs/scene-format.md
// (scene_key_docs; tests/cli/scene_keys_test.cpp checks the docs against it).
// Keys are read in table order, those marked `late` after the others.

// Where a plain key's value is stored.
using Slot = std::variant<double*, std::optional<double>*, int*, bool*, std::string*, Vec3*, Quaternion*,
                          std::optional<std::array<double, 3>>*>;

// How a plain key's value is checked; custom: the rule's own reader.
enum class Check {
  custom, number, positive, non_negative, in_range, integer, boolean, string, non_empty_string,
  vec3, non_zero_vec3, color, quaternion
};

// The key's row in docs/scene-format.md: type, unit, default ("" where the docs
// leave the cell empty or the table has no such column).
struct KeyDoc {
  const char* type = "";
  const char* unit = "";
  const char* fallback = "";
};

template <class T>
struct KeyRule {
  const char* name;
  Check check = Check::custom;
  Slot (*slot)(T&) = nullptr;                                                        // plain keys
  void (*read)(const SceneReader&, const json&, const std::string&, T&) = nullptr;  // Check::custom
  double lo = 0.0, hi = 0.0;                  // in_range, integer
  Magnitude bound = {};                       // number, positive, non_negative, vec3: largest magnitude
  bool required = false;
  // Read after the other keys: of several bad values the one reported first
  // stays the one reported before the tables (solver.far_field_theta after
  // near_field, an event's optional keyframes time after its keys).
  bool late = false;
  KeyDoc doc = {};
};

template <class T>
using KeyTable = std::vector<KeyRule<T>>;

// A key whose value is one of a few words, each naming a value of an enum:
// the pairs in the order that "is not one of" messages list the words.
template <class E, size_t N>
using Choices = std::array<std::pair<std::string_view, E>, N>;

template <class E, size_t N>
E read_choice(const SceneReader& r, const json& x, const std::string& p, const Choices<E, N>& choices) {
  std::vector<std::string_view> words;
  for (const auto& choice : choices) words.push_back(choice.first);
  const std::string word = r.choice(x, p, words);
  for (const auto& choice : choices)
    if (word == choice.first) return choice.second;
  return choices[0].second;  // r.choice throws on any other word
}

const Choices<BackendKind, 3> kBackendChoices = {
    {{"cpu", BackendKind::cpu}, {"cuda", BackendKind::cuda}, {"auto", BackendKind::automatic}}};
const Choices<ContactSolver, 3> kContactSolverChoices = {
    {{"auto", ContactSolver::automatic}, {"quick", ContactSolver::quick}, {"exact", ContactSolver::exact}}};
const Choices<MagneticSolve, 2> kMagneticSolveChoices = {
    {{"substep", MagneticSolve::substep}, {"moving", MagneticSolve::moving}}};
using Statistic = OutcomeDescription::Statistic;
const Choices<Statistic, 3> kStatisticChoices = {
    {{"max", Statistic::max}, {"min", Statistic::min}, {"mean", Statistic::mean}}};

// The slot of a plain key: SLOT(relax.tolerance).
#define SLOT(field) [](auto& t) -> Slot { return &t.field; }

// A key whose value its object's reader has read before the table (a material's
// "type", an event's "action").
constexpr auto kReadBefore = [](const SceneReader&, const json&, const std::string&, auto&) {};

template <class V>
void store(const Slot& slot, V value) {
  std::visit(
      [&](auto* target) {
        using Target = std::remove_pointer_t<decltype(target)>;
        if constexpr (std::is_same_v<Target, V> || std::is_same_v<Target, std::optional<V>>)
          *target = std::move(value);
        else
          throw std::logic_error("scene key table: a slot of the wrong type");
      },
      slot);
}

// v must be an object whose keys are all in the table.
template <class T>
void check_unknown(const SceneReader& r, const json& v, const std::string& path,
                   const KeyTable<T>& table) {
  r.require_object(v, path);
  for (const auto& [key, value] : v.items()) {
    bool known = false;
    for (const KeyRule<T>& rule : table) known = known || key == rule.name;
    if (known) continue;
    std::string list;
    for (const KeyRule<T>& rule : table) list += (list.empty() ? "" : ", ") + std::string(rule.name);
    r.fail(member(path, key), "unknown key (expected one of: " + list + ")");
  }
}

template <class T>
void read_value(const SceneReader& r, const KeyRule<T>& rule, const json& x, const std::string& p,
                T& target) {
  if (rule.check == Check::custom) return rule.read(r, x, p, target);
  const Slot slot = rule.slot(target);
  const auto lo = static_cast<int>(rule.lo), hi = static_cast<int>(rule.hi);
  switch (rule.check) {
    case Check::number: return store(slot, r.bounded(r.number(x, p), p, rule.bound));
    case Check::positive: return store(slot, r.bounded(r.positive(x, p), p, rule.bound));
    case Check::non_negative: return store(slot, r.bounded(r.non_negative(x, p), p, rule.bound));
    case Check::in_range: return store(slot, r.in_range(x, p, rule.lo, rule.hi));
    case Check::integer: return store(slot, r.int_value(x, p, lo, hi));
    case Check::boolean: return store(slot, r.boolean(x, p));
    case Check::string: return store(slot, r.string(x, p));
    case Check::non_empty_string: return store(slot, r.non_empty_string(x, p));
    case Check::vec3: return store(slot, r.bounded(r.vec3(x, p), p, rule.bound));
    case Check::non_zero_vec3: return store(slot, r.bounded(r.non_zero_vec3(x, p), p, rule.bound));
    case Check::color: return store(slot, r.color(x, p));
    case Check::quaternion: return store(slot, r.quaternion(x, p));
    case Check::custom: break;
  }
}

// Reads the keys of v that the table has (a missing required key fails).
template <class T>
void read_present(const SceneReader& r, const json& v, const std::string& path, const KeyTable<T>& table,
                  T& target) {
  for (const bool late : {false, true})
    for (const KeyRule<T>& rule : table) {
      if (rule.late != late) continue;
      const auto it = v.find(rule.name);
      if (it == v.end()) {
        if (rule.required) r.fail(member(path, rule.name), "required key is missing");
        continue;
      }
      read_value(r, rule, *it, member(path, rule.name), target);
    }
}

template <class T>
void read_object(const SceneReader& r, const json& v, const std::string& path, const KeyTable<T>& table,
                 T& target) {
  check_unknown(r, v, path, table);
  read_present(r, v, path, table, target);
}

// ---- materials ------------------------------------------------------------------

// validate_material reports "KEY must ..."; name that key in the path.
std::string material_message_key(const std::string& message) {
  for (std::string_view key : {"magnetization", "recoil_susceptibility", "saturation",
                               "susceptibility", "anisotropy_field", "easy_axis", "damping",
                               "moments_per_cell", "coil_field"})
    if (message.rfind(std::string(key) + " ", 0) == 0) return std::string(key);
  return {};
}

template <class M>
struct MaterialTarget {
  M material;
  std::optional<std::array<double, 3>> color;
};

const KeyTable<MaterialTarget<PermanentMaterial>> kPermanentKeys = {
    {.name = "type", .read = kReadBefore, .required = true, .doc = {"string", "", "**required**"}},
    {.name = "magnetization", .check = Check::vec3, .slot = SLOT(material.magnetization), .bound = kFieldStrength, .required = true,
     .doc = {"vector", "A/m", "**required**"}},
    {.name = "recoil_susceptibility", .check = Check::non_negative, .slot = SLOT(material.recoil_susceptibility),
     .doc = {"number", "", "`0`"}},
    {.name = "color", .check = Check::color, .slot = SLOT(color),
     .doc = {"[r, g, b]", "", "material default"}},
};

const KeyTable<MaterialTarget<SoftMaterial>> kSoftKeys = {
    {.name = "type", .read = kReadBefore, .required = true, .doc = {"string", "", "**required**"}},
    {.name = "saturation", .check = Check::positive, .slot = SLOT(material.saturation), .bound = kFieldStrength,
     .doc = {"number", "A/m", "required without `bh_curve`"}},
    {.name = "susceptibility",
     .read = [](const SceneReader& r, const json& x, const std::string& p, MaterialTarget<SoftMaterial>& t) {
       if (x.is_string()) {
         if (x.get<std::string>() != "infinite") r.fail(p, "must be a number > 0 or the string \"infinite\"");
         t.material.susceptibility = std::numeric_limits<double>::infinity();
       } else {
         t.material.susceptibility = r.positive(x, p);
       }
     },
     .doc = {"number or `\"infinite\"`", "", "`\"infinite\"`"}},
    {.name = "anisotropy_field", .check = Check::non_negative, .slot = SLOT(material.anisotropy_field), .bound = kFieldStrength,
     .doc = {"number", "A/m", "`0`"}},
    {.name = "easy_axis", .check = Check::non_zero_vec3, .slot = SLOT(material.easy_axis),
     .doc = {"vector", "", "`[0, 0, 1]`"}},
    {.name = "damping", .check = Check::positive, .slot = SLOT(material.damping),
     .doc = {"number", "", "`1`"}},
    {.name = "moments_per_cell",
     .read = [](const SceneReader& r, const json& x, const std::string& p, MaterialTarget<SoftMaterial>& t) {
       const int n = r.int_value(x, p, 2, kMaxMomentsPerCell);
       if (n % 2 != 0)
         r.fail(p, "must be an even integer from 2 to " + std::to_string(kMaxMomentsPerCell) + ", got " +
                       std::to_string(n));
       t.material.moments_per_cell = n;
     },
     .doc = {"integer", "", "`2`"}},
    {.name = "coil_field", .check = Check::vec3, .slot = SLOT(material.coil_field), .bound = kFieldStrength,
     .doc = {"[x, y, z]", "A/m, body frame", "`[0, 0, 0]`"}},
    {.name = "bh_curve",
     .read = [](const SceneReader& r, const json& x, const std::string& p, MaterialTarget<SoftMaterial>& t) {
       if (!x.is_array() || x.size() < 2) r.fail(p, "must be an array of at least two [H, B] points (A/m, T)");
       for (size_t i = 0; i < x.size(); ++i) {
         r.require_array(x[i], element(p, i), 2);
         t.material.bh_curve.push_back({r.non_negative(x[i][0], element(element(p, i), 0)),
                                        r.non_negative(x[i][1], element(element(p, i), 1))});
       }
       if (const std::string e = bh_curve_error(t.material.bh_curve); !e.empty()) r.fail(p, e);
     },
     .doc = {"[[H, B], ...]", "A/m, T", "none"}},
    {.name = "color", .check = Check::color, .slot = SLOT(color),
     .doc = {"[r, g, b]", "", "material default"}},
};

// A linear medium, M = chi H (diamagnets down to a superconductor's -1,
// paramagnets): a recoil cell with M_r = 0 (docs/model.md "Diamagnets").
const KeyTable<MaterialTarget<PermanentMaterial>> kLinearKeys = {
    {.name = "type", .read = kReadBefore, .required = true, .doc = {"string", "", "**required**"}},
    {.name = "susceptibility", .check = Check::in_range, .slot = SLOT(material.recoil_susceptibility), .lo = -1.0,
     .hi = 1e6, .required = true, .doc = {"number", "", "**required**"}},
    {.name = "color", .check = Check::color, .slot = SLOT(color),
     .doc = {"[r, g, b]", "", "material default"}},
};

const KeyTable<MaterialTarget<InertMaterial>> kInertKeys = {
    {.name = "type", .read = kReadBefore, .required = true, .doc = {"string", "", "**required**"}},
    {.name = "color", .check = Check::color, .slot = SLOT(color),
     .doc = {"[r, g, b]", "", "material default"}},
};

template <class M>
Material read_material_keys(const SceneReader& r, const json& v, const std::string& path,
                            const KeyTable<MaterialTarget<M>>& table,
                            std::optional<std::array<double, 3>>& color) {
  MaterialTarget<M> t;
  read_object(r, v, path, table, t);
  color = t.color;
  return t.material;
}

Material read_material(const SceneReader& r, const json& v, const std::string& path,
                       std::optional<std::array<double, 3>>& color) {
  r.require_object(v, path);
  const std::string type =
      r.choice(r.required(v, "type", path), member(path, "type"), {"permanent", "soft", "linear", "inert"});
  if (type == "soft") {
    // saturation and susceptibility come from a B-H curve where there is one.
    const bool curve = v.contains("bh_curve");
    if (!curve && !v.contains("saturation")) r.fail(member(path, "saturation"), "required key is missing (or give a bh_curve)");
    for (const char* key : {"saturation", "susceptibility"})
      if (curve && v.contains(key)) r.fail(member(path, key), "the bh_curve sets it: leave it out");
  }
  const Material material = type == "permanent" ? read_material_keys(r, v, path, kPermanentKeys, color)
                            : type == "linear"  ? read_material_keys(r, v, path, kLinearKeys, color)
                            : type == "soft"    ? read_material_keys(r, v, path, kSoftKeys, color)
                                                : read_material_keys(r, v, path, kInertKeys, color);
  // The physics checks of the magnetics library, as a backstop.
  if (const std::string e = validate_material(material); !e.empty())
    r.fail(member(path, material_message_key(e)), e);
  return material;
}


// ---- coils (current sources carried by a body) --------------------------------------

template <class S>
struct CoilTarget {
  S source;
};

#define COIL_TYPE {.name = "type", .read = kReadBefore, .required = true}
#define COIL_CENTRE {.name = "centre", .check = Check::vec3, .slot = SLOT(source.centre), .bound = kLength}
#define COIL_AXIS {.name = "axis", .check = Check::non_zero_vec3, .slot = SLOT(source.axis)}
#define COIL_CURRENT {.name = "current", .check = Check::number, .slot = SLOT(source.current), .bound = kCurrent, .required = true}
#define COIL_TURNS {.name = "turns", .check = Check::positive, .slot = SLOT(source.turns), .bound = kTurns}
#define COIL_SIZE(key, field)                                                                       \
  {.name = key, .read = [](const SceneReader& r, const json& x, const std::string& p, auto& t) { \
     t.source.field = r.size(x, p);                                                                \
   },                                                                                              \
   .required = true}
#define COIL_WIRE_RADIUS                                                                       \
  {.name = "wire_radius", .read = [](const SceneReader& r, const json& x, const std::string& p, auto& t) { \
     t.source.wire_radius = r.size(x, p);                                                         \
   }}
#define COIL_QUADRATURE \
  {.name = "quadrature_order", .check = Check::integer, .slot = SLOT(source.quadrature_order), .lo = 1, .hi = 64}

const KeyTable<CoilTarget<CircularLoop>> kLoopKeys = {COIL_TYPE,    COIL_CENTRE, COIL_AXIS, COIL_SIZE("radius", radius),
                                                      COIL_CURRENT, COIL_TURNS,  COIL_WIRE_RADIUS};
const KeyTable<CoilTarget<Solenoid>> kSolenoidKeys = {
    COIL_TYPE, COIL_CENTRE, COIL_AXIS, COIL_SIZE("radius", radius),
    {.name = "length", .check = Check::non_negative, .slot = SLOT(source.length), .bound = kLength, .required = true},
    COIL_CURRENT, COIL_TURNS};
const KeyTable<CoilTarget<CircularCoil>> kCircularCoilKeys = {
    COIL_TYPE,
    COIL_CENTRE,
    COIL_AXIS,
    {.name = "inner_radius", .check = Check::non_negative, .slot = SLOT(source.inner_radius), .bound = kLength,
     .required = true},
    COIL_SIZE("outer_radius", outer_radius),
    COIL_SIZE("length", length),
    COIL_CURRENT,
    COIL_TURNS,
    COIL_QUADRATURE};
const KeyTable<CoilTarget<RoundedRectangleCoil>> kRoundedRectangleKeys = {
    COIL_TYPE,
    COIL_CENTRE,
    COIL_AXIS,
    {.name = "width_direction", .check = Check::non_zero_vec3, .slot = SLOT(source.width_direction)},
    COIL_SIZE("core_half_width", core_half_width),
    COIL_SIZE("core_half_depth", core_half_depth),
    {.name = "inner_corner_radius", .check = Check::non_negative, .slot = SLOT(source.inner_corner_radius),
     .bound = kLength},
    COIL_SIZE("outer_corner_radius", outer_corner_radius),
    COIL_SIZE("height", height),
    COIL_CURRENT,
    COIL_TURNS,
    COIL_QUADRATURE};
const KeyTable<CoilTarget<StraightSegment>> kSegmentKeys = {
    COIL_TYPE,
    {.name = "a", .check = Check::vec3, .slot = SLOT(source.a), .bound = kLength, .required = true},
    {.name = "b", .check = Check::vec3, .slot = SLOT(source.b), .bound = kLength, .required = true},
    COIL_CURRENT,
    COIL_TURNS,
    COIL_WIRE_RADIUS};
const KeyTable<CoilTarget<Arc>> kArcKeys = {
    COIL_TYPE,
    COIL_CENTRE,
    COIL_AXIS,
    COIL_SIZE("radius", radius),
    {.name = "start", .check = Check::non_zero_vec3, .slot = SLOT(source.start)},
    {.name = "angle", .check = Check::number, .slot = SLOT(source.angle), .bound = kAngle, .required = true},
    COIL_CURRENT,
    COIL_TURNS,
    COIL_WIRE_RADIUS};

#undef COIL_TYPE
#undef COIL_CENTRE
#undef COIL_AXIS
#undef COIL_CURRENT
#undef COIL_TURNS
#undef COIL_SIZE
#undef COIL_QUADRATURE
#undef COIL_WIRE_RADIUS

template <class S>
CoilSource read_coil_keys(const SceneReader& r, const json& v, const std::string& path,
                          const KeyTable<CoilTarget<S>>& table) {
  CoilTarget<S> t;
  read_object(r, v, path, table, t);
  return t.source;
}

CoilSource read_coil(const SceneReader& r, const json& v, const std::string& path) {
  r.require_object(v, path);
  const std::string type = r.choice(r.required(v, "type", path), member(path, "type"),
                                    {"loop", "solenoid", "circular_coil", "rounded_rectangle", "segment", "arc"});
  const CoilSource coil = type == "loop"                ? read_coil_keys(r, v, path, kLoopKeys)
                          : type == "solenoid"          ? read_coil_keys(r, v, path, kSolenoidKeys)
                          : type == "circular_coil"     ? read_coil_keys(r, v, path, kCircularCoilKeys)
                          : type == "rounded_rectangle" ? read_coil_keys(r, v, path, kRoundedRectangleKeys)
                          : type == "segment"           ? read_coil_keys(r, v, path, kSegmentKeys)
                                                        : read_coil_keys(r, v, path, kArcKeys);
  if (const std::string e = coil_source_error(coil); !e.empty()) r.fail(path, e);
  if (std::abs(ampere_turns(coil)) > kAmpereTurns.max)
    r.fail(member(path, "current"), "the ampere-turns current x turns = " + format_number(ampere_turns(coil)) +
                                        " A exceed the largest accepted, " + format_number(kAmpereTurns.max) + " A");
  return coil;
}

// ---- bodies -----------------------------------------------------------------------

// Body name -> index in scene.bodies, filled as the bodies are read: the
// duplicate-name check and the events' body lookups stay O(log n) per body
// (SceneDescription::find_body is a linear search: a file with 16000 bodies
// and events took seconds; docs/testing.md, fuzzing findings).
using BodyIndex = std::map<std::string, size_t, std::less<>>;

const KeyTable<Cylinder> kCylinderKeys = {
    {.name = "radius", .read = [](const SceneReader& r, const json& x, const std::string& p, Cylinder& c) {
       c.radius = r.size(x, p);
     },
     .required = true},
    {.name = "length", .read = [](const SceneReader& r, const json& x, const std::string& p, Cylinder& c) {
       c.length = r.size(x, p);
     },
     .required = true},
};

// ---- meshes and compounds (docs/scene-format.md "Meshes", "Compounds") ----------

struct MeshSpec {
  std::string file;
  double scale = 1.0;
  std::vector<Vec3> vertices;
  std::vector<std::array<int, 3>> triangles;
  bool inline_vertices = false, inline_triangles = false;
};

const KeyTable<MeshSpec> kMeshKeys = {
    {.name = "file", .check = Check::non_empty_string, .slot = SLOT(file), .doc = {"string", "", "none"}},
    {.name = "scale", .read = [](const SceneReader& r, const json& x, const std::string& p, MeshSpec& m) {
       m.scale = r.bounded(r.positive(x, p), p, kLength);
     },
     .doc = {"number", "m per unit", "`1`"}},
    {.name = "vertices",
     .read = [](const SceneReader& r, const json& x, const std::string& p, MeshSpec& m) {
       if (!x.is_array() || x.empty()) r.fail(p, "must be a non-empty array of [x, y, z]");
       if (x.size() > 3 * kMaxMeshTriangles) r.fail(p, std::to_string(x.size()) + " vertices: too many");
       for (size_t i = 0; i < x.size(); ++i) m.vertices.push_back(r.bounded(r.vec3(x[i], element(p, i)), element(p, i), kLength));
       m.inline_vertices = true;
     },
     .doc = {"[[x, y, z], ...]", "units", "none"}},
    {.name = "triangles",
     .read = [](const SceneReader& r, const json& x, const std::string& p, MeshSpec& m) {
       if (!x.is_array() || x.empty()) r.fail(p, "must be a non-empty array of [i, j, k]");
       if (x.size() > kMaxMeshTriangles) r.fail(p, "has " + mesh_size_refusal(x.size()));
       for (size_t i = 0; i < x.size(); ++i) {
         const std::string q = element(p, i);
         if (!x[i].is_array() || x[i].size() != 3) r.fail(q, "must be an array of 3 vertex indices");
         m.triangles.push_back({r.int_value(x[i][0], element(q, 0), 0, std::numeric_limits<int>::max()),
                                r.int_value(x[i][1], element(q, 1), 0, std::numeric_limits<int>::max()),
                                r.int_value(x[i][2], element(q, 2), 0, std::numeric_limits<int>::max())});
       }
       m.inline_triangles = true;
     },
     .doc = {"[[i, j, k], ...]", "", "none"}},
};

// A mesh from a file or inline: checked, turned outward (with a notice),
// scaled and moved so that its centre of mass is the body's origin.
Mesh read_mesh(const SceneReader& r, const json& v, const std::string& path) {
  MeshSpec spec;
  read_object(r, v, path, kMeshKeys, spec);
  const bool from_file = !spec.file.empty();
  if (from_file == (spec.inline_vertices || spec.inline_triangles))
    r.fail(path, "must have either file or vertices and triangles");
  if (!from_file && !(spec.inline_vertices && spec.inline_triangles))
    r.fail(member(path, spec.inline_vertices ? "triangles" : "vertices"), "required key is missing");
  // Where a mesh's defect is reported: the file, or the inline arrays.
  const std::string key = member(path, from_file ? "file" : "triangles");
  if (from_file) {
    namespace fs = std::filesystem;
    fs::path file = spec.file;
    if (file.is_relative()) file = fs::path(r.file()).parent_path() / file;
    try {
      MeshFileContent content = read_mesh_file(file.lexically_normal().string());
      spec.vertices = std::move(content.vertices);
      spec.triangles = std::move(content.triangles);
    } catch (const MeshFileError& e) {
      r.fail(key, e.what());
    }
  }
  for (Vec3& x : spec.vertices) x = spec.scale * x;
  const std::string where = from_file ? "mesh file \"" + spec.file + "\": " : "";
  Mesh mesh(std::move(spec.vertices), std::move(spec.triangles));
  if (const std::string e = validate_mesh(mesh); !e.empty()) r.fail(key, where + e);
  bool flipped = false;
  mesh = mesh_outward(mesh, &flipped);
  if (flipped) r.notice(key, where + "the triangles run clockwise seen from outside (negative volume); turned outward");
  const MeshData::Index& ix = mesh_index(mesh);
  const Vec3 ext = ix.hi - ix.lo;
  const double big = std::max({ext.x, ext.y, ext.z});
  if (big > 100.0 || big < 1e-6)
    r.notice(key, where + "the mesh is " + short_number(big) + " m across: are its units right (" +
                      member(path, "scale") + ")?");
  return mesh_centred(mesh);
}

Shape read_shape(const SceneReader& r, const json& v, const std::string& path);

struct PartTarget {
  CompoundPart part;
  Quaternion orientation;
};

const KeyTable<PartTarget> kCompoundPartKeys = {
    {.name = "shape",
     .read = [](const SceneReader& r, const json& x, const std::string& p, PartTarget& t) {
       const Shape s = read_shape(r, x, p);
       if (std::holds_alternative<Compound>(s)) r.fail(member(p, "compound"), "a compound's part cannot be a compound");
       std::visit(Overloaded{[&](const Compound&) {}, [&](const auto& primitive) { t.part.shape = primitive; }}, s);
     },
     .required = true, .doc = {"object", "m", "**required**"}},
    {.name = "position", .check = Check::vec3, .slot = SLOT(part.position), .bound = kLength,
     .doc = {"vector", "m", "`[0, 0, 0]`"}},
    {.name = "orientation", .check = Check::quaternion, .slot = SLOT(orientation),
     .doc = {"[w, x, y, z]", "", "`[1, 0, 0, 0]`"}},
    {.name = "material",
     .read = [](const SceneReader& r, const json&, const std::string& p, PartTarget&) {
       r.fail(p, "a compound's parts share their body's material: parts of different materials in one body "
                 "are not supported (docs/scene-format.md \"Compounds\")");
     },
     .doc = {"string", "", "none"}},
};

Compound read_compound(const SceneReader& r, const json& v, const std::string& path) {
  if (!v.is_array() || v.empty()) r.fail(path, "must be a non-empty array of parts {shape, position, orientation}");
  std::vector<CompoundPart> parts;
  for (size_t i = 0; i < v.size(); ++i) {
    PartTarget t;
    read_object(r, v[i], element(path, i), kCompoundPartKeys, t);
    t.part.orientation = rotation_from_quaternion(t.orientation.w, t.orientation.x, t.orientation.y, t.orientation.z);
    parts.push_back(std::move(t.part));
  }
  const Compound compound(std::move(parts));
  if (const std::string e = validate_compound(compound); !e.empty()) r.fail(path, e);
  return compound_centred(compound);
}

// Exactly one of these is present (read_shape).
const KeyTable<Shape> kShapeKeys = {
    {.name = "sphere",
     .read = [](const SceneReader& r, const json& x, const std::string& p, Shape& s) {
       s = Sphere{r.size(x, p)};
     }},
    {.name = "box",
     .read = [](const SceneReader& r, const json& x, const std::string& p, Shape& s) {
       r.require_array(x, p, 3);
       Box box;
       for (size_t i = 0; i < 3; ++i) box.size[static_cast<int>(i)] = r.size(x[i], element(p, i));
       s = box;
     }},
    {.name = "cylinder",
     .read = [](const SceneReader& r, const json& x, const std::string& p, Shape& s) {
       Cylinder c;
       read_object(r, x, p, kCylinderKeys, c);
       s = c;
     }},
    {.name = "mesh",
     .read = [](const SceneReader& r, const json& x, const std::string& p, Shape& s) { s = read_mesh(r, x, p); }},
    {.name = "compound",
     .read = [](const SceneReader& r, const json& x, const std::string& p, Shape& s) {
       s = read_compound(r, x, p);
     }},
};

Shape read_shape(const SceneReader& r, const json& v, const std::string& path) {
  check_unknown(r, v, path, kShapeKeys);
  if (v.size() != 1)
    r.fail(path, "must have exactly one of the keys sphere, box, cylinder, mesh, compound (it has " +
                     std::to_string(v.size()) + ")");
  Shape shape;
  read_present(r, v, path, kShapeKeys, shape);
  if (std::holds_alternative<Mesh>(shape) || std::holds_alternative<Compound>(shape)) return shape;  // checked
  if (const std::string e = validate_shape(shape); !e.empty()) r.fail(member(path, v.begin().key()), e);
  return shape;
}

struct BodyTarget {
  BodyDescription body;
  const SceneDescription& scene;
  const BodyIndex& index;
};

const KeyTable<BodyTarget> kBodyKeys = {
    {.name = "name",
     .read = [](const SceneReader& r, const json& x, const std::string& p, BodyTarget& t) {
       t.body.name = r.non_empty_string(x, p);
       if (t.index.count(t.body.name)) r.fail(p, "another body is already named " + as_literal(t.body.name));
     },
     .required = true, .doc = {"string", "", "**required**"}},
    {.name = "shape",
     .read = [](const SceneReader& r, const json& x, const std::string& p, BodyTarget& t) {
       t.body.shape = read_shape(r, x, p);
     },
     .required = true, .doc = {"object", "m", "**required**"}},
    {.name = "material",
     .read = [](const SceneReader& r, const json& x, const std::string& p, BodyTarget& t) {
       t.body.material = r.string(x, p);
       if (!t.scene.materials.count(t.body.material))
         r.fail(p, "no material named " + as_literal(t.body.material) + " in materials");
     },
     .required = true, .doc = {"string", "", "**required**"}},
    {.name = "position", .check = Check::vec3, .slot = SLOT(body.position), .bound = kLength,
     .doc = {"vector", "m", "`[0, 0, 0]`"}},
    {.name = "orientation", .check = Check::quaternion, .slot = SLOT(body.orientation),
     .doc = {"[w, x, y, z]", "", "`[1, 0, 0, 0]`"}},
    {.name = "velocity", .check = Check::vec3, .slot = SLOT(body.velocity), .bound = kSpeed,
     .doc = {"vector", "m/s", "`[0, 0, 0]`"}},
    {.name = "angular_velocity", .check = Check::vec3, .slot = SLOT(body.angular_velocity), .bound = kAngularSpeed,
     .doc = {"vector", "rad/s", "`[0, 0, 0]`"}},
    {.name = "fixed", .check = Check::boolean, .slot = SLOT(body.fixed), .doc = {"bool", "", "`false`"}},
    {.name = "density", .check = Check::positive, .slot = SLOT(body.density), .bound = kDensity,
     .doc = {"number", "kg/m^3", "`1000`"}},
    {.name = "cell_size", .check = Check::non_negative, .slot = SLOT(body.cell_size), .bound = kLength,
     .doc = {"number", "m", "see below"}},
    {.name = "present", .check = Check::boolean, .slot = SLOT(body.present),
     .doc = {"bool", "", "`true`"}},
    {.name = "color", .check = Check::color, .slot = SLOT(body.color),
     .doc = {"[r, g, b]", "", "material colour"}},
    {.name = "coils",
     .read = [](const SceneReader& r, const json& x, const std::string& p, BodyTarget& t) {
       if (!x.is_array()) r.fail(p, "must be an array of coil objects");
       for (size_t i = 0; i < x.size(); ++i) t.body.coils.push_back(read_coil(r, x[i], element(p, i)));
     },
     .doc = {"array", "body frame", "`[]`"}},
};

BodyDescription read_body(const SceneReader& r, const json& v, const std::string& path,
                          const SceneDescription& scene, const BodyIndex& index) {
  BodyTarget t{{}, scene, index};
  read_object(r, v, path, kBodyKeys, t);
  BodyDescription& body = t.body;

  // The lattice must stay a sensible size (magnetics/model/model.h).
  const double h = lattice_spacing(body, scene.cell_size);
  if (h > 0.0 && !is_inert(scene.materials.at(body.material)))
    if (std::string e = validate_body_lattice(body.name, body.shape, h); !e.empty())
      r.fail(body.cell_size ? member(path, "cell_size") : "cell_size", e);
  return body;
}

// ---- joints ------------------------------------------------------------------------

struct JointTarget {
  JointDescription joint;
  const SceneDescription& scene;
  const BodyIndex& index;
};

const KeyTable<JointTarget> kJointKeys = {
    {.name = "type",
     .read = [](const SceneReader& r, const json& x, const std::string& p, JointTarget& t) {
       const std::string type = r.choice(x, p, {"hinge", "ball", "slider", "fixed"});
       t.joint.type = type == "hinge"    ? JointDescription::Type::hinge
                      : type == "ball"   ? JointDescription::Type::ball
                      : type == "slider" ? JointDescription::Type::slider
                                         : JointDescription::Type::fixed;
     },
     .required = true, .doc = {"string", "", "**required**"}},
    {.name = "bodies",
     .read = [](const SceneReader& r, const json& x, const std::string& p, JointTarget& t) {
       if (!x.is_array() || x.empty() || x.size() > 2)
         r.fail(p, "must be an array of one body name (jointed to the world) or two");
       size_t fixed = 0;
       for (size_t i = 0; i < x.size(); ++i) {
         const std::string name = r.string(x[i], element(p, i));
         const auto it = t.index.find(name);
         if (it == t.index.end()) r.fail(element(p, i), "no body named " + as_literal(name));
         if (i == 1 && name == t.joint.bodies[0]) r.fail(element(p, i), "a joint needs two different bodies");
         fixed += t.scene.bodies[it->second].fixed ? 1 : 0;
         t.joint.bodies.push_back(name);
       }
       if (fixed == x.size())
         r.fail(p, x.size() == 1 ? "the body is fixed: a joint to the world would do nothing"
                                 : "both bodies are fixed: the joint would do nothing");
     },
     .required = true, .doc = {"array", "", "**required**"}},
    {.name = "anchor", .check = Check::vec3, .slot = SLOT(joint.anchor), .bound = kLength,
     .doc = {"vector", "m", "hinge, ball: required"}},
    {.name = "axis", .check = Check::non_zero_vec3, .slot = SLOT(joint.axis),
     .doc = {"vector", "", "`[0, 0, 1]`"}},
    {.name = "limits",
     .read = [](const SceneReader& r, const json& x, const std::string& p, JointTarget& t) {
       if (!x.is_array() || x.size() != 2) r.fail(p, "must be an array [low, high]");
       const bool hinge = t.joint.type == JointDescription::Type::hinge;
       const double lo = hinge ? r.in_range(x[0], element(p, 0), -kPi, kPi)
                               : r.bounded(r.number(x[0], element(p, 0)), element(p, 0), kLength);
       const double hi = hinge ? r.in_range(x[1], element(p, 1), -kPi, kPi)
                               : r.bounded(r.number(x[1], element(p, 1)), element(p, 1), kLength);
       if (!(lo <= hi)) r.fail(p, "low must not exceed high, got [" + format_number(lo) + ", " + format_number(hi) + "]");
       t.joint.limits = std::array<double, 2>{lo, hi};
     },
     .doc = {"[low, high]", "rad or m", "no limits"}},
};

JointDescription read_joint(const SceneReader& r, const json& v, const std::string& path,
                            const SceneDescription& scene, const BodyIndex& index) {
  JointTarget t{{}, scene, index};
  read_object(r, v, path, kJointKeys, t);
  // Which keys a joint of each type takes.
  using Type = JointDescription::Type;
  const Type type = t.joint.type;
  const bool anchored = type == Type::hinge || type == Type::ball;
  const bool has_axis = type == Type::hinge || type == Type::slider;
  const char* name = type == Type::hinge ? "hinge" : type == Type::ball ? "ball" : type == Type::slider ? "slider" : "fixed";
  if (anchored && !v.contains("anchor")) r.fail(member(path, "anchor"), std::string("a ") + name + " joint needs an anchor");
  if (!anchored && v.contains("anchor")) r.fail(member(path, "anchor"), std::string("a ") + name + " joint has no anchor");
  if (!has_axis && v.contains("axis")) r.fail(member(path, "axis"), std::string("a ") + name + " joint has no axis");
  if (!has_axis && v.contains("limits"))
    r.fail(member(path, "limits"), std::string("a ") + name + " joint has no limits (hinge and slider have)");
  return t.joint;
}

// ---- settings ----------------------------------------------------------------------

const KeyTable<SolverSettings> kSolverKeys = {
    {.name = "scheme",
     .read = [](const SceneReader& r, const json& x, const std::string& p, SolverSettings& s) {
       const bool paper = r.choice(x, p, {"two_level", "paper"}) == "paper";
       s.relax.scheme = paper ? RelaxScheme::paper : RelaxScheme::two_level;
     },
     .doc = {"string", "", "`\"two_level\"`"}},
    {.name = "tolerance", .check = Check::positive, .slot = SLOT(relax.tolerance),
     .doc = {"number", "", "`1e-6`"}},
    {.name = "max_iterations", .check = Check::integer, .slot = SLOT(relax.max_iterations), .lo = 1,
     .hi = std::numeric_limits<int>::max(), .doc = {"integer", "", "`200`"}},
    {.name = "anderson_depth", .check = Check::integer, .slot = SLOT(relax.anderson_depth),
     .lo = 0, .hi = 100,
     .doc = {"integer", "", "`20`"}},
    {.name = "mixing", .check = Check::positive, .slot = SLOT(relax.mixing),
     .doc = {"number", "", "`1`"}},
    {.name = "mutual_induction", .check = Check::boolean, .slot = SLOT(relax.mutual_induction),
     .doc = {"bool", "", "`true`"}},
    {.name = "time_step_factor", .check = Check::positive, .slot = SLOT(relax.local.time_step_factor),
     .doc = {"number", "", "`0.5`"}},
    {.name = "noise", .check = Check::non_negative, .slot = SLOT(relax.local.noise_ratio),
     .doc = {"number", "", "`1e-6`"}},
    {.name = "far_field_theta", .check = Check::in_range, .slot = SLOT(relax.far_field_theta), .lo = 0.0,
     .hi = 0.9, .late = true, .doc = {"number", "", "`0`"}},
    {.name = "skip_unchanged", .check = Check::boolean, .slot = SLOT(relax.skip_unchanged),
     .doc = {"bool", "", "`false`"}},
    {.name = "near_field", .check = Check::boolean, .slot = SLOT(relax.near_field),
     .doc = {"bool", "", "`true`"}},
    {.name = "graded_cells", .check = Check::boolean, .slot = SLOT(graded_cells),
     .doc = {"bool", "", "`false`"}},
    {.name = "contact_refinement", .check = Check::boolean, .slot = SLOT(contact_refinement),
     .doc = {"bool", "", "`true`"}},
    {.name = "backend",
     .read = [](const SceneReader& r, const json& x, const std::string& p, SolverSettings& s) {
       s.backend = read_choice(r, x, p, kBackendChoices);
     },
     .late = true, .doc = {"string", "", "`\"auto\"`"}},
    {.name = "threads", .check = Check::integer, .slot = SLOT(threads),
     .lo = 0, .hi = 65536, .late = true,
     .doc = {"integer", "", "`0`"}},
};

const KeyTable<ContactSettings> kContactKeys = {
    {.name = "friction", .check = Check::non_negative, .slot = SLOT(friction),
     .doc = {"number", "", "`0.5`"}},
    {.name = "restitution", .check = Check::in_range, .slot = SLOT(restitution), .lo = 0.0, .hi = 1.0,
     .doc = {"number", "", "`0.1`"}},
    {.name = "softness", .check = Check::non_negative, .slot = SLOT(softness),
     .doc = {"number", "", "`1e-5`"}},
    {.name = "erp", .check = Check::in_range, .slot = SLOT(erp), .lo = 0.0, .hi = 1.0,
     .doc = {"number", "", "`0.2`"}},
    {.name = "rolling_friction", .check = Check::non_negative, .slot = SLOT(rolling_friction),
     .doc = {"number", "m", "`1e-5`"}},
    {.name = "spinning_friction", .check = Check::non_negative, .slot = SLOT(spinning_friction),
     .doc = {"number", "m", "as `rolling_friction`"}},
};

const KeyTable<SimulationSettings> kSimulationKeys = {
    {.name = "time_step", .check = Check::positive, .slot = SLOT(time_step),
     .doc = {"number", "s", "`0.004`"}},
    {.name = "duration", .check = Check::non_negative, .slot = SLOT(duration),
     .doc = {"number", "s", "`2`"}},
    {.name = "frame_rate", .check = Check::positive, .slot = SLOT(frame_rate),
     .doc = {"number", "1/s", "`30`"}},
    {.name = "contact_solver",
     .read = [](const SceneReader& r, const json& x, const std::string& p, SimulationSettings& s) {
       s.contact_solver = read_choice(r, x, p, kContactSolverChoices);
     },
     .doc = {"string", "", "`\"auto\"`"}},
    {.name = "solver_iterations", .check = Check::integer, .slot = SLOT(solver_iterations), .lo = 1,
     .hi = 1000000, .doc = {"integer", "", "`30`"}},
    {.name = "ground", .check = Check::boolean, .slot = SLOT(ground), .doc = {"bool", "", "`true`"}},
    {.name = "ground_height", .check = Check::number, .slot = SLOT(ground_height), .bound = kLength,
     .doc = {"number", "m", "`0`"}},
    {.name = "contact",
     .read = [](const SceneReader& r, const json& x, const std::string& p, SimulationSettings& s) {
       read_object(r, x, p, kContactKeys, s.contact);
     },
     .doc = {"object", "", ""}},
    {.name = "linear_damping", .check = Check::in_range, .slot = SLOT(linear_damping), .lo = 0.0, .hi = 1.0,
     .doc = {"number", "", "`0`"}},
    {.name = "angular_damping", .check = Check::in_range, .slot = SLOT(angular_damping), .lo = 0.0, .hi = 1.0,
     .doc = {"number", "", "`0`"}},
    {.name = "max_substeps", .check = Check::integer, .slot = SLOT(max_substeps), .lo = 1, .hi = 100000,
     .doc = {"integer", "", "`64`"}},
    {.name = "stiffness_limit", .check = Check::positive, .slot = SLOT(stiffness_limit),
     .doc = {"number", "", "`1`"}},
    {.name = "magnetic_solve",
     .read = [](const SceneReader& r, const json& x, const std::string& p, SimulationSettings& s) {
       s.magnetic_solve = read_choice(r, x, p, kMagneticSolveChoices);
     },
     .doc = {"string", "", "`\"substep\"`"}},
};

const KeyTable<CameraSettings> kCameraKeys = {
    {.name = "position", .check = Check::vec3, .slot = SLOT(position), .bound = kLength,
     .doc = {"vector", "m", "`[0.3, -0.3, 0.2]`"}},
    {.name = "target", .check = Check::vec3, .slot = SLOT(target), .bound = kLength,
     .doc = {"vector", "m", "`[0, 0, 0.05]`"}},
    {.name = "up", .check = Check::non_zero_vec3, .slot = SLOT(up),
     .doc = {"vector", "", "`[0, 0, 1]`"}},
    {.name = "fov", .check = Check::in_range, .slot = SLOT(fov_degrees), .lo = 1.0, .hi = 179.0,
     .doc = {"number", "degrees", "`40`"}},
    {.name = "width", .check = Check::integer, .slot = SLOT(width), .lo = 16, .hi = 8192,
     .doc = {"integer", "pixels", "`640`"}},
    {.name = "height", .check = Check::integer, .slot = SLOT(height), .lo = 16, .hi = 8192,
     .doc = {"integer", "pixels", "`480`"}},
};

CameraSettings read_camera(const SceneReader& r, const json& v, const std::string& path) {
  CameraSettings c;
  read_object(r, v, path, kCameraKeys, c);
  const Vec3 view = c.target - c.position;
  if (view.x == 0.0 && view.y == 0.0 && view.z == 0.0)
    r.fail(member(path, "target"), "must differ from camera.position");
  // |target - position| can underflow to 0 or overflow to infinity (docs/testing.md, fuzzing findings).
  const double distance = norm(view);
  if (!(distance > 0.0) || !std::isfinite(distance))
    r.fail(member(path, "target"), "distance from camera.position must be between about 1e-150 and 1e150 m");
  if (!(norm(cross(normalized(view), normalized(c.up))) >= 1e-9))
    r.fail(member(path, "up"), "must not be parallel to the viewing direction (target - position)");
  return c;
}

const KeyTable<RenderSettings> kRenderKeys = {
    {.name = "field_lines", .check = Check::boolean, .slot = SLOT(field_lines),
     .doc = {"bool", "", "`false`"}},
    {.name = "field_line_count", .check = Check::integer, .slot = SLOT(field_line_count),
     .lo = 1, .hi = 100000,
     .doc = {"integer", "", "`48`"}},
    {.name = "force_colors", .check = Check::boolean, .slot = SLOT(force_colors),
     .doc = {"bool", "", "`false`"}},
};

// ---- time line ---------------------------------------------------------------------

struct KeyframeTarget {
  Keyframe key;
  const Keyframe* previous;  // the key before, if any
};

const KeyTable<KeyframeTarget> kKeyframeKeys = {
    {.name = "time",
     .read = [](const SceneReader& r, const json& x, const std::string& p, KeyframeTarget& t) {
       t.key.time = r.non_negative(x, p);
       if (t.previous && !(t.key.time > t.previous->time))
         r.fail(p, "key times must increase (previous key: " + format_number(t.previous->time) + ")");
     },
     .required = true},
    {.name = "position", .check = Check::vec3, .slot = SLOT(key.position), .bound = kLength},
    {.name = "orientation", .check = Check::quaternion, .slot = SLOT(key.orientation)},
};

std::vector<Keyframe> read_keys(const SceneReader& r, const json& v, const std::string& path,
                                const BodyDescription& body) {
  if (!v.is_array() || v.empty()) r.fail(path, "must be a non-empty array of {time, position, orientation}");
  std::vector<Keyframe> keys;
  for (size_t k = 0; k < v.size(); ++k) {
    KeyframeTarget t{{0.0, body.position, body.orientation}, keys.empty() ? nullptr : &keys.back()};
    read_object(r, v[k], element(path, k), kKeyframeKeys, t);
    keys.push_back(t.key);
  }
  return keys;
}

struct EventTarget {
  TimelineEvent e;
  const SceneDescription& scene;
  const BodyIndex& index;
  const BodyDescription* body = nullptr;  // the event's body, once read
};

// The existing body named by the event's "body".
void read_event_body(const SceneReader& r, const json& x, const std::string& p, EventTarget& t) {
  const std::string name = r.string(x, p);
  const auto it = t.index.find(name);
  if (it == t.index.end()) r.fail(p, "no body named " + as_literal(name));
  t.body = &t.scene.bodies[it->second];
  t.e.body = t.body->name;
}

const KeyRule<EventTarget> kEventTime = {
    .name = "time",
    .read = [](const SceneReader& r, const json& x, const std::string& p, EventTarget& t) {
      t.e.time = r.non_negative(x, p);
      t.e.end_time = t.e.time;
    },
    .required = true};
const KeyRule<EventTarget> kEventAction = {.name = "action", .read = kReadBefore, .required = true};
const KeyRule<EventTarget> kEventBody = {.name = "body", .read = read_event_body, .required = true};
const KeyRule<EventTarget> kEventEndTime = {
    .name = "end_time",
    .read = [](const SceneReader& r, const json& x, const std::string& p, EventTarget& t) {
      const double end = r.number(x, p);
      if (end < t.e.time)
        r.fail(p, "must be >= time (" + format_number(t.e.time) + "), got " + format_number(end));
      t.e.end_time = end;
    }};

const KeyTable<EventTarget> kBodyEventKeys = {kEventTime, kEventAction, kEventBody};

const KeyTable<EventTarget> kScaleEventKeys = {
    kEventTime,
    kEventAction,
    {.name = "body",
     .read = [](const SceneReader& r, const json& x, const std::string& p, EventTarget& t) {
       read_event_body(r, x, p, t);
       const Material& material = t.scene.materials.at(t.body->material);
       const SoftMaterial* soft = std::get_if<SoftMaterial>(&material);
       const bool electromagnet = (soft && norm(soft->coil_field) > 0.0) || !t.body->coils.empty();
       if (!std::holds_alternative<PermanentMaterial>(material) && !electromagnet)
         r.fail(p, "body " + as_literal(t.e.body) + " is neither a permanent magnet nor an electromagnet (material " +
                       as_literal(t.body->material) + ", no coils)");
     },
     .required = true},
    {.name = "to",
     .read = [](const SceneReader& r, const json& x, const std::string& p, EventTarget& t) {
       t.e.value = r.number(x, p);
       // The scaled magnetization (or coil field) stays within kFieldStrength.
       const Material& material = t.scene.materials.at(t.body->material);
       const PermanentMaterial* permanent = std::get_if<PermanentMaterial>(&material);
       const SoftMaterial* soft = std::get_if<SoftMaterial>(&material);
       const Vec3 scaled = permanent ? permanent->magnetization : soft ? soft->coil_field : Vec3{};
       const double largest = std::max({std::abs(scaled.x), std::abs(scaled.y), std::abs(scaled.z)});
       // The scaled currents stay within kAmpereTurns.
       double largest_ni = 0.0;
       for (const CoilSource& coil : t.body->coils) largest_ni = std::max(largest_ni, std::abs(ampere_turns(coil)));
       const double limit = largest_magnetization_scale(largest, largest_ni);
       if (std::abs(t.e.value) > limit)
         r.fail(p, "scales the magnetization or the coils' ampere-turns beyond the largest accepted, " +
                       format_number(kFieldStrength.max) + " A/m and " + format_number(kAmpereTurns.max) +
                       " A (at most " + format_number(limit) + " for this body)");
     },
     .required = true},
    kEventEndTime,
};

const KeyTable<EventTarget> kInductionEventKeys = {
    kEventTime, kEventAction,
    {.name = "enabled", .check = Check::boolean, .slot = SLOT(e.enabled), .required = true}};

const KeyTable<EventTarget> kFieldEventKeys = {
    kEventTime, kEventAction, {.name = "field", .check = Check::vec3, .slot = SLOT(e.field), .bound = kFieldStrength, .required = true},
    kEventEndTime};

const KeyTable<EventTarget> kKeyframesEventKeys = {
    // Optional here, read after the keys: it defaults to the first key's time.
    {.name = "time",
     .read = [](const SceneReader& r, const json& x, const std::string& p, EventTarget& t) {
       t.e.time = r.non_negative(x, p);
     },
     .late = true},
    kEventAction,
    kEventBody,
    {.name = "keys",
     .read = [](const SceneReader& r, const json& x, const std::string& p, EventTarget& t) {
       t.e.keys = read_keys(r, x, p, *t.body);
       t.e.time = t.e.keys.front().time;
     },
     .required = true},
};

struct EventAction {
  const char* action;
  TimelineEvent::Kind kind;
  const KeyTable<EventTarget>* keys;
};

const std::vector<EventAction> kEventActions = {
    {"add", TimelineEvent::Kind::add_body, &kBodyEventKeys},
    {"remove", TimelineEvent::Kind::remove_body, &kBodyEventKeys},
    {"scale_magnetization", TimelineEvent::Kind::scale_magnetization, &kScaleEventKeys},
    {"mutual_induction", TimelineEvent::Kind::mutual_induction, &kInductionEventKeys},
    {"external_field", TimelineEvent::Kind::external_field, &kFieldEventKeys},
    {"keyframes", TimelineEvent::Kind::keyframes, &kKeyframesEventKeys},
};

TimelineEvent read_event(const SceneReader& r, const json& v, const std::string& path,
                         const SceneDescription& scene, const BodyIndex& index) {
  r.require_object(v, path);
  std::vector<std::string_view> actions;
  for (const EventAction& a : kEventActions) actions.push_back(a.action);
  const std::string action = r.choice(r.required(v, "action", path), member(path, "action"), actions);
  EventTarget t{{}, scene, index};
  for (const EventAction& a : kEventActions)
    if (action == a.action) {
      t.e.kind = a.kind;
      read_object(r, v, path, *a.keys, t);
    }
  if (t.e.kind == TimelineEvent::Kind::keyframes) t.e.end_time = std::max(t.e.time, t.e.keys.back().time);
  return t.e;
}

struct OutcomeTarget {
  OutcomeDescription outcome;
  const SceneDescription& scene;
  const BodyIndex& index;
};

// The body named by x, stored in the outcome's bodies.
void read_outcome_body(const SceneReader& r, const json& x, const std::string& p, OutcomeTarget& t) {
  const std::string name = r.string(x, p);
  if (!t.index.count(name)) r.fail(p, "no body named " + as_literal(name));
  t.outcome.bodies.push_back(name);
}

const KeyTable<OutcomeTarget> kCountAboveKeys = {
    {.name = "prefix",
     .read = [](const SceneReader& r, const json& x, const std::string& p, OutcomeTarget& t) {
       t.outcome.prefix = r.string(x, p);
       // A prefix that names no body would count nothing, silently.
       for (const BodyDescription& body : t.scene.bodies)
         if (body.name.rfind(t.outcome.prefix, 0) == 0) return;
       r.fail(p, "no body's name starts with " + as_literal(t.outcome.prefix));
     },
     .required = true},
    {.name = "height", .check = Check::number, .slot = SLOT(outcome.height), .bound = kLength, .required = true},
};
const KeyTable<OutcomeTarget> kOutcomeBodyKeys = {
    {.name = "body", .read = read_outcome_body, .required = true},
};
const KeyTable<OutcomeTarget> kOutcomeVectorKeys = {
    {.name = "body", .read = read_outcome_body, .required = true},
    {.name = "component",
     .read = [](const SceneReader& r, const json& x, const std::string& p, OutcomeTarget& t) {
       const std::string c = r.choice(x, p, {"x", "y", "z", "magnitude"});
       t.outcome.component = c == "magnitude" ? -1 : c[0] - 'x';
     }},
};
const KeyTable<OutcomeTarget> kDistanceKeys = {
    {.name = "bodies",
     .read = [](const SceneReader& r, const json& x, const std::string& p, OutcomeTarget& t) {
       if (!x.is_array() || x.size() != 2) r.fail(p, "must be an array of two body names");
       for (size_t i = 0; i < 2; ++i) read_outcome_body(r, x[i], element(p, i), t);
     },
     .required = true},
};

// The quantity keys of an outcome, each with its object's keys.
struct OutcomeQuantity {
  const char* key;
  OutcomeDescription::Quantity quantity;
  const KeyTable<OutcomeTarget>* keys;
};
const std::vector<OutcomeQuantity> kOutcomeQuantities = {
    {"count_above", OutcomeDescription::Quantity::count_above, &kCountAboveKeys},
    {"distance", OutcomeDescription::Quantity::distance, &kDistanceKeys},
    {"height", OutcomeDescription::Quantity::height, &kOutcomeBodyKeys},
    {"speed", OutcomeDescription::Quantity::speed, &kOutcomeBodyKeys},
    {"contact_count", OutcomeDescription::Quantity::contact_count, &kOutcomeBodyKeys},
    {"force", OutcomeDescription::Quantity::force, &kOutcomeVectorKeys},
    {"moment", OutcomeDescription::Quantity::moment, &kOutcomeVectorKeys},
};

template <int Q>
void read_quantity(const SceneReader& r, const json& x, const std::string& p, OutcomeTarget& t) {
  t.outcome.quantity = kOutcomeQuantities[Q].quantity;
  read_object(r, x, p, *kOutcomeQuantities[Q].keys, t);
}

const KeyTable<OutcomeTarget> kOutcomeKeys = {
    {.name = "name", .check = Check::non_empty_string, .slot = SLOT(outcome.name), .required = true,
     .doc = {"string", "", "**required**"}},
    {.name = "count_above", .read = read_quantity<0>, .doc = {"object", "", "one quantity is required"}},
    {.name = "distance", .read = read_quantity<1>, .doc = {"object", "", ""}},
    {.name = "height", .read = read_quantity<2>, .doc = {"object", "", ""}},
    {.name = "speed", .read = read_quantity<3>, .doc = {"object", "", ""}},
    {.name = "contact_count", .read = read_quantity<4>, .doc = {"object", "", ""}},
    {.name = "force", .read = read_quantity<5>, .doc = {"object", "", ""}},
    {.name = "moment", .read = read_quantity<6>, .doc = {"object", "", ""}},
    {.name = "time", .check = Check::number, .slot = SLOT(outcome.time), .doc = {"number", "s", "`-1`"}},
    {.name = "statistic",
     .read = [](const SceneReader& r, const json& x, const std::string& p, OutcomeTarget& t) {
       t.outcome.statistic = read_choice(r, x, p, kStatisticChoices);
     },
     .doc = {"string", "", "`\"\"`"}},
    {.name = "from", .check = Check::non_negative, .slot = SLOT(outcome.from), .doc = {"number", "s", "`0`"}},
};

OutcomeDescription read_outcome(const SceneReader& r, const json& v, const std::string& path,
                                const SceneDescription& scene, const BodyIndex& index) {
  r.require_object(v, path);
  size_t quantities = 0;
  for (const OutcomeQuantity& q : kOutcomeQuantities) quantities += v.contains(q.key) ? 1 : 0;
  if (quantities != 1)
    r.fail(path, "must have exactly one of the keys count_above, distance, height, speed, contact_count, force, "
                 "moment (it has " + std::to_string(quantities) + ")");
  OutcomeTarget t{{}, scene, index};
  read_object(r, v, path, kOutcomeKeys, t);
  if (t.outcome.statistic != Statistic::none && v.contains("time"))
    r.fail(member(path, "time"), "an outcome with a statistic (max, min, mean over the run) has no time");
  if (t.outcome.statistic == Statistic::none && v.contains("from"))
    r.fail(member(path, "from"), "only an outcome with a statistic (max, min, mean) has a start time");
  return t.outcome;
}

// ---- the whole file --------------------------------------------------------------

struct SceneTarget {
  SceneDescription scene;
  BodyIndex index;
};

const KeyTable<SceneTarget> kSceneKeys = {
    {.name = "title", .check = Check::string, .slot = SLOT(scene.title),
     .doc = {"string", "", "`\"\"`"}},
    {.name = "gravity", .check = Check::vec3, .slot = SLOT(scene.gravity), .bound = kAcceleration,
     .doc = {"vector", "m/s^2", "`[0, 0, -9.81]`"}},
    {.name = "external_field", .check = Check::vec3, .slot = SLOT(scene.external_field), .bound = kFieldStrength,
     .doc = {"vector", "A/m", "`[0, 0, 0]`"}},
    {.name = "cell_size", .check = Check::non_negative, .slot = SLOT(scene.cell_size), .bound = kLength,
     .doc = {"number", "m", "`0`"}},
    {.name = "seed",
     .read = [](const SceneReader& r, const json& x, const std::string& p, SceneTarget& t) {
       if (!x.is_number_unsigned() && !(x.is_number_integer() && x.get<long long>() >= 0))
         r.fail(p, "must be a non-negative integer");
       t.scene.seed = x.get<uint64_t>();
     },
     .doc = {"integer", "", "`1`"}},
    {.name = "materials",
     .read = [](const SceneReader& r, const json& x, const std::string& path, SceneTarget& t) {
       r.require_object(x, path);
       for (const auto& [name, value] : x.items()) {
         const std::string p = member(path, name);
         if (name.empty()) r.fail(p, "a material name must not be empty");
         std::optional<std::array<double, 3>> color;
         t.scene.materials.emplace(name, read_material(r, value, p, color));
         if (color) t.scene.material_colors.emplace(name, *color);
       }
     },
     .required = true, .doc = {"object", "", "**required**"}},
    {.name = "bodies",
     .read = [](const SceneReader& r, const json& x, const std::string& p, SceneTarget& t) {
       if (!x.is_array() || x.empty()) r.fail(p, "must be a non-empty array of bodies");
       for (size_t b = 0; b < x.size(); ++b) {
         t.scene.bodies.push_back(read_body(r, x[b], element(p, b), t.scene, t.index));
         t.index.emplace(t.scene.bodies.back().name, b);
       }
     },
     .required = true, .doc = {"array", "", "**required**"}},
    {.name = "joints",
     .read = [](const SceneReader& r, const json& x, const std::string& p, SceneTarget& t) {
       if (!x.is_array()) r.fail(p, "must be an array of joints");
       for (size_t i = 0; i < x.size(); ++i)
         t.scene.joints.push_back(read_joint(r, x[i], element(p, i), t.scene, t.index));
     },
     .doc = {"array", "", "`[]`"}},
    {.name = "solver",
     .read = [](const SceneReader& r, const json& x, const std::string& p, SceneTarget& t) {
       read_object(r, x, p, kSolverKeys, t.scene.solver);
     },
     .doc = {"object", "", ""}},
    {.name = "simulation",
     .read = [](const SceneReader& r, const json& x, const std::string& p, SceneTarget& t) {
       read_object(r, x, p, kSimulationKeys, t.scene.simulation);
     },
     .doc = {"object", "", ""}},
    {.name = "timeline",
     .read = [](const SceneReader& r, const json& x, const std::string& p, SceneTarget& t) {
       if (!x.is_array()) r.fail(p, "must be an array of events");
       for (size_t i = 0; i < x.size(); ++i)
         t.scene.timeline.push_back(read_event(r, x[i], element(p, i), t.scene, t.index));
     },
     .doc = {"array", "", "`[]`"}},
    {.name = "camera",
     .read = [](const SceneReader& r, const json& x, const std::string& p, SceneTarget& t) {
       t.scene.camera = read_camera(r, x, p);
     },
     .doc = {"object", "", ""}},
    {.name = "render",
     .read = [](const SceneReader& r, const json& x, const std::string& p, SceneTarget& t) {
       read_object(r, x, p, kRenderKeys, t.scene.render);
     },
     .doc = {"object", "", ""}},
    {.name = "outcomes",
     .read = [](const SceneReader& r, const json& x, const std::string& p, SceneTarget& t) {
       if (!x.is_array()) r.fail(p, "must be an array of outcomes");
       std::set<std::string> names;
       for (size_t i = 0; i < x.size(); ++i) {
         const OutcomeDescription o = read_outcome(r, x[i], element(p, i), t.scene, t.index);
         t.scene.outcomes.push_back(o);
         if (!names.insert(o.name).second)
           r.fail(member(element(p, i), "name"), "another outcome is already named " + as_literal(o.name));
       }
     },
     .doc = {"array", "", "`[]`"}},
};

#undef SLOT

SceneDescription read_scene(const SceneReader& r, const json& root) {
  SceneTarget t;
  t.scene.file = r.file();
  read_object(r, root, "", kSceneKeys, t);
  t.scene.notices = r.notices();
  return std::move(t.scene);
}

// A target as the loader starts from when an object's keys are read: the
// description structs' default values (the references of body and event
// targets bound to an empty scene).
template <class T>
struct FreshTarget {
  T target{};
};
template <>
struct FreshTarget<BodyTarget> {
  SceneDescription scene;
  BodyIndex index;
  BodyTarget target{{}, scene, index};
};
template <>
struct FreshTarget<OutcomeTarget> {
  SceneDescription scene;
  BodyIndex index;
  OutcomeTarget target{{}, scene, index};
};
template <>
struct FreshTarget<JointTarget> {
  SceneDescription scene;
  BodyIndex index;
  JointTarget target{{}, scene, index};
};
template <>
struct FreshTarget<EventTarget> {
  SceneDescription scene;
  BodyIndex index;
  EventTarget target{{}, scene, index};
};

// A slot's value as JSON text; "" for an empty optional.
std::string json_text(const Slot& slot) {
  return std::visit(
      [](auto* value) -> std::string {
        using V = std::remove_pointer_t<decltype(value)>;
        if constexpr (std::is_same_v<V, Vec3>) {
          return json::array({value->x, value->y, value->z}).dump();
        } else if constexpr (std::is_same_v<V, Quaternion>) {
          return json::array({value->w, value->x, value->y, value->z}).dump();
        } else if constexpr (std::is_same_v<V, std::optional<double>> ||
                             std::is_same_v<V, std::optional<std::array<double, 3>>>) {
          return *value ? json(**value).dump() : "";
        } else {
          return json(*value).dump();
        }
      },
      slot);
}

template <class T>
void add_key_docs(std::vector<SceneKeyDoc>& docs, const std::string& section, const KeyTable<T>& table) {
  for (const KeyRule<T>& rule : table) {
    FreshTarget<T> fresh;
    docs.push_back({section, rule.name, rule.doc.type, rule.doc.unit, rule.doc.fallback, rule.required,
                    rule.slot ? json_text(rule.slot(fresh.target)) : ""});
  }
}

}  // namespace

std::vector<SceneKeyDoc> scene_key_docs() {
  std::vector<SceneKeyDoc> docs;
  add_key_docs(docs, "", kSceneKeys);
  add_key_docs(docs, "materials.permanent", kPermanentKeys);
  add_key_docs(docs, "materials.linear", kLinearKeys);
  add_key_docs(docs, "materials.soft", kSoftKeys);
  add_key_docs(docs, "materials.inert", kInertKeys);
  add_key_docs(docs, "bodies[]", kBodyKeys);
  add_key_docs(docs, "bodies[].shape", kShapeKeys);
  add_key_docs(docs, "bodies[].shape.cylinder", kCylinderKeys);
  add_key_docs(docs, "bodies[].shape.mesh", kMeshKeys);
  add_key_docs(docs, "bodies[].shape.compound[]", kCompoundPartKeys);
  add_key_docs(docs, "bodies[].coils[].loop", kLoopKeys);
  add_key_docs(docs, "bodies[].coils[].solenoid", kSolenoidKeys);
  add_key_docs(docs, "bodies[].coils[].circular_coil", kCircularCoilKeys);
  add_key_docs(docs, "bodies[].coils[].rounded_rectangle", kRoundedRectangleKeys);
  add_key_docs(docs, "bodies[].coils[].segment", kSegmentKeys);
  add_key_docs(docs, "bodies[].coils[].arc", kArcKeys);
  add_key_docs(docs, "joints[]", kJointKeys);
  add_key_docs(docs, "solver", kSolverKeys);
  add_key_docs(docs, "simulation", kSimulationKeys);
  add_key_docs(docs, "simulation.contact", kContactKeys);
  for (const EventAction& a : kEventActions)
    add_key_docs(docs, std::string("timeline[].") + a.action, *a.keys);
  add_key_docs(docs, "timeline[].keys[]", kKeyframeKeys);
  add_key_docs(docs, "camera", kCameraKeys);
  add_key_docs(docs, "render", kRenderKeys);
  add_key_docs(docs, "outcomes[]", kOutcomeKeys);
  for (const OutcomeQuantity& q : kOutcomeQuantities) add_key_docs(docs, std::string("outcomes[].") + q.key, *q.keys);
  return docs;
}

void check_json_text(const std::string& json_text, const std::string& file) {
  // The JSON parser takes a NUL byte for the end of the text: whatever follows
  // it would be ignored.
  if (const size_t nul = json_text.find('\0'); nul != std::string::npos)
    throw SceneError(file, "", "invalid JSON: a NUL byte at offset " + std::to_string(nul) +
                                   " (a scene file is JSON text)");
  PathTracker tracker(file);
  if (!json::sax_parse(json_text, &tracker)) {
    const std::string what = without_exception_tag(tracker.error().value_or("syntax error"));
    // 406: a number too large for a double (1e999); JSON has no infinity.
    if (tracker.error_id() == 406) throw SceneError(file, tracker.path(), what + " (numbers must be finite)");
    // The key being read when the text broke off: "FILE: bodies[1].position: invalid JSON: ...".
    throw SceneError(file, tracker.path(), "invalid JSON: " + what);
  }
}

SceneDescription parse_scene(const std::string& json_text, const std::string& file) {
  check_json_text(json_text, file);
  json root;
  try {
    root = json::parse(json_text);  // the text the first pass accepted
  } catch (const json::exception& e) {
    throw SceneError(file, "", "invalid JSON: " + without_exception_tag(e.what()));
  }
  if (!root.is_object()) throw SceneError(file, "", "the scene must be a JSON object {...}");
  return read_scene(SceneReader(file), root);
}

std::string read_json_file(const std::string& path) {
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec)) throw SceneError(path, "", "cannot open: is a directory");
  std::ifstream in(path, std::ios::binary);
  if (!in) throw SceneError(path, "", std::string("cannot open: ") + std::strerror(errno));
  // Read in pieces up to a bound: `odemag solve /dev/zero` must not take all
  // the memory (a scene of a million bodies is about 60 MB).
  constexpr size_t kMaxSceneBytes = size_t{256} << 20;
  std::string text;
  char buffer[65536];
  while (in.read(buffer, sizeof buffer) || in.gcount() > 0) {
    text.append(buffer, static_cast<size_t>(in.gcount()));
    if (text.size() > kMaxSceneBytes) throw SceneError(path, "", "the file is larger than 256 MiB");
  }
  if (in.bad()) throw SceneError(path, "", "cannot read the file");
  return text;
}

SceneDescription load_scene(const std::string& path) { return parse_scene(read_json_file(path), path); }

}  // namespace odemag
