// Counter-based random numbers: a value depends only on (seed, stream, counter),
// never on thread scheduling, so runs are reproducible with any thread count.
#pragma once

#include <cstdint>

#include "magnetics/kernels/hd.h"
#include "odemag/vec3.h"

namespace odemag {

// SplitMix64 finaliser: a bijective 64-bit mix with good avalanche.
ODEMAG_HD uint64_t mix64(uint64_t z) {
  z += 0x9e3779b97f4a7c15ULL;
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
  return z ^ (z >> 31);
}

ODEMAG_HD uint64_t hash_key(uint64_t seed, uint64_t a, uint64_t b, uint64_t c) {
  return mix64(seed ^ mix64(a ^ mix64(b ^ mix64(c))));
}

// Uniform double in [0, 1) from a 64-bit key.
ODEMAG_HD double unit_interval(uint64_t key) {
  return static_cast<double>(key >> 11) * (1.0 / 9007199254740992.0);
}

// Uniformly distributed unit vector (Archimedes: z uniform in [-1, 1], azimuth uniform).
ODEMAG_HD Vec3 random_unit_vector(uint64_t key) {
  const double u = unit_interval(mix64(key));
  const double v = unit_interval(mix64(key + 0x632be59bd9b4e019ULL));
  const double z = 2.0 * u - 1.0;
  const double rho = sqrt(fmax(0.0, 1.0 - z * z));
  const double phi = 2.0 * 3.14159265358979323846 * v;
  return {rho * cos(phi), rho * sin(phi), z};
}

}  // namespace odemag
