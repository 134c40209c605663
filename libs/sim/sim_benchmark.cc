// Generation rate of the simulator (frames/s) on the default urban world.
#include <benchmark/benchmark.h>

#include "sim/sequence.h"

namespace {

const jvl::sim::World& DemoWorld() {
  static const auto world = jvl::sim::BuildWorld(jvl::sim::SequenceOptions());
  return *world;
}

void BM_BuildWorld(benchmark::State& state) {
  for (auto _ : state) benchmark::DoNotOptimize(jvl::sim::BuildWorld(jvl::sim::SequenceOptions()));
}
BENCHMARK(BM_BuildWorld)->Unit(benchmark::kMillisecond);

// One full frame (scan + image + GT VPs), frames spread over the route.
void BM_SimulateFrame(benchmark::State& state) {
  const auto& world = DemoWorld();
  int64_t k = 0;
  for (auto _ : state) {
    benchmark::DoNotOptimize(jvl::sim::SimulateFrame(world, (k * 37) % 500));
    ++k;
  }
  state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_SimulateFrame)->Unit(benchmark::kMillisecond);

// The whole demo sequence in memory on 1 and 2 threads (no disk writes).
void BM_GenerateSequence(benchmark::State& state) {
  const auto& world = DemoWorld();
  for (auto _ : state) {
    jvl::sim::GenerateSequence(world, static_cast<int>(state.range(0)),
                               [](jvl::sim::SimFrame&& f) { benchmark::DoNotOptimize(f.scan); });
  }
  state.SetItemsProcessed(state.iterations() * static_cast<int64_t>(world.ground_truth.size()));
}
BENCHMARK(BM_GenerateSequence)->Arg(2)->Unit(benchmark::kSecond)->Iterations(1)->UseRealTime();

}  // namespace

BENCHMARK_MAIN();
