// The dense pair kernels of the CPU backend (Google Benchmark): one
// responsive-field evaluation (the exo field of N one-cell soft balls on each
// other, N^2 pairs) and one force evaluation (force and field per pair), in
// ns per pair and GFLOP/s. Flop counts per pair, counting a division and a
// square root as one each: field 33 (offset 3, r^2 5, coefficients 12, r.mu
// 5, field 8), force and field 57. docs/benchmarks.md relates them to the
// machine's peak.
#include <benchmark/benchmark.h>

#include <cmath>

#include "benchmarks/bench_common.h"
#include "magnetics/model/backend.h"
#include "magnetics/kernels/rng.h"

namespace odemag {
namespace {

constexpr double kFieldFlops = 33.0, kForceFlops = 57.0;

using Heap = bench::BallHeap;

void ResponsiveField(benchmark::State& bench) {
  const int n = static_cast<int>(bench.range(0)), threads = static_cast<int>(bench.range(1));
  Heap heap(n);
  auto backend = make_cpu_backend(threads);
  backend->begin_step(heap.model, heap.state);
  std::vector<Vec3> H(heap.model.cell_count());
  for (auto _ : bench) {
    backend->responsive_field(heap.model, heap.state, H);
    benchmark::DoNotOptimize(H.data());
  }
  const double pairs = static_cast<double>(n) * (n - 1);
  bench.counters["ns_per_pair"] = benchmark::Counter(pairs * 1e-9, benchmark::Counter::kIsIterationInvariantRate |
                                                                        benchmark::Counter::kInvert);
  bench.counters["GFLOPs"] = benchmark::Counter(pairs * kFieldFlops * 1e-9, benchmark::Counter::kIsIterationInvariantRate);
}

void Forces(benchmark::State& bench) {
  const int n = static_cast<int>(bench.range(0)), threads = static_cast<int>(bench.range(1));
  Heap heap(n);
  auto backend = make_cpu_backend(threads);
  backend->begin_step(heap.model, heap.state);
  for (auto _ : bench) {
    backend->forces(heap.model, heap.state);
    benchmark::DoNotOptimize(heap.state.force.data());
  }
  const double pairs = static_cast<double>(n) * (n - 1);
  bench.counters["ns_per_pair"] = benchmark::Counter(pairs * 1e-9, benchmark::Counter::kIsIterationInvariantRate |
                                                                        benchmark::Counter::kInvert);
  bench.counters["GFLOPs"] = benchmark::Counter(pairs * kForceFlops * 1e-9, benchmark::Counter::kIsIterationInvariantRate);
}

BENCHMARK(ResponsiveField)->ArgsProduct({{256, 1024, 4096}, {1, 2}})->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(Forces)->ArgsProduct({{256, 1024, 4096}, {1, 2}})->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace
}  // namespace odemag

BENCHMARK_MAIN();
