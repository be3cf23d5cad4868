// Small magnetic systems of the tests and the benchmarks (tests/support/):
// soft materials, a model with its state and a CPU backend, and relaxation
// options.
#pragma once

#include <memory>

#include "magnetics/model/backend.h"
#include "magnetics/model/model.h"
#include "magnetics/model/state.h"
#include "magnetics/relax/relax.h"

namespace odemag::test_support {

// A soft material linear up to saturation: M_s (A/m) and chi.
inline SoftMaterial soft_material(double saturation, double susceptibility) {
  SoftMaterial m;
  m.saturation = saturation;
  m.susceptibility = susceptibility;
  return m;
}

// A remanent steel: soft_material with the anisotropy field H_K (A/m) along
// the body's z axis and n moments per cell.
inline SoftMaterial anisotropic_steel(double saturation, double susceptibility, double anisotropy_field,
                                      int moments_per_cell) {
  SoftMaterial m = soft_material(saturation, susceptibility);
  m.anisotropy_field = anisotropy_field;
  m.easy_axis = {0, 0, 1};
  m.moments_per_cell = moments_per_cell;
  return m;
}

// Relaxation options with the given tolerance, near field on or off.
inline RelaxOptions relax_options(double tolerance, bool near_field = true) {
  RelaxOptions o;
  o.tolerance = tolerance;
  o.near_field = near_field;
  return o;
}

// A magnetic model, its state and a CPU backend on `threads` threads (0: all).
struct MagneticSetup {
  MagneticModel model;
  MagneticState state;
  std::unique_ptr<MagneticBackend> backend;
  explicit MagneticSetup(int threads = 1) : backend(make_cpu_backend(threads)) {}
};

}  // namespace odemag::test_support
