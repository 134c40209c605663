// Global optimisation at the size of a 4500-frame sequence (one keyframe every 3 frames), built
// in memory by the synthetic generator of the tests: fresh IMLS traversal + LM solve.
//   cmake -S . -B build -DJVL_BUILD_BENCHMARKS=ON && cmake --build build --target
//   global_mapping_benchmark && build/bin/global_mapping_benchmark
#include <benchmark/benchmark.h>

#include "core/timer.h"
#include "mapping/global_mapping.h"
#include "mapping/global_synthetic.h"

namespace {

using namespace jvl;

void BM_Global4500Frames(benchmark::State& state) {
  mapping::testing::SyntheticGlobalOptions so;
  so.keyframes = 1500;
  so.frames_per_keyframe = 3;
  so.yaw_drift = 0.01 * M_PI / 180.0;
  const auto syn = mapping::testing::MakeSyntheticGlobal(so);
  mapping::GlobalMappingOptions o;
  o.solve.threads = static_cast<int>(state.range(0));
  for (auto _ : state) {
    const auto r = mapping::OptimizeGlobal(syn.input, o);
    state.counters["iterations"] = r.solve.iterations;
    state.counters["traversal_s"] = r.traversal_time_s;
    state.counters["solve_s"] = r.solve.time_s;
    state.counters["visual"] = static_cast<double>(r.solve.before.visual.count);
    state.counters["imls"] = static_cast<double>(r.solve.before.imls.count);
    state.counters["directions"] = static_cast<double>(r.solve.before.direction.count);
    state.counters["usable"] = r.solve.usable ? 1 : 0;
  }
  state.counters["peak_rss_MiB"] = static_cast<double>(PeakMemoryBytes()) / (1 << 20);
}
BENCHMARK(BM_Global4500Frames)->Arg(2)->Iterations(1)->Unit(benchmark::kSecond)->UseRealTime();

}  // namespace

BENCHMARK_MAIN();
