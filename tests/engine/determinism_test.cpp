// Determinism on the CPU backend: the same scene run twice gives bit-identical
// states, with one thread and with two (every cell's field is summed by one
// thread in a fixed order, and per-body sums run serially), and a pinned hash
// of the final state per scene catches any change to the numbers.
//
// What changes the pinned hashes legitimately: any change to the physics or
// its arithmetic (a formula, a tolerance, the order of a sum), to a scene
// file, to ODE's version, to the compiler or its flags (-march=native picks
// AVX-512 or not, and FMA contraction). The hashes are pinned for the
// reference build (GCC 12, x86-64 with AVX-512, -O3 -march=native via
// ODEMAG_NATIVE); on any other build the pinned-hash test is skipped with the
// hash it computed, while the run-to-run and thread-count tests still run.
// After a deliberate change, run build/bin/engine_determinism_test and copy
// the hashes it prints here.
//
// Each re-pinning is recorded with its reason in the commit that makes it.
#include <gtest/gtest.h>

#include <cstdint>
#include <cstdio>
#include <cstring>
#include <string>

#include "odemag/scene.h"
#include "odemag/simulation.h"
#include "magnetics/model/backend.h"
#include "engine/simulation/rigid_world.h"

namespace odemag {
namespace {

std::string scene_path(const std::string& name) {
  return std::string(ODEMAG_SOURCE_DIR) + "/demos/scenes/" + name + ".json";
}

// FNV-1a over the bytes of every double of the state.
struct StateHash {
  uint64_t h = 1469598103934665603ULL;
  void add(double x) {
    unsigned char b[sizeof x];
    std::memcpy(b, &x, sizeof x);
    for (unsigned char c : b) h = (h ^ c) * 1099511628211ULL;
  }
  void add(const Vec3& v) {
    add(v.x);
    add(v.y);
    add(v.z);
  }
};

// Runs `name` for `duration` s with `threads` threads and hashes every body's
// pose, velocities, moment, force and torque.
uint64_t run_and_hash(const std::string& name, double duration, int threads) {
  Simulation sim(load_scene(scene_path(name)), make_cpu_backend(threads));
  sim.advance_to(duration);
  StateHash hash;
  for (int b = 0; b < sim.world().body_count(); ++b) {
    const BodyPose pose = sim.world().pose(b);
    for (const auto& row : pose.rotation.m)
      for (double x : row) hash.add(x);
    hash.add(pose.position);
    hash.add(sim.world().velocity(b));
    hash.add(sim.world().angular_velocity(b));
    hash.add(sim.magnetics().moment(b));
    hash.add(sim.magnetics().force(b));
    hash.add(sim.magnetics().torque(b));
  }
  return hash.h;
}

struct Case {
  const char* scene;
  double duration;  // s: long enough for contacts, induction and remanence to matter
  uint64_t pinned;  // reference build (see the top of the file)
};

const Case kCases[] = {
    {"ball_chain", 1.5, 0x81a03f7e8f6a94e6ULL},
    {"iron_plate", 1.7, 0x796c9db197b5703aULL},
    {"thin_iron_plate", 1.0, 0xaededbfcbc1c8d29ULL},
    {"nail_and_balls", 3.2, 0x64d0ce9460d9562cULL},
};

// Set by tests/engine/CMakeLists.txt for a Release build with
// ODEMAG_NATIVE on, no sanitizers, GCC 12; the hashes are checked only there
// and only on an AVX-512 x86-64 machine.
bool reference_build() {
#if defined(ODEMAG_REFERENCE_BUILD) && defined(__AVX512F__) && defined(__x86_64__)
  return true;
#else
  return false;
#endif
}

TEST(Determinism, SameSceneTwiceAndWithOneOrTwoThreadsIsBitIdentical) {
  for (const Case& c : kCases) {
    const uint64_t one = run_and_hash(c.scene, c.duration, 1);
    EXPECT_EQ(one, run_and_hash(c.scene, c.duration, 1)) << c.scene << ": two runs on one thread differ";
    EXPECT_EQ(one, run_and_hash(c.scene, c.duration, 2)) << c.scene << ": one and two threads differ";
  }
}

TEST(Determinism, StateHashesArePinned) {
  for (const Case& c : kCases) {
    const uint64_t h = run_and_hash(c.scene, c.duration, 1);
    std::printf("    {\"%s\", %g, 0x%016llxULL},\n", c.scene, c.duration, static_cast<unsigned long long>(h));
    if (reference_build()) {
      EXPECT_EQ(h, c.pinned) << c.scene << ": state hash changed (see the top of determinism_test.cpp)";
    }
  }
  if (!reference_build()) GTEST_SKIP() << "not the reference build (Release, -march=native with AVX-512, GCC 12, no sanitizers): hashes printed, not compared";
}

}  // namespace
}  // namespace odemag
