// Builds the magnetic model and state of a scene. Model body b is scene body b
// (inert bodies are bodies without cells), so indices agree everywhere.
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "odemag/scene.h"
#include "gpu/backend_choice.h"
#include "magnetics/model/backend.h"
#include "magnetics/model/model.h"
#include "magnetics/relax/relax.h"
#include "magnetics/model/state.h"

namespace odemag {

// The magnetic system of a scene: its model and its state. ("Scene" names one
// type, the scene file's SceneDescription; the renderer draws RenderFrames.)
struct MagneticSystem {
  MagneticModel model;
  MagneticState state;  // poses from the scene, bodies with present=false inactive
  std::vector<std::vector<RefinedZone>> contact_zones;  // by body (scene_contact_zones)
};

// Throws SceneError naming the body when a shape or material is rejected.
MagneticSystem build_magnetic_system(const SceneDescription& scene);

// What the time line does at t = 0 (docs/scene-format.md "timeline"), applied
// to a system built by build_magnetic_system and to the relaxation options:
// events at time 0 that take no time (add, remove, scale_magnetization,
// mutual_induction, external_field) and the keyframed bodies' poses at t = 0.
// `odemag solve` and `field` report this state; a Simulation starts from it
// (its constructor applies the same events to the ODE world).
void apply_events_at_start(const SceneDescription& scene, MagneticSystem& system, RelaxOptions& options);

// Cells the scene's magnetic model has, counted without building it (a
// lattice body's tensors take time quadratic in its cells): every body,
// present or added later. responsive: soft and recoil cells, which the
// relaxation solves for; magnetized: those and the fixed magnets' cells.
struct SceneCellCounts {
  double responsive = 0.0, magnetized = 0.0;
  // Cell pairs that one evaluation of the responsive field sums.
  double pairs_per_field_evaluation() const { return responsive * magnetized; }
};
SceneCellCounts count_scene_cells(const SceneDescription& scene);

// Where the scene's cells are known to be poor and the program cannot make
// them better itself, one line per body naming it, the reason and what to
// change: a responsive body under kMinVolumeShareExtent cells across along
// some axis keeps centre-inside cells (docs/model.md "Cells"), which keep its
// moment but not where its material is.
std::vector<std::string> scene_notices(const SceneDescription& scene);

// The refined contact zones of every body, indexed as scene.bodies
// (docs/model.md "Refined contact zones"), with solver.contact_refinement, at
// the scene's poses (the zones stay where they are in the body frame):
// contact_zones of every body. Empty lists otherwise.
std::vector<std::vector<RefinedZone>> scene_contact_zones(const SceneDescription& scene);
// Whether body b may get refined contact zones: a lattice ball or box
// (volume-share cells) of a material with positive susceptibility. Does not
// look at solver.contact_refinement.
bool takes_contact_zones(const SceneDescription& scene, int b);

// The contact points of scene_contact_zones at the given poses (indexed as
// scene.bodies): ball b's surface points, body frame, towards each other
// magnetized or soft body (active, when active is not empty) whose nearest
// point lies within kContactRefinementGap radii of its surface. Empty unless
// b is a lattice ball of a material with positive susceptibility; does not
// look at solver.contact_refinement.
std::vector<Vec3> contact_points(const SceneDescription& scene, const std::vector<BodyPose>& poses,
                                 const std::vector<uint8_t>& active, int b);
inline constexpr double kContactRefinementGap = 0.5;
// Two boxes facing each other across a gap of at most this many cells of the
// refined box get a zone on its facing patch (contact_zones).
inline constexpr double kBoxContactGap = 1.0;

// Body b's zones at the given poses: a ball's one at each of its
// contact_points, with default_refinement_radii; a box's one on each patch of
// its faces that another magnetized or soft box faces across a gap of at most
// kBoxContactGap cells (not where they touch: the near field joins touching
// aligned lattices), refined to h/2 within the patch's half diagonal of its
// centre. scene_contact_zones is this at the scene's poses;
// Simulation::follow_contact_zones at a step's end.
std::vector<RefinedZone> contact_zones(const SceneDescription& scene,
                                       const std::vector<BodyPose>& poses,
                                       const std::vector<uint8_t>& active, int b);
// A run moves a ball's zones (Simulation::follow_contact_zones) once one of
// its contact points lies farther than this many cell sizes h from every
// zone point. Two balls 0.05 R apart at R/h 4.5: zones left 0.39 h and
// 0.79 h behind the contact gave force errors of +1.1% and +1.2% (moved:
// +0.2%, -1.6%), 2.4 h and 3.5 h behind +8.0% and +25.9% (moved: +1.0%,
// +0.8%) (docs/validation.md section 5, refined_contact --rolling).
inline constexpr double kContactZoneFollowDistance = 0.5;

// The body's pose in the scene description.
BodyPose scene_pose(const BodyDescription& body);


// "" or the first of the scene's CPU-only features, as a user reads it: graded
// cells (solver.graded_cells), refined contact zones (solver.contact_refinement
// with a body that takes_contact_zones: a run may give it zones later), a
// B-H curve (materials.NAME.bh_curve).
std::string cpu_only_feature(const SceneDescription& scene);

}  // namespace odemag
