// Scene files: JSON text -> validated SceneDescription (docs/scene-format.md).
//
// Every value is checked where it is read, and every failure names the file
// and the JSON key path of the offending value ("bodies[2].shape.sphere").
#include "engine/scene/scene.h"

#include <cerrno>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <initializer_list>
#include <limits>
#include <set>
#include <sstream>
#include <string_view>
#include <utility>

#include <nlohmann/json.hpp>

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

// A body's lattice may have at most this many points (bounding box / h^3):
// beyond it the per-body tensors alone take gigabytes.
constexpr double kMaxLatticePoints = 4194304.0;  // 2^22

// The deepest scene value is 5 levels down (timeline[0].keys[0].position[0]);
// deeper nesting is rejected while parsing, so that a file of a million '['
// fails at once instead of building a million-level tree (docs/testing.md, fuzzing findings).
constexpr size_t kMaxNesting = 64;

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

  // v must be an object whose keys are all in `allowed`.
  void check_keys(const json& v, const std::string& path,
                  std::initializer_list<std::string_view> allowed) const {
    require_object(v, path);
    for (const auto& [key, value] : v.items()) {
      bool known = false;
      for (std::string_view a : allowed) known = known || key == a;
      if (known) continue;
      std::string list;
      for (std::string_view a : allowed) list += (list.empty() ? "" : ", ") + std::string(a);
      fail(member(path, key), "unknown key (expected one of: " + list + ")");
    }
  }

  const json& required(const json& obj, std::string_view key, const std::string& path) const {
    const auto it = obj.find(key);
    if (it == obj.end()) fail(member(path, key), "required key is missing");
    return *it;
  }

  // Calls read(value, key_path) when obj has the key.
  template <class Read>
  void optional(const json& obj, std::string_view key, const std::string& path, Read&& read) const {
    const auto it = obj.find(key);
    if (it != obj.end()) read(*it, member(path, key));
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
                     std::initializer_list<std::string_view> words) const {
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

 private:
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

// ---- materials ------------------------------------------------------------------

// validate_material reports "KEY must ..."; name that key in the path.
std::string material_message_key(const std::string& message) {
  for (std::string_view key : {"magnetization", "recoil_susceptibility", "saturation",
                               "susceptibility", "anisotropy_field", "easy_axis", "damping",
                               "moments_per_cell", "coil_field"})
    if (message.rfind(std::string(key) + " ", 0) == 0) return std::string(key);
  return {};
}

Material read_material(const SceneReader& r, const json& v, const std::string& path,
                       std::optional<std::array<double, 3>>& color) {
  r.require_object(v, path);
  const std::string type =
      r.choice(r.required(v, "type", path), member(path, "type"), {"permanent", "soft", "inert"});
  Material material;
  if (type == "permanent") {
    r.check_keys(v, path, {"type", "magnetization", "recoil_susceptibility", "color"});
    PermanentMaterial m;
    m.magnetization = r.vec3(r.required(v, "magnetization", path), member(path, "magnetization"));
    r.optional(v, "recoil_susceptibility", path,
               [&](const json& x, const std::string& p) { m.recoil_susceptibility = r.non_negative(x, p); });
    material = m;
  } else if (type == "soft") {
    r.check_keys(v, path, {"type", "saturation", "susceptibility", "anisotropy_field", "easy_axis",
                           "damping", "moments_per_cell", "coil_field", "color"});
    SoftMaterial m;
    m.saturation = r.positive(r.required(v, "saturation", path), member(path, "saturation"));
    r.optional(v, "susceptibility", path, [&](const json& x, const std::string& p) {
      if (x.is_string()) {
        if (x.get<std::string>() != "infinite")
          r.fail(p, "must be a number > 0 or the string \"infinite\"");
        m.susceptibility = std::numeric_limits<double>::infinity();
      } else {
        m.susceptibility = r.positive(x, p);
      }
    });
    r.optional(v, "anisotropy_field", path,
               [&](const json& x, const std::string& p) { m.anisotropy_field = r.non_negative(x, p); });
    r.optional(v, "easy_axis", path,
               [&](const json& x, const std::string& p) { m.easy_axis = r.non_zero_vec3(x, p); });
    r.optional(v, "damping", path,
               [&](const json& x, const std::string& p) { m.damping = r.positive(x, p); });
    r.optional(v, "moments_per_cell", path, [&](const json& x, const std::string& p) {
      const int n = r.int_value(x, p, 2, kMaxMomentsPerCell);
      if (n % 2 != 0)
        r.fail(p, "must be an even integer from 2 to " + std::to_string(kMaxMomentsPerCell) +
                      ", got " + std::to_string(n));
      m.moments_per_cell = n;
    });
    r.optional(v, "coil_field", path, [&](const json& x, const std::string& p) { m.coil_field = r.vec3(x, p); });
    material = m;
  } else {
    r.check_keys(v, path, {"type", "color"});
    material = InertMaterial{};
  }
  r.optional(v, "color", path, [&](const json& x, const std::string& p) { color = r.color(x, p); });
  // The physics checks of the magnetics library, as a backstop.
  if (const std::string e = validate_material(material); !e.empty())
    r.fail(member(path, material_message_key(e)), e);
  return material;
}

// ---- bodies -----------------------------------------------------------------------

// Body name -> index in scene.bodies, filled as the bodies are read: the
// duplicate-name check and the events' body lookups stay O(log n) per body
// (SceneDescription::find_body is a linear search: a file with 16000 bodies
// and events took seconds; docs/testing.md, fuzzing findings).
using BodyIndex = std::map<std::string, size_t, std::less<>>;

Shape read_shape(const SceneReader& r, const json& v, const std::string& path) {
  r.check_keys(v, path, {"sphere", "box", "cylinder"});
  if (v.size() != 1)
    r.fail(path, "must have exactly one of the keys sphere, box, cylinder (it has " +
                     std::to_string(v.size()) + ")");
  const std::string kind = v.begin().key();
  const json& value = v.begin().value();
  const std::string p = member(path, kind);
  Shape shape;
  if (kind == "sphere") {
    shape = Sphere{r.positive(value, p)};
  } else if (kind == "box") {
    r.require_array(value, p, 3);
    Box box;
    for (size_t i = 0; i < 3; ++i) box.size[static_cast<int>(i)] = r.positive(value[i], element(p, i));
    shape = box;
  } else {
    r.check_keys(value, p, {"radius", "length"});
    Cylinder c;
    c.radius = r.positive(r.required(value, "radius", p), member(p, "radius"));
    c.length = r.positive(r.required(value, "length", p), member(p, "length"));
    shape = c;
  }
  if (const std::string e = validate_shape(shape); !e.empty()) r.fail(p, e);
  return shape;
}

BodyDescription read_body(const SceneReader& r, const json& v, const std::string& path,
                          const SceneDescription& scene, const BodyIndex& index) {
  r.check_keys(v, path, {"name", "shape", "material", "position", "orientation", "velocity",
                         "angular_velocity", "fixed", "density", "cell_size", "present", "color"});
  BodyDescription body;
  body.name = r.non_empty_string(r.required(v, "name", path), member(path, "name"));
  if (index.count(body.name))
    r.fail(member(path, "name"), "another body is already named " + as_literal(body.name));
  body.shape = read_shape(r, r.required(v, "shape", path), member(path, "shape"));
  body.material = r.string(r.required(v, "material", path), member(path, "material"));
  if (!scene.materials.count(body.material))
    r.fail(member(path, "material"), "no material named " + as_literal(body.material) + " in materials");
  r.optional(v, "position", path, [&](const json& x, const std::string& p) { body.position = r.vec3(x, p); });
  r.optional(v, "orientation", path,
             [&](const json& x, const std::string& p) { body.orientation = r.quaternion(x, p); });
  r.optional(v, "velocity", path, [&](const json& x, const std::string& p) { body.velocity = r.vec3(x, p); });
  r.optional(v, "angular_velocity", path,
             [&](const json& x, const std::string& p) { body.angular_velocity = r.vec3(x, p); });
  r.optional(v, "fixed", path, [&](const json& x, const std::string& p) { body.fixed = r.boolean(x, p); });
  r.optional(v, "density", path, [&](const json& x, const std::string& p) { body.density = r.positive(x, p); });
  r.optional(v, "cell_size", path,
             [&](const json& x, const std::string& p) { body.cell_size = r.non_negative(x, p); });
  r.optional(v, "present", path, [&](const json& x, const std::string& p) { body.present = r.boolean(x, p); });
  r.optional(v, "color", path, [&](const json& x, const std::string& p) { body.color = r.color(x, p); });


  // The lattice must stay a sensible size.
  const double h = lattice_spacing(body, scene.cell_size);
  if (h > 0.0 && !is_inert(scene.materials.at(body.material))) {
    const Vec3 half = shape_half_extents(body.shape);
    double points = 1.0;
    for (int a = 0; a < 3; ++a) points *= std::max(1.0, std::round(2.0 * half[a] / h));
    if (points > kMaxLatticePoints) {
      std::ostringstream msg;
      msg.precision(3);
      msg << "cell size " << format_number(h) << " gives body " << as_literal(body.name) << " a lattice of "
          << points << " points; at most " << static_cast<long long>(kMaxLatticePoints) << " are allowed";
      r.fail(body.cell_size ? member(path, "cell_size") : "cell_size", msg.str());
    }
  }
  return body;
}

// ---- settings ----------------------------------------------------------------------

SolverSettings read_solver(const SceneReader& r, const json& v, const std::string& path) {
  r.check_keys(v, path, {"scheme", "tolerance", "max_iterations", "anderson_depth", "mixing",
                         "mutual_induction", "time_step_factor", "noise", "far_field_theta",
                         "skip_unchanged", "near_field", "backend", "threads"});
  SolverSettings s;
  RelaxOptions& o = s.relax;
  r.optional(v, "scheme", path, [&](const json& x, const std::string& p) {
    o.scheme = r.choice(x, p, {"two_level", "paper"}) == "paper" ? RelaxScheme::paper : RelaxScheme::two_level;
  });
  r.optional(v, "tolerance", path, [&](const json& x, const std::string& p) { o.tolerance = r.positive(x, p); });
  r.optional(v, "max_iterations", path, [&](const json& x, const std::string& p) {
    o.max_iterations = r.int_value(x, p, 1, std::numeric_limits<int>::max());
  });
  r.optional(v, "anderson_depth", path,
             [&](const json& x, const std::string& p) { o.anderson_depth = r.int_value(x, p, 0, 100); });
  r.optional(v, "mixing", path, [&](const json& x, const std::string& p) { o.mixing = r.positive(x, p); });
  r.optional(v, "mutual_induction", path,
             [&](const json& x, const std::string& p) { o.mutual_induction = r.boolean(x, p); });
  r.optional(v, "time_step_factor", path,
             [&](const json& x, const std::string& p) { o.local.time_step_factor = r.positive(x, p); });
  r.optional(v, "noise", path,
             [&](const json& x, const std::string& p) { o.local.noise_ratio = r.non_negative(x, p); });
  r.optional(v, "skip_unchanged", path,
             [&](const json& x, const std::string& p) { o.skip_unchanged = r.boolean(x, p); });
  r.optional(v, "near_field", path,
             [&](const json& x, const std::string& p) { o.near_field = r.boolean(x, p); });
  r.optional(v, "far_field_theta", path, [&](const json& x, const std::string& p) {
    o.far_field_theta = r.in_range(x, p, 0.0, 0.9);
  });
  r.optional(v, "backend", path,
             [&](const json& x, const std::string& p) { s.backend = r.choice(x, p, {"cpu", "cuda", "auto"}); });
  r.optional(v, "threads", path, [&](const json& x, const std::string& p) {
    s.threads = r.int_value(x, p, 0, 65536);
  });
  return s;
}

SimulationSettings read_simulation(const SceneReader& r, const json& v, const std::string& path) {
  r.check_keys(v, path, {"time_step", "duration", "frame_rate", "contact_solver", "solver_iterations", "ground",
                         "ground_height", "contact", "linear_damping", "angular_damping",
                         "max_substeps", "stiffness_limit"});
  SimulationSettings s;
  r.optional(v, "time_step", path, [&](const json& x, const std::string& p) { s.time_step = r.positive(x, p); });
  r.optional(v, "duration", path, [&](const json& x, const std::string& p) { s.duration = r.non_negative(x, p); });
  r.optional(v, "frame_rate", path, [&](const json& x, const std::string& p) { s.frame_rate = r.positive(x, p); });
  r.optional(v, "contact_solver", path, [&](const json& x, const std::string& p) {
    s.contact_solver = r.choice(x, p, {"auto", "quick", "exact"});
  });
  r.optional(v, "solver_iterations", path, [&](const json& x, const std::string& p) {
    s.solver_iterations = r.int_value(x, p, 1, 1000000);
  });
  r.optional(v, "ground", path, [&](const json& x, const std::string& p) { s.ground = r.boolean(x, p); });
  r.optional(v, "ground_height", path,
             [&](const json& x, const std::string& p) { s.ground_height = r.number(x, p); });
  r.optional(v, "contact", path, [&](const json& c, const std::string& cp) {
    r.check_keys(c, cp, {"friction", "restitution", "softness", "erp", "rolling_friction"});
    ContactSettings& k = s.contact;
    r.optional(c, "friction", cp, [&](const json& x, const std::string& p) { k.friction = r.non_negative(x, p); });
    r.optional(c, "restitution", cp,
               [&](const json& x, const std::string& p) { k.restitution = r.in_range(x, p, 0.0, 1.0); });
    r.optional(c, "softness", cp, [&](const json& x, const std::string& p) { k.softness = r.non_negative(x, p); });
    r.optional(c, "erp", cp, [&](const json& x, const std::string& p) { k.erp = r.in_range(x, p, 0.0, 1.0); });
    r.optional(c, "rolling_friction", cp,
               [&](const json& x, const std::string& p) { k.rolling_friction = r.non_negative(x, p); });
  });
  r.optional(v, "linear_damping", path,
             [&](const json& x, const std::string& p) { s.linear_damping = r.non_negative(x, p); });
  r.optional(v, "angular_damping", path,
             [&](const json& x, const std::string& p) { s.angular_damping = r.non_negative(x, p); });
  r.optional(v, "max_substeps", path,
             [&](const json& x, const std::string& p) { s.max_substeps = r.int_value(x, p, 1, 100000); });
  r.optional(v, "stiffness_limit", path,
             [&](const json& x, const std::string& p) { s.stiffness_limit = r.positive(x, p); });
  return s;
}

CameraSettings read_camera(const SceneReader& r, const json& v, const std::string& path) {
  r.check_keys(v, path, {"position", "target", "up", "fov", "width", "height"});
  CameraSettings c;
  r.optional(v, "position", path, [&](const json& x, const std::string& p) { c.position = r.vec3(x, p); });
  r.optional(v, "target", path, [&](const json& x, const std::string& p) { c.target = r.vec3(x, p); });
  r.optional(v, "up", path, [&](const json& x, const std::string& p) { c.up = r.non_zero_vec3(x, p); });
  r.optional(v, "fov", path, [&](const json& x, const std::string& p) { c.fov_degrees = r.in_range(x, p, 1.0, 179.0); });
  r.optional(v, "width", path, [&](const json& x, const std::string& p) { c.width = r.int_value(x, p, 16, 8192); });
  r.optional(v, "height", path, [&](const json& x, const std::string& p) { c.height = r.int_value(x, p, 16, 8192); });
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

RenderSettings read_render(const SceneReader& r, const json& v, const std::string& path) {
  r.check_keys(v, path, {"field_lines", "field_line_count", "force_colors"});
  RenderSettings s;
  r.optional(v, "field_lines", path, [&](const json& x, const std::string& p) { s.field_lines = r.boolean(x, p); });
  r.optional(v, "field_line_count", path, [&](const json& x, const std::string& p) {
    s.field_line_count = r.int_value(x, p, 1, 100000);
  });
  r.optional(v, "force_colors", path, [&](const json& x, const std::string& p) { s.force_colors = r.boolean(x, p); });
  return s;
}

// ---- time line ---------------------------------------------------------------------

// The existing body named by the event's "body".
const BodyDescription& event_body(const SceneReader& r, const json& v, const std::string& path,
                                  const SceneDescription& scene, const BodyIndex& index) {
  const std::string p = member(path, "body");
  const std::string name = r.string(r.required(v, "body", path), p);
  const auto it = index.find(name);
  if (it == index.end()) r.fail(p, "no body named " + as_literal(name));
  return scene.bodies[it->second];
}

double event_end_time(const SceneReader& r, const json& v, const std::string& path, double time) {
  double end = time;
  r.optional(v, "end_time", path, [&](const json& x, const std::string& p) {
    end = r.number(x, p);
    if (end < time) r.fail(p, "must be >= time (" + format_number(time) + "), got " + format_number(end));
  });
  return end;
}

std::vector<Keyframe> read_keys(const SceneReader& r, const json& v, const std::string& path,
                                const BodyDescription& body) {
  if (!v.is_array() || v.empty()) r.fail(path, "must be a non-empty array of {time, position, orientation}");
  std::vector<Keyframe> keys;
  for (size_t k = 0; k < v.size(); ++k) {
    const std::string kp = element(path, k);
    r.check_keys(v[k], kp, {"time", "position", "orientation"});
    Keyframe key;
    key.time = r.non_negative(r.required(v[k], "time", kp), member(kp, "time"));
    if (!keys.empty() && !(key.time > keys.back().time))
      r.fail(member(kp, "time"), "key times must increase (previous key: " +
                                     format_number(keys.back().time) + ")");
    key.position = body.position;
    key.orientation = body.orientation;
    r.optional(v[k], "position", kp, [&](const json& x, const std::string& p) { key.position = r.vec3(x, p); });
    r.optional(v[k], "orientation", kp,
               [&](const json& x, const std::string& p) { key.orientation = r.quaternion(x, p); });
    keys.push_back(key);
  }
  return keys;
}

TimelineEvent read_event(const SceneReader& r, const json& v, const std::string& path,
                         const SceneDescription& scene, const BodyIndex& index) {
  using Kind = TimelineEvent::Kind;
  r.require_object(v, path);
  const std::string action =
      r.choice(r.required(v, "action", path), member(path, "action"),
               {"add", "remove", "scale_magnetization", "mutual_induction", "external_field", "keyframes"});
  TimelineEvent e;
  const auto read_time = [&] {
    e.time = r.non_negative(r.required(v, "time", path), member(path, "time"));
    e.end_time = e.time;
  };
  if (action == "add" || action == "remove") {
    r.check_keys(v, path, {"time", "action", "body"});
    e.kind = action == "add" ? Kind::add_body : Kind::remove_body;
    read_time();
    e.body = event_body(r, v, path, scene, index).name;
  } else if (action == "scale_magnetization") {
    r.check_keys(v, path, {"time", "action", "body", "to", "end_time"});
    e.kind = Kind::scale_magnetization;
    read_time();
    const BodyDescription& body = event_body(r, v, path, scene, index);
    e.body = body.name;
    const Material& material = scene.materials.at(body.material);
    const SoftMaterial* soft = std::get_if<SoftMaterial>(&material);
    const bool electromagnet = soft && norm(soft->coil_field) > 0.0;
    if (!std::holds_alternative<PermanentMaterial>(material) && !electromagnet)
      r.fail(member(path, "body"), "body " + as_literal(e.body) +
                                       " is neither a permanent magnet nor an electromagnet (material " +
                                       as_literal(body.material) + ")");
    e.value = r.number(r.required(v, "to", path), member(path, "to"));
    e.end_time = event_end_time(r, v, path, e.time);
  } else if (action == "mutual_induction") {
    r.check_keys(v, path, {"time", "action", "enabled"});
    e.kind = Kind::mutual_induction;
    read_time();
    e.enabled = r.boolean(r.required(v, "enabled", path), member(path, "enabled"));
  } else if (action == "external_field") {
    r.check_keys(v, path, {"time", "action", "field", "end_time"});
    e.kind = Kind::external_field;
    read_time();
    e.field = r.vec3(r.required(v, "field", path), member(path, "field"));
    e.end_time = event_end_time(r, v, path, e.time);
  } else {
    r.check_keys(v, path, {"time", "action", "body", "keys"});
    e.kind = Kind::keyframes;
    const BodyDescription& body = event_body(r, v, path, scene, index);
    e.body = body.name;
    e.keys = read_keys(r, r.required(v, "keys", path), member(path, "keys"), body);
    e.time = e.keys.front().time;
    r.optional(v, "time", path, [&](const json& x, const std::string& p) { e.time = r.non_negative(x, p); });
    e.end_time = std::max(e.time, e.keys.back().time);
  }
  return e;
}

OutcomeDescription read_outcome(const SceneReader& r, const json& v, const std::string& path) {
  r.check_keys(v, path, {"name", "count_above", "time"});
  OutcomeDescription o;
  o.name = r.non_empty_string(r.required(v, "name", path), member(path, "name"));
  const std::string cp = member(path, "count_above");
  const json& c = r.required(v, "count_above", path);
  r.check_keys(c, cp, {"prefix", "height"});
  o.prefix = r.string(r.required(c, "prefix", cp), member(cp, "prefix"));
  o.height = r.number(r.required(c, "height", cp), member(cp, "height"));
  r.optional(v, "time", path, [&](const json& x, const std::string& p) { o.time = r.number(x, p); });
  return o;
}

// ---- the whole file --------------------------------------------------------------

SceneDescription read_scene(const SceneReader& r, const json& root) {
  SceneDescription scene;
  scene.file = r.file();
  r.check_keys(root, "", {"title", "gravity", "external_field", "cell_size", "seed", "materials",
                          "bodies", "solver", "simulation", "timeline", "camera", "render", "outcomes"});
  r.optional(root, "title", "", [&](const json& x, const std::string& p) { scene.title = r.string(x, p); });
  r.optional(root, "gravity", "", [&](const json& x, const std::string& p) { scene.gravity = r.vec3(x, p); });
  r.optional(root, "external_field", "",
             [&](const json& x, const std::string& p) { scene.external_field = r.vec3(x, p); });
  r.optional(root, "cell_size", "", [&](const json& x, const std::string& p) { scene.cell_size = r.non_negative(x, p); });
  r.optional(root, "seed", "", [&](const json& x, const std::string& p) {
    if (!x.is_number_unsigned() && !(x.is_number_integer() && x.get<long long>() >= 0))
      r.fail(p, "must be a non-negative integer");
    scene.seed = x.get<uint64_t>();
  });

  const json& materials = r.required(root, "materials", "");
  r.require_object(materials, "materials");
  for (const auto& [name, value] : materials.items()) {
    const std::string p = member("materials", name);
    if (name.empty()) r.fail(p, "a material name must not be empty");
    std::optional<std::array<double, 3>> color;
    scene.materials.emplace(name, read_material(r, value, p, color));
    if (color) scene.material_colors.emplace(name, *color);
  }

  const json& bodies = r.required(root, "bodies", "");
  if (!bodies.is_array() || bodies.empty()) r.fail("bodies", "must be a non-empty array of bodies");
  BodyIndex index;
  for (size_t b = 0; b < bodies.size(); ++b) {
    scene.bodies.push_back(read_body(r, bodies[b], element("bodies", b), scene, index));
    index.emplace(scene.bodies.back().name, b);
  }

  r.optional(root, "solver", "", [&](const json& x, const std::string& p) { scene.solver = read_solver(r, x, p); });
  r.optional(root, "simulation", "",
             [&](const json& x, const std::string& p) { scene.simulation = read_simulation(r, x, p); });
  r.optional(root, "timeline", "", [&](const json& x, const std::string& p) {
    if (!x.is_array()) r.fail(p, "must be an array of events");
    for (size_t i = 0; i < x.size(); ++i) scene.timeline.push_back(read_event(r, x[i], element(p, i), scene, index));
  });
  r.optional(root, "camera", "", [&](const json& x, const std::string& p) { scene.camera = read_camera(r, x, p); });
  r.optional(root, "render", "", [&](const json& x, const std::string& p) { scene.render = read_render(r, x, p); });
  r.optional(root, "outcomes", "", [&](const json& x, const std::string& p) {
    if (!x.is_array()) r.fail(p, "must be an array of outcomes");
    std::set<std::string> names;
    for (size_t i = 0; i < x.size(); ++i) {
      scene.outcomes.push_back(read_outcome(r, x[i], element(p, i)));
      if (!names.insert(scene.outcomes.back().name).second)
        r.fail(member(element(p, i), "name"), "another outcome is already named " +
                                                  as_literal(scene.outcomes.back().name));
    }
  });
  return scene;
}

}  // namespace

SceneDescription parse_scene(const std::string& json_text, const std::string& file) {
  PathTracker tracker(file);
  if (!json::sax_parse(json_text, &tracker)) {
    const std::string what = without_exception_tag(tracker.error().value_or("syntax error"));
    // 406: a number too large for a double (1e999); JSON has no infinity.
    if (tracker.error_id() == 406) throw SceneError(file, tracker.path(), what + " (numbers must be finite)");
    const std::string where = tracker.path();
    throw SceneError(file, "", "invalid JSON: " + what + (where.empty() ? "" : " (while reading " + where + ")"));
  }
  json root;
  try {
    root = json::parse(json_text);  // the text the first pass accepted
  } catch (const json::exception& e) {
    throw SceneError(file, "", "invalid JSON: " + without_exception_tag(e.what()));
  }
  if (!root.is_object()) throw SceneError(file, "", "the scene must be a JSON object {...}");
  return read_scene(SceneReader(file), root);
}

SceneDescription load_scene(const std::string& path) {
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
  return parse_scene(text, path);
}

}  // namespace odemag
