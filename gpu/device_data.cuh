// Data the CUDA kernels read, and the launchers of the kernels (one kernel per
// .cu file, as MuMax3 does). Everything here is plain data: the backend
// (cuda_backend.cu) gathers it from the model and state on the host; the
// kernels call the shared host/device formulas of magnetics/ (kernels.h,
// llg.h, cell_field.h), so both backends evaluate one copy of each formula.
//
// Cell lists, as in the CPU backend (magnetics/relax/cpu_backend.cpp), ordered by
// body and, within a body, by cell:
//   responsive: cells of active soft and recoil bodies (targets and sources of
//               the responsive field, the cells relax_cells updates);
//   fixed:      cells of active fixed permanent magnets (sources of fixed_field);
//   all:        cells of every active magnetic body (forces).
#pragma once

#include <cuda_runtime.h>

#include <cstdint>

#include "magnetics/kernels/cell_field.h"
#include "magnetics/kernels/llg.h"
#include "odemag/vec3.h"

namespace odemag::gpu {

// Threads per block of every kernel; the tiled kernels load one source per
// thread into shared memory per tile, so a tile has this many sources.
inline constexpr int kThreadsPerBlock = 128;

inline int block_count(int items) { return (items + kThreadsPerBlock - 1) / kThreadsPerBlock; }

// World position of a cell and its contact radius (CellSet::contact_radius;
// the contact distance of a pair of cells of different bodies is the sum of
// their contact radii, below which the bounded kernel applies; kernels.h).
struct alignas(32) CellPoint {
  double x, y, z, radius;
};

// One body at the current rigid step (indexed by the model's body index).
struct DeviceBody {
  Mat3 rotation;         // body frame -> world (state.pose)
  SoftCellParams soft;   // soft bodies: material of every cell (body frame)
  Vec3 remanent;         // recoil magnets: R (scale M_r), world
  double recoil;         // recoil magnets: chi_r
  long long table;       // first double of the body's offset tensors in the table array, -1: none
  int key_centre;        // table entry (in tensors) of offset zero: key(a) - key(b) + key_centre
  int cell_count;
  int kind;              // CellKind
};

// Lattice key of a cell: with it the intra-body table entry of the offset
// a - b is key(a) - key(b) + key_centre, the same entry as
// MagneticBody::offset_index(a, b) (the index is linear in a - b).
inline int lattice_key(int i, int j, int k, int extent_x, int extent_y) {
  return i + extent_x * (j + extent_y * k);
}

// mu = V M (world) and, when mu_body is not null, R^T mu (body frame); V the
// cell's own volume (CellSet::volumes).
struct CellMomentsArgs {
  int cells;
  const int* body;
  const DeviceBody* bodies;
  const double* volume;
  const Vec3* magnetization;
  Vec3* mu;
  Vec3* mu_body;  // may be null
};
void launch_cell_moments(const CellMomentsArgs& a, cudaStream_t stream);

// H = H_E + sum over fixed sources of the dipole field (fixed_field).
struct FixedFieldArgs {
  int targets;
  const CellPoint* target;
  int sources;
  const CellPoint* source;
  const Vec3* source_mu;
  Vec3 external;
  Vec3* H;
};
void launch_fixed_field(const FixedFieldArgs& a, cudaStream_t stream);

// Field of the responsive cells at each responsive cell: other bodies through
// the dipole kernel, the own body through the cached offset tensors
// (responsive_field; the host adds the boundary correction, add_boundary_field).
struct ResponsiveFieldArgs {
  int cells;
  const CellPoint* point;
  const int* body;
  const int* key;
  const Vec3* mu;       // world
  const Vec3* mu_body;  // body frame
  const DeviceBody* bodies;
  const double* tables;
  Vec3* H;
};
void launch_responsive_field(const ResponsiveFieldArgs& a, cudaStream_t stream);

// Counters of relax_cells, reduced over the cells with integer atomics
// (order-independent, so deterministic).
struct RelaxTotals {
  unsigned long long llg_steps;
  unsigned long long newton_steps;
  unsigned long long max_residual_bits;  // bits of the largest residual (>= 0 orders as integer; NaN above all)
};

// Local relaxation of every responsive cell under its frozen H_A (relax_cells).
struct RelaxCellsArgs {
  int cells;
  const int* body;
  const int* cell;    // model cell index (noise stream)
  const int* moment;  // first moment in moments / hc_prev, -1 for recoil magnets
  const DeviceBody* bodies;
  const Vec3* applied;  // H_A, world
  Vec3* magnetization;  // out, world
  Vec3* moments;        // body frame
  Vec3* hc_prev;
  uint8_t* history;
  uint64_t* counter;
  uint64_t seed;
  LocalRelaxOptions options;
  RelaxTotals* totals;
};
void launch_relax_cells(const RelaxCellsArgs& a, cudaStream_t stream);

// Per cell: force on it and field at it from every cell of the other bodies.
struct CellForcesArgs {
  int cells;
  const CellPoint* point;
  const int* body;
  const Vec3* mu;
  Vec3* force;
  Vec3* field;
};
void launch_cell_forces(const CellForcesArgs& a, cudaStream_t stream);

// H at points from H_E and every probe cell (MagneticBackend::probe_field).
struct ProbeFieldArgs {
  int points;
  const Vec3* point;
  int cells;
  const ProbeCell* cell;
  Vec3 external;
  Vec3* H;
};
void launch_probe_field(const ProbeFieldArgs& a, cudaStream_t stream);

// cudaSuccess when the current device can run this build's kernels (an sm_90
// image or compute_90 PTX the driver can compile for it).
cudaError_t check_kernel_image();

}  // namespace odemag::gpu
