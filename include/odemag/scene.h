// Scene files (docs/scene-format.md documents every key). A SceneDescription is
// the validated, SI-unit content of one file: the demos, the tests, the
// benchmarks, Python and `odemag` all read scenes through it.
#pragma once

#include <array>
#include <map>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "odemag/coil.h"
#include "odemag/material.h"
#include "odemag/shape.h"
#include "odemag/settings.h"
#include "odemag/vec3.h"

namespace odemag {

// A bad scene: the file, the JSON key path (e.g. "bodies[2].shape.sphere")
// and what is wrong. what() reads "FILE: KEY: message".
class SceneError : public std::runtime_error {
 public:
  SceneError(std::string file, std::string key, std::string message);
  const std::string& file() const { return file_; }
  const std::string& key() const { return key_; }
  const std::string& message() const { return message_; }

 private:
  std::string file_, key_, message_;
};

struct Quaternion {
  double w = 1.0, x = 0.0, y = 0.0, z = 0.0;
};

struct BodyDescription {
  std::string name;
  Shape shape;
  std::string material;             // key into SceneDescription::materials
  Vec3 position;                    // centre of mass, world, m
  Quaternion orientation;           // body -> world
  Vec3 velocity;                    // m/s
  Vec3 angular_velocity;            // rad/s
  bool fixed = false;               // not moved by dynamics (may be moved by keyframes)
  double density = 1000.0;          // kg/m^3
  std::optional<double> cell_size;  // overrides the scene's cell_size
  bool present = true;              // false: added later by an "add" event
  std::optional<std::array<double, 3>> color;  // RGB 0..1, overrides the material colour
  std::vector<CoilSource> coils;    // current sources carried by the body, body frame (MagneticModel::add_coil)
};

// An ODE joint between two bodies, or between one body and the world
// (docs/scene-format.md "joints"). Anchor and axis are in the world frame
// at the bodies' initial poses.
struct JointDescription {
  enum class Type { hinge, ball, slider, fixed };
  Type type = Type::hinge;
  std::vector<std::string> bodies;  // one (jointed to the world) or two
  Vec3 anchor;                      // m: hinge and ball
  Vec3 axis{0.0, 0.0, 1.0};         // hinge and slider
  // Stops: hinge angle in rad (-pi..pi) from the initial pose, slider travel in m.
  std::optional<std::array<double, 2>> limits;
};

struct SolverSettings {
  RelaxOptions relax;          // scheme, tolerance, max_iterations, mutual_induction, ...
  BackendKind backend = BackendKind::automatic;  // "auto", "cpu", "cuda"
  int threads = 0;             // 0: all cores
  // Graded cells for responsive boxes (MagneticModel::set_graded_cells,
  // docs/model.md "Graded cells"); CPU backend only ("auto" then picks it).
  bool graded_cells = false;
  // Refined contact zones for lattice balls near other bodies at the scene's
  // poses (engine/simulation/magnetic_system.h scene_contact_zones, docs/model.md
  // "Refined contact zones"); CPU backend only.
  bool contact_refinement = true;
};

struct ContactSettings {
  double friction = 0.5;          // Coulomb mu
  double restitution = 0.1;       // bounce
  double softness = 1e-5;         // ODE CFM
  double erp = 0.2;               // ODE error reduction parameter
  // m: rolling resistance torque = this * normal force (ODE rho); 1e-5 m is
  // a rolling-resistance coefficient of 0.002 for a 5 mm steel ball.
  double rolling_friction = 1e-5;
  // m: spinning resistance torque, about the contact normal, = this * normal
  // force (ODE rhoN); below 0 (the default): rolling_friction.
  double spinning_friction = -1.0;
  double spinning() const { return spinning_friction < 0.0 ? rolling_friction : spinning_friction; }
};

struct SimulationSettings {
  double time_step = 0.004;   // rigid step, s
  double duration = 2.0;      // s
  double frame_rate = 30.0;   // frames written per simulated second
  // ODE's constraint solver: "exact" (dWorldStep, direct), "quick"
  // (dWorldQuickStep, iterative, solver_iterations sweeps) or "auto" (exact up
  // to 32 dynamic bodies, quick beyond). docs/simulation.md: with strong
  // magnetic forces pressing balls together quick throws some out at 3-7 m/s
  // where exact throws none, and for small scenes exact is also faster.
  ContactSolver contact_solver = ContactSolver::automatic;
  int solver_iterations = 30;
  bool ground = true;         // a ground plane z = ground_height
  double ground_height = 0.0;
  ContactSettings contact;
  double linear_damping = 0.0;
  double angular_damping = 0.0;
  // A rigid step is split into substeps, each with its own magnetic forces
  // and collision check, so that no free body moves more than a tenth of its
  // size per substep (no tunnelling) and the magnetic force is resolved in
  // time (omega h <= stiffness_limit, omega^2 = |F| / (m size)). 1 disables.
  int max_substeps = 64;
  double stiffness_limit = 1.0;  // bound on omega h for the magnetic force (see above)
  // When the magnetization is relaxed (MagneticSolve, docs/simulation.md
  // "Substeps"): "substep" or "moving".
  MagneticSolve magnetic_solve = MagneticSolve::substep;
};

// A keyframe of a scripted (kinematic) body.
struct Keyframe {
  double time = 0.0;
  Vec3 position;
  Quaternion orientation;
};

// Time-line events (docs/scene-format.md "timeline").
struct TimelineEvent {
  enum class Kind {
    add_body,             // body appears at `time`
    remove_body,          // body stops existing at `time`
    scale_magnetization,  // permanent magnet's M_r scaled from its value at `time` to `value` at `end_time`
    mutual_induction,     // switch mutual induction to `enabled`
    external_field,       // H_E ramps to `field` between `time` and `end_time`
    keyframes,            // body follows `keys` (linear position, slerp orientation)
  };
  Kind kind = Kind::remove_body;
  double time = 0.0;
  double end_time = 0.0;      // == time for instantaneous events
  std::string body;
  double value = 1.0;
  bool enabled = true;
  Vec3 field;
  std::vector<Keyframe> keys;
};

struct CameraSettings {
  Vec3 position{0.3, -0.3, 0.2};
  Vec3 target{0.0, 0.0, 0.05};
  Vec3 up{0.0, 0.0, 1.0};
  double fov_degrees = 40.0;
  int width = 640;
  int height = 480;
};

struct RenderSettings {
  bool field_lines = false;   // grey field lines traced from the solved field
  int field_line_count = 48;
  bool force_colors = false;  // bodies coloured by force magnitude (teal..yellow, docs/rendering.md)
};

// A number a run reports in its summary (docs/scene-format.md "outcomes").
struct OutcomeDescription {
  enum class Quantity {
    count_above,    // bodies named prefix* with their centre above height
    distance,       // between the centres of bodies[0] and bodies[1], m
    height,         // z of the body's centre, m
    speed,          // |v| of the body, m/s
    contact_count,  // contacts of the body in the last substep
    force,          // magnetic force on the body, N (component or magnitude)
    moment,         // the body's magnetic moment, A m^2 (component or magnitude)
  };
  std::string name;
  Quantity quantity = Quantity::count_above;
  std::string prefix;               // count_above
  double height = 0.0;              // count_above: m
  std::vector<std::string> bodies;  // the body; two for distance
  int component = -1;               // force, moment: 0, 1, 2 for x, y, z; -1: the magnitude
  double time = -1.0;               // s; when to evaluate; negative: at the end of the run
  // Over every step from `from` on: the largest, the smallest, the mean; or
  // none, the value at `time`.
  enum class Statistic { none, max, min, mean };
  Statistic statistic = Statistic::none;
  double from = 0.0;                // s; a statistic's first sample (steps at t >= from)
};

struct SceneDescription {
  std::string file;            // path the scene was read from (for messages)
  // What the loader changed or suspects (an inverted mesh turned outward,
  // a mesh of unlikely size), one line each naming the key; odemag prints them.
  std::vector<std::string> notices;
  std::string title;
  Vec3 gravity{0.0, 0.0, -9.81};
  Vec3 external_field;         // uniform H_E, A/m
  double cell_size = 0.0;      // lattice spacing h, m; 0: single cells
  uint64_t seed = 1;           // initial moment directions and noise
  std::map<std::string, Material> materials;
  std::map<std::string, std::array<double, 3>> material_colors;  // optional "color" per material
  std::vector<BodyDescription> bodies;
  std::vector<JointDescription> joints;
  SolverSettings solver;
  SimulationSettings simulation;
  std::vector<TimelineEvent> timeline;
  CameraSettings camera;
  RenderSettings render;
  std::vector<OutcomeDescription> outcomes;

  int find_body(const std::string& name) const;  // -1 when absent

  // Lattice spacing of body b: lattice_spacing(bodies[b], cell_size).
  double body_cell_size(int b) const;
};

// Lattice spacing of a body (docs/scene-format.md "Bodies"): its own cell_size if given;
// otherwise one cell for a sphere and the scene's cell_size for the rest.
double lattice_spacing(const BodyDescription& body, double scene_cell_size);

// Reads and validates a scene file. Throws SceneError (bad content, unknown
// key, wrong type, NaN, negative size, missing key, unknown material, ...).
SceneDescription load_scene(const std::string& path);
// Same, from JSON text; `file` is used in messages.
SceneDescription parse_scene(const std::string& json_text, const std::string& file);
}  // namespace odemag
