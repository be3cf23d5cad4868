// odemag: magnets for the Open Dynamics Engine (docs/embedding.md). The one
// header of the public API:
//   vec3.h, constants.h   vectors, rotations, poses, SI constants
//   shape.h, material.h   body shapes and magnetic materials
//   coil.h                current sources (coils)
//   settings.h            the relaxation, the step loop, the backends
//   magnetic_forces.h     magnetics for the bodies of your own ODE world
//   stepper.h             the step loop in substeps (MagneticStepper)
//   scene.h               scene files (load_scene)
//   simulation.h          a scene in motion (Simulation)
//   solve.h               a scene relaxed at t = 0: forces, moments, fields
#pragma once

#include "odemag/coil.h"
#include "odemag/constants.h"
#include "odemag/magnetic_forces.h"
#include "odemag/material.h"
#include "odemag/scene.h"
#include "odemag/settings.h"
#include "odemag/shape.h"
#include "odemag/simulation.h"
#include "odemag/solve.h"
#include "odemag/stepper.h"
#include "odemag/vec3.h"
