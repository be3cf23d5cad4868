// Cost of one field evaluation of each current source (magnetics/sources/coil.h),
// Google Benchmark, ns per evaluation, one thread: the closed forms (loop,
// segment, arc, solenoid sheet) and the quadratures over a cross-section (a
// circular coil, the TEAM 20 rounded-rectangle coil) at points off and in
// the copper. docs/model.md "Current sources (coils)" quotes the numbers.
#include <benchmark/benchmark.h>

#include <cmath>
#include <vector>

#include "magnetics/sources/coil.h"
#include "tests/support/team20.h"

namespace odemag {
namespace {

// Points spread over a box around the source (fixed pseudo-random sequence).
std::vector<Vec3> points(double half, double z0, int n) {
  std::vector<Vec3> p;
  for (int i = 0; i < n; ++i) {
    const double a = std::fmod(0.754877666 * (i + 1), 1.0), b = std::fmod(0.569840291 * (i + 1), 1.0),
                 c = std::fmod(0.438579 * (i + 1), 1.0);
    p.push_back({half * (2 * a - 1), half * (2 * b - 1), z0 + half * (2 * c - 1)});
  }
  return p;
}

void Field(benchmark::State& bench, const CoilSource& source, const std::vector<Vec3>& at) {
  size_t i = 0;
  for (auto _ : bench) {
    benchmark::DoNotOptimize(coil_field_H(source, at[i]));
    i = (i + 1) % at.size();
  }
}

// Points near a source of size ~0.05 m, and TEAM 20 pole cells (inside the
// coil's hole, |x| < 12.5 mm, |y| < 5 mm).
const std::vector<Vec3>& near_points() {
  static const std::vector<Vec3> p = points(0.08, 0.0, 1024);
  return p;
}
const std::vector<Vec3>& pole_points() {
  static const std::vector<Vec3> p = [] {
    std::vector<Vec3> q = points(1.0, 0.0, 1024);
    for (Vec3& x : q) x = {0.0125 * x.x, 0.005 * x.y, 0.075 + 0.049 * x.z};
    return q;
  }();
  return p;
}
const std::vector<Vec3>& copper_points() {  // inside the TEAM 20 winding
  static const std::vector<Vec3> p = [] {
    std::vector<Vec3> q = points(1.0, 0.0, 1024);
    for (Vec3& x : q) x = {0.0195 + 0.009 * (1 + x.x), 0.014 * x.y, 0.075 + 0.048 * x.z};
    return q;
  }();
  return p;
}

void Loop(benchmark::State& b) { Field(b, CircularLoop{{}, {0, 0, 1}, 0.03, 1.0, 1}, near_points()); }
void Segment(benchmark::State& b) { Field(b, StraightSegment{{-0.03, 0, 0}, {0.03, 0.01, 0}, 1.0, 1}, near_points()); }
void QuarterArc(benchmark::State& b) {
  Field(b, Arc{{}, {0, 0, 1}, 0.03, {1, 0, 0}, 0.5 * 3.14159265358979, 1.0, 1}, near_points());
}
void SolenoidSheet(benchmark::State& b) { Field(b, Solenoid{{}, {0, 0, 1}, 0.03, 0.05, 1.0, 100}, near_points()); }
void ThickCircularCoil(benchmark::State& b) {
  CircularCoil c{{}, {0, 0, 1}, 0.02, 0.03, 0.05, 1.0, 100};
  c.quadrature_order = static_cast<int>(b.range(0));
  Field(b, c, near_points());
}
void Team20Coil_PoleCells(benchmark::State& b) {
  RoundedRectangleCoil c = team20::coil(1000.0);
  c.quadrature_order = static_cast<int>(b.range(0));
  Field(b, c, pole_points());
}
void Team20Coil_InTheCopper(benchmark::State& b) {
  RoundedRectangleCoil c = team20::coil(1000.0);
  c.quadrature_order = static_cast<int>(b.range(0));
  Field(b, c, copper_points());
}

BENCHMARK(Loop);
BENCHMARK(Segment);
BENCHMARK(QuarterArc);
BENCHMARK(SolenoidSheet);
BENCHMARK(ThickCircularCoil)->Arg(4)->Arg(8);
BENCHMARK(Team20Coil_PoleCells)->Arg(4)->Arg(6)->Arg(8);
BENCHMARK(Team20Coil_InTheCopper)->Arg(8);

}  // namespace
}  // namespace odemag

BENCHMARK_MAIN();
