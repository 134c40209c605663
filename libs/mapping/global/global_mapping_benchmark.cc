// Global optimisation at the size of a 4500-frame sequence (one keyframe every 3 frames), built
// in memory by the synthetic generator of the tests: fresh IMLS traversal + LM solve.
//   cmake -S . -B build -DJVL_BUILD_BENCHMARKS=ON && cmake --build build --target
//   global_mapping_benchmark && build/bin/global_mapping_benchmark
#include <benchmark/benchmark.h>

#include "core/timer.h"
#include "mapping/global/global_mapping.h"
#include "mapping/global/global_synthetic.h"

namespace {

using namespace jvl;

void BM_Global4500Frames(benchmark::State& state) {
  mapping::testing::SyntheticGlobalOptions so;
  so.keyframes = 1500;
  so.frames_per_keyframe = 3;
  so.yaw_drift = 0.01 * M_PI / 180.0;
  so.biased_local = false;
  const auto syn = mapping::testing::MakeSyntheticGlobal(so);
  size_t scan_points = 0;
  for (const auto& s : syn.input.scans) scan_points += s.points.size();
  state.counters["scan_points"] = static_cast<double>(scan_points);
  auto o = mapping::GlobalMappingOptions::EveryObservation();
  o.solve.threads = static_cast<int>(state.range(0));
  for (auto _ : state) {
    const auto r = mapping::OptimizeGlobal(syn.input, o);
    state.counters["iterations"] = r.total_iterations;
    const auto ape = mapping::testing::Ape(syn.truth, r.keyframes);
    const auto ape_prior = mapping::testing::Ape(syn.truth, syn.prior);
    state.counters["ape_m"] = ape.translation_m;
    state.counters["ape_prior_m"] = ape_prior.translation_m;
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
